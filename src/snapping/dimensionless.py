"""The nondimensional numbers of a real line, one per physical mechanism that can cap its snap.

Each mechanism has a scale of its own; measured in the chain's units (length L, mass per
length lambda = M/L, gravity g) it is one number, and the ideal chain is the limit where
every number goes to zero (issue 24):

===================  =====================================  ==========================================
name                 definition                             mechanism
===================  =====================================  ==========================================
``beta``             EI / (lambda g L^3)                    bending stiffness EI [N m^2]
``stretching``       c / sqrt(g L),  c = sqrt(EA / lambda)  axial stiffness EA [N]: longitudinal waves
``drag_normal``      0.5 rho C_n d L / lambda               cross-flow air drag (diameter d)
``drag_tangential``  0.5 rho C_t pi d L / lambda            skin friction along the line
``end_mass``         M_end / (lambda L)                     a point mass at the free end
``link_scale``       h / L = 1 / N (graded: the smallest)   the links (the discreteness)
===================  =====================================  ==========================================

The bending and drag numbers are those of :func:`snapping.units.body_numbers` (the
coefficients the simulator's :class:`snapping.simulate.Body` takes: the drag per length
``0.5 rho C_n d |v_n| v_n`` normal and ``0.5 rho C_t (pi d) |v_t| v_t`` tangential, so
they are ``rho C d L / lambda`` times 1/2 and pi/2); they are computed there, once, and
only gathered here.

Example
-------
>>> n = line_numbers(1.0, 1.0, N=100, ei=0.01, ea=1e5, diameter=0.01)   # 1 m, 1 kg/m
>>> round(n["beta"], 8), round(n["stretching"], 4), n["link_scale"]
(0.00101937, 100.9638, 0.01)
"""

from __future__ import annotations

import math

from . import _validate as V
from . import units

__all__ = ["NUMBERS", "line_numbers", "number_rows"]

#: name -> (definition, mechanism), in the order they are printed
NUMBERS: dict[str, tuple[str, str]] = {
    "beta": ("EI/(lambda g L^3)", "bending"),
    "stretching": ("c/sqrt(g L), c = sqrt(EA/lambda)", "stretching (longitudinal wave speed)"),
    "drag_normal": ("0.5 rho C_n d L/lambda", "normal air drag"),
    "drag_tangential": ("0.5 rho C_t pi d L/lambda", "tangential air drag"),
    "end_mass": ("M_end/(lambda L)", "end mass"),
    "link_scale": ("h/L (1/N; graded links: the smallest)", "links"),
}


def line_numbers(length, mass, g: float = units.G_STANDARD, *, N=None, ei=0.0, ea=None, diameter=None,
                 air_density: float | None = None, cd_normal: float | None = None,
                 cd_tangential: float | None = None, end_mass: float | None = 0.0) -> dict:
    """The nondimensional numbers (:data:`NUMBERS`) of a line of ``length`` L [m] and ``mass`` M [kg]
    under ``g`` [m s-2].

    Parameters
    ----------
    N : int or sequence of int, optional
        Number of links (a sequence: one ``link_scale`` per N, as a tuple).
    ei : float
        Bending stiffness EI in N m^2 (0: a chain); ``beta`` only when not 0.
    ea : float, optional
        Axial stiffness EA in N; ``stretching`` only when given.
    diameter, air_density, cd_normal, cd_tangential
        The air drag, as :func:`snapping.units.body_numbers` takes them (drag numbers only with
        ``diameter``).
    end_mass : float or None
        Point mass at the free end, kg (None: not said, e.g. a scan over end masses).

    Returns
    -------
    dict
        ``{name: value}`` for the mechanisms given, in the order of :data:`NUMBERS`
        (``end_mass`` unless None).

    Raises
    ------
    SnappingInputError
        A value out of range, named (``ea`` must be finite and > 0; ``end_mass`` finite and
        >= 0; ``N`` integers >= 1; the rest as :func:`snapping.units.body_numbers`).

    >>> n = line_numbers(2.0, 0.05, end_mass=0.01, N=[50, 100])
    >>> round(n["end_mass"], 12), n["link_scale"]
    (0.2, (0.02, 0.01))
    """
    L, M, gg = V.si_scales(length, mass, g)  # (not units.Scales: pint only where the body needs it)
    lam = M / L
    out: dict = {}
    body: dict = {}
    if not (isinstance(ei, (int, float)) and ei == 0.0) or diameter is not None or air_density is not None \
            or cd_normal is not None or cd_tangential is not None:  # (pint only then: a table query stays light)
        body = units.body_numbers(L, M, gg, ei=ei, diameter=diameter, air_density=air_density,
                                  cd_normal=cd_normal, cd_tangential=cd_tangential)
    if not isinstance(body.get("bending", 0.0), float):
        raise V.SnappingInputError(f"ei={ei!r} must be one number (N m^2) here")
    if body.get("bending", 0.0) != 0.0:
        out["beta"] = body["bending"]
    if ea is not None:
        e = V.real("ea", ea)
        if not (math.isfinite(e) and e > 0.0):
            raise V.SnappingInputError(f"ea={e!r} is out of range: the axial stiffness EA must be finite and > 0 (N)")
        # c/sqrt(gL) = sqrt(EA/lambda)/sqrt(gL): [N / (kg m-1)] = m2 s-2, over [m s-2 m] = m2 s-2
        out["stretching"] = math.sqrt(e / lam) / math.sqrt(gg * L)
    for k in ("drag_normal", "drag_tangential"):
        if k in body:
            if not isinstance(body[k], float):
                raise V.SnappingInputError(f"diameter={diameter!r} must be one number (m) here")
            out[k] = body[k]
    if end_mass is not None:
        em = V.real("end_mass", end_mass)
        if not (math.isfinite(em) and em >= 0.0):
            raise V.SnappingInputError(f"end_mass={em!r} is out of range: must be finite and >= 0 (kg)")
        out["end_mass"] = em / (lam * L)
    if N is not None:
        many = not isinstance(N, (int,)) and hasattr(N, "__iter__")
        ns = list(N) if many else [N]
        for n in ns:
            if isinstance(n, bool) or not isinstance(n, int) or n < 1:
                raise V.SnappingInputError(f"N={n!r} is out of range: the number of links, an integer >= 1")
        scales = tuple(1.0 / n for n in ns)
        out["link_scale"] = scales if many else scales[0]
    return out


def number_rows(numbers: dict) -> list[tuple[str, str, str]]:
    """Rows ``(name, value, definition -- mechanism)`` of :func:`line_numbers`' numbers, for a
    printed block "Dimensionless numbers".

    >>> number_rows({"beta": 0.5})
    [('beta', '0.5', 'EI/(lambda g L^3) -- bending')]
    """
    rows = []
    for k, v in numbers.items():
        text = ", ".join(f"{x:.6g}" for x in v) if isinstance(v, (tuple, list)) else f"{v:.6g}"
        d, mech = NUMBERS.get(k, ("", ""))
        rows.append((k, text, f"{d} -- {mech}" if d else ""))
    return rows
