"""Snap loads users ask about, in SI, from the extensible line (:mod:`snapping.simulate.elastic`).

:func:`climbing_fall`: a mass caught by a rope after a free fall of ``fall_factor`` rope
lengths (the EN 892 / UIAA drop test: 80 kg at fall factor 1.77, peak force at most 12 kN),
beside the massless-rope formula

    F_max = m g [1 + sqrt(1 + 2 f EA/(m g))].

The model: the rope (``N`` links of its mass per length and EA, tension-only) hangs straight
down from the anchor at its rest length, the mass at its free end; at t = 0 the mass moves
down at the free-fall speed ``sqrt(2 g f L)`` and the rope's points at the speed that falls
linearly from it to 0 at the anchor (the massless rope's profile: the rope is just taut and
stretches uniformly). For a rope much lighter than the mass the peak is the formula's; the
rope's own mass changes it by a fraction of order ``lambda L/m``.

Example
-------
>>> from snapping.simulate.elastic_loads import climbing_fall
>>> r = climbing_fall(mass=80.0, fall_factor=1.77, ea=20e3, mass_per_length=3e-3, rope_length=2.6, N=6)
>>> abs(r["peak_force"] / r["formula_force"] - 1.0) < 1e-3
True
"""

from __future__ import annotations

import math

import numpy as np

from .. import _validate as V

__all__ = ["climbing_fall", "massless_peak_force", "EN892_LIMIT", "jerk_peak_force", "jerk_taut"]

#: the peak force (N) EN 892 / UIAA 101 allow a dynamic single rope in its first test drop
EN892_LIMIT = 12e3


def massless_peak_force(mass: float, fall_factor: float, ea: float, g: float = 9.81) -> float:
    """``m g [1 + sqrt(1 + 2 f EA/(m g))]``: the peak force of a massless linear rope catching
    ``mass`` (kg) after a fall of ``fall_factor`` rope lengths (N, for ``ea`` in N).

    >>> round(massless_peak_force(80.0, 1.77, 20e3, 9.81), 3)
    8280.115
    """
    w = V.positive("mass", mass) * V.positive("g", g)
    return w * (1.0 + math.sqrt(1.0 + 2.0 * V.positive("fall_factor", fall_factor) * V.positive("ea", ea) / w))


def climbing_fall(*, mass: float = 80.0, fall_factor: float = 1.77, rope: str | None = "climbing-rope",
                  ea: float | None = None, mass_per_length: float | None = None, rope_length: float = 2.6,
                  g: float = 9.81, N: int = 20, damping: float = 0.0, tol: float = 1e-8) -> dict:
    """The peak force of a fall caught by an elastic rope with mass (N), beside the massless formula.

    Parameters
    ----------
    mass : float
        The falling mass, kg (EN 892: 80 kg).
    fall_factor : float
        Height of the free fall over the rope length (EN 892: 1.77).
    rope : str or None
        A line of :mod:`snapping.lines` giving ``ea`` and ``mass_per_length`` where those are
        not given (default the catalogue's dynamic single rope, whose EA is an estimate from
        its static elongation).
    ea, mass_per_length : float, optional
        The rope's axial stiffness (N) and mass per length (kg/m).
    rope_length : float
        The rope length between anchor and mass, m (the peak of a massless rope depends only
        on the fall factor; the rope's mass enters through ``mass_per_length * rope_length``).
    g : float
        Gravity, m/s^2.
    N : int
        Links of the rope.
    damping : float
        Kelvin-Voigt damping of the rope, N s (force per unit strain rate).
    tol : float
        Tolerance of :func:`snapping.simulate.elastic.solve`.

    Returns
    -------
    dict
        ``peak_force`` (N, the largest link tension over the catch, refined between steps),
        ``anchor_force`` (N, the largest force on the anchor over the recorded steps),
        ``formula_force`` (N, :func:`massless_peak_force`), ``limit_force`` (12 kN),
        ``t_peak`` (s after the rope goes taut), ``peak_strain``, ``mass_ratio`` (rope
        mass over the falling mass), ``ea``, ``mass_per_length``, and ``run``
        (the :class:`ElasticRun`, nondimensional: rope length, rope mass, g).
    """
    from .elastic_model import Elastic
    from .elastic_solve import solve
    from .problem import Links, Problem

    m = V.positive("mass", mass)
    f = V.positive("fall_factor", fall_factor)
    L = V.positive("rope_length", rope_length)
    g = V.positive("g", g)
    N = V.integer("N", N, 1)
    damping = V.real("damping", damping)
    if not (math.isfinite(damping) and damping >= 0.0):
        raise V.SnappingInputError(f"damping={damping!r} is out of range: must be finite and >= 0 (N s)")
    if rope is not None and (ea is None or mass_per_length is None):
        from .. import lines

        line = lines.get(rope)
        ea = line.ea if ea is None else ea
        mass_per_length = line.mass_per_length if mass_per_length is None else mass_per_length
    if ea is None or mass_per_length is None:
        raise V.SnappingInputError("climbing_fall: give ea and mass_per_length (or a rope of snapping.lines with them)")
    ea = V.positive("ea", ea)
    lam = V.positive("mass_per_length", mass_per_length)
    Mr = lam * L  # the units: rope length, rope mass, g
    F = Mr * g
    tip = m / Mr
    links = Links.uniform(N, tip_mass=tip, lumping="shared")
    y = np.concatenate([np.cumsum(links.h[::-1])[::-1], [0.0]])
    p = Problem.nodes(np.zeros(N + 1), y, links=links)
    ea_nd = ea / F
    omega = math.sqrt(ea_nd / (tip + 1.0 / 3.0))  # the mass on the rope's spring (a third of the rope's mass)
    v0 = math.sqrt(2.0 * f)
    r = solve(p, Elastic(ea=ea_nd, damping=damping / (F * math.sqrt(L / g))),
              initial=(p.x, p.y, p.vx, v0 * p.y), t_end=1.25 * math.pi / omega, tol=tol)
    s = r.summary()
    ds = r.dataset
    anchor = float(np.hypot(ds["pin_force_x"].values, ds["pin_force_y"].values).max())
    return {"peak_force": s["sigma_peak"] * F, "anchor_force": anchor * F,
            "formula_force": massless_peak_force(m, f, ea, g), "limit_force": EN892_LIMIT,
            "t_peak": s["t_snap_sigma"] * math.sqrt(L / g), "peak_strain": s["strain_peak"], "mass_ratio": Mr / m,
            "ea": ea, "mass_per_length": lam, "run": r}


def jerk_peak_force(mass: float, speed: float, stiffness: float, *, slack: float = 0.0, g: float = 0.0) -> dict:
    """The closed form of a point mass on a massless linear spring jerked taut by its other end.

    The mass ``mass`` hangs at rest, the spring (``stiffness`` k, N/m) slack by ``slack``; at
    t = 0 the end starts to move away from the mass at constant ``speed`` V, and gravity ``g``
    pulls the mass away from the end along the line. The gap closes at
    ``t_taut = (sqrt(V^2 + 2 g slack) - V)/g`` (``slack/V`` without gravity), the mass then
    leaving the end at ``w = sqrt(V^2 + 2 g slack)``. With u the stretch after that,
    ``u'' = g - (k/m) u``, ``u(0) = 0``, ``u'(0) = w``, so

        T_max = k u_max = m g + sqrt((m g)^2 + k m w^2)

    (``V sqrt(k m)`` without gravity and slack; the climbing fall's formula with k = EA/L and
    w^2 = 2 g f L), reached ``(pi/2 + atan2(g/omega^2, w/omega))/omega`` after ``t_taut``
    (omega = sqrt(k/m)).

    >>> r = jerk_peak_force(2.0, 3.0, 800.0)
    >>> r["peak_force"] == 3.0 * (800.0 * 2.0) ** 0.5, r["t_taut"]
    (True, 0.0)
    """
    m = V.positive("mass", mass)
    v = V.positive("speed", speed)
    k = V.positive("stiffness", stiffness)
    d = V.real("slack", slack)
    g = V.real("g", g)
    for name, x in (("slack", d), ("g", g)):
        if not (math.isfinite(x) and x >= 0.0):
            raise V.SnappingInputError(f"{name}={x!r} is out of range: must be finite and >= 0")
    w = math.sqrt(v * v + 2.0 * g * d)
    t_taut = 2.0 * d / (v + w)  # (= (w - V)/g, without the cancellation; slack/V for g = 0)
    om = math.sqrt(k / m)
    a = g / (om * om)
    return {"peak_force": m * g + math.sqrt((m * g) ** 2 + k * m * w * w), "t_taut": t_taut, "impact_speed": w,
            "t_peak": t_taut + (0.5 * math.pi + math.atan2(a, w / om)) / om, "omega": om}


def jerk_taut(*, mass: float, speed: float, slack: float, ea: float, length: float,
              mass_per_length: float, g: float = 0.0, N: int = 10, damping: float = 0.0, tol: float = 1e-8) -> dict:
    """A slack tether jerked taut by its held end (N), beside :func:`jerk_peak_force`.

    The tether (rest ``length`` m, ``mass_per_length`` kg/m, axial stiffness ``ea`` N,
    tension-only, ``N`` links) hangs straight down from its held end with ``mass`` (kg) at its
    free end, slack by ``slack`` m (the link at the held end shortened by it, the rest of the
    line at its rest length: a loop of slack at the top, carrying nothing), all at rest; at t = 0 the held end starts upward at constant ``speed`` (m/s),
    gravity ``g`` (m/s^2, 0: none, a tow line on the level) pulling the mass and the line
    down. The run is made in units of the length, the tether's mass and ``length/speed``
    (so g = 0 is allowed), and ends half a period of the mass on the spring after the formula's
    peak, or two round trips of the longitudinal wave (4 L/c) after the line goes taut if later.
    With ``N = 1`` the model is the formula's (one node: the mass and half the tether's); with
    more links the tether's own mass adds a longitudinal wave, measured here to raise the peak
    by about ``speed sqrt(EA mass_per_length)`` (the line's impedance times the jerk's speed:
    +12 N on 729 N at a mass ratio 6e-4, +62 N on 731 N at 0.03; the guide's table).

    Returns
    -------
    dict
        ``peak_force`` (N: the largest link tension, refined between steps), ``formula_force``
        (N: :func:`jerk_peak_force` for the free-end node's mass on the spring EA/length),
        ``t_taut`` and ``t_peak`` (s, the formula's), ``t_peak_run`` (s: when the run's peak
        tension came), ``mass_ratio`` (tether mass over ``mass``), ``run`` (the
        :class:`ElasticRun`, nondimensional).

    Examples
    --------
    >>> r = jerk_taut(mass=5.0, speed=2.0, slack=0.5, ea=2e4, length=3.0, mass_per_length=1e-4, N=1)
    >>> abs(r["peak_force"] / r["formula_force"] - 1.0) < 1e-6
    True
    """
    from .elastic_model import Elastic
    from .elastic_solve import solve
    from .pin import PinMotion
    from .problem import Links, Problem

    m = V.positive("mass", mass)
    v = V.positive("speed", speed)
    L = V.positive("length", length)
    d = V.real("slack", slack)
    N = V.integer("N", N, 1)
    if not (math.isfinite(d) and 0.0 <= d < L / N):
        raise V.SnappingInputError(f"slack={d!r} is out of range: must lie in [0, length/N={L / N!r}) m (it is "
                                   f"the shortening of the link at the held end)")
    ea = V.positive("ea", ea)
    lam = V.positive("mass_per_length", mass_per_length)
    g = V.real("g", g)
    if not (math.isfinite(g) and g >= 0.0):
        raise V.SnappingInputError(f"g={g!r} is out of range: must be finite and >= 0 (m/s^2)")
    N = V.integer("N", N, 1)
    damping = V.real("damping", damping)
    if not (math.isfinite(damping) and damping >= 0.0):
        raise V.SnappingInputError(f"damping={damping!r} is out of range: must be finite and >= 0 (N s)")
    Mr = lam * L
    tau = L / v  # units: length L, mass Mr, time L/V; force Mr V^2/L
    F = Mr * v * v / L
    links = Links.uniform(N, tip_mass=m / Mr, lumping="shared")
    m0 = float(links.m[0]) * Mr  # the free-end node: the mass and its share of the tether
    ref = jerk_peak_force(m0, v, ea / L, slack=d, g=g)
    # past the formula's peak by half a period, and past two round trips of the longitudinal wave
    t_end = max(ref["t_peak"] + 0.5 * math.pi / ref["omega"], ref["t_taut"] + 4.0 * L / math.sqrt(ea / lam)) / tau
    ts = np.linspace(0.0, 2.0 * t_end, 5)
    pin = PinMotion.from_table(ts, 0.0 * ts, -ts)  # upward (y points down) at speed 1
    y = np.concatenate([np.cumsum(links.h[::-1])[::-1], [0.0]])
    p = Problem.nodes(np.zeros(N + 1), y, links=links, pin=pin, gravity=g * L / (v * v), name="jerk-taut")
    z = np.zeros(N + 1)
    vy = z.copy()
    vy[-1] = pin.kinematics(0.0)[3]  # (-1 to the spline's round-off)
    y0 = y.copy()
    y0[:N] -= d / L  # the slack in the link at the held end: the rest of the line hangs at its rest length
    r = solve(p, Elastic(ea=ea / F, damping=damping / (F * tau)), initial=(z, y0, z, vy), t_end=t_end, tol=tol)
    s = r.summary()
    return {"peak_force": s["sigma_peak"] * F, "formula_force": ref["peak_force"], "t_taut": ref["t_taut"],
            "t_peak": ref["t_peak"], "t_peak_run": s["t_snap_sigma"] * tau, "mass_ratio": Mr / m, "run": r}
