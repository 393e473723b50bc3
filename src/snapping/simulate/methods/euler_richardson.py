"""The paper's Euler-Richardson method (position form), driven chunk by chunk.

The whole stepping loop is compiled (:func:`snapping.simulate.kernels.advance`); Python
only sees it every few thousand steps, or when something must happen (a snapshot, a stop
check, a full record buffer). :class:`Engine` is the method's state and buffers; the
driver (:mod:`snapping.simulate.driver`) runs it through the interface every method
shares (``loop``, ``records``, ``snapshots_now``, ``results``, ``checkpoint_vars``,
``restore``, ``worst_node``, ``failure_message``, ``final_state``). It takes the paper's
chain only (N equal links and masses 1/N, a fixed held end, g = 1), from any state.
"""

from __future__ import annotations

import math

import numpy as np

from ... import _validate as V
from .. import kernels as K
from .._engine_common import (AFTER_PEAK_FRACTIONS, RECORD_CHUNK, SPEED_LEVEL_0, SPEED_LEVEL_FACTOR, CheckpointMixin,
                              checkpoint_getter)
from ..chain import ChainState, initial_state

__all__ = ["Engine", "setup", "complete", "NAMES", "CHECKPOINT_VARS", "DEFAULT_TOL"]

#: the names this method answers to (``-fixed``: the same step at a fixed dt = dt0)
NAMES = ("euler-richardson", "euler-richardson-fixed")
#: tolerance of a run that gives none: the paper's eps_tol
DEFAULT_TOL = 1e-8
#: node-steps per call into the compiled loop (sets how often the progress bar moves,
#: and how soon a signal or a due checkpoint is acted on: ~0.1-0.2 s)
NODE_STEPS_PER_CALL = 10_000_000


def _checkpoint_names():
    from ... import schema

    return schema.CHECKPOINT_VARS


#: the checkpoint variables of this method's run files
CHECKPOINT_VARS = _checkpoint_names()


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


_compiled = False


def _warm_up() -> None:
    """Compile (or load from the numba cache) the kernels on a tiny problem, so that
    compilation is not counted in a run's wall time."""
    global _compiled
    if _compiled:
        return
    st = initial_state(0.5, 2)
    Engine(st, tol=1e-6, dt0=1e-3, fixed=False, t_end=1e-3, stop_fraction=0.0, thin=0.0, max_link_error=0.5,
            snapshot_times=()).loop(None)
    _compiled = True


class Engine(CheckpointMixin):
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
        c[K.C_VFLOOR] = max(self.meas[K.M_VMAX], K.STOP_FLOOR * np.sqrt(float(np.sum(l0))))  # (g = 1 here)
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

    # -- the interface of the driver (snapping.simulate.driver._drive; every method's engine has it)
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
        from ... import schema

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


def _worst_node(code: int, eng: Engine) -> int:
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


def _failure_message(code: int, eng: Engine, node: int = -1) -> str:
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


def _results(eng: Engine, status: str, reason: str, wall: float, failure: str = "", node: int = -1) -> dict:
    from ... import __version__

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


def complete(opts, method: str):
    """The options with this method's defaults filled in: the initial step dt0 = sqrt(tol)
    (eps ~ dt^2 max|a|/4 at rest, accepted for max|a| ~ 1), or dt_min if that is larger
    (a smaller first step would be below the floor); the fixed-step variant needs dt0."""
    import math

    if opts.dt0 is None:
        if method == "euler-richardson-fixed":
            raise V.SnappingInputError("dt0=None: method 'euler-richardson-fixed' needs the step dt0 > 0")
        opts = opts.replace(dt0=max(math.sqrt(opts.tol), opts.dt_min))
    return opts


def setup(chi, N, method: str, opts, *, chords: str, initial=None, problem=None):
    """The input attributes and the engine of a run (``opts``: completed :class:`RunOptions`).
    The paper's chain only: a general problem reaches here as ``initial`` (the driver checks)."""
    if problem is not None:  # pragma: no cover - the driver turns what this method takes into ``initial``
        raise V.SnappingInputError(f"method={method!r} takes only the paper's chain (use method='fast')")
    state0 = initial_state(chi, N, chords) if initial is None else initial.copy()
    inputs = {"chi": chi, "N": N, "method": method, **opts.input_attrs(), "chords": chords,
              "initial": "catenary" if initial is None else "snapshot"}
    _warm_up()
    eng = Engine(state0, fixed=method == "euler-richardson-fixed", **opts.engine_kwargs())
    return inputs, eng
