"""What a line is made of: bending stiffness, bending damping, air drag, wind, a clamped held end.

A :class:`Body` is the material side of a :class:`snapping.simulate.problem.Problem` (the
geometry, masses, start and held end stay in the problem). Everything is nondimensional,
in the units of the chain (length L, mass M of the chain, g; ``lambda = M/L``):

* ``bending``: bending stiffness ``B = EI`` in units of ``lambda g L^3`` (the bending
  number ``beta``): a number, a function of the arclength ``s`` from the held end (e.g.
  :meth:`Body.taper_profile`), or one value per node (N + 1, index 0 the free end);
* ``curvature``: natural curvature ``kappa0`` (1/L; a pre-curved line, turning the link
  angle ``theta`` up towards the held end where positive), same forms; zero by default;
* ``damping``: Kelvin-Voigt bending damping ``eta`` (moment per curvature rate, units of
  ``lambda g L^3 sqrt(L/g)``), same forms;
* ``drag_normal``, ``drag_tangential``: quadratic drag per unit length (units of
  ``lambda/L``; a line falling broadside reaches ``1/sqrt(drag_normal)``), same forms;
  ``drag_linear_normal``, ``drag_linear_tangential``: linear (Stokes) drag per unit length
  (units of ``lambda sqrt(g/L)``); ``wind``: a uniform air velocity ``(wx, wy)``
  (y downward; ``(wx, wy, wz)`` in space, :mod:`snapping.spatial`; a planar run takes
  ``wz = 0`` only); ``tip_drag``: body drag ``c_d`` of the free end's tip body
  (force ``-c_d |u| u``, units of ``M/L``);
* ``clamp``: None (the held end a free hinge, the default), ``"start"`` (clamped in the
  direction the start leaves the held end, set when the problem is built), an angle (radians: the
  direction in which the line leaves the held end, measured from +x towards +y, y
  downward: 0 straight out to the right, pi/2 hanging down), or a prescribed motion
  ``(t, angle)`` (samples from t = 0; a cubic spline with zero rate at both ends, constant
  after the last sample). A clamp needs bending stiffness at the held end.

The force terms are :mod:`snapping.simulate.force_bending` and
:mod:`snapping.simulate.force_drag`, gathered in :mod:`snapping.simulate.forced`. A body
with no stiffness, damping or drag and no clamp is *inactive*: the problem is then solved
exactly as without one (the same kernels, the same runs bit for bit).

>>> from snapping.simulate import Body, Problem
>>> p = Problem.catenary(0.25, 40, body=Body(bending=1e-4, drag_normal=2.0))
>>> p.body.active, p.is_paper, p.describe()["body"]["bending"]
(True, False, 0.0001)
>>> Body(bending=-1.0)
Traceback (most recent call last):
...
snapping._validate.SnappingInputError: bending=-1.0 is out of range: must be finite and >= 0 (units of lambda g L^3)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V

__all__ = ["Body", "PROFILE_MAX", "summarize"]

#: largest coefficient accepted (stiffness, damping, drag, curvature, wind), nondimensional
PROFILE_MAX = 1e8

_UNITS = {
    "bending": "units of lambda g L^3",
    "curvature": "units of 1/L",
    "damping": "units of lambda g L^3 sqrt(L/g)",
    "drag_normal": "units of lambda/L",
    "drag_tangential": "units of lambda/L",
    "drag_linear_normal": "units of lambda sqrt(g/L)",
    "drag_linear_tangential": "units of lambda sqrt(g/L)",
}
_PROFILES = tuple(_UNITS)


def _profile(name: str, v, signed: bool = False):
    """A profile as given, checked as far as it can be without the chain: a float, a callable,
    or a 1-D float array (its length is checked by :meth:`Body.node_values`)."""
    lo = "finite" if signed else "finite and >= 0"
    if callable(v):
        return v
    if np.ndim(v) == 0:
        x = V.real(name, v)
        if not (math.isfinite(x) and (signed or x >= 0.0) and abs(x) <= PROFILE_MAX):
            raise V.SnappingInputError(f"{name}={x!r} is out of range: must be {lo} ({_UNITS[name]})")
        return x
    a = np.asarray(V.float_array(name, v), dtype=float)
    if a.ndim != 1:
        raise V.SnappingInputError(f"{name} must be a number, a function of s or one value per node; got shape "
                                   f"{a.shape}")
    _check_values(name, a, signed)
    return a.copy()


def _check_values(name, a, signed):
    ok = np.isfinite(a) & (np.abs(a) <= PROFILE_MAX)
    if not signed:
        ok &= a >= 0.0
    bad = np.flatnonzero(~ok)
    if bad.size:
        j = int(bad[0])
        lo = "finite" if signed else "finite and >= 0"
        raise V.SnappingInputError(f"{name}[{j}]={float(a[j])!r} is out of range: every entry must be {lo} "
                                   f"(at most {PROFILE_MAX:g}; {_UNITS[name]})")


def _describe_profile(v):
    if callable(v):
        return {"function": getattr(v, "__name__", "function")}
    if isinstance(v, np.ndarray):
        return [float(x) for x in v]
    return float(v)


@dataclass(frozen=True, eq=False, init=False)
class Body:
    """Bending stiffness, damping and drag of a line, and how its held end holds it (see
    the module's text for units and forms). Validated on construction; the lengths of
    per-node arrays when the problem is built."""

    bending: object
    curvature: object
    damping: object
    drag_normal: object
    drag_tangential: object
    drag_linear_normal: object
    drag_linear_tangential: object
    wind: tuple
    tip_drag: float
    clamp: object

    def __init__(self, bending=0.0, *, curvature=0.0, damping=0.0, drag_normal=0.0, drag_tangential=0.0,
                 drag_linear_normal=0.0, drag_linear_tangential=0.0, wind=(0.0, 0.0), tip_drag=0.0, clamp=None):
        set_ = object.__setattr__
        for name, v in (("bending", bending), ("curvature", curvature), ("damping", damping),
                        ("drag_normal", drag_normal), ("drag_tangential", drag_tangential),
                        ("drag_linear_normal", drag_linear_normal),
                        ("drag_linear_tangential", drag_linear_tangential)):
            set_(self, name, _profile(name, v, signed=(name == "curvature")))
        try:
            w = np.asarray(wind, dtype=float)
        except (TypeError, ValueError):
            raise V.SnappingInputError(f"wind={wind!r} must be two numbers (wx, wy)") from None
        if w.shape not in ((2,), (3,)) or not np.all(np.isfinite(w)) or np.abs(w).max() > PROFILE_MAX:
            raise V.SnappingInputError(f"wind={wind!r} must be two finite numbers (wx, wy) (units of sqrt(g L), "
                                       f"y downward; three (wx, wy, wz) in space); got shape {w.shape}")
        set_(self, "wind", tuple(float(x) for x in w))
        cd = V.real("tip_drag", tip_drag)
        if not (math.isfinite(cd) and 0.0 <= cd <= PROFILE_MAX):
            raise V.SnappingInputError(f"tip_drag={cd!r} is out of range: must be finite and >= 0 (units of M/L)")
        set_(self, "tip_drag", cd)
        set_(self, "clamp", self._check_clamp(clamp))
        if self.clamp is not None and self._zero("bending"):
            raise V.SnappingInputError(f"clamp={clamp!r} needs bending stiffness: a clamped held end holds the "
                                       f"line's direction only through its bending stiffness (give bending=B > 0)")

    @staticmethod
    def _check_clamp(clamp):
        if clamp is None or (isinstance(clamp, str) and clamp == "start"):
            return clamp
        if np.ndim(clamp) == 0:
            a = V.real("clamp", clamp)
            if not (math.isfinite(a) and abs(a) <= 1e3):
                raise V.SnappingInputError(f"clamp={a!r} is out of range: a finite angle in radians, |angle| <= 1000")
            return a
        try:
            t, a = (np.asarray(V.float_array("clamp", x), dtype=float).ravel() for x in clamp)
        except (TypeError, ValueError):
            raise V.SnappingInputError(f"clamp={clamp!r} must be an angle or samples (t, angle)") from None
        if t.size != a.size or t.size < 2:
            raise V.SnappingInputError(f"clamp: samples (t, angle) need the same length >= 2; got {t.size}, {a.size}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(a)) and np.abs(a).max() <= 1e3):
            raise V.SnappingInputError("clamp: sample times and angles must be finite (|angle| <= 1000 radians)")
        if t[0] != 0.0 or not np.all(np.diff(t) > 0.0):
            raise V.SnappingInputError(f"clamp: sample times must start at 0 and increase strictly; got t[0]={t[0]!r}")
        return (t.copy(), a.copy())

    def _zero(self, name) -> bool:
        v = getattr(self, name)
        if callable(v):
            return False
        return bool(np.all(np.asarray(v) == 0.0))

    @property
    def active(self) -> bool:
        """Whether the body changes anything (stiffness, damping, drag or a clamp)."""
        return self.clamp is not None or self.tip_drag != 0.0 or not all(
            self._zero(k) for k in ("bending", "damping", "drag_normal", "drag_tangential", "drag_linear_normal",
                                    "drag_linear_tangential"))

    @property
    def has_bending(self) -> bool:
        return self.clamp is not None or not (self._zero("bending") and self._zero("damping"))

    @classmethod
    def from_si(cls, length, mass, g: float = 9.81, *, ei=0.0, bending_damping=0.0, curvature=0.0, diameter=None,
                air_density=None, cd_normal=None, cd_tangential=None, tip_drag_area=0.0, wind=None,
                drag_linear_normal=0.0, drag_linear_tangential=0.0, clamp=None) -> "Body":
        """The body of a line described in SI, for a chain of ``length`` [m] and ``mass`` [kg]
        under ``g`` [m s-2]: EI in N m^2, the diameter in m (drag with the coefficients
        ``cd_normal``, ``cd_tangential``), the air density in kg/m^3, the tip body's drag area
        C_d A in m^2, the wind in m/s (the conversions: :func:`snapping.units.body_numbers`).
        The linear drags and the clamp stay nondimensional.

        >>> b = Body.from_si(2.0, 0.02, ei=1e-3, diameter=1e-3)   # 2 m of 10 g/m line
        >>> round(b.bending, 8), round(b.drag_normal, 6)
        (0.00127421, 0.144)
        """
        from ..units import body_numbers

        si = {"ei": ei, "bending_damping": bending_damping, "curvature": curvature, "diameter": diameter,
              "tip_drag_area": tip_drag_area, "wind": wind}
        kw = body_numbers(length, mass, g, air_density=air_density, cd_normal=cd_normal, cd_tangential=cd_tangential,
                          **si)
        made = {"ei": ("bending",), "bending_damping": ("damping",), "curvature": ("curvature",),
                "diameter": ("drag_normal", "drag_tangential"), "tip_drag_area": ("tip_drag",), "wind": ("wind",)}
        for name, keys in made.items():  # a number out of the body's range is named by its SI input
            if all(k in kw for k in keys):
                try:
                    cls(**{k: kw[k] for k in keys})
                except V.SnappingInputError as exc:
                    v = si[name]
                    text = f"{v!r}" if np.ndim(v) == 0 and not callable(v) else "(its values)"
                    raise V.SnappingInputError(f"{name}={text} gives {exc}") from None
        return cls(kw.pop("bending"), drag_linear_normal=drag_linear_normal,
                   drag_linear_tangential=drag_linear_tangential, clamp=clamp, **kw)

    @classmethod
    def from_line(cls, name: str, length=None, g: float = 9.81, **overrides) -> "Body":
        """The body of ``length`` m (default: the catalogue's typical length) of the real line
        ``name`` of :mod:`snapping.lines` (``ball-chain``, ``fly-line``, ``bullwhip``, ...):
        ``snapping.lines.get(name).body(length, g, **overrides)``; any keyword of
        :meth:`from_si` overrides the catalogue's value. A tapered line's masses are
        :meth:`snapping.lines.Line.links` (or build the whole problem with
        :meth:`snapping.lines.Line.problem`).

        >>> round(Body.from_line("nylon-monofilament", 2.0).bending, 9)   # 2 m of 0.30 mm nylon
        0.000125744
        """
        from ..lines import get

        return get(name).body(length, g, **overrides)

    def numbers(self, h=None) -> dict:
        """The body's nondimensional numbers, compactly, for a summary: every entry that is
        not zero (a profile that varies: its range ``[min, max]`` over the nodes; a function
        of s: over the nodes of a chain with links ``h``, else its name), ``beta`` for the
        bending number."""
        return summarize(self.describe(h))

    @staticmethod
    def taper_profile(B0: float, ratio: float, power: float = 1.0):
        """``B(s) = B0 (1 - c s/L)^power`` with ``B(L)/B(0) = ratio`` (s from the held end,
        L = 1): a tapered stiffness for ``bending=`` (a whip: ``power = 4`` for a cone)."""
        B0 = V.real("B0", B0)
        ratio = V.positive("ratio", ratio)
        power = V.positive("power", power)
        c = 1.0 - ratio ** (1.0 / power)

        def taper(s):
            return B0 * (1.0 - c * s) ** power

        taper.__name__ = f"taper(B0={B0!r}, ratio={ratio!r}, power={power!r})"
        return taper

    # -- on a chain
    def node_values(self, name: str, h: np.ndarray) -> np.ndarray:
        """The profile ``name`` at the N + 1 nodes of a chain with links ``h``."""
        N = h.size
        v = getattr(self, name)
        snode = np.zeros(N + 1)
        snode[:N] = np.cumsum(h[::-1])[::-1]
        if callable(v):
            try:
                if callable(getattr(v, "on_array", None)):  # the same numbers, one call for every node
                    a = np.asarray(v.on_array(snode), dtype=float)
                else:
                    a = np.asarray([float(v(float(x))) for x in snode], dtype=float)
            except Exception as exc:  # noqa: BLE001 - the user's function failed
                raise V.SnappingInputError(f"{name}(s) failed or did not return a number ({type(exc).__name__}: "
                                           f"{str(exc)[:120]})") from None
            _check_values(name, a, name == "curvature")
            return a
        if isinstance(v, np.ndarray):
            if v.size != N + 1:
                raise V.SnappingInputError(f"{name} has {v.size} entries; the chain has {N + 1} nodes (one value "
                                           f"per node, index 0 the free end)")
            return v.copy()
        return np.full(N + 1, float(v))

    def check(self, h, dims: int = 2) -> None:
        """Check the per-node profiles against a chain with links ``h`` (SnappingInputError); a
        planar chain (``dims = 2``) takes no out-of-plane wind."""
        if dims == 2 and len(self.wind) == 3 and self.wind[2] != 0.0:
            raise V.SnappingInputError(f"wind={self.wind!r} blows out of the plane (wz != 0): a planar run takes "
                                       f"(wx, wy); run it in space (snapping.spatial, --dims 3)")
        for name in _PROFILES:
            self.node_values(name, np.asarray(h, dtype=float))
        if self.clamp is not None and self.node_values("bending", np.asarray(h, dtype=float))[-1] == 0.0:
            raise V.SnappingInputError("clamp: the bending stiffness at the held end (s = 0) is 0; a clamp needs "
                                       "bending > 0 there")

    def resolved(self, x, y) -> "Body":
        """This body with ``clamp="start"`` replaced by the direction in which a start with
        nodes ``x, y`` (index N the held end) leaves the held end."""
        if not (isinstance(self.clamp, str) and self.clamp == "start"):
            return self
        kw = {k: getattr(self, k) for k in _PROFILES if k != "bending"}  # (functions of s kept as they are)
        return Body(self.bending, wind=self.wind, tip_drag=self.tip_drag,
                    clamp=math.atan2(float(y[-2] - y[-1]), float(x[-2] - x[-1])), **kw)

    def hinged(self) -> "Body":
        """This body with the held end a free hinge (no clamp)."""
        kw = {k: getattr(self, k) for k in _PROFILES if k != "bending"}
        return Body(self.bending, wind=self.wind, tip_drag=self.tip_drag, clamp=None, **kw)

    def model(self, mdl, h, theta0: float):
        """The compiled model (:func:`snapping.simulate.forced.make_body_model`) from the general
        model ``mdl`` of a chain with links ``h``; ``theta0``: the held link's angle at t = 0
        (the clamp's link angle is taken within pi of it)."""
        from . import forced as FR

        if isinstance(self.clamp, str):
            raise V.SnappingInputError("clamp='start' is set from a start: build the Problem with this body")
        h = np.asarray(h, dtype=float)
        clamped = self.clamp is not None
        arrays = self.node_arrays(h, clamped)
        alpha, table = 0.0, None
        if clamped:
            if isinstance(self.clamp, tuple):
                from scipy.interpolate import CubicSpline

                t, a = self.clamp
                a0 = float(a[0])
                table = (t, CubicSpline(t, a, bc_type="clamped").c)
            else:
                a0 = float(self.clamp)
            phi = a0 + math.pi  # the link angle: the held link points towards the held end
            k = round((theta0 - phi) / (2.0 * math.pi))
            alpha = (phi + 2.0 * math.pi * k) - (a0 if table is not None else 0.0)
        return FR.make_body_model(mdl, arrays, clamped=clamped, alpha=alpha, clamp_table=table, wind=self.wind,
                                  tip_drag=self.tip_drag)

    def node_arrays(self, h, clamped: bool = False) -> dict:
        """The compiled models' node arrays (N + 1 each, by node) of a chain with links ``h``:
        ``Bl = B/l``, ``K0L = kappa0 l``, ``El = eta/l`` at the inner nodes (and node N when
        ``clamped``), the drags ``CN, CT, KN, KT`` times ``l`` at nodes 0 .. N - 1; ``l`` the
        node's share of length."""
        h = np.asarray(h, dtype=float)
        N = h.size
        l = np.zeros(N + 1)
        l[0] = 0.5 * h[0]
        l[1:N] = 0.5 * (h[:-1] + h[1:])
        l[N] = 0.5 * h[N - 1]
        B = self.node_values("bending", h)
        k0 = self.node_values("curvature", h)
        eta = self.node_values("damping", h)
        inner = np.zeros(N + 1)
        inner[1:N] = 1.0
        if clamped:
            inner[N] = 1.0
        arrays = {"Bl": inner * B / l, "K0L": inner * k0 * l, "El": inner * eta / l}
        drag = np.ones(N + 1)
        drag[N] = 0.0
        for key, name in (("CN", "drag_normal"), ("CT", "drag_tangential"), ("KN", "drag_linear_normal"),
                          ("KT", "drag_linear_tangential")):
            arrays[key] = drag * self.node_values(name, h) * l
        return arrays

    def describe(self, h=None) -> dict:
        """JSON-friendly description; with the chain's links ``h``, a profile given as a
        function is recorded with its node values (``nodes``), so that it can be read back."""
        d = {k: _describe_profile(getattr(self, k)) for k in _PROFILES}
        funcs = [k for k in _PROFILES if callable(getattr(self, k))]
        if funcs and h is not None:
            d["nodes"] = {k: [float(x) for x in self.node_values(k, np.asarray(h, dtype=float))] for k in funcs}
        d["wind"] = list(self.wind)
        d["tip_drag"] = self.tip_drag
        if isinstance(self.clamp, tuple):
            d["clamp"] = {"t": [float(x) for x in self.clamp[0]], "angle": [float(x) for x in self.clamp[1]]}
        elif self.clamp == "start":
            d["clamp"] = "start"
        else:
            d["clamp"] = self.clamp
        return d

    @classmethod
    def from_describe(cls, d: dict, h=None) -> "Body":
        """The body of a description (:meth:`describe`); a profile recorded as a function is
        read back as its node values ``d['nodes'][name]`` (recorded beside it)."""
        kw = {}
        for k in _PROFILES:
            v = d.get(k, 0.0)
            if isinstance(v, dict):
                v = d["nodes"][k]
            kw[k] = np.asarray(v, dtype=float) if isinstance(v, list) else v
        c = d.get("clamp")
        if isinstance(c, dict):
            c = (c["t"], c["angle"])
        return cls(kw.pop("bending"), wind=tuple(d.get("wind", (0.0, 0.0))), tip_drag=d.get("tip_drag", 0.0),
                   clamp=c, **kw)


#: the names :func:`summarize` gives the body's numbers
SUMMARY_NAMES = {"bending": "beta", "curvature": "curvature", "damping": "bending_damping",
                 "drag_normal": "drag_normal", "drag_tangential": "drag_tangential",
                 "drag_linear_normal": "drag_linear_normal", "drag_linear_tangential": "drag_linear_tangential"}


def summarize(d: dict) -> dict:
    """The nonzero numbers of a body description (:meth:`Body.describe`, or its JSON as a run
    records it in its attribute ``body``), compact: ``beta`` (the bending number
    B/(lambda g L^3)), the drag numbers, the wind, the tip drag and the clamp; a profile that
    varies along the line as ``[min, max]`` of its node values (a function's are recorded
    beside it as ``nodes``).

    >>> summarize(Body(1e-3, drag_normal=[0.0, 1.0, 2.0]).describe())
    {'beta': 0.001, 'drag_normal': [0.0, 2.0]}
    """
    import json as _json

    if isinstance(d, str):
        d = _json.loads(d)
    out = {}
    for k, name in SUMMARY_NAMES.items():
        v = d.get(k, 0.0)
        if isinstance(v, dict):  # a function: its node values, recorded beside it
            vals = (d.get("nodes") or {}).get(k)
            v = vals if vals is not None else v.get("function", "function")
        if isinstance(v, list):
            if any(x != 0.0 for x in v):
                out[name] = [float(min(v)), float(max(v))] if min(v) != max(v) else float(v[0])
        elif isinstance(v, str):
            out[name] = v
        elif v:
            out[name] = float(v)
    w = d.get("wind") or [0.0, 0.0]
    if any(w):
        out["wind"] = [float(x) for x in w]
    if d.get("tip_drag"):
        out["tip_drag"] = float(d["tip_drag"])
    c = d.get("clamp")
    if c is not None:
        out["clamp"] = c if not isinstance(c, dict) else "prescribed motion (t, angle)"
    return out
