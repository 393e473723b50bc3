"""The held end's motion: fixed, or prescribed ``r_p(t)`` (:class:`PinMotion`).

Presets with closed forms (a constant-acceleration pull, a one-period-of-a-sine flick)
and any motion given as a function or samples (a cubic spline through them). The
compiled evaluation is :func:`snapping.simulate.general.pin_kinematics`, so that what is
run, recorded and reported is the same function.

Example
-------
>>> from snapping.simulate.pin import PinMotion
>>> PinMotion.pull((0.0, -1.0), duration=0.5).kinematics(1.0)     # y downward: a yank upward
(0.0, -0.375, 0.0, -0.5, 0.0, 0.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from .._validate import _short
from . import general as G

__all__ = ["PinMotion", "parse_pin_motion", "PIN_KINDS"]

PIN_KINDS = ("fixed", "pull", "flick", "table")
#: most samples of a motion given as a function
MAX_SAMPLES = 1_000_000
#: shortest duration or period of a preset (nondimensional time)
MIN_DURATION = 1e-9
#: largest acceleration of a preset (units of g) and latest time of a sampled motion
ACCEL_MAX = 1e6
T_MAX = 1e6
#: largest coordinate of a sampled motion (chain lengths)
POSITION_MAX = 1e6


@dataclass(frozen=True, eq=False)
class PinMotion:
    """The motion of the held end: ``fixed``, ``pull`` (constant acceleration ``accel`` from
    ``t0`` for ``duration``, then constant velocity), ``flick`` (acceleration
    ``accel sin(2 pi (t - t0)/period)`` for one period: twice differentiable everywhere,
    the end moves by ``accel period^2/(2 pi)`` and is at rest again), or ``table`` (a cubic
    spline through samples of ``r_p(t)`` from t = 0, constant velocity after the last).
    The held end starts at the origin."""

    kind: str = "fixed"
    accel: tuple = (0.0, 0.0)
    t0: float = 0.0
    duration: float = math.inf
    table: tuple | None = None  # (t, x, y) samples

    def __post_init__(self):  # built directly too (PinMotion("pull", ...)): checked as the constructors check
        if not isinstance(self.kind, str) or self.kind not in PIN_KINDS:
            raise V.SnappingInputError(f"kind={self.kind!r} is not one of {PIN_KINDS} (build a PinMotion with "
                                       f"PinMotion.fixed, .pull, .flick, .from_table or .from_function)")
        accel = self._vector("accel", self.accel)
        t0 = V.real("t0", self.t0)
        if t0 < 0.0:
            raise V.SnappingInputError(f"t0={t0!r} is out of range: must be >= 0")
        d = self.duration
        if self.kind in ("pull", "flick") and not (self.kind == "pull" and isinstance(d, (int, float))
                                                   and d == math.inf):
            d = V.positive("period" if self.kind == "flick" else "duration", d)
            if d < MIN_DURATION:
                raise V.SnappingInputError(f"{'period' if self.kind == 'flick' else 'duration'}={d!r} is out of "
                                           f"range: must be >= {MIN_DURATION:g}")
        table = self.table
        if self.kind == "table" or table is not None:
            if self.kind != "table" or not isinstance(table, tuple) or len(table) != 3:
                raise V.SnappingInputError(f"table={_short(table)} must be the samples (t, x, y) of a PinMotion of "
                                           f"kind 'table' (use PinMotion.from_table)")
            table = self._checked_table(*table)
            d = float(table[0][-1])
        for name, v in (("accel", accel), ("t0", t0), ("duration", float(d)), ("table", table)):
            object.__setattr__(self, name, v)

    @classmethod
    def fixed(cls) -> "PinMotion":
        return cls()

    @classmethod
    def pull(cls, accel, duration: float = math.inf, t0: float = 0.0) -> "PinMotion":
        """A constant-acceleration pull ``accel = (ax, ay)`` (y downward) from ``t0`` for ``duration``.

        >>> PinMotion.pull((0.0, -0.5)).velocity(2.0)
        (0.0, -1.0)
        """
        ax, ay = cls._vector("accel", accel)
        t0 = V.real("t0", t0)
        if t0 < 0.0:
            raise V.SnappingInputError(f"t0={t0!r} is out of range: must be >= 0")
        d = math.inf if isinstance(duration, (int, float)) and duration == math.inf else \
            V.positive("duration", duration)
        if d < MIN_DURATION:
            raise V.SnappingInputError(f"duration={d!r} is out of range: must be >= {MIN_DURATION:g}")
        return cls("pull", (ax, ay), t0, d)

    @classmethod
    def flick(cls, accel, period: float, t0: float = 0.0) -> "PinMotion":
        """One period of a sine in the acceleration, peak ``accel = (ax, ay)``, over ``period``.

        >>> f = PinMotion.flick((1.0, 0.0), 0.5)
        >>> [round(v, 12) for v in f.position(0.5)], f.velocity(0.5)
        ([0.039788735773, 0.0], (0.0, 0.0))
        """
        ax, ay = cls._vector("accel", accel)
        T = V.positive("period", period)
        if T < MIN_DURATION:
            raise V.SnappingInputError(f"period={T!r} is out of range: must be >= {MIN_DURATION:g}")
        t0 = V.real("t0", t0)
        if t0 < 0.0:
            raise V.SnappingInputError(f"t0={t0!r} is out of range: must be >= 0")
        return cls("flick", (ax, ay), t0, T)

    @classmethod
    def from_function(cls, r, t_max: float, samples: int = 2001) -> "PinMotion":
        """The motion ``r(t) -> (x, y)`` on [0, t_max], sampled at ``samples`` equal times and
        interpolated by a cubic spline (the motion that is run and recorded; constant velocity
        after ``t_max``). ``r(0)`` must be the origin.

        >>> import math
        >>> p = PinMotion.from_function(lambda t: (0.1 * math.sin(t), 0.0), 1.0)
        >>> round(p.position(0.5)[0], 9) == round(0.1 * math.sin(0.5), 9)
        True
        """
        t, xy = sample_function(r, t_max, samples, ("x", "y"))
        return cls.from_table(t, xy[:, 0], xy[:, 1])

    @classmethod
    def from_table(cls, t, x, y) -> "PinMotion":
        """The motion through samples ``(t_i, x_i, y_i)``, t_0 = 0 and (x_0, y_0) = (0, 0),
        t increasing, at least 4 samples (a not-a-knot cubic spline through them)."""
        t, x, y = cls._checked_table(t, x, y)
        return cls("table", (0.0, 0.0), 0.0, float(t[-1]), (t, x, y))

    @staticmethod
    def _checked_table(t, x, y):
        t = np.asarray(V.float_array("t", t), dtype=float).ravel()
        x = np.asarray(V.float_array("x", x), dtype=float).ravel()
        y = np.asarray(V.float_array("y", y), dtype=float).ravel()
        if not (t.size == x.size == y.size) or t.size < 4:
            raise V.SnappingInputError(f"pin table t, x, y must have the same length >= 4; got {t.size}, {x.size}, "
                                       f"{y.size}")
        for name, a in (("t", t), ("x", x), ("y", y)):
            if not np.all(np.isfinite(a)):
                i = int(np.flatnonzero(~np.isfinite(a))[0])
                raise V.SnappingInputError(f"pin motion {name}[{i}]={a[i]!r} is not finite")
        if t[0] != 0.0 or not np.all(np.diff(t) > 0.0):
            raise V.SnappingInputError(f"pin table times must start at 0 and increase; got t[0]={t[0]!r}")
        for name, a, hi in (("t", t, T_MAX), ("x", x, POSITION_MAX), ("y", y, POSITION_MAX)):
            if np.abs(a).max() > hi:
                i = int(np.argmax(np.abs(a)))
                raise V.SnappingInputError(f"pin motion {name}[{i}]={float(a[i])!r} is out of range: must lie in "
                                           f"[-{hi:g}, {hi:g}]" + (" (chain lengths)" if name != "t" else ""))
        scale = max(1.0, float(np.abs(np.concatenate([x, y])).max()))
        if abs(x[0]) > 1e-12 * scale or abs(y[0]) > 1e-12 * scale:
            raise V.SnappingInputError(f"x[0], y[0] = ({float(x[0])!r}, {float(y[0])!r}): the held end must start "
                                       f"at the origin")
        x = x.copy()
        y = y.copy()
        x[0] = y[0] = 0.0
        return t.copy(), x, y

    @staticmethod
    def _vector(name, v):
        try:
            a = np.asarray(v, dtype=float).ravel()
        except (TypeError, ValueError, OverflowError):
            raise V.SnappingInputError(f"{name}={v!r} is not a pair of numbers (ax, ay)") from None
        if a.size != 2 or not np.all(np.isfinite(a)):
            raise V.SnappingInputError(f"{name}={v!r} must be two finite numbers (ax, ay)")
        if np.abs(a).max() > ACCEL_MAX:
            raise V.SnappingInputError(f"{name}={v!r} is out of range: each component must lie in "
                                       f"[-{ACCEL_MAX:g}, {ACCEL_MAX:g}] (units of g)")
        return float(a[0]), float(a[1])

    # -- compiled form and evaluation
    def _spline_table(self):
        from scipy.interpolate import CubicSpline

        t, x, y = self.table
        return t, CubicSpline(t, x).c, CubicSpline(t, y).c

    def model_args(self) -> dict:
        """Keyword arguments of :func:`general.make_model` for this motion."""
        code = {"fixed": G.PIN_FIXED, "pull": G.PIN_PULL, "flick": G.PIN_FLICK, "table": G.PIN_TABLE}[self.kind]
        ax, ay = self.accel
        return {"pin": (code, ax, ay, self.t0, self.duration),
                "table": self._spline_table() if self.kind == "table" else None}

    def kinematics(self, t: float):
        """(x, y, vx, vy, ax, ay) of the held end at time t (the compiled evaluation).

        Where the acceleration jumps (the start and end of a pull, the last sample of a
        table) it is the acceleration from t on, the right limit: what the run uses from t
        and shows in its snapshot at t (a pull from t0 = 0 accelerates the chain at t = 0).

        >>> PinMotion.pull((0.0, -2.0), duration=0.5).kinematics(0.0)[4:]
        (0.0, -2.0)
        >>> PinMotion.pull((0.0, -2.0), duration=0.5).kinematics(0.5)[4:]
        (0.0, 0.0)
        """
        t = V.real("t", t)
        mdl = G.make_model(np.ones(1), np.ones(1), **self.model_args())
        out = [float(v) for v in G.pin_kinematics(t, mdl[0], mdl[-1])]
        if t in G.breakpoints(mdl):  # (position and velocity are continuous there)
            out[4:] = [float(v) for v in G.pin_kinematics(float(np.nextafter(t, np.inf)), mdl[0], mdl[-1])[4:]]
        return tuple(out)

    def position(self, t: float):
        return self.kinematics(t)[:2]

    def velocity(self, t: float):
        return self.kinematics(t)[2:4]

    @property
    def is_fixed(self) -> bool:
        return self.kind == "fixed"

    def describe(self) -> dict:
        d = {"kind": self.kind}
        if self.kind in ("pull", "flick"):
            d.update({"accel": list(self.accel), "t0": self.t0,
                      ("duration" if self.kind == "pull" else "period"): self.duration})
        if self.kind == "table":
            d["samples"] = int(self.table[0].size)
            d["t_max"] = float(self.table[0][-1])
        return d


def parse_pin_motion(spec: str | None) -> PinMotion:
    """A :class:`PinMotion` from a command-line spec: ``fixed``, ``pull:AX,AY[,DURATION[,T0]]``
    or ``flick:AX,AY,PERIOD[,T0]`` (nondimensional; y downward).

    >>> parse_pin_motion("flick:2,0,0.3").describe()["period"]
    0.3
    >>> parse_pin_motion("pull:0,-0.5").duration
    inf
    """
    if spec is None or str(spec).strip() in ("", "fixed"):
        return PinMotion.fixed()
    kind, _, rest = str(spec).partition(":")
    kind = kind.strip()
    try:
        vals = [float(v) for v in rest.split(",")] if rest.strip() else []
    except ValueError:
        raise V.SnappingInputError(f"pin_motion={spec!r}: the parameters after {kind + ':'!r} must be numbers") \
            from None
    if kind == "pull" and 2 <= len(vals) <= 4:
        return PinMotion.pull(vals[:2], *(vals[2:3] or [math.inf]), *(vals[3:4] or [0.0]))
    if kind == "flick" and 3 <= len(vals) <= 4:
        return PinMotion.flick(vals[:2], vals[2], *(vals[3:4] or [0.0]))
    raise V.SnappingInputError(f"pin_motion={spec!r} is not one of 'fixed', 'pull:AX,AY[,DURATION[,T0]]', "
                               f"'flick:AX,AY,PERIOD[,T0]'")


def sample_function(r, t_max: float, samples: int, names=("x", "y")):
    """``(t, r(t))``: the user's motion ``r(t) -> (names...)`` sampled at ``samples`` equal
    times on [0, t_max], every input checked (SnappingInputError naming it); shared by the
    planar :meth:`PinMotion.from_function` and the 3D ``Pin3D.from_function``."""
    d = len(names)
    what = f"{('two', 'three')[d - 2]} numbers ({', '.join(names)})"
    if not callable(r):
        raise V.SnappingInputError(f"r={r!r} is not callable (expected a function t -> ({', '.join(names)}))")
    t_max = V.positive("t_max", t_max)
    if not MIN_DURATION <= t_max <= T_MAX:
        raise V.SnappingInputError(f"t_max={t_max!r} is out of range: must lie in [{MIN_DURATION:g}, {T_MAX:g}]")
    n = V.integer("samples", samples, 4)
    if n > MAX_SAMPLES:
        raise V.SnappingInputError(f"samples={n} is out of range: at most {MAX_SAMPLES}")
    t = np.linspace(0.0, t_max, n)
    try:
        pts = np.array([np.asarray(r(float(v)), dtype=float).ravel() for v in t])
    except Exception as exc:  # noqa: BLE001 - the user's function failed
        raise V.SnappingInputError(f"r(t) failed or did not return {what} "
                                   f"({type(exc).__name__}: {str(exc)[:120]})") from None
    if pts.ndim != 2 or pts.shape[1] != d:
        raise V.SnappingInputError(f"r(t) must return {what}; got shape {pts.shape[1:]}")
    return t, pts
