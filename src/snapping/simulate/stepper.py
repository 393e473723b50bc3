"""Running the chain: the paper's Euler-Richardson stepper driven chunk by chunk.

The whole stepping loop is compiled (:func:`snapping.simulate.kernels.advance`);
Python only sees it every few thousand steps, or when something must happen
(a snapshot, a stop check, a full record buffer), to draw the progress bar,
copy snapshots and drain the per-step record.
"""

from __future__ import annotations

import math
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .. import _validate as V
from . import kernels as K
from ._engine_common import CheckpointMixin, checkpoint_getter
from .chain import ChainState, initial_state
from .dataset import build_dataset, check_writable, inputs_from_attrs, open_netcdf, save

__all__ = ["run", "rerun", "resume", "is_resumable", "memory_need", "Run", "SimulationError", "NonFiniteError",
           "StepSizeError", "DriftError", "EnergyDriftError", "RejectionError", "RunInterrupted", "METHODS",
           "integrate_fixed"]

#: ``euler-richardson``: the paper's adaptive scheme (reference);
#: ``euler-richardson-fixed``: the same step at a fixed dt = dt0 (for order studies).
#: ``dop853``: the chain in link angles (links exact to round-off) with a compiled
#: Dormand-Prince 8(5,3) pair and dense output (:mod:`snapping.simulate.highorder`);
#: ``fast``: always the project's best exact method (now ``dop853``).
METHODS = ("euler-richardson", "euler-richardson-fixed", "dop853", "fast")

#: automatic snapshots when v_max first reaches SPEED_LEVEL_0 * SPEED_LEVEL_FACTOR**n
SPEED_LEVEL_0 = 1.0
SPEED_LEVEL_FACTOR = 1.5
#: automatic snapshots after the peak, when v_max falls below these fractions of it
AFTER_PEAK_FRACTIONS = (0.9, 0.7)
#: record buffer rows handed back to Python at a time
RECORD_CHUNK = 8192
#: node-steps per call into the compiled loop (sets how often the progress bar moves,
#: and how soon a signal or a due checkpoint is acted on: ~0.1-0.2 s)
NODE_STEPS_PER_CALL = 10_000_000
#: default wall-clock seconds between checkpoints of a run with an output file
CHECKPOINT_EVERY = 300.0
#: layout version of the checkpoint variables (schema.CHECKPOINT_VARS)
CHECKPOINT_VERSION = 1
#: largest stepper tolerance accepted
MAX_TOL = 0.1
#: fraction of the available memory a run may plan to use (resource guard)
MEMORY_MARGIN = 0.8
#: test hook: called with the engine after every return of the compiled loop; may
#: return a signal number to act as if that signal had arrived
_chunk_hook = None


class SimulationError(RuntimeError):
    """A run failed numerically (NaN, step-size underflow, link drift past the bound).

    The specific failures are the subclasses :class:`NonFiniteError`,
    :class:`StepSizeError`, :class:`DriftError` (link lengths),
    :class:`EnergyDriftError` and :class:`RejectionError`.

    Attributes
    ----------
    dataset : xarray.Dataset
        What was computed until the failure (``status = 'failed'``, ``stop_reason``,
        ``failure``, ``failure_node``).
    path : str or None
        Where it was saved, when the run had an output path.
    t : float
        Time of the last accepted step.
    step : int
        Number of accepted steps.
    node : int
        Index along the Dataset's ``node`` dimension of the worst node (0: free end), -1 if unknown.
    kind : str
        The ``failure`` attribute ('non_finite', 'step_size', 'link_drift', 'energy_drift', 'rejections').
    """

    kind = ""

    def __init__(self, message: str, dataset: xr.Dataset | None = None, path: str | None = None, *,
                 t: float = float("nan"), step: int = -1, node: int = -1):
        super().__init__(message)
        self.dataset = dataset
        self.path = path
        self.t = t
        self.step = step
        self.node = node


class NonFiniteError(SimulationError):
    """NaN or infinite values in the state, accelerations or error estimate."""

    kind = "non_finite"


class StepSizeError(SimulationError):
    """The adaptive time step fell below the floor ``dt_min``."""

    kind = "step_size"


class DriftError(SimulationError):
    """A link length drifted from 1/N past ``max_link_error`` (plus the initial chord error)."""

    kind = "link_drift"


class EnergyDriftError(DriftError):
    """The total energy drifted from its initial value past ``max_energy_drift``."""

    kind = "energy_drift"


class RejectionError(SimulationError):
    """More than ``max_rejections`` consecutive steps were rejected."""

    kind = "rejections"


class RunInterrupted(KeyboardInterrupt):
    """A run stopped at a step boundary on SIGINT or SIGTERM (a ``KeyboardInterrupt``).

    Attributes
    ----------
    signum : int
        The signal (``signal.SIGINT`` or ``signal.SIGTERM``); exit status ``128 + signum``.
    dataset : xarray.Dataset
        The run so far (``status = 'interrupted'``), with its checkpoint.
    path : str or None
        Where it was saved (resume with :func:`resume` or ``snapping simulate --resume``).
    """

    def __init__(self, message: str, signum: int, dataset: xr.Dataset | None = None, path: str | None = None):
        super().__init__(message)
        self.signum = signum
        self.dataset = dataset
        self.path = path

    @property
    def exit_status(self) -> int:
        """128 + the signal number (130 for SIGINT, 143 for SIGTERM)."""
        return 128 + int(self.signum)


@dataclass
class Run:
    """Result of :func:`run`: the run Dataset, and the final state to continue from.

    Attributes
    ----------
    dataset : xarray.Dataset
        The run (see :mod:`snapping.schema`).
    state : ChainState
        The state at the last accepted step.
    path : str or None
        Where the dataset was saved, if anywhere.
    """

    dataset: xr.Dataset
    state: ChainState
    path: str | None = None

    def summary(self) -> dict:
        """The detected results and inputs as a plain dict (also the CLI's --json)."""
        return summary(self.dataset)

    def save(self, path) -> str:
        """Write the dataset as netCDF4."""
        self.path = save(self.dataset, path)
        return self.path


SUMMARY_KEYS = (
    "chi", "N", "method", "tol", "dt0", "status", "stop_reason",
    "t_snap_v", "t_snap_a", "t_snap_sigma", "v_peak", "a_peak", "sigma_peak", "kappa_peak", "kappa_max_0",
    "energy_drift", "link_drift", "link_drift_initial", "length_drift", "link_error_initial",
    "t_final", "dt_min_accepted", "n_steps", "n_rejected", "n_rhs", "wall_time", "snapping_version",
    "start", "tip_mass", "pin_motion", "gravity",  # (general problems only)
)


def summary(ds: xr.Dataset) -> dict:
    """Inputs and detected results of a run Dataset, as a dict of plain Python values."""
    out = {}
    for k in SUMMARY_KEYS:
        if k in ds.attrs:
            v = ds.attrs[k]
            out[k] = v.item() if isinstance(v, np.generic) else v
    return out


def _parabola_vertex(tm, qm, t0, q0, tp, qp) -> float:
    """Time of the vertex of the parabola through three samples around a maximum
    (falls back to the middle sample when ill-posed)."""
    if not all(math.isfinite(v) for v in (tm, qm, t0, q0, tp, qp)) or not (tm < t0 < tp):
        return t0
    h1, h2 = t0 - tm, tp - t0
    d1, d2 = (q0 - qm) / h1, (qp - q0) / h2
    curv = (d2 - d1) / (h1 + h2)  # half the second derivative
    if curv >= 0.0:
        return t0
    # q'(t) of the parabola: slope at midpoint between samples
    tv = 0.5 * (tm + t0) - d1 / (2.0 * curv)
    return tv if tm <= tv <= tp else t0


def _validate_guards(max_energy_drift, dt_min, max_rejections, checkpoint_every):
    """The failure bounds and the checkpoint interval."""
    if max_energy_drift is not None:
        max_energy_drift = V.positive("max_energy_drift", max_energy_drift)
    dt_min = V.positive("dt_min", dt_min)
    max_rejections = V.integer("max_rejections", max_rejections, 0)
    if checkpoint_every is not None:
        checkpoint_every = V.real("checkpoint_every", checkpoint_every)
        if checkpoint_every < 0:
            raise V.SnappingInputError(f"checkpoint_every={checkpoint_every!r} is out of range: must be >= 0 seconds "
                                       "(or None: no periodic checkpoints)")
    return max_energy_drift, dt_min, max_rejections, checkpoint_every


def _resolve_problem(chi, N, chords, initial, problem, method):
    """(chi, N, chords, initial, problem) of a run given a Problem: the paper's problem
    becomes (chi, N, chords) (today's runs, bit for bit); a uniform chain with a fixed held
    end from another start becomes ``initial`` for Euler-Richardson; any other problem
    stays a problem, which only the angle-form methods take."""
    from .problem import Problem

    if isinstance(chi, Problem):
        if problem is not None:
            raise V.SnappingInputError("a Problem was given twice (as chi and as problem=)")
        chi, problem = None, chi
    if problem is None:
        return chi, N, chords, initial, None
    if not isinstance(problem, Problem):
        raise V.SnappingInputError(f"problem={type(problem).__name__} is not a snapping.simulate.Problem")
    if chi is not None:
        raise V.SnappingInputError(f"chi={chi!r} given with a Problem: the problem's start sets the shape")
    if initial is not None:
        raise V.SnappingInputError("initial= given with a Problem: the problem's start is the initial state")
    if chords != "arclength":
        raise V.SnappingInputError(f"chords={chords!r} given with a Problem: use Problem.catenary(chi, N, "
                                   f"chords={chords!r})")
    if N is not None and V.integer("N", N, 1) != problem.N:
        raise V.SnappingInputError(f"N={N!r} disagrees with the problem's {problem.N} links")
    if problem.is_paper:
        return problem.chi, problem.N, problem.chords, None, None
    if method in ("euler-richardson", "euler-richardson-fixed"):
        why = []
        if not problem.links.is_paper:
            why.append("links or masses other than N equal links and masses 1/N" if problem.links.tip_mass == 0
                       else f"a tip mass ({problem.links.tip_mass:g})")
        if not problem.pin.is_fixed:
            why.append(f"a moving held end (pin motion {problem.pin.kind!r})")
        if problem.gravity != 1.0:
            why.append(f"gravity={problem.gravity:g} (it takes g = 1)")
        if why:
            raise V.SnappingInputError(f"method={method!r} takes only the paper's chain with a fixed held end and "
                                       f"g = 1; this problem has {', '.join(why)}: use method='fast' (dop853)")
        return None, problem.N, chords, ChainState(problem.x, problem.y, problem.vx, problem.vy, 0.0), None
    return None, problem.N, chords, None, problem


def _validate(chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times, record_thin,
              max_link_error, chords, initial, output, problem=None):
    if problem is not None:
        N = problem.N
        chi = float("nan")
    elif initial is None:
        chi = V.open_interval("chi", chi, 0.0, 1.0)
        N = V.integer("N", N, 1)
    else:
        if not isinstance(initial, ChainState):
            raise V.SnappingInputError(f"initial={type(initial).__name__} must be a ChainState")
        if N is not None and V.integer("N", N, 1) != initial.N:
            raise V.SnappingInputError(f"N={N} does not match the initial state's N={initial.N}")
        N = initial.N
        chi = float("nan") if chi is None else V.open_interval("chi", chi, 0.0, 1.0)
    tol = V.positive("tol", tol)
    if tol > MAX_TOL:
        raise V.SnappingInputError(f"tol={tol!r} is out of range: must lie in (0, {MAX_TOL:g}] (the error estimate is a "
                                   "velocity, of order 1)")
    if not isinstance(method, str) or method not in METHODS:
        raise V.SnappingInputError(f"method={method!r} is not one of {METHODS}")
    if dt0 is not None:
        dt0 = V.positive("dt0", dt0)
    elif method == "euler-richardson-fixed":
        raise V.SnappingInputError("dt0=None: method 'euler-richardson-fixed' needs the step dt0 > 0")
    if t_end is not None:
        t_end = V.positive("t_end", t_end)
    stop_fraction = V.open_interval("stop_fraction", stop_fraction, 0.0, 1.0)
    t_end_max = V.positive("t_end_max", t_end_max)
    if snapshot_times is None:
        snapshot_times = ()
    if isinstance(snapshot_times, (str, bytes)):
        raise V.SnappingInputError(f"snapshot_times={snapshot_times!r} is not a sequence of times")
    try:
        vals = np.atleast_1d(np.asarray(snapshot_times, dtype=float)).ravel()
    except (TypeError, ValueError):
        raise V.SnappingInputError(f"snapshot_times={snapshot_times!r} is not a sequence of times") from None
    snapshot_times = tuple(sorted(V.real("snapshot_times", float(v)) for v in vals))
    for v in snapshot_times:
        if v < 0:
            raise V.SnappingInputError(f"snapshot_times contains {v!r}: must be >= 0")
    record_thin = V.real("record_thin", record_thin)
    if not 0.0 <= record_thin < 1.0:
        raise V.SnappingInputError(f"record_thin={record_thin!r} is out of range: must lie in [0, 1)")
    max_link_error = V.open_interval("max_link_error", max_link_error, 0.0, 1.0)
    if not isinstance(chords, str) or chords not in ("arclength", "exact"):
        raise V.SnappingInputError(f"chords={chords!r} is not one of ('arclength', 'exact')")
    if output is not None:
        output = check_writable(output)
    return (chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times, record_thin,
            max_link_error, chords, output)


_compiled = False


def _warm_up() -> None:
    """Compile (or load from the numba cache) the kernels on a tiny problem, so that
    compilation is not counted in a run's wall time."""
    global _compiled
    if _compiled:
        return
    st = initial_state(0.5, 2)
    _Engine(st, tol=1e-6, dt0=1e-3, fixed=False, t_end=1e-3, stop_fraction=0.0, thin=0.0, max_link_error=0.5,
            snapshot_times=()).loop(None)
    _compiled = True


class _Engine(CheckpointMixin):
    """Buffers and control state of one run (the compiled loop's arguments)."""

    def __init__(self, state: ChainState, *, tol, dt0, fixed, t_end, stop_fraction, thin, max_link_error,
                 snapshot_times, dt_min=1e-14, max_energy_drift=None, max_rejections=100):
        N = state.N
        self.N = N
        self.S = np.zeros((2, K.NROWS, N + 1))
        self.S[0] = state.as_array()
        self.H = np.zeros((K.NROWS, N + 1))
        self.PS = np.zeros((K.NROWS, N + 1))
        self.work = np.zeros((4, N))
        l0 = state.link_lengths()
        self.link_error_initial = float(np.max(np.abs(N * l0 - 1.0)))
        if not (np.all(l0 > 0.0) and self.link_error_initial < 0.5):
            raise V.SnappingInputError(
                f"initial state: link lengths must be close to 1/N={1.0 / N:.6g} (largest relative error "
                f"{self.link_error_initial:.3g}, at most 0.5 allowed)")
        self.rinv0 = 1.0 / (l0 * l0)
        self.meas = np.zeros(K.NMEAS)
        K.measure(N, self.S[0], self.rinv0, self.meas)
        if self.meas[K.M_FINITE] == 0.0 or not np.all(np.isfinite(self.S[0])):
            raise V.SnappingInputError("initial state: non-finite accelerations, tension or energy "
                                       "(positions or velocities far too large)")
        self.meas0 = self.meas.copy()
        self.rec = np.zeros((RECORD_CHUNK, K.NREC))
        K._write_record(self.rec, 0, state.t, 0.0, 0.0, self.meas)
        c = np.zeros(K.NCTL)
        c[K.C_T] = state.t
        c[K.C_DT] = dt0
        c[K.C_NREC] = 1
        c[K.C_TOL] = tol
        c[K.C_FIXED] = 1.0 if fixed else 0.0
        c[K.C_THIN] = thin
        # the failure bound counts from the initial chord error (sampling the catenary)
        c[K.C_MAXLINK] = max_link_error + self.link_error_initial
        c[K.C_DTMIN] = dt_min
        c[K.C_STEPS_PER_CALL] = max(50, NODE_STEPS_PER_CALL // N)
        c[K.C_TEND] = t_end
        c[K.C_TRET] = np.inf
        c[K.C_VUP] = np.inf
        c[K.C_STOPFRAC] = stop_fraction
        c[K.C_E0] = self.meas[K.M_ENERGY]
        c[K.C_L0] = float(np.sum(l0))
        c[K.C_LAST_V] = self.meas[K.M_VMAX]
        c[K.C_LAST_A] = self.meas[K.M_AMAX]
        c[K.C_LAST_S] = self.meas[K.M_SIGMAX]
        c[K.C_LAST_K] = self.meas[K.M_KMAX]
        c[K.C_T_PEAKSTATE] = np.nan
        c[K.C_DT_MIN_ACC] = np.inf
        c[K.C_DT_MAX_ACC] = 0.0
        c[K.C_MAXENERGY] = np.inf if max_energy_drift is None else max_energy_drift
        c[K.C_MAXREJ] = max_rejections
        c[K.C_CONSREJ] = 0.0
        self.ctl = c
        pk = np.full((4, K.NPK), np.nan)
        for qi, m in enumerate(K._PEAK_MEAS):
            pk[qi, K.P_TPREV] = state.t
            pk[qi, K.P_QPREV] = self.meas[m]
            pk[qi, K.P_T0] = state.t
            pk[qi, K.P_Q0] = self.meas[m]
            pk[qi, K.P_NEED] = 0.0
        self.pk = pk
        self.chunks: list[np.ndarray] = []
        self.snapshots: list = [(state.t, "initial", self.S[0].copy())]
        self.requested = list(snapshot_times)
        self.after_fracs = [f for f in AFTER_PEAK_FRACTIONS if f > stop_fraction]
        self.t0 = state.t

    # -- helpers
    @property
    def t(self) -> float:
        return float(self.ctl[K.C_T])

    def current(self) -> np.ndarray:
        return self.S[int(self.ctl[K.C_CUR])]

    # -- the interface of the driver (:func:`_drive`; shared with highorder._Engine)
    @property
    def n_steps(self) -> int:
        return int(self.ctl[K.C_NSTEPS])

    def results(self, status: str, reason: str, wall: float, failure: str = "", node: int = -1) -> dict:
        return _results(self, status, reason, wall, failure, node)

    def worst_node(self, code: int) -> int:
        return _worst_node(code, self)

    def failure_message(self, code: int, node: int = -1) -> str:
        return _failure_message(code, self, node)

    def final_state(self) -> ChainState:
        Z = self.current()
        return ChainState(Z[K.RX].copy(), Z[K.RY].copy(), Z[K.RVX].copy(), Z[K.RVY].copy(), self.t)

    def drain(self) -> None:
        n = int(self.ctl[K.C_NREC])
        if n:
            self.chunks.append(self.rec[:n].copy())
        self.ctl[K.C_NREC] = 0

    def records(self) -> np.ndarray:
        self.drain()
        if len(self.chunks) > 1:
            self.chunks = [np.concatenate(self.chunks)]
        return self.chunks[0] if self.chunks else np.zeros((0, K.NREC))

    def snapshots_now(self) -> list:
        """The snapshots so far plus the running peak of v_max and the current state ('final')."""
        snaps = list(self.snapshots)
        if math.isfinite(self.ctl[K.C_T_PEAKSTATE]):
            snaps.append((float(self.ctl[K.C_T_PEAKSTATE]), "peak", self.PS.copy()))
        snaps.append((self.t, "final", self.current().copy()))
        return snaps

    # -- checkpoints (the shared part: _engine_common.CheckpointMixin)
    def checkpoint_vars(self) -> dict:
        """The checkpoint variables (schema.CHECKPOINT_VARS), to add to the run Dataset so far."""
        from .. import schema

        row, nd = "checkpoint_row", schema.NODE_DIM
        return self._checkpoint_vars({
            "checkpoint_S": (("checkpoint_buffer", row, nd), self.S.copy()),
            "checkpoint_peak_state": ((row, nd), self.PS.copy()),
        }, schema.CHECKPOINT_VARS)

    def restore(self, ds) -> None:
        """Continue from the checkpoint in run Dataset ``ds`` (the inverse of :meth:`checkpoint_vars`)."""
        get = checkpoint_getter(ds)
        self.S[...] = get("checkpoint_S", self.S.shape)
        self.PS[...] = get("checkpoint_peak_state", self.PS.shape)
        self._restore_ctl(get, K.NCTL)
        self.pk[...] = get("checkpoint_pk", self.pk.shape)
        self.meas[...] = get("checkpoint_meas", self.meas.shape)
        self.meas0[...] = get("checkpoint_meas0", self.meas0.shape)
        self._restore_scales(ds, get)
        self._restore_history(ds, get, K.C_NREC)

    def _set_targets(self) -> None:
        c = self.ctl
        while self.requested and self.requested[0] <= self.t:  # e.g. a request for t = 0
            self.requested.pop(0)
        c[K.C_TRET] = self.requested[0] if self.requested else np.inf
        c[K.C_VDOWN] = self.after_fracs[0] if self.after_fracs else 0.0

    def loop(self, bar, poll=None) -> int:
        """Run the compiled loop until a stop or failure code; returns it.

        ``poll()`` is called at every clean step boundary (each return of the
        compiled loop, after its snapshot is taken); a non-None result stops the
        loop and is returned (``RET_SIGNAL``)."""
        c = self.ctl
        if not np.isfinite(c[K.C_VUP]):
            c[K.C_VUP] = SPEED_LEVEL_0
            while c[K.C_VUP] <= self.meas0[K.M_VMAX]:
                c[K.C_VUP] *= SPEED_LEVEL_FACTOR
        self._set_targets()
        w = self.work
        while True:
            code = K.advance(self.N, self.S, self.H, w[0], w[1], w[2], w[3], self.rinv0, c, self.rec, self.pk,
                             self.PS, self.meas)
            self.drain()
            if bar is not None:
                bar.update(self.t - bar.n)
                bar.set_postfix_str(f"v_max={self.meas[K.M_VMAX]:.4g} dt={c[K.C_DT]:.3g} steps={int(c[K.C_NSTEPS])}",
                                    refresh=False)
            t = self.t
            if code == K.RET_T_RETURN:
                self.snapshots.append((t, "requested", self.current().copy()))
                while self.requested and self.requested[0] <= t:
                    self.requested.pop(0)
            elif code == K.RET_V_UP:
                self.snapshots.append((t, "speed_level", self.current().copy()))
                while c[K.C_VUP] <= self.meas[K.M_VMAX]:
                    c[K.C_VUP] *= SPEED_LEVEL_FACTOR
            elif code == K.RET_V_DOWN:
                self.snapshots.append((t, "after_peak", self.current().copy()))
                vpk = self.pk[0, K.P_Q0]
                while self.after_fracs and self.meas[K.M_VMAX] < self.after_fracs[0] * vpk:
                    self.after_fracs.pop(0)
            elif code in (K.RET_CALL_LIMIT, K.RET_RECORD_FULL):
                pass
            else:
                return code
            self._set_targets()
            if poll is not None:
                stop = poll()
                if stop is not None:
                    return stop


#: Python-side return code of :meth:`_Engine.loop`: stopped by a signal (or the test hook)
RET_SIGNAL = -1

_FAILURES = {
    K.RET_FAIL_NAN: NonFiniteError,
    K.RET_FAIL_DT: StepSizeError,
    K.RET_FAIL_DRIFT: DriftError,
    K.RET_FAIL_ENERGY: EnergyDriftError,
    K.RET_FAIL_REJECT: RejectionError,
}


def _worst_node(code: int, eng: _Engine) -> int:
    """Index (along ``node``, 0 = free end) of the node behind a failure."""
    N = eng.N
    Z = eng.current()
    if code == K.RET_FAIL_NAN:  # the state, then the half step's positions/velocities, then the rest
        for A in (Z[:, :N], eng.H[: K.RVY + 1, :N], eng.H[:, :N]):
            bad = ~np.all(np.isfinite(A), axis=0)
            if bad.any():
                return int(np.argmax(bad))
        return -1
    if code == K.RET_FAIL_DRIFT:
        err = np.abs(N * np.hypot(np.diff(Z[K.RX]), np.diff(Z[K.RY])) - 1.0)
        return int(np.argmax(err))
    if code == K.RET_FAIL_ENERGY:
        return int(np.argmax(np.hypot(Z[K.RAX, :N], Z[K.RAY, :N])))
    # step size / rejections: the node that set the error estimate of the last attempt
    H = eng.H
    dv = np.hypot(H[K.RVX, :N] - Z[K.RVX, :N], H[K.RVY, :N] - Z[K.RVY, :N])
    da = np.hypot(H[K.RAX, :N] - Z[K.RAX, :N], H[K.RAY, :N] - Z[K.RAY, :N])
    m = np.maximum(dv, da)
    return int(np.argmax(np.where(np.isfinite(m), m, np.inf)))


def _failure_message(code: int, eng: _Engine, node: int = -1) -> str:
    t = eng.t
    c = eng.ctl
    where = f" (step {int(c[K.C_NSTEPS])}, worst node {node}: s={(eng.N - node) / eng.N:.6g})" if node >= 0 else ""
    if code == K.RET_FAIL_NAN:
        return f"non-finite values (NaN/inf) in the state at t={t:.9g}{where}"
    if code == K.RET_FAIL_DT:
        return f"time-step underflow at t={t:.9g}: dt={c[K.C_DT]:.3g} < dt_min={c[K.C_DTMIN]:.3g}{where}"
    if code == K.RET_FAIL_DRIFT:
        return (f"link-length drift past the bound at t={t:.9g}: relative link error "
                f"{eng.meas[K.M_LINKERR]:.3g} > max_link_error + link_error_initial = {c[K.C_MAXLINK]:.3g}{where}")
    if code == K.RET_FAIL_ENERGY:
        de = abs(eng.meas[K.M_ENERGY] - c[K.C_E0])
        return f"energy drift past the bound at t={t:.9g}: |E - E0| = {de:.3g} > max_energy_drift={c[K.C_MAXENERGY]:.3g}{where}"
    if code == K.RET_FAIL_REJECT:
        return (f"{int(c[K.C_CONSREJ])} consecutive rejected steps at t={t:.9g} > max_rejections="
                f"{int(c[K.C_MAXREJ])} (last dt={c[K.C_DT]:.3g}){where}")
    return f"unknown failure code {code}"


def run(
    chi: float | None = None,
    N: int | None = None,
    *,
    tol: float = 1e-8,
    method: str = "euler-richardson",
    dt0: float | None = None,
    t_end: float | None = None,
    stop_fraction: float = 0.5,
    t_end_max: float = 10.0,
    snapshot_times=(),
    record_thin: float = 0.0,
    max_link_error: float = 1e-2,
    chords: str = "arclength",
    initial: ChainState | None = None,
    output=None,
    progress: bool | None = False,
    max_energy_drift: float | None = None,
    dt_min: float = 1e-14,
    max_rejections: int = 100,
    checkpoint_every: float | None = CHECKPOINT_EVERY,
    problem=None,
) -> Run:
    """Simulate the falling chain released from the paper's catenary, to the snap and a bit after.

    The N-pendulum of the paper's appendix (eqs. (discretemo) and the tension
    system) integrated with its Euler-Richardson scheme: half step, full step,
    error estimate eq. (error), dt_new = 0.9 dt (tol/eps)^(1/2) (eq. (dtau)).

    Step rejection: a step is accepted when eps <= tol; otherwise it is retried
    from the same state with dt = 0.9 dt (tol/eps)^(1/2) (the same rule). The
    half-step evaluation alone decides, so a rejected step costs one evaluation
    and an accepted step two (the accelerations at the end of a step are those
    at the start of the next). Initial step: ``dt0 = sqrt(tol)`` unless given
    (eps ~ dt^2 max|a|/4 at rest, so this is accepted for max|a| ~ 1 and adapts
    from there); if eps = 0 exactly the step grows by ``ZERO_ERROR_GROWTH``.

    Stopping: with ``t_end`` the run ends at that time (the last step is clipped to
    land on it). Otherwise at the snap: the run stops once the maximum speed over
    the chain has fallen below ``stop_fraction`` of its running peak (the global
    peak of v_max), or at ``t_end_max`` at the latest.

    Recording: every accepted step (or, with ``record_thin > 0``, only steps where
    v_max, a_max, sigma_max or kappa_max changed by more than that fraction since
    the last recorded step; this keeps memory bounded and the record stays dense
    where things change fast, near the snap). The three steps around the peak of
    each of v_max, a_max, sigma_max, kappa_max are tracked densely regardless,
    and give the snapping times (vertex of the parabola through them).
    Snapshots of the full profiles: at t = 0, at the first step at or after each
    time in ``snapshot_times``, whenever v_max first reaches 1, 1.5, 1.5^2, ...
    (they pile up towards the snap), at the peak of v_max, when v_max falls to
    0.9 and 0.7 of the peak, and at the end.

    Parameters
    ----------
    chi : float or Problem
        Initial end separation / length, in (0, 1); or a
        :class:`snapping.simulate.problem.Problem` (any chain, start, held end, gravity).
    N : int
        Number of links, >= 1.
    problem : Problem, optional
        The problem to solve (the same as passing it as ``chi``): unequal links and
        masses, a tip mass, any start shape and velocities, a moving held end, any
        gravity. ``run(Problem.catenary(chi, N))`` is ``run(chi, N)``, bit for bit.
        Methods ``dop853``/``fast`` take every problem; ``euler-richardson`` only the
        paper's chain (N equal links and masses) with a fixed held end and g = 1.
    tol : float
        Stepper tolerance eps_tol (paper: 1e-8).
    method : {"euler-richardson", "euler-richardson-fixed"}
        The paper's adaptive scheme, or the same step with fixed dt = dt0.
    dt0 : float, optional
        Initial (fixed-mode: constant) time step.
    t_end : float, optional
        End time (> 0); default: stop automatically after the snap.
    stop_fraction : float
        Automatic stop when v_max < stop_fraction * peak, in (0, 1).
    t_end_max : float
        Hard end time of an automatic run.
    snapshot_times : sequence of float
        Extra snapshot times.
    record_thin : float
        Relative-change threshold of the thinned per-step record, in [0, 1).
    max_link_error : float
        The run fails when a link length is off from 1/N by more than this fraction
        plus the initial chord error ``link_error_initial``.
    chords : {"arclength", "exact"}
        Initial node placement (see :func:`initial_state`).
    initial : ChainState, optional
        Start from this state instead of the catenary (``chi`` then optional).
    output : path, optional
        Write the netCDF4 file here (checked for writability before the run;
        also written when the run fails or is interrupted).
    progress : bool or None
        tqdm progress bar on stderr (None: only on a terminal).
    max_energy_drift : float, optional
        The run fails when |E(t) - E(0)| exceeds this (default: no bound).
    dt_min : float
        The run fails when the adaptive time step falls below this floor.
    max_rejections : int
        The run fails after more than this many consecutive rejected steps.
    checkpoint_every : float or None
        With ``output``: save the full state of the run to ``output`` (status
        'checkpoint', atomically) every this many seconds of wall time (0: at every
        return of the compiled loop; None: only when stopped). A checkpointed or
        interrupted file continues with :func:`resume` to the same Dataset, bit for bit.

    Returns
    -------
    Run
        ``.dataset`` (xarray.Dataset, schema in :mod:`snapping.schema`), ``.state``.

    Raises
    ------
    SnappingInputError
        Bad input, before anything runs; also a run whose record and snapshots
        would not fit in the available memory (see :func:`memory_need`).
    SimulationError
        A numerical failure, as one of its subclasses: :class:`NonFiniteError`
        (NaN/inf), :class:`StepSizeError` (dt below ``dt_min``), :class:`DriftError`
        (link drift past ``max_link_error``), :class:`EnergyDriftError` (past
        ``max_energy_drift``), :class:`RejectionError` (more than
        ``max_rejections`` consecutive rejections). It carries ``t``, ``step`` and
        the worst ``node``; what was computed is in ``exc.dataset`` (and in
        ``output``), status 'failed', ``stop_reason`` and ``failure`` saying why.
    RunInterrupted
        SIGINT or SIGTERM arrived: the run stopped at a step boundary and was saved
        (status 'interrupted') with its checkpoint; a ``KeyboardInterrupt``.

    Examples
    --------
    >>> r = run(0.5, 8, t_end=0.05, chords="exact")
    >>> ds = r.dataset
    >>> ds.attrs["status"], int(ds.attrs["N"]), float(ds.t[-1])
    ('completed', 8, 0.05)
    >>> bool(ds.attrs["energy_drift"] < 1e-9), bool(ds.attrs["link_drift"] < 1e-9)
    (True, True)
    >>> snap = run(0.5, 50).dataset.attrs                 # to shortly after the snap
    >>> round(snap["t_snap_v"], 3), snap["stop_reason"]
    (1.144, 'snap detected: v_max fell below 0.5 of its peak')
    """
    chi, N, chords, initial, problem = _resolve_problem(chi, N, chords, initial, problem, method)
    (chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times, record_thin, max_link_error,
     chords, output) = _validate(chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times,
                                 record_thin, max_link_error, chords, initial, output, problem)
    max_energy_drift, dt_min, max_rejections, checkpoint_every = _validate_guards(
        max_energy_drift, dt_min, max_rejections, checkpoint_every)
    progress = _check_progress(progress)
    if method in ("dop853", "fast"):  # issue 6: angle form + DOP853, in snapping.simulate.highorder
        from .highorder import run_highorder

        return run_highorder(chi, N, tol=tol, method=method, dt0=dt0, t_end=t_end, stop_fraction=stop_fraction,
                             t_end_max=t_end_max, snapshot_times=snapshot_times, record_thin=record_thin,
                             max_link_error=max_link_error, chords=chords, initial=initial, output=output,
                             progress=progress, dt_min=dt_min, max_energy_drift=max_energy_drift,
                             max_rejections=max_rejections, checkpoint_every=checkpoint_every,
                             problem=problem)
    if dt0 is None:
        dt0 = math.sqrt(tol)
    _check_memory(N, chi=chi, tol=tol, method=method, dt0=dt0, t_end=t_end, t_end_max=t_end_max,
                  snapshot_times=snapshot_times, record_thin=record_thin)
    inputs, eng = _setup(chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times, record_thin,
                         max_link_error, chords, initial, max_energy_drift, dt_min, max_rejections)
    return _drive(eng, inputs, output=output, progress=progress, checkpoint_every=checkpoint_every, wall_before=0.0)


def _setup(chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times, record_thin, max_link_error,
           chords, initial, max_energy_drift, dt_min, max_rejections):
    """The input attributes and the engine of a run (validated arguments)."""
    state0 = initial_state(chi, N, chords) if initial is None else initial.copy()
    inputs = {
        "chi": chi, "N": N, "method": method, "tol": tol, "dt0": dt0, "t_end": 0.0 if t_end is None else t_end,
        "stop_fraction": stop_fraction, "snapshot_times": list(snapshot_times), "record_thin": record_thin,
        "chords": chords, "initial": "catenary" if initial is None else "snapshot", "t_end_max": t_end_max,
        "max_link_error": max_link_error, "max_energy_drift": 0.0 if max_energy_drift is None else max_energy_drift,
        "dt_min": dt_min, "max_rejections": max_rejections,
    }
    _warm_up()
    eng = _Engine(state0, tol=tol, dt0=dt0, fixed=method == "euler-richardson-fixed",
                  t_end=(t_end if t_end is not None else t_end_max),
                  stop_fraction=(0.0 if t_end is not None else stop_fraction), thin=record_thin,
                  max_link_error=max_link_error, snapshot_times=snapshot_times, dt_min=dt_min,
                  max_energy_drift=max_energy_drift, max_rejections=max_rejections)
    return inputs, eng


def check_inputs(chi=None, N=None, **options) -> None:
    """Check the inputs of :func:`run` without running it (a sweep checks every run
    before the first starts); raises :class:`SnappingInputError` like :func:`run`.

    >>> check_inputs(0.3, 10, tol=-1.0)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: tol=-1.0 is out of range: must be > 0
    """
    import inspect

    params = inspect.signature(run).parameters
    unknown = sorted(k for k in options if k not in params or k in ("chi", "N"))
    if unknown:
        raise V.SnappingInputError(f"unknown keywords {unknown} of simulate.run (valid: "
                                   f"{sorted(k for k in params if k not in ('chi', 'N'))})")
    kw = {k: p.default for k, p in params.items() if k not in ("chi", "N")}
    kw.update(options)
    (chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times, record_thin, _, _, _) = _validate(
        chi, N, kw["tol"], kw["method"], kw["dt0"], kw["t_end"], kw["stop_fraction"], kw["t_end_max"],
        kw["snapshot_times"], kw["record_thin"], kw["max_link_error"], kw["chords"], kw["initial"], kw["output"])
    _validate_guards(kw["max_energy_drift"], kw["dt_min"], kw["max_rejections"], kw["checkpoint_every"])
    _check_progress(kw["progress"])
    _check_memory(N, chi=chi, tol=tol, method=method, dt0=math.sqrt(tol) if dt0 is None else dt0, t_end=t_end,
                  t_end_max=t_end_max, snapshot_times=snapshot_times, record_thin=record_thin)


def _check_progress(progress):
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise V.SnappingInputError(f"progress={progress!r} must be True, False or None")
    return progress


# ---------------------------------------------------------------- resource guard
def _available_memory() -> int | None:
    """Bytes of memory available to a new allocation (MemAvailable, else free pages); None if unknown."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def memory_need(N: int, *, chi: float | None = None, tol: float = 1e-8, method: str = "euler-richardson",
                dt0: float | None = None, t_end: float | None = None, t_end_max: float = 10.0,
                snapshot_times=(), record_thin: float = 0.0) -> dict:
    """Estimated peak memory of a run: per-step record, snapshots and state buffers.

    The number of steps is exact for the fixed-step method (``t_end / dt0``) and,
    for the adaptive one, the calibrated cost model of the benchmark (right-hand-side
    evaluations ~ 4e5 (0.25/chi)^0.9 (N/400)^0.35 (1e-8/tol)^0.5, an upper bound on
    the steps). With ``record_thin > 0`` at most ~4 ln(1e8)/ln(1 + record_thin)
    rows are recorded. Each recorded row takes 16 float64 three times over (the
    record, its concatenation and the Dataset); each snapshot (N + 1) x 23 float64.

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
    if method == "euler-richardson-fixed" and dt0:
        steps = math.ceil((t_end if t_end else t_end_max) / dt0 * (1.0 - 1e-8))
    else:
        c = 0.25 if chi is None or not math.isfinite(chi) else chi
        steps = math.ceil(4.0e5 * (0.25 / c) ** 0.9 * (max(N, 1) / 400.0) ** 0.35 * (1e-8 / tol) ** 0.5
                          * (max(1.0, t_end / 1.5) if t_end else 1.0))
    records = steps + 1
    if record_thin > 0.0:
        records = min(records, int(4 * math.log(1e8) / math.log1p(record_thin)) + 1000)
    snaps = len(snapshot_times) + 40
    record_bytes = 3 * records * K.NREC * 8
    snapshot_bytes = snaps * (N + 1) * 23 * 8
    state_bytes = (6 * K.NROWS + 14) * (N + 1) * 8 + RECORD_CHUNK * K.NREC * 8
    return {"bytes": record_bytes + snapshot_bytes + state_bytes, "steps": steps, "records": records,
            "snapshots": snaps, "record_bytes": record_bytes, "snapshot_bytes": snapshot_bytes,
            "state_bytes": state_bytes}


def _check_memory(N, **kw) -> None:
    need = memory_need(N, **kw)
    avail = _available_memory()
    if avail is None or need["bytes"] <= MEMORY_MARGIN * avail:
        return
    gib = 2.0 ** 30
    raise V.SnappingInputError(
        f"the run would need about {need['bytes'] / gib:.3g} GiB of memory (record: ~{need['records']:.3g} steps "
        f"x {K.NREC * 8} B x 3 = {need['record_bytes'] / gib:.3g} GiB; snapshots: {need['snapshots']} x {N + 1} "
        f"nodes = {need['snapshot_bytes'] / gib:.3g} GiB; state: {need['state_bytes'] / gib:.3g} GiB) but only "
        f"{avail / gib:.3g} GiB is available (a run may use {MEMORY_MARGIN:.0%} of it); thin the record with "
        f"record_thin (e.g. 1e-3, --record-thin 1e-3), or use fewer snapshot_times, a smaller N or a larger tol/dt0")


# ---------------------------------------------------------------- the driver: signals, checkpoints, results
def _results(eng: _Engine, status: str, reason: str, wall: float, failure: str = "", node: int = -1) -> dict:
    from .. import __version__

    c, pk = eng.ctl, eng.pk
    results = {"status": status, "stop_reason": reason, "failure": failure, "failure_node": int(node)}
    for qi, name in enumerate(K.PEAK_QUANTITIES):
        tv = _parabola_vertex(*(float(pk[qi, j]) for j in (K.P_TM1, K.P_QM1, K.P_T0, K.P_Q0, K.P_TP1, K.P_QP1)))
        if name != "kappa":
            results[f"t_snap_{name}"] = tv
        results[f"{name}_peak"] = float(pk[qi, K.P_Q0])
    results.update({
        "kappa_max_0": float(eng.meas0[K.M_KMAX]),
        "energy_drift": float(c[K.C_DRIFT_E]),
        "link_drift": float(max(c[K.C_DRIFT_LINK], eng.link_error_initial)),
        "link_drift_initial": float(c[K.C_DRIFT_LINK0]),
        "length_drift": float(c[K.C_DRIFT_LEN]),
        "link_error_initial": eng.link_error_initial,
        "t_final": eng.t,
        "energy_initial": float(eng.meas0[K.M_ENERGY]),
        "dt_min_accepted": float(c[K.C_DT_MIN_ACC]) if np.isfinite(c[K.C_DT_MIN_ACC]) else float("nan"),
        "dt_max_accepted": float(c[K.C_DT_MAX_ACC]) if c[K.C_DT_MAX_ACC] > 0 else float("nan"),
        "n_steps": int(c[K.C_NSTEPS]),
        "n_rejected": int(c[K.C_NREJ]),
        "n_rhs": int(c[K.C_NRHS]),
        "wall_time": wall,
        "snapping_version": __version__,
    })
    return results


def _checkpoint_dataset(eng: _Engine, inputs: dict, results: dict) -> xr.Dataset:
    ds = build_dataset(eng.records(), eng.snapshots_now(), eng.N, inputs, results)
    ds = ds.assign(eng.checkpoint_vars())
    ds.attrs.update({
        "checkpoint_version": CHECKPOINT_VERSION,
        "checkpoint_wall_time": float(results["wall_time"]),
        "checkpoint_link_error_initial": eng.link_error_initial,
        "checkpoint_time": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
    })
    return ds


def _resume_command(path) -> str:
    import shlex

    return f"snapping simulate --resume {shlex.quote(str(path))}"


def _drive(eng: _Engine, inputs: dict, *, output, progress, checkpoint_every, wall_before: float) -> Run:
    """Run ``eng`` to its end, with progress bar, signal handling and checkpoints; build and save the result.

    ``eng`` is an Euler-Richardson :class:`_Engine` or an angle-form
    :class:`snapping.simulate.highorder._Engine`: both provide ``t``, ``n_steps``,
    ``loop(bar, poll)``, ``records()``, ``snapshots_now()``, ``checkpoint_vars()``,
    ``results(...)``, ``worst_node(code)``, ``failure_message(code, node)``,
    ``final_state()`` and ``link_error_initial``."""
    t_end = inputs["t_end"] or None
    N = eng.N
    bar = None
    if progress or progress is None:
        from tqdm.auto import tqdm

        desc = f"chain N={N}" if inputs["method"] in ("euler-richardson", "euler-richardson-fixed") else \
            f"chain N={N} ({inputs['method']})"
        bar = tqdm(total=t_end, initial=eng.t, file=sys.stderr, disable=None if progress is None else False,
                   unit="t", desc=desc, dynamic_ncols=True,
                   bar_format=("{desc}: t={n:.5f}/{total:.5f} {bar} [{elapsed}<{remaining}]{postfix}" if t_end
                               else "{desc}: t={n:.5f} [{elapsed}]{postfix}"))
    got = {"signum": None, "last": time.monotonic()}
    wall0 = time.perf_counter()

    def on_signal(signum, frame):
        got["signum"] = signum

    def poll():
        if _chunk_hook is not None:
            r = _chunk_hook(eng)
            if r:
                got["signum"] = int(r)
        if got["signum"] is not None:
            return RET_SIGNAL
        if output is not None and checkpoint_every is not None and time.monotonic() - got["last"] >= checkpoint_every:
            wall = wall_before + time.perf_counter() - wall0
            res = eng.results("checkpoint", f"running; checkpoint at t={eng.t:.9g}, step {eng.n_steps}; "
                              f"if the run was killed, continue with: {_resume_command(output)}", wall)
            save(_checkpoint_dataset(eng, inputs, res), output)
            got["last"] = time.monotonic()
        return None

    handlers = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            try:
                handlers[sig] = signal.signal(sig, on_signal)
            except (ValueError, OSError):  # pragma: no cover - exotic embedding
                pass
    try:
        status, reason, code = "completed", "", None
        try:
            code = eng.loop(bar, poll)
        except KeyboardInterrupt:  # no handler of ours (e.g. one raised by another handler)
            got["signum"] = signal.SIGINT
            code = RET_SIGNAL
        finally:
            wall = wall_before + time.perf_counter() - wall0
            if bar is not None:
                bar.close()
        failure, node = "", -1
        if code == RET_SIGNAL:
            status = "interrupted"
            try:
                name = signal.Signals(got["signum"]).name
            except ValueError:
                name = f"signal {got['signum']}"
            reason = f"interrupted by {name} at t={eng.t:.9g}, step {eng.n_steps}"
            if output is not None:
                reason += f"; continue with: {_resume_command(output)}"
            ds = _checkpoint_dataset(eng, inputs, eng.results(status, reason, wall))
            path = save(ds, output) if output is not None else None
            raise RunInterrupted(f"{reason}" + (f" (saved in {path})" if path else " (not saved: no output file)"),
                                 int(got["signum"]), dataset=ds, path=path)
        if code == K.RET_STOP:
            reason = f"snap detected: v_max fell below {inputs['stop_fraction']:g} of its peak"
        elif code == K.RET_END:
            reason = "t_end reached" if t_end is not None else "t_end_max reached before the speed fell after a peak"
        else:
            status = "failed"
            node = eng.worst_node(code)
            reason = eng.failure_message(code, node)
            failure = _FAILURES.get(code, SimulationError).kind
        ds = build_dataset(eng.records(), eng.snapshots_now(), N, inputs,
                           eng.results(status, reason, wall, failure, node))
        final = eng.final_state() if status == "completed" else None
        path = save(ds, output) if output is not None else None
    finally:
        for sig, h in handlers.items():
            signal.signal(sig, h)
    if status == "failed":
        where = f"; what was computed is saved in {path}" if path else ""
        cls = _FAILURES.get(code, SimulationError)
        raise cls(f"simulation failed: {reason}{where}", dataset=ds, path=path, t=eng.t,
                  step=eng.n_steps, node=node)
    return Run(ds, final, path)


def rerun(ds: xr.Dataset, **overrides) -> Run:
    """Run again from a run Dataset's attributes (``run(**inputs_from_attrs(ds))``).

    Examples
    --------
    >>> r1 = run(0.5, 6, t_end=0.02)
    >>> r2 = rerun(r1.dataset)
    >>> bool((r1.dataset.v_max == r2.dataset.v_max).all())
    True
    """
    kw = inputs_from_attrs(ds)
    kw.update(overrides)
    return run(**kw)


def _open_checkpoint(path) -> xr.Dataset:
    """Load a run file that :func:`resume` can continue, or raise SnappingInputError saying why not."""
    from .. import schema

    p = os.fspath(path) if isinstance(path, (str, os.PathLike)) else None
    if not p:
        raise V.SnappingInputError(f"path={path!r} is not a file path")
    ds = open_netcdf(p)
    status = str(ds.attrs.get("status", ""))
    if status not in schema.RESUMABLE_STATUS:
        if status in ("completed", "failed"):
            raise V.SnappingInputError(f"path={p!r} is a {status} run (status={status!r}): there is nothing to "
                                       f"resume, only runs with status in {schema.RESUMABLE_STATUS} continue")
        raise V.SnappingInputError(f"path={p!r} is not a snapping run checkpoint (status={status!r}; "
                                   f"expected one of {schema.RESUMABLE_STATUS})")
    ck_vars = schema.CHECKPOINT_VARS_DOP853 if str(ds.attrs.get("method", "")) in ("dop853", "fast") else \
        schema.CHECKPOINT_VARS
    missing = [k for k in (*ck_vars, schema.CHECKPOINT_KIND_VAR, *schema.STEP_VARS) if k not in ds.variables]
    missing += [k for k in (*schema.CHECKPOINT_ATTRS, "chi", "N", "method", "tol") if k not in ds.attrs]
    if missing:
        raise V.SnappingInputError(f"path={p!r} is not a complete checkpoint: missing {missing[:5]}")
    if int(ds.attrs["checkpoint_version"]) != CHECKPOINT_VERSION:
        raise V.SnappingInputError(f"path={p!r}: checkpoint version {ds.attrs['checkpoint_version']} is not "
                                   f"supported by this version (expects {CHECKPOINT_VERSION})")
    return ds


def is_resumable(path, **expected) -> bool:
    """True if ``path`` is a checkpoint :func:`resume` can continue and, for each keyword
    given (``chi``, ``N``, ``tol``, any input of :func:`run`), its input equals that value.

    >>> is_resumable("no/such/run.nc")
    False
    """
    try:
        ds = _open_checkpoint(path)
        kw = inputs_from_attrs(ds)
    except (V.SnappingInputError, KeyError, ValueError, TypeError):
        return False
    for k, v in expected.items():
        if v is None or k in ("output", "progress", "checkpoint_every"):
            continue
        have = kw.get(k)
        if k == "method" and v == "fast":  # files name the method it stands for
            from .highorder import resolve_method

            v = resolve_method(v)
        if k == "snapshot_times":
            if tuple(float(x) for x in np.atleast_1d(np.asarray(v, dtype=float))) != tuple(have or ()):
                return False
        elif isinstance(v, float) or isinstance(have, float):
            try:
                if float(v) != float(have):
                    return False
            except (TypeError, ValueError):
                return False
        elif v != have:
            return False
    return True


def resume(path, *, output=None, progress: bool | None = False, checkpoint_every: float | None = CHECKPOINT_EVERY) -> Run:
    """Continue an interrupted or checkpointed run file to its end.

    The run continues from the complete state stored in the file (positions and
    velocities of every node, t, dt, the stepper's counters, the record so far,
    the snapshots and the peak trackers; :data:`snapping.schema.CHECKPOINT_VARS`),
    and gives the same accepted steps and the same Dataset, bit for bit, as a run
    that was never interrupted (``wall_time`` aside: it adds up the sessions).

    Parameters
    ----------
    path : path
        A run file with status 'checkpoint' or 'interrupted'.
    output : path, optional
        Where to write the run (default: ``path`` itself, replaced atomically).
    progress, checkpoint_every
        As for :func:`run`.

    Returns
    -------
    Run

    Raises
    ------
    SnappingInputError
        Not a readable run checkpoint (a completed or failed run, another
        program's file, a truncated file), or an unwritable ``output``.
    SimulationError, RunInterrupted
        As for :func:`run`.

    Examples
    --------
    >>> import os, tempfile
    >>> p = os.path.join(tempfile.mkdtemp(), "run.nc")
    >>> resume(p)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: path='...run.nc' does not exist or is not a file
    """
    ds = _open_checkpoint(path)
    out = check_writable(path if output is None else output)
    _, _, _, checkpoint_every = _validate_guards(None, 1.0, 0, checkpoint_every)
    progress = _check_progress(progress)
    try:
        kw = inputs_from_attrs(ds)
        (chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times, record_thin, max_link_error,
         chords, _) = _validate(kw["chi"], kw["N"], kw["tol"], kw["method"], kw["dt0"], kw["t_end"],
                                kw["stop_fraction"], kw["t_end_max"], kw["snapshot_times"], kw["record_thin"],
                                kw["max_link_error"], kw["chords"], kw.get("initial"), None, kw.get("problem"))
        max_energy_drift, dt_min, max_rejections, _ = _validate_guards(
            kw["max_energy_drift"], kw["dt_min"], kw["max_rejections"], None)
    except (KeyError, TypeError, ValueError) as exc:
        raise V.SnappingInputError(f"path={os.fspath(path)!r}: the inputs stored in the checkpoint are not valid "
                                   f"({type(exc).__name__}: {exc})") from None
    _check_memory(N, chi=chi, tol=tol, method=method, dt0=dt0, t_end=t_end, t_end_max=t_end_max,
                  snapshot_times=snapshot_times, record_thin=record_thin)
    if method in ("dop853", "fast"):
        from .highorder import _setup as _setup_highorder

        inputs, eng = _setup_highorder(chi, N, tol=tol, method=method, dt0=dt0, t_end=t_end,
                                       stop_fraction=stop_fraction, t_end_max=t_end_max,
                                       snapshot_times=snapshot_times, record_thin=record_thin,
                                       max_link_error=max_link_error, chords=chords, initial=kw.get("initial"),
                                       dt_min=dt_min, max_energy_drift=max_energy_drift,
                                       max_rejections=max_rejections, problem=kw.get("problem"))
    else:
        inputs, eng = _setup(chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times,
                             record_thin, max_link_error, chords, kw.get("initial"), max_energy_drift, dt_min,
                             max_rejections)
    try:
        eng.restore(ds)
    except (KeyError, ValueError, TypeError) as exc:
        if isinstance(exc, V.SnappingInputError):
            raise V.SnappingInputError(f"path={os.fspath(path)!r}: {exc}") from None
        raise V.SnappingInputError(f"path={os.fspath(path)!r}: the checkpoint is damaged ({exc})") from None
    return _drive(eng, inputs, output=out, progress=progress, checkpoint_every=checkpoint_every,
                  wall_before=float(ds.attrs["checkpoint_wall_time"]))


def integrate_fixed(state: ChainState, dt: float, n_steps: int) -> ChainState:
    """Advance ``state`` by ``n_steps`` Euler-Richardson steps of fixed size ``dt``
    (no error control; for measuring the order of accuracy).

    >>> s = integrate_fixed(initial_state(0.5, 4), 1e-3, 10)
    >>> round(s.t, 12)
    0.01
    """
    if not isinstance(state, ChainState):
        raise V.SnappingInputError(f"state={type(state).__name__} is not a ChainState")
    dt = V.positive("dt", dt)
    n_steps = V.integer("n_steps", n_steps, 1)
    r = run(initial=state, method="euler-richardson-fixed", dt0=dt, t_end=state.t + n_steps * dt,
            max_link_error=0.5, progress=False)
    return r.state
