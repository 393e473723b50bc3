"""The numerical options every method shares, validated once (:class:`RunOptions`),
and the resource guard (:func:`memory_need`).

The driver builds one :class:`RunOptions` from the keywords of
:func:`snapping.simulate.run` (or from a run file's attributes) and hands it to the
method; nothing downstream re-validates or re-passes the options one by one.

Example
-------
>>> from snapping.simulate.options import RunOptions
>>> o = RunOptions(tol=1e-6, snapshot_times=[0.2, 0.1])
>>> o.snapshot_times, o.engine_kwargs()["t_end"]     # sorted; an automatic run ends by t_end_max
((0.1, 0.2), 10.0)
>>> RunOptions(record_thin=1.5)
Traceback (most recent call last):
...
snapping._validate.SnappingInputError: record_thin=1.5 is out of range: must lie in [0, 1)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from .. import _validate as V
from . import kernels as K
from ._memory import MEMORY_MARGIN, _available_memory  # noqa: F401 (re-exported: options.MEMORY_MARGIN)

__all__ = ["RunOptions", "memory_need", "check_memory", "check_progress", "check_checkpoint_every", "MAX_TOL"]

#: largest stepper tolerance accepted
MAX_TOL = 0.1
#: smallest stepper tolerance accepted (a few times the round-off of an O(1) velocity)
MIN_TOL = 1e-15
_DT_MIN_DEFAULT = 1e-14
#: the stiff method's stage solves (``drag_jacobian``): ``"banded"`` (the banded Jacobian, drag left out;
#: the default) or ``"correct"`` (each stage corrected once for what it leaves out: one evaluation and one
#: banded solve more per stage, :func:`snapping.simulate.rosenbrock._stage_correct`)
DRAG_JACOBIAN = ("banded", "correct")
#: record buffer rows handed back to Python at a time (the engines' chunk; memory_need counts it)
RECORD_CHUNK = 8192
#: latest end time accepted (units of sqrt(l/g); the snap is at t ~ 1.2)
T_MAX = 1e6


@dataclass(frozen=True)
class RunOptions:
    """How a run is stepped, stopped and recorded (every method; see :func:`snapping.simulate.run`
    for the meaning of each). Validated on construction: a bad value raises
    :class:`snapping._validate.SnappingInputError` naming it."""

    tol: float = 1e-8
    dt0: float | None = None
    t_end: float | None = None
    stop_fraction: float = 0.5
    t_end_max: float = 10.0
    snapshot_times: tuple = ()
    record_thin: float = 0.0
    max_link_error: float = 1e-2
    max_energy_drift: float | None = None
    dt_min: float = 1e-14
    max_rejections: int = 100
    drag_jacobian: str = "banded"

    def __post_init__(self):
        def put(name, value):
            object.__setattr__(self, name, value)

        tol = V.positive("tol", self.tol)
        if not MIN_TOL <= tol <= MAX_TOL:
            raise V.SnappingInputError(f"tol={tol!r} is out of range: must lie in [{MIN_TOL:g}, {MAX_TOL:g}] (the "
                                       "error estimate is a velocity, of order 1)")
        put("tol", tol)
        dt_min = V.positive("dt_min", self.dt_min)
        put("dt0", None if self.dt0 is None else V.positive("dt0", self.dt0))
        put("t_end", None if self.t_end is None else V.positive("t_end", self.t_end))
        put("stop_fraction", V.open_interval("stop_fraction", self.stop_fraction, 0.0, 1.0))
        put("t_end_max", V.positive("t_end_max", self.t_end_max))
        end = self.t_end_max if self.t_end is None else self.t_end
        if dt_min != _DT_MIN_DEFAULT and end is not None and dt_min > end:  # the user's dt_min is the culprit
            raise V.SnappingInputError(f"dt_min={dt_min!r} is out of range: must be <= "
                                       f"{'t_end' if self.t_end is not None else 't_end_max'}={end:g}")
        for name in ("t_end", "t_end_max"):
            v = getattr(self, name)
            if v is not None and not dt_min <= v <= T_MAX:
                raise V.SnappingInputError(f"{name}={v!r} is out of range: must lie in [dt_min={dt_min:g}, "
                                           f"{T_MAX:g}]")
        if self.dt0 is not None and not dt_min <= self.dt0 <= T_MAX:
            raise V.SnappingInputError(f"dt0={self.dt0!r} is out of range: must lie in [dt_min={dt_min:g}, "
                                       f"{T_MAX:g}]")
        put("snapshot_times", _times(self.snapshot_times))
        if self.snapshot_times and end is not None and self.snapshot_times[-1] > end:  # never reached: refused
            raise V.SnappingInputError(f"snapshot_times contains {self.snapshot_times[-1]!r}, after the run's end "
                                       f"{'t_end' if self.t_end is not None else 't_end_max'}={end:g}: it would "
                                       f"never be recorded")
        thin = V.real("record_thin", self.record_thin)
        if not 0.0 <= thin < 1.0:
            raise V.SnappingInputError(f"record_thin={thin!r} is out of range: must lie in [0, 1)")
        put("record_thin", thin)
        put("max_link_error", V.open_interval("max_link_error", self.max_link_error, 0.0, 1.0))
        put("max_energy_drift", None if self.max_energy_drift is None
            else V.positive("max_energy_drift", self.max_energy_drift))
        put("dt_min", dt_min)
        put("max_rejections", V.integer("max_rejections", self.max_rejections, 0))
        if not isinstance(self.drag_jacobian, str) or self.drag_jacobian not in DRAG_JACOBIAN:
            raise V.SnappingInputError(f"drag_jacobian={self.drag_jacobian!r} is not one of {DRAG_JACOBIAN} (the "
                                       "stiff method's stage solves: the banded Jacobian, which leaves drag out, or "
                                       "that and one correction per stage)")

    @classmethod
    def names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))

    @classmethod
    def pick(cls, kw: dict) -> "RunOptions":
        """The options among the keywords ``kw`` (others ignored)."""
        return cls(**{k: kw[k] for k in cls.names() if k in kw})

    def replace(self, **changes) -> "RunOptions":
        return RunOptions(**{**{k: getattr(self, k) for k in self.names()}, **changes})

    def engine_kwargs(self) -> dict:
        """The keywords of an engine's constructor: an automatic run (no ``t_end``) ends by
        ``t_end_max`` at the latest and stops after the snap; a run with ``t_end`` does not."""
        auto = self.t_end is None
        return {"tol": self.tol, "dt0": self.dt0, "t_end": self.t_end_max if auto else self.t_end,
                "stop_fraction": self.stop_fraction if auto else 0.0, "thin": self.record_thin,
                "max_link_error": self.max_link_error, "snapshot_times": self.snapshot_times,
                "dt_min": self.dt_min, "max_energy_drift": self.max_energy_drift,
                "max_rejections": self.max_rejections}

    def input_attrs(self) -> dict:
        """The options as run-file attributes (schema.INPUT_ATTRS; 0 stands for None; ``drag_jacobian``
        only when not the default, so the default run's file is unchanged)."""
        return {"tol": self.tol, "dt0": 0.0 if self.dt0 is None else self.dt0,
                "t_end": 0.0 if self.t_end is None else self.t_end, "stop_fraction": self.stop_fraction,
                "snapshot_times": list(self.snapshot_times), "record_thin": self.record_thin,
                "t_end_max": self.t_end_max, "max_link_error": self.max_link_error,
                "max_energy_drift": 0.0 if self.max_energy_drift is None else self.max_energy_drift,
                "dt_min": self.dt_min, "max_rejections": self.max_rejections,
                **({} if self.drag_jacobian == "banded" else {"drag_jacobian": self.drag_jacobian})}


def _times(snapshot_times) -> tuple:
    if snapshot_times is None:
        return ()
    if isinstance(snapshot_times, (str, bytes)):
        raise V.SnappingInputError(f"snapshot_times={snapshot_times!r} is not a sequence of times")
    try:
        vals = np.atleast_1d(np.asarray(snapshot_times, dtype=float)).ravel()
    except (TypeError, ValueError, OverflowError):
        raise V.SnappingInputError(f"snapshot_times={snapshot_times!r} is not a sequence of times") from None
    out = tuple(sorted(V.real("snapshot_times", float(v)) for v in vals))
    for v in out:
        if v < 0:
            raise V.SnappingInputError(f"snapshot_times contains {v!r}: must be >= 0")
    return out


def check_checkpoint_every(checkpoint_every):
    """The checkpoint interval in seconds (>= 0), or None (no periodic checkpoints)."""
    if checkpoint_every is None:
        return None
    v = V.real("checkpoint_every", checkpoint_every)
    if v < 0:
        raise V.SnappingInputError(f"checkpoint_every={v!r} is out of range: must be >= 0 seconds "
                                   "(or None: no periodic checkpoints)")
    return v


def check_progress(progress):
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise V.SnappingInputError(f"progress={progress!r} must be True, False or None")
    return progress


# ---------------------------------------------------------------- resource guard
#: a count beyond any run (steps, records): extreme inputs are counted as this, then refused
_MAX_COUNT = 1e30


def memory_need(N: int, *, chi: float | None = None, tol: float = 1e-8, method: str = "fast",
                dt0: float | None = None, t_end: float | None = None, t_end_max: float = 10.0,
                snapshot_times=(), record_thin: float = 0.0) -> dict:
    """Estimated peak memory of a run: per-step record, snapshots and state buffers.

    The number of steps is exact for the fixed-step method (``t_end / dt0``) and,
    for the adaptive one, the calibrated cost model of the benchmark (right-hand-side
    evaluations ~ 4e5 (0.25/chi)^0.9 (N/400)^0.35 (1e-8/tol)^0.5, an upper bound on
    the steps). With ``record_thin > 0`` at most ~4 ln(1e8)/ln(1 + record_thin)
    rows are recorded. Each recorded row takes 16 float64 three times over (the
    record, its concatenation and the Dataset); each snapshot (N + 1) x 23 float64.
    For ``dop853``/``fast``: a tenth of the steps (it needs 6-40x fewer evaluations,
    12 per step) and its step slots (2 x 25 vectors of 2N + 1).

    Returns
    -------
    dict
        ``bytes`` (total), ``steps``, ``records``, ``snapshots``, and the parts
        ``record_bytes``, ``snapshot_bytes``, ``state_bytes``.

    Examples
    --------
    >>> need = memory_need(100, chi=0.25, method="euler-richardson-fixed", dt0=1e-3, t_end=1.0)
    >>> need["steps"], need["records"]
    (1000, 1001)
    """
    N = V.integer("N", N, 1)
    if chi is not None:
        from ..estimates import check_chi

        chi = check_chi(chi)
    tol = V.positive("tol", tol)
    if not MIN_TOL <= tol <= MAX_TOL:
        raise V.SnappingInputError(f"tol={tol!r} is out of range: must lie in [{MIN_TOL:g}, {MAX_TOL:g}]")
    dt0 = None if dt0 is None else V.positive("dt0", dt0)
    t_end = None if t_end is None else V.positive("t_end", t_end)
    t_end_max = V.positive("t_end_max", t_end_max)
    record_thin = V.real("record_thin", record_thin)
    angle_form = method in ("dop853", "fast", "rodas4", "stiff")
    try:  # in floats: an extreme input makes an astronomical (not an overflowing) count, refused by the guard
        if method == "euler-richardson-fixed" and dt0:
            steps_f = (t_end if t_end else t_end_max) / dt0 * (1.0 - 1e-8)
        else:
            c = 0.25 if chi is None else chi
            steps_f = (4.0e5 * (0.25 / c) ** 0.9 * (max(N, 1) / 400.0) ** 0.35 * (1e-8 / tol) ** 0.5
                       * (max(1.0, t_end / 1.5) if t_end else 1.0))
            if angle_form:  # dop853: 6-40x fewer evaluations than Euler-Richardson, 12 per step
                steps_f = steps_f / 10
    except OverflowError:
        steps_f = math.inf
    steps = math.ceil(min(steps_f, _MAX_COUNT))
    records = steps + 1
    if record_thin > 0.0:
        cap = 4 * math.log(1e8) / math.log1p(record_thin)
        if cap < _MAX_COUNT:
            records = min(records, int(cap) + 1000)
    snaps = len(snapshot_times) + 40
    record_bytes = 3 * records * K.NREC * 8
    snapshot_bytes = snaps * (N + 1) * 23 * 8
    state_bytes = (6 * K.NROWS + 14) * (N + 1) * 8 + RECORD_CHUNK * K.NREC * 8
    if angle_form:  # two step slots of 16 stages, 7 dense-output vectors and start/end states, 2N + 1 each
        state_bytes += 2 * (16 + 7 + 2) * (2 * N + 1) * 8
    return {"bytes": record_bytes + snapshot_bytes + state_bytes, "steps": steps, "records": records,
            "snapshots": snaps, "record_bytes": record_bytes, "snapshot_bytes": snapshot_bytes,
            "state_bytes": state_bytes}


def check_memory(N: int, opts: RunOptions, *, chi=None, method: str = "fast") -> dict:
    """Raise SnappingInputError when the run's record and snapshots would not fit in memory;
    else return the estimate (:func:`memory_need`, with ``file_bytes``: the run file's size)."""
    dt0 = math.sqrt(opts.tol) if opts.dt0 is None else opts.dt0
    if chi is not None and not math.isfinite(chi):  # (nan: a run from a given state, no catenary)
        chi = None
    need = memory_need(N, chi=chi, tol=opts.tol, method=method, dt0=dt0, t_end=opts.t_end,
                       t_end_max=opts.t_end_max, snapshot_times=opts.snapshot_times, record_thin=opts.record_thin)
    need["file_bytes"] = need["record_bytes"] / 3 + need["snapshot_bytes"]
    avail = _available_memory()
    if avail is None or need["bytes"] <= MEMORY_MARGIN * avail:
        return need
    gib = 2.0 ** 30
    inputs = ", ".join(f"{k}={v if isinstance(v, int) else format(v, 'g')}" for k, v in (("N", N), ("chi", chi), ("tol", opts.tol), ("dt0", opts.dt0),
                                                    ("t_end", opts.t_end)) if v is not None)
    raise V.SnappingInputError(
        f"{inputs} ({method}): the run would need about {need['bytes'] / gib:.3g} GiB of memory (record: ~{need['records']:.3g} steps "
        f"x {K.NREC * 8} B x 3 = {need['record_bytes'] / gib:.3g} GiB; snapshots: {need['snapshots']} x {N + 1} "
        f"nodes = {need['snapshot_bytes'] / gib:.3g} GiB; state: {need['state_bytes'] / gib:.3g} GiB) but only "
        f"{avail / gib:.3g} GiB is available (a run may use {MEMORY_MARGIN:.0%} of it); thin the record with "
        f"record_thin (e.g. 1e-3, --record-thin 1e-3), or use fewer snapshot_times, a smaller N or a larger tol/dt0")
