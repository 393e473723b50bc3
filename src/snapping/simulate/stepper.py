"""Running the chain: the paper's Euler-Richardson stepper driven chunk by chunk.

The whole stepping loop is compiled (:func:`snapping.simulate.kernels.advance`);
Python only sees it every few thousand steps, or when something must happen
(a snapshot, a stop check, a full record buffer), to draw the progress bar,
copy snapshots and drain the per-step record.
"""

from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .. import _validate as V
from . import kernels as K
from .chain import ChainState, initial_state
from .dataset import build_dataset, check_writable, inputs_from_attrs, save

__all__ = ["run", "rerun", "Run", "SimulationError", "METHODS", "integrate_fixed"]

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
#: node-steps per call into the compiled loop (sets how often the progress bar moves)
NODE_STEPS_PER_CALL = 10_000_000


class SimulationError(RuntimeError):
    """A run failed numerically (NaN, step-size underflow, link drift past the bound).

    Attributes
    ----------
    dataset : xarray.Dataset
        What was computed until the failure (``status = 'failed'``, ``stop_reason``).
    path : str or None
        Where it was saved, when the run had an output path.
    """

    def __init__(self, message: str, dataset: xr.Dataset | None = None, path: str | None = None):
        super().__init__(message)
        self.dataset = dataset
        self.path = path


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


def _validate(chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times, record_thin,
              max_link_error, chords, initial, output):
    if initial is None:
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
    if method not in METHODS:
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
    if chords not in ("arclength", "exact"):
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


class _Engine:
    """Buffers and control state of one run (the compiled loop's arguments)."""

    def __init__(self, state: ChainState, *, tol, dt0, fixed, t_end, stop_fraction, thin, max_link_error,
                 snapshot_times, dt_min=1e-14):
        N = state.N
        self.N = N
        self.S = np.zeros((2, K.NROWS, N + 1))
        self.S[0] = state.as_array()
        self.H = np.zeros((K.NROWS, N + 1))
        self.PS = np.zeros((K.NROWS, N + 1))
        self.work = np.zeros((4, N))
        l0 = state.link_lengths()
        self.link_error_initial = float(np.max(np.abs(N * l0 - 1.0)))
        self.rinv0 = 1.0 / (l0 * l0)
        self.meas = np.zeros(K.NMEAS)
        K.measure(N, self.S[0], self.rinv0, self.meas)
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

    def drain(self) -> None:
        n = int(self.ctl[K.C_NREC])
        if n:
            self.chunks.append(self.rec[:n].copy())
        self.ctl[K.C_NREC] = 0

    def records(self) -> np.ndarray:
        self.drain()
        return np.concatenate(self.chunks) if self.chunks else np.zeros((0, K.NREC))

    def _set_targets(self) -> None:
        c = self.ctl
        while self.requested and self.requested[0] <= self.t:  # e.g. a request for t = 0
            self.requested.pop(0)
        c[K.C_TRET] = self.requested[0] if self.requested else np.inf
        c[K.C_VDOWN] = self.after_fracs[0] if self.after_fracs else 0.0

    def loop(self, bar) -> int:
        """Run the compiled loop until a stop or failure code; returns it."""
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


def _failure_message(code: int, eng: _Engine) -> str:
    t = eng.t
    if code == K.RET_FAIL_NAN:
        return f"non-finite values (NaN/inf) in the state at t={t:.9g}"
    if code == K.RET_FAIL_DT:
        return f"time-step underflow at t={t:.9g}: dt={eng.ctl[K.C_DT]:.3g} < {eng.ctl[K.C_DTMIN]:.3g}"
    if code == K.RET_FAIL_DRIFT:
        return (f"link-length drift past the bound at t={t:.9g}: relative link error "
                f"{eng.meas[K.M_LINKERR]:.3g} > max_link_error + link_error_initial = {eng.ctl[K.C_MAXLINK]:.3g}")
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
    chi : float
        Initial end separation / length, in (0, 1).
    N : int
        Number of links, >= 1.
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

    Returns
    -------
    Run
        ``.dataset`` (xarray.Dataset, schema in :mod:`snapping.schema`), ``.state``.

    Raises
    ------
    SnappingInputError
        Bad input, before anything runs.
    SimulationError
        NaN, step-size underflow or link drift past ``max_link_error``; what was
        computed is in ``exc.dataset`` (and in ``output``), status 'failed'.

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
    from .. import __version__

    (chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times, record_thin, max_link_error,
     chords, output) = _validate(chi, N, tol, method, dt0, t_end, stop_fraction, t_end_max, snapshot_times,
                                 record_thin, max_link_error, chords, initial, output)
    if method in ("dop853", "fast"):  # issue 6: angle form + DOP853, in snapping.simulate.highorder
        from .highorder import run_highorder

        return run_highorder(chi, N, tol=tol, method=method, dt0=dt0, t_end=t_end, stop_fraction=stop_fraction,
                             t_end_max=t_end_max, snapshot_times=snapshot_times, record_thin=record_thin,
                             max_link_error=max_link_error, chords=chords, initial=initial, output=output,
                             progress=progress)
    state0 = initial_state(chi, N, chords) if initial is None else initial.copy()
    if dt0 is None:
        dt0 = math.sqrt(tol)
    fixed = method == "euler-richardson-fixed"
    inputs = {
        "chi": chi, "N": N, "method": method, "tol": tol, "dt0": dt0, "t_end": 0.0 if t_end is None else t_end,
        "stop_fraction": stop_fraction, "snapshot_times": list(snapshot_times), "record_thin": record_thin,
        "chords": chords, "initial": "catenary" if initial is None else "snapshot", "t_end_max": t_end_max,
        "max_link_error": max_link_error,
    }
    _warm_up()
    eng = _Engine(state0, tol=tol, dt0=dt0, fixed=fixed, t_end=(t_end if t_end is not None else t_end_max),
                  stop_fraction=(0.0 if t_end is not None else stop_fraction), thin=record_thin,
                  max_link_error=max_link_error, snapshot_times=snapshot_times)
    bar = None
    if progress or progress is None:
        from tqdm.auto import tqdm

        bar = tqdm(total=t_end, file=sys.stderr, disable=None if progress is None else False, unit="t",
                   desc=f"chain N={N}", dynamic_ncols=True,
                   bar_format=("{desc}: t={n:.5f}/{total:.5f} {bar} [{elapsed}<{remaining}]{postfix}" if t_end
                               else "{desc}: t={n:.5f} [{elapsed}]{postfix}"))
    status, reason, code = "completed", "", None
    wall0 = time.perf_counter()
    try:
        code = eng.loop(bar)
    except KeyboardInterrupt:
        status, reason = "interrupted", f"interrupted by the user at t={eng.t:.9g}"
    finally:
        wall = time.perf_counter() - wall0
        if bar is not None:
            bar.close()
    if code is not None:
        if code == K.RET_STOP:
            reason = f"snap detected: v_max fell below {stop_fraction:g} of its peak"
        elif code == K.RET_END:
            reason = "t_end reached" if t_end is not None else "t_end_max reached before the speed fell after a peak"
        else:
            status, reason = "failed", _failure_message(code, eng)
    # ---- snapshots at the peak and at the end
    if math.isfinite(eng.ctl[K.C_T_PEAKSTATE]):
        eng.snapshots.append((float(eng.ctl[K.C_T_PEAKSTATE]), "peak", eng.PS.copy()))
    eng.snapshots.append((eng.t, "final", eng.current().copy()))
    records = eng.records()
    c, pk = eng.ctl, eng.pk
    results = {"status": status, "stop_reason": reason}
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
    ds = build_dataset(records, eng.snapshots, N, inputs, results)
    Z = eng.current()
    final = ChainState(Z[K.RX].copy(), Z[K.RY].copy(), Z[K.RVX].copy(), Z[K.RVY].copy(), eng.t)
    path = save(ds, output) if output is not None else None
    if status == "failed":
        where = f"; what was computed is saved in {path}" if path else ""
        raise SimulationError(f"simulation failed: {reason}{where}", dataset=ds, path=path)
    if status == "interrupted":
        raise KeyboardInterrupt(reason + (f"; saved in {path}" if path else ""))
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


def integrate_fixed(state: ChainState, dt: float, n_steps: int) -> ChainState:
    """Advance ``state`` by ``n_steps`` Euler-Richardson steps of fixed size ``dt``
    (no error control; for measuring the order of accuracy).

    >>> s = integrate_fixed(initial_state(0.5, 4), 1e-3, 10)
    >>> round(s.t, 12)
    0.01
    """
    dt = V.positive("dt", dt)
    n_steps = V.integer("n_steps", n_steps, 1)
    r = run(initial=state, method="euler-richardson-fixed", dt0=dt, t_end=state.t + n_steps * dt,
            max_link_error=0.5, progress=False)
    return r.state
