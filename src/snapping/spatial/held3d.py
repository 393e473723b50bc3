"""The held end of a 3D chain: fixed, pulled, flicked, driven around a circle, or along samples.

:class:`Pin3D` is the held end's prescribed motion ``r_p(t)`` in space (it starts at the
origin); the compiled evaluation is :func:`snapping.spatial.motion3d.pin3d`, so that what is
run, recorded and reported is one function. The kinds:

* ``fixed``; ``pull`` (acceleration ``accel`` from ``t0`` for ``duration``, then constant
  velocity); ``flick`` (``accel sin(2 pi (t - t0)/duration)`` for one period): as the planar
  :class:`snapping.simulate.pin.PinMotion`, with 3-vectors;
* ``circle`` (:meth:`Pin3D.circle`): around a circle of radius ``R`` about ``axis`` at the
  rate ``omega``, spun up from rest over ``ramp`` from ``t0`` (the rate rises as
  ``omega (tau - sin(2 pi tau)/(2 pi))``, tau = (t - t0)/ramp: the acceleration is
  continuous), or (``ramp = 0``, ``t0 = 0``) moving steadily from the start;
* ``table`` (:meth:`Pin3D.from_table`, :meth:`Pin3D.from_function`, :func:`read_pin_table`):
  not-a-knot cubic splines through samples ``(t_i, x_i, y_i, z_i)`` from t = 0, constant
  velocity after the last sample (as the planar table).

Conventions as the planar held end: :meth:`Pin3D.kinematics` at a breakpoint (where the
acceleration or a derivative jumps: a pull's or a flick's ends, a ramp's ends, a table's
last sample) is the right limit, the acceleration from t on (the steppers land on the
breakpoints and start the next step with it); the stop rule judges the chain's speed
relative to the held end from the last breakpoint on (:attr:`Pin3D.settle_time`). A held
end that starts moving (a steady circle, a table whose first velocity is not zero) carries
the chain's start with it: the nodes' velocities are given in the ground frame, the held
end's own is the motion's at t = 0 (:meth:`snapping.spatial.starts3d.Problem3D.with_pin`
adds it to a start at rest).

Example
-------
>>> from snapping.spatial.held3d import Pin3D
>>> p = Pin3D.circle(0.1, 2.0, ramp=0.5)                  # about the vertical (y), spun up over 0.5
>>> [round(v, 12) for v in p.kinematics(10.0)[3:6]][1], round(p.speed_after_ramp, 12)
(0.0, 0.2)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from .._validate import _short
from ..simulate.pin import ACCEL_MAX, MIN_DURATION, POSITION_MAX, T_MAX, sample_function
from . import chain3d as C
from . import motion3d as M

__all__ = ["Pin3D", "parse_pin3d", "read_pin_table", "PIN3D_KINDS"]

PIN3D_KINDS = ("fixed", "pull", "flick", "circle", "table")
_CODES = {"fixed": M.PIN_FIXED, "pull": M.PIN_PULL, "flick": M.PIN_FLICK, "circle": M.PIN_CIRCLE,
          "table": M.PIN_TABLE}
#: relative tolerance of a unit vector's length
UNIT_RTOL = 1e-9
#: largest circle rate (radians per time unit sqrt(L/g))
OMEGA_MAX = 1e6


def _vec3(name: str, v, hi: float = math.inf) -> np.ndarray:
    try:
        a = np.asarray(v, dtype=float).ravel()
    except (TypeError, ValueError, OverflowError):
        raise V.SnappingInputError(f"{name}={_short(v)} is not 3 numbers (x, y, z)") from None
    if a.size != 3 or not np.all(np.isfinite(a)):
        raise V.SnappingInputError(f"{name}={_short(v)} must be 3 finite numbers (x, y, z)")
    if np.abs(a).max() > hi:
        raise V.SnappingInputError(f"{name}={tuple(a.tolist())!r} is out of range: each component must lie in "
                                   f"[-{hi:g}, {hi:g}]")
    return a


def unit3(name: str, v) -> np.ndarray:
    """A unit 3-vector, or SnappingInputError naming ``name`` (zero or not of length 1)."""
    a = _vec3(name, v)
    n = float(np.linalg.norm(a))
    if not abs(n - 1.0) <= UNIT_RTOL:
        raise V.SnappingInputError(f"{name}={tuple(a.tolist())!r} has length {n:.6g}: it must be a unit vector "
                                   f"(length 1 to within {UNIT_RTOL:g})")
    return a


@dataclass(frozen=True, eq=False)
class Pin3D:
    """The held end's motion in space (see the module): ``kind`` one of :data:`PIN3D_KINDS`;
    ``accel``, ``t0``, ``duration`` (a pull's, a flick's period, a circle's ramp); a circle's
    ``radius``, ``omega`` and ``axis`` (unit), ``start_dir`` (unit, normal to the axis: from the
    circle's centre to the start); a table's samples ``(t, x, y, z)``. Starts at the origin."""

    kind: str = "fixed"
    accel: tuple = (0.0, 0.0, 0.0)
    t0: float = 0.0
    duration: float = math.inf
    radius: float = 0.0
    omega: float = 0.0
    axis: tuple = (0.0, 1.0, 0.0)
    start_dir: tuple | None = None
    table: tuple | None = None

    def __post_init__(self):
        if not isinstance(self.kind, str) or self.kind not in _CODES:
            raise V.SnappingInputError(f"kind={self.kind!r} is not one of {PIN3D_KINDS}")
        object.__setattr__(self, "accel", tuple(_vec3("accel", self.accel, ACCEL_MAX).tolist()))
        t0 = V.real("t0", self.t0)
        if not (math.isfinite(t0) and 0.0 <= t0 <= T_MAX):
            raise V.SnappingInputError(f"t0={t0!r} is out of range: must be finite and in [0, {T_MAX:g}]")
        object.__setattr__(self, "t0", t0)
        d = math.inf if self.duration == math.inf else V.real("duration", self.duration)
        if self.kind == "circle":
            self._check_circle(d)
        elif self.kind == "table":
            if not (isinstance(self.table, tuple) and len(self.table) == 4):
                raise V.SnappingInputError(f"table={_short(self.table)} must be the samples (t, x, y, z) of a Pin3D of "
                                           f"kind 'table' (use Pin3D.from_table)")
            object.__setattr__(self, "table", _checked_table(*self.table))
            object.__setattr__(self, "duration", float(self.table[0][-1]))
        elif not (d >= MIN_DURATION) or (self.kind == "flick" and not math.isfinite(d)):
            raise V.SnappingInputError(f"duration={d!r} is out of range: must be >= {MIN_DURATION:g} (finite for a "
                                       f"flick: its period)")
        if self.kind != "table" and self.table is not None:
            raise V.SnappingInputError(f"table: only a Pin3D of kind 'table' has samples (kind={self.kind!r})")

    def _check_circle(self, ramp: float) -> None:
        R = V.real("radius", self.radius)
        if not (math.isfinite(R) and 0.0 < R <= POSITION_MAX):
            raise V.SnappingInputError(f"radius={R!r} is out of range: must lie in (0, {POSITION_MAX:g}] (chain "
                                       f"lengths)")
        w = V.real("omega", self.omega)
        if not (math.isfinite(w) and 0.0 < abs(w) <= OMEGA_MAX):
            raise V.SnappingInputError(f"omega={w!r} is out of range: the circle's rate must be nonzero, "
                                       f"|omega| <= {OMEGA_MAX:g} (radians per sqrt(L/g))")
        if not (math.isfinite(ramp) and (ramp == 0.0 or ramp >= MIN_DURATION)):
            raise V.SnappingInputError(f"ramp={ramp!r} is out of range: the spin-up time must be finite, 0 (steady "
                                       f"from the start) or >= {MIN_DURATION:g}")
        if ramp == 0.0 and self.t0 != 0.0:
            raise V.SnappingInputError(f"ramp=0 with t0={self.t0!r}: a held end at rest that starts circling at once "
                                       f"would jump in velocity; give a ramp > 0 (or t0 = 0: circling from the start)")
        n = unit3("axis", self.axis)
        a = _default_start_dir(n) if self.start_dir is None else unit3("start_dir", self.start_dir)
        if abs(float(a @ n)) > 1e-9:
            raise V.SnappingInputError(f"start_dir={tuple(a.tolist())!r} is not normal to axis={tuple(n.tolist())!r} "
                                       f"(their dot product is {float(a @ n):.3g}): it points from the circle's "
                                       f"centre to the start, in the circle's plane")
        for name, v in (("radius", R), ("omega", w), ("duration", ramp), ("axis", tuple(n.tolist())),
                        ("start_dir", tuple(a.tolist()))):
            object.__setattr__(self, name, v)

    # -- constructors
    @classmethod
    def fixed(cls) -> "Pin3D":
        return cls()

    @classmethod
    def pull(cls, accel, duration: float = math.inf, t0: float = 0.0) -> "Pin3D":
        """Constant acceleration ``accel = (ax, ay, az)`` from ``t0`` for ``duration``."""
        return cls("pull", accel, t0, duration)

    @classmethod
    def flick(cls, accel, period: float, t0: float = 0.0) -> "Pin3D":
        """One period of a sine in the acceleration, peak ``accel``, over ``period``."""
        return cls("flick", accel, t0, period)

    @classmethod
    def circle(cls, radius: float, omega: float, ramp: float = 0.0, t0: float = 0.0, axis=(0.0, 1.0, 0.0),
               start_dir=None) -> "Pin3D":
        """Around the circle of ``radius`` about ``axis`` (unit; default the vertical, y) through
        the start, at the rate ``omega`` (right-handed about ``axis``), spun up from rest over
        ``ramp`` from ``t0`` (``ramp = 0``: steady from t = 0, the held end moving at the start);
        ``start_dir``: from the circle's centre to the start (unit, normal to ``axis``; default
        x, or z if the axis is x)."""
        return cls("circle", t0=t0, duration=ramp, radius=radius, omega=omega, axis=axis, start_dir=start_dir)

    @classmethod
    def from_table(cls, t, x, y, z) -> "Pin3D":
        """Through samples ``(t_i, x_i, y_i, z_i)``: t_0 = 0 and the first point the origin, t
        increasing, at least 4 samples (not-a-knot cubic splines; constant velocity after)."""
        return cls("table", table=(t, x, y, z))

    @classmethod
    def from_function(cls, r, t_max: float, samples: int = 2001) -> "Pin3D":
        """The motion ``r(t) -> (x, y, z)`` on [0, t_max] sampled at ``samples`` equal times."""
        t, xyz = sample_function(r, t_max, samples, ("x", "y", "z"))
        return cls.from_table(t, *xyz.T)

    @classmethod
    def from_planar(cls, pin) -> "Pin3D":
        """The planar :class:`snapping.simulate.pin.PinMotion` in the plane z = 0."""
        if pin.kind == "table":
            t, x, y = pin.table
            return cls.from_table(t, x, y, np.zeros_like(t))
        ax, ay = pin.accel
        return cls(pin.kind, (ax, ay, 0.0), pin.t0, pin.duration)

    # -- compiled form and evaluation
    def model_args(self) -> tuple:
        """``pin`` of :func:`snapping.spatial.chain3d.make_model`: ``(kind, accel, t0, T, data)``."""
        data = None
        if self.kind == "circle":
            n, a = np.asarray(self.axis), np.asarray(self.start_dir)
            data = M.circle_data(self.radius, self.omega, a, np.cross(n, a))
        elif self.kind == "table":
            from scipy.interpolate import CubicSpline

            t, *xyz = self.table
            data = M.table_data(t, *(CubicSpline(t, c).c for c in xyz))
        return (_CODES[self.kind], self.accel, float(self.t0), float(self.duration), data)

    def _par(self):
        par = self.__dict__.get("_par_cache")
        if par is None:  # (built once: a table's splines)
            par = C.make_model([1.0], [1.0], pin=self.model_args())[0]
            object.__setattr__(self, "_par_cache", par)
        return par

    @property
    def breakpoints(self) -> list[float]:
        return M.breakpoints(self._par())

    @property
    def settle_time(self) -> float:
        """From this time on the stop rule judges the chain's speed relative to the held end
        (its last breakpoint; -1: a fixed end, the rule on the largest speed from t = 0)."""
        return -1.0 if self.kind == "fixed" else max([0.0] + self.breakpoints)

    @property
    def speed_after_ramp(self) -> float:
        """A circle's steady speed ``R |omega|`` (0 for the other kinds)."""
        return abs(self.radius * self.omega) if self.kind == "circle" else 0.0

    def kinematics(self, t: float) -> tuple:
        """(x, y, z, vx, vy, vz, ax, ay, az) at t; at a breakpoint the acceleration from t on (the
        right limit), as :meth:`snapping.simulate.pin.PinMotion.kinematics`.

        >>> Pin3D.pull((0.0, -2.0, 1.0), duration=0.5).kinematics(0.0)[6:]
        (0.0, -2.0, 1.0)
        >>> Pin3D.pull((0.0, -2.0, 1.0), duration=0.5).kinematics(0.5)[6:]
        (0.0, 0.0, 0.0)
        """
        t = V.real("t", t)
        par = self._par()
        out = [float(v) for v in M.pin3d(t, par)]
        if t in M.breakpoints(par):  # (position and velocity are continuous there)
            out[6:] = [float(v) for v in M.pin3d(float(np.nextafter(t, np.inf)), par)[6:]]
        return tuple(out)

    def position(self, t: float) -> tuple:
        return self.kinematics(t)[:3]

    def velocity(self, t: float) -> tuple:
        return self.kinematics(t)[3:6]

    def describe(self) -> dict:
        """The motion as JSON-able values (what a run file records; :meth:`from_description` reads it)."""
        d = {"kind": self.kind}
        if self.kind in ("pull", "flick"):
            d.update(accel=list(self.accel), t0=self.t0, duration=self.duration)
        elif self.kind == "circle":
            d.update(radius=self.radius, omega=self.omega, ramp=self.duration, t0=self.t0, axis=list(self.axis),
                     start_dir=list(self.start_dir))
        elif self.kind == "table":
            d.update(samples=int(self.table[0].size), t_max=float(self.table[0][-1]))
        return d

    @classmethod
    def from_description(cls, d: dict, table=None) -> "Pin3D":
        """The motion :meth:`describe` described (a table's samples given as ``table``)."""
        kind = d.get("kind", "fixed")
        if kind == "circle":
            return cls.circle(d["radius"], d["omega"], d["ramp"], d["t0"], d["axis"], d["start_dir"])
        if kind == "table":
            return cls.from_table(*table)
        if kind in ("pull", "flick"):
            return cls(kind, d["accel"], d["t0"], d["duration"])
        return cls()


def _default_start_dir(n: np.ndarray) -> np.ndarray:
    """x made normal to the axis n (z when n is along x)."""
    e = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    a = e - (e @ n) * n
    return a / np.linalg.norm(a)


def _checked_table(t, x, y, z):
    arrs = {}
    for name, a in (("t", t), ("x", x), ("y", y), ("z", z)):
        arrs[name] = np.asarray(V.float_array(name, a), dtype=float).ravel()
    sizes = [a.size for a in arrs.values()]
    if len(set(sizes)) != 1 or sizes[0] < 4:
        raise V.SnappingInputError(f"pin table t, x, y, z must have the same length >= 4; got {sizes}")
    for name, a in arrs.items():
        if not np.all(np.isfinite(a)):
            i = int(np.flatnonzero(~np.isfinite(a))[0])
            raise V.SnappingInputError(f"pin motion {name}[{i}]={float(a[i])!r} is not finite")
        hi = T_MAX if name == "t" else POSITION_MAX
        if np.abs(a).max() > hi:
            i = int(np.argmax(np.abs(a)))
            raise V.SnappingInputError(f"pin motion {name}[{i}]={float(a[i])!r} is out of range: must lie in "
                                       f"[-{hi:g}, {hi:g}]")
    t = arrs["t"]
    if t[0] != 0.0 or not np.all(np.diff(t) > 0.0):
        raise V.SnappingInputError(f"pin table times must start at 0 and increase; got t[0]={t[0]!r}")
    xyz = [arrs[k].copy() for k in ("x", "y", "z")]
    scale = max(1.0, max(float(np.abs(a).max()) for a in xyz))
    if max(abs(float(a[0])) for a in xyz) > 1e-12 * scale:
        raise V.SnappingInputError(f"x[0], y[0], z[0] = {tuple(float(a[0]) for a in xyz)!r}: the held end must "
                                   f"start at the origin")
    for a in xyz:
        a[0] = 0.0
    return (t.copy(), *xyz)


def read_pin_table(path) -> Pin3D:
    """A sampled held-end motion from a CSV file of 4 columns ``t, x, y, z`` (a header line is
    skipped; t from 0, the first point the origin): :meth:`Pin3D.from_table`."""
    from .._files import check_input

    p = check_input(path, name="pin table")
    import warnings

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            a = np.genfromtxt(p, delimiter=",", dtype=float, comments="#")
    except (OSError, ValueError) as exc:
        first = (str(exc).strip().splitlines() or [""])[-1][:160]
        raise V.SnappingInputError(f"pin table {p!r}: cannot read it as CSV of 4 columns t, x, y, z ({first})") \
            from None
    a = np.atleast_2d(a)
    if a.ndim != 2 or a.shape[1] != 4 or a.shape[0] == 0:
        raise V.SnappingInputError(f"pin table {p!r}: expected 4 comma-separated columns t, x, y, z; got "
                                   f"{a.shape[1] if a.ndim == 2 else 0} columns")
    if np.all(np.isnan(a[0])):
        a = a[1:]
    bad = np.flatnonzero(np.any(np.isnan(a), axis=1))
    if bad.size:
        raise V.SnappingInputError(f"pin table {p!r}: data row {int(bad[0]) + 1} is not 4 numbers t, x, y, z (only "
                                   f"the first line may be a header)")
    return Pin3D.from_table(*a.T)


def parse_pin3d(spec: str | None, axis=None) -> Pin3D:
    """A :class:`Pin3D` from a command-line spec: the planar specs in the plane z = 0
    (``fixed``, ``pull:AX,AY[,DURATION[,T0]]``, ``flick:AX,AY,PERIOD[,T0]``), their 3D forms
    ``pull3d:AX,AY,AZ[,DURATION[,T0]]`` and ``flick3d:AX,AY,AZ,PERIOD[,T0]``,
    ``circle:R,OMEGA[,RAMP[,T0]]`` (about ``axis``, default the vertical) or ``table:FILE.csv``
    (columns t, x, y, z).

    >>> parse_pin3d("circle:0.1,3,0.5").describe()["ramp"]
    0.5
    >>> parse_pin3d("pull3d:0,-1,0.5,0.2").accel, parse_pin3d("pull:0,-1,0.2").duration
    ((0.0, -1.0, 0.5), 0.2)
    """
    kind, _, rest = ("fixed" if spec is None else str(spec)).partition(":")
    kind = kind.strip() or "fixed"
    if axis is not None and kind != "circle":
        raise V.SnappingInputError(f"pin_axis={axis!r} is only for a circle (pin_motion='circle:R,OMEGA,...'); "
                                   f"pin_motion={spec!r}")
    if kind == "table":
        return read_pin_table(rest.strip())
    if kind in ("fixed", "pull", "flick"):
        from ..simulate.pin import parse_pin_motion

        return Pin3D.from_planar(parse_pin_motion(spec))
    try:
        vals = [float(v) for v in rest.split(",")] if rest.strip() else []
    except ValueError:
        raise V.SnappingInputError(f"pin_motion={spec!r}: the parameters after {kind + ':'!r} must be numbers") \
            from None
    if kind == "circle" and 2 <= len(vals) <= 4:
        return Pin3D.circle(vals[0], vals[1], *(vals[2:3] or [0.0]), *(vals[3:4] or [0.0]),
                            **({} if axis is None else {"axis": axis}))
    if kind == "pull3d" and 3 <= len(vals) <= 5:
        return Pin3D.pull(vals[:3], *(vals[3:4] or [math.inf]), *(vals[4:5] or [0.0]))
    if kind == "flick3d" and 4 <= len(vals) <= 5:
        return Pin3D.flick(vals[:3], vals[3], *(vals[4:5] or [0.0]))
    raise V.SnappingInputError(f"pin_motion={spec!r} is not one of 'fixed', 'pull:AX,AY[,DURATION[,T0]]', "
                               f"'flick:AX,AY,PERIOD[,T0]', 'pull3d:AX,AY,AZ[,DURATION[,T0]]', "
                               f"'flick3d:AX,AY,AZ,PERIOD[,T0]', 'circle:R,OMEGA[,RAMP[,T0]]', 'table:FILE.csv'")
