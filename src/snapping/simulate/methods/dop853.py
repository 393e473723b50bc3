"""Runs with the exactly inextensible, high-order method (``method="dop853"``, alias ``"fast"``).

The chain in link angles (:mod:`snapping.simulate.angles` for the paper's chain,
:mod:`snapping.simulate.general` for any :class:`snapping.simulate.problem.Problem`:
every link keeps its length to round-off) integrated with the compiled Dormand-Prince
8(5,3) pair and its dense output (:mod:`snapping.simulate.rk`), landing on the
breakpoints of a held end's prescribed motion. Same inputs, same run Dataset (the names of
:mod:`snapping.schema`), same stop rules and automatic snapshots as the paper's
Euler-Richardson runs (:func:`snapping.simulate.run`), with three differences:

* the peaks ``v_peak, a_peak, sigma_peak, kappa_peak`` and the snapping times
  ``t_snap_*`` are located between steps on the dense output (steps are large);
* requested snapshots are taken exactly at the requested times (dense output), and
  the ``peak`` snapshot exactly at ``t_snap_v``;
* the initial chain has links of length exactly 1/N in the directions of the chosen
  sampling of the catenary: with ``chords="exact"`` this is the Euler-Richardson
  initial state itself (the default of :func:`snapping.simulate.run`); with ``chords="arclength"`` the chords of the
  sampled catenary, slightly shorter than 1/N, are lengthened to 1/N. Compare with
  Euler-Richardson runs at ``chords="exact"``.

Long runs behave as the Euler-Richardson ones (the same driver,
:func:`snapping.simulate.driver._drive`): periodic atomic checkpoints into the run
file (``checkpoint_every``; names :data:`snapping.schema.CHECKPOINT_VARS_DOP853`: the
two last steps with their stages, the first-same-as-last stage and the dense output,
the step controller, the records, snapshots and peak trackers), SIGINT/SIGTERM stop at
a step boundary with a saved file, :func:`snapping.simulate.resume` continues bit for
bit, and ``max_energy_drift``, ``max_rejections``, ``dt_min`` raise the subclasses of
:class:`snapping.simulate.SimulationError` (attributes ``failure``, ``failure_node``).

``tol`` is the relative and absolute tolerance of every angle and angular velocity
per step (max norm); ``link_error`` is the link-length error of the chain itself,
``|N |d_k| - 1|`` with ``d_k = (cos theta_k, sin theta_k)/N`` (positions, as float64
sums of links, carry an extra round-off up to about N ulp).
"""

from __future__ import annotations

import numpy as np

from ... import _validate as V
from .. import angles as AG
from .. import general as G
from .. import models as MD
from .. import kernels as K
from ..dense_peaks import _PEAK_MEAS_G, DenseOutputPeaks
from .. import rk as R
from .._engine_common import (AFTER_PEAK_FRACTIONS, RECORD_CHUNK, SPEED_LEVEL_0, SPEED_LEVEL_FACTOR, CheckpointMixin,
                              checkpoint_getter)
from ..chain import ChainState, initial_state

__all__ = ["Engine", "setup", "complete", "resolve_method", "NAMES", "CHECKPOINT_VARS", "DEFAULT_TOL"]

#: the names this method answers to; ``fast`` always names the project's best exact method
NAMES = ("dop853", "fast")
#: tolerance of a run that gives none (the default method's): the largest tol of 1e-6 ... 1e-11
#: whose peak speed, acceleration and tension agree with tol 1e-11 to within 1e-7 (relative) at
#: chi 0.1, 0.25, 0.5 and N 200, 1000 (worst: 3.0e-8, a_peak at chi 0.25, N 200; below
#: tol 1e-7 the errors stay at ~5e-9, the peak location's floor; 1e-6 takes 1.7-2.2x fewer
#: evaluations than 1e-8): benchmarks/bench_default_tol.py, docs/benchmarks/bench_default_tol.txt
DEFAULT_TOL = 1e-6
FAST = "dop853"


def _checkpoint_names():
    from ... import schema

    return schema.CHECKPOINT_VARS_DOP853


#: the checkpoint variables of this method's run files
CHECKPOINT_VARS = _checkpoint_names()

#: node-evaluations per call into the compiled loop (sets how often the progress bar moves)
NODE_EVALS_PER_CALL = 20_000_000
#: beta of the PI step-size controller (0: the classical I controller)
PI_BETA = 0.0


def resolve_method(method: str) -> str:
    """The concrete method a name stands for (``"fast"`` -> the best exact method).

    >>> resolve_method("fast")
    'dop853'
    """
    return FAST if method == "fast" else method


class Engine(DenseOutputPeaks, CheckpointMixin):
    """State and buffers of a DOP853 angle-form run (see :func:`rk.advance_rk`)."""

    def __init__(self, y0, t0, *, tol, dt0, t_end, stop_fraction, thin, max_link_error, snapshot_times,
                 dt_min=1e-14, max_energy_drift=None, max_rejections=100, mdl=None):
        N = y0.size // 2 if mdl is None else mdl[1].size
        self.N = N
        self.mdl = G.uniform_model(N) if mdl is None else mdl
        self.general = self.mdl[0][G.P_KIND] != G.KIND_UNIFORM
        n = G.state_dim(self.mdl)
        if y0.size != n:
            raise ValueError(f"state of length {y0.size} for a model of {n} unknowns")  # pragma: no cover
        self.Y0 = np.zeros((2, n))
        self.Y1 = np.zeros((2, n))
        self.KK = np.zeros((2, R.NSX, n))
        self.F = np.zeros((2, R.NI, n))
        self.TS = np.zeros(2)
        self.HS = np.zeros(2)
        self.DOK = np.zeros(2)
        self.ytmp = np.zeros(n)
        self.breaks = [b for b in G.breakpoints(self.mdl) if b > t0]
        # at a breakpoint of the held end's motion (e.g. a pull from t = 0) the run starts
        # with the right limit of the derivative there
        t_eval = float(np.nextafter(t0, np.inf)) if t0 in G.breakpoints(self.mdl) else t0
        self.w = AG.Work(N)
        self.rw = AG.Work(N)  # scratch of peak searches and snapshots
        self._mscratch = None  # meas_at's arrays (made on first use)
        self.Z = np.zeros((K.NROWS, N + 1))
        self.rinv0 = np.full(N, float(N) * float(N))
        self.nmeas = G.NMEAS_G if self.general else K.NMEAS
        self.nrec = G.NREC_G if self.general else K.NREC
        if self.mdl[0][G.P_KIND] == G.KIND_BODY:  # (bending energy and energy dissipated: forced.M_BEND, M_DISS)
            self.nmeas, self.nrec = G.NMEAS_G + 2, G.NREC_G + 2
        self.meas = np.zeros(self.nmeas)
        self.rec = np.zeros((RECORD_CHUNK, self.nrec))
        self.tol = tol
        self.n_extra = 0
        # initial state: slot 0 holds it as the end of a zero-length step
        self.Y1[0] = y0
        w = self.w
        MD.model_rhs(N, t_eval, y0, self.KK[0, R.NS], w.c, w.s, w.S, w.cp, w.dp, w.sig, self.mdl)
        self.TS[0] = t0
        self.HS[0] = 0.0
        MD.model_measure(N, t_eval, y0, w.c, w.s, w.sig, self.Z, self.rinv0, self.meas, self.mdl)
        self.meas0 = self.meas.copy()
        self.link_error_initial = float(self.meas[K.M_LINKERR])
        if dt0 is None:
            dt0 = self._initial_step(y0, self.KK[0, R.NS].copy(), t_eval)
        self.dt0 = dt0
        K._write_record(self.rec, 0, t0, 0.0, 0.0, self.meas)
        self.rec[0, K.NREC:] = self.meas[K.NMEAS:]
        c = np.zeros(R.NQ)
        c[R.Q_T] = t0
        c[R.Q_H] = dt0
        c[R.Q_SLOT] = 0
        c[R.Q_NRHS] = 1 + self.n_extra
        c[R.Q_NREC] = 1
        c[R.Q_TOL] = tol
        c[R.Q_THIN] = thin
        c[R.Q_MAXLINK] = max_link_error
        c[R.Q_DTMIN] = dt_min
        c[R.Q_STEPS_PER_CALL] = max(20, NODE_EVALS_PER_CALL // (R.NS * N))
        c[R.Q_TEND] = t_end
        c[R.Q_TRET] = np.inf
        c[R.Q_VUP] = np.inf
        c[R.Q_STOPFRAC] = stop_fraction
        c[R.Q_VFLOOR] = max(self.meas[K.M_VMAX], K.STOP_FLOOR * np.sqrt(self.mdl[0][G.P_G] * float(np.sum(self.mdl[1]))))
        c[R.Q_E0] = self.meas[K.M_ENERGY]
        c[R.Q_L0] = self.meas[K.M_LENGTH]
        c[R.Q_LAST_V] = self.meas[K.M_VMAX]
        c[R.Q_LAST_A] = self.meas[K.M_AMAX]
        c[R.Q_LAST_S] = self.meas[K.M_SIGMAX]
        c[R.Q_LAST_K] = self.meas[K.M_KMAX]
        c[R.Q_DRIFT_LINK] = self.link_error_initial
        c[R.Q_DT_MIN_ACC] = np.inf
        c[R.Q_DT_MAX_ACC] = 0.0
        c[R.Q_ERROLD] = 1e-4
        c[R.Q_BETA] = PI_BETA
        c[R.Q_MAXENERGY] = np.inf if max_energy_drift is None else max_energy_drift
        c[R.Q_MAXREJ] = max_rejections
        c[R.Q_CONSREJ] = 0.0
        c[R.Q_TBRK] = np.inf
        c[R.Q_LASTBRK] = np.nan
        # the stop rule of a moving held end: armed from its settle time (general.settle_time)
        c[R.Q_TSETTLE] = G.settle_time(self.mdl)
        if 0.0 <= c[R.Q_TSETTLE] <= t0:
            c[R.Q_ARMED] = 1.0
            c[R.Q_VRBASE] = c[R.Q_VRPEAK] = self.meas[G.M_VREL]
        self.ctl = c
        # a general chain tracks a fifth peak, kappa_peak_approach (rk.after_attempt_with)
        pk = np.full((5 if self.general else 4, R.NPKR), np.nan)
        for qi, m in enumerate(_PEAK_MEAS_G[:pk.shape[0]]):
            pk[qi, R.PK_SBEST] = self.meas[m]
            pk[qi, R.PK_TPREV] = t0
            pk[qi, R.PK_TBEFORE] = t0
            pk[qi, R.PK_NEED] = 0.0
            pk[qi, R.PK_BEST] = self.meas[m]
            pk[qi, R.PK_TBEST] = t0
        self.pk = pk
        self.peak_state = None
        self.chunks: list[np.ndarray] = []
        self.snapshots: list = [(t0, "initial", self.Z.copy())]
        self.requested = list(snapshot_times)
        self.after_fracs = [f for f in AFTER_PEAK_FRACTIONS if f > stop_fraction]
        self.t0 = t0

    @property
    def settle_time(self) -> float:
        """When the stop rule of a moving held end is armed (:func:`general.settle_time`; -1: fixed)."""
        return float(self.ctl[R.Q_TSETTLE])

    def _initial_step(self, y0, f0, t0) -> float:
        """Hairer's starting step (Solving ODE I, II.4), in the max norm of the run."""
        N = self.N
        sc = self.tol * (1.0 + np.abs(y0))
        d0 = np.max(np.abs(y0) / sc)
        d1 = np.max(np.abs(f0) / sc)
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        y1 = y0 + h0 * f0
        f1 = np.empty_like(y0)
        w = self.rw
        MD.model_rhs(N, t0 + h0, y1, f1, w.c, w.s, w.S, w.cp, w.dp, w.sig, self.mdl)
        self.n_extra += 1
        d2 = np.max(np.abs(f1 - f0) / sc) / h0
        if max(d1, d2) <= 1e-15:
            h1 = max(1e-6, h0 * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
        return float(min(100.0 * h0, h1))

    # -- helpers
    @property
    def t(self) -> float:
        return float(self.ctl[R.Q_T])

    def drain(self) -> None:
        n = int(self.ctl[R.Q_NREC])
        if n:
            self.chunks.append(self.rec[:n].copy())
        self.ctl[R.Q_NREC] = 0

    def records(self) -> np.ndarray:
        self.drain()
        return np.concatenate(self.chunks) if self.chunks else np.zeros((0, self.nrec))

    def _set_targets(self) -> None:
        c = self.ctl
        while self.requested and self.requested[0] <= self.t:
            self.requested.pop(0)
        c[R.Q_TRET] = self.requested[0] if self.requested else np.inf
        c[R.Q_VDOWN] = self.after_fracs[0] if self.after_fracs else 0.0
        while self.breaks and self.breaks[0] <= self.t:
            self.breaks.pop(0)
        c[R.Q_TBRK] = self.breaks[0] if self.breaks else np.inf

    def start(self) -> None:
        """Targets of the first call into the compiled loop."""
        c = self.ctl
        if not np.isfinite(c[R.Q_VUP]):
            c[R.Q_VUP] = SPEED_LEVEL_0
            while c[R.Q_VUP] <= self.meas0[K.M_VMAX]:
                c[R.Q_VUP] *= SPEED_LEVEL_FACTOR
        self._set_targets()

    def handle(self, code: int, bar=None):
        """Act on a return code of the compiled loop (peaks, snapshots, progress); returns
        None to go on, or the final code."""
        c = self.ctl
        self.drain()
        if c[R.Q_REFINE] != 0.0:
            self.refine()
        if bar is not None:
            bar.update(self.t - bar.n)
            bar.set_postfix_str(f"v_max={self.meas[K.M_VMAX]:.4g} dt={c[R.Q_H]:.3g} steps={int(c[R.Q_NSTEPS])}",
                                refresh=False)
        t = self.t
        if code < K.RET_FAIL_NAN:  # every requested time the last step passed (the step that ends the run,
            while self.requested and self.requested[0] <= t:  # or meets a speed level, may pass one too)
                tr = self.requested.pop(0)
                self.snapshots.append((tr, "requested", self.Z_at(tr)[0]))
        if code == K.RET_T_RETURN:
            pass
        elif code == K.RET_V_UP:
            self.snapshots.append((t, "speed_level", self.Z.copy()))
            while c[R.Q_VUP] <= self.meas[K.M_VMAX]:
                c[R.Q_VUP] *= SPEED_LEVEL_FACTOR
        elif code == K.RET_V_DOWN:
            self.snapshots.append((t, "after_peak", self.Z.copy()))
            vpk = self.pk[0, R.PK_BEST]
            while self.after_fracs and self.meas[K.M_VMAX] < self.after_fracs[0] * vpk:
                self.after_fracs.pop(0)
        elif code in (K.RET_CALL_LIMIT, K.RET_RECORD_FULL, R.RET_REFINE):
            pass
        else:
            return code
        self._set_targets()
        return None

    def loop(self, bar, poll=None) -> int:
        """Run the compiled loop until a stop or failure code; returns it. ``poll()`` is
        called at every clean step boundary (see :meth:`snapping.simulate.methods.euler_richardson.Engine.loop`);
        a non-None result stops the loop and is returned."""
        self.start()
        w = self.w
        while True:
            code = R.advance_rk(self.N, self.Y0, self.Y1, self.KK, self.TS, self.HS, self.DOK, self.ytmp,
                                w.c, w.s, w.S, w.cp, w.dp, w.sig, self.Z, self.rinv0, self.ctl, self.rec, self.pk,
                                self.meas, self.mdl)
            final = self.handle(code, bar)
            if final is not None:
                return final
            if poll is not None:
                stop = poll()
                if stop is not None:
                    return stop

    # -- the interface of the shared driver (snapping.simulate.driver._drive)
    @property
    def n_steps(self) -> int:
        return int(self.ctl[R.Q_NSTEPS])

    def snapshots_now(self) -> list:
        """The snapshots so far plus the located peak of v_max and the current state ('final')."""
        snaps = list(self.snapshots)
        if self.peak_state is not None:
            snaps.append((self.peak_state[0], "peak", self.peak_state[1].copy()))
        snaps.append((self.t, "final", self.Z.copy()))
        return snaps

    def final_state(self) -> ChainState:
        """The state at the end (for a moving held end: relative to it, which is then in
        ``extra["pin"]`` as (x, y, vx, vy))."""
        Z = self.Z
        pin = Z[:4, self.N].copy()
        rel = Z[:4] - pin[:, None]
        final = ChainState(rel[0].copy(), rel[1].copy(), rel[2].copy(), rel[3].copy(), self.t)
        final.x[-1] = final.y[-1] = final.vx[-1] = final.vy[-1] = 0.0
        if np.any(pin != 0.0):
            final.extra["pin"] = tuple(float(v) for v in pin)
        final.extra["angles"] = self.Y1[int(self.ctl[R.Q_SLOT])].copy()
        return final

    def results(self, status: str, reason: str, wall: float, failure: str = "", node: int = -1) -> dict:
        """The result attributes (schema.RESULT_ATTRS) of the run so far."""
        from ... import __version__

        c, pk = self.ctl, self.pk
        results = {"status": status, "stop_reason": reason, "failure": failure, "failure_node": int(node)}
        if self.general:  # (schema.PROBLEM_ATTRS)
            results["t_pin_settled"] = float(c[R.Q_TSETTLE]) if c[R.Q_TSETTLE] >= 0.0 else float("nan")
            results["kappa_peak_approach"] = float(pk[4, R.PK_BEST])
            results["t_kappa_peak_approach"] = float(pk[4, R.PK_TBEST])
        for qi, name in enumerate(K.PEAK_QUANTITIES):
            if name != "kappa":
                results[f"t_snap_{name}"] = float(pk[qi, R.PK_TBEST])
            results[f"{name}_peak"] = float(pk[qi, R.PK_BEST])
        results.update({
            "kappa_max_0": float(self.meas0[K.M_KMAX]),
            "energy_drift": float(c[R.Q_DRIFT_E]),
            "link_drift": float(c[R.Q_DRIFT_LINK]),
            "link_drift_initial": float(c[R.Q_DRIFT_LINK]),
            "length_drift": float(c[R.Q_DRIFT_LEN]),
            "link_error_initial": self.link_error_initial,
            "t_final": self.t,
            "energy_initial": float(self.meas0[K.M_ENERGY]),
            "dt_min_accepted": float(c[R.Q_DT_MIN_ACC]) if np.isfinite(c[R.Q_DT_MIN_ACC]) else float("nan"),
            "dt_max_accepted": float(c[R.Q_DT_MAX_ACC]) if c[R.Q_DT_MAX_ACC] > 0 else float("nan"),
            "n_steps": int(c[R.Q_NSTEPS]),
            "n_rejected": int(c[R.Q_NREJ]),
            "n_rhs": int(c[R.Q_NRHS]),
            "wall_time": wall,
            "snapping_version": __version__,
        })
        return results

    def worst_node(self, code: int) -> int:
        """Index (along ``node``, 0 = free end) of the node behind a failure: the first
        non-finite node (state, then the failed attempt's angles), the start of the worst
        link, the largest acceleration (energy), or the link whose angle or angular
        velocity changed most in the last attempted step (step size, rejections)."""
        N = self.N
        Z = self.Z
        sl = int(self.ctl[R.Q_SLOT])
        att = self.Y1[1 - sl]
        if code == K.RET_FAIL_NAN:
            bad = ~np.all(np.isfinite(Z[:, :N]), axis=0)
            if not bad.any():
                bad = ~(np.isfinite(att[:N]) & np.isfinite(att[N:2 * N]))
            return int(np.argmax(bad)) if bad.any() else -1
        if code == K.RET_FAIL_DRIFT:
            return int(np.argmax(np.abs(N * np.hypot(np.diff(Z[K.RX]), np.diff(Z[K.RY])) - 1.0)))
        if code == K.RET_FAIL_ENERGY:
            return int(np.argmax(np.hypot(Z[K.RAX, :N], Z[K.RAY, :N])))
        cur = self.Y1[sl]
        m = np.maximum(np.abs(att[:N] - cur[:N]), np.abs(att[N:2 * N] - cur[N:2 * N]))
        return int(np.argmax(np.where(np.isfinite(m), m, np.inf)))

    def failure_message(self, code: int, node: int = -1) -> str:
        return _failure_message(code, self, node)

    # -- checkpoints (the shared part: _engine_common.CheckpointMixin)
    def checkpoint_vars(self) -> dict:
        """The checkpoint variables (schema.CHECKPOINT_VARS_DOP853), to add to the run Dataset so far."""
        from ... import schema

        nd = schema.NODE_DIM
        row, slot, ang = "checkpoint_row", "checkpoint_slot", "checkpoint_angle"
        peak_t, peak_Z = (np.nan, np.full_like(self.Z, np.nan)) if self.peak_state is None else self.peak_state
        return self._checkpoint_vars({
            "checkpoint_Y0": ((slot, ang), self.Y0.copy()),
            "checkpoint_Y1": ((slot, ang), self.Y1.copy()),
            "checkpoint_stages": ((slot, "checkpoint_stage", ang), self.KK.copy()),
            "checkpoint_dense": ((slot, "checkpoint_dense", ang), self.F.copy()),
            "checkpoint_step_t": ((slot,), self.TS.copy()),
            "checkpoint_step_h": ((slot,), self.HS.copy()),
            "checkpoint_dense_ok": ((slot,), self.DOK.copy()),
            "checkpoint_Z": ((row, nd), self.Z.copy()),
            "checkpoint_peak_t": ((), np.float64(peak_t)),
            "checkpoint_peak_state": ((row, nd), np.array(peak_Z, dtype=float)),
        }, schema.CHECKPOINT_VARS_DOP853)

    def restore(self, ds) -> None:
        """Continue from the checkpoint in run Dataset ``ds`` (the inverse of :meth:`checkpoint_vars`)."""
        self._restore_from(ds, (("checkpoint_dense", self.F), ("checkpoint_dense_ok", self.DOK)))

    def _restore_from(self, ds, own) -> None:
        """Restore the state every step loop of this engine shares, then the loop's ``own``
        (name, array) pairs (the steps' stages, slots, control, peaks, scales and history)."""
        get = checkpoint_getter(ds)
        for name, arr in (("checkpoint_Y0", self.Y0), ("checkpoint_Y1", self.Y1), ("checkpoint_stages", self.KK),
                          ("checkpoint_step_t", self.TS), ("checkpoint_step_h", self.HS),
                          ("checkpoint_Z", self.Z), *own):
            arr[...] = get(name, arr.shape)
        for name, arr in (("checkpoint_pk", self.pk), ("checkpoint_meas", self.meas), ("checkpoint_meas0", self.meas0)):
            _restore_grown(get, name, arr)
        self._restore_ctl(get, R.NQ)
        self._restore_scales(ds, get)
        peak_t = float(get("checkpoint_peak_t", ()))
        self.peak_state = None if np.isnan(peak_t) else (peak_t, get("checkpoint_peak_state", self.Z.shape))
        self._restore_history(ds, get, R.Q_NREC)

def _restore_grown(get, name: str, arr: np.ndarray) -> None:
    """Checkpoint variable ``name`` into ``arr``; a file written before a general chain's fifth peak row
    (kappa_peak_approach) and its measurement (general.M_KIN) lacks them: the rest is restored in place,
    the new ones are NaN (the run resumes; its kappa_peak_approach is NaN)."""
    a = get(name, None)
    if a.shape == arr.shape:
        arr[...] = a
    elif arr.ndim == 1 and a.shape == (arr.size - 1,) and arr.size > G.M_KIN:  # measurements: M_KIN was inserted
        arr[:G.M_KIN], arr[G.M_KIN], arr[G.M_KIN + 1:] = a[:G.M_KIN], np.nan, a[G.M_KIN:]
    elif arr.ndim == 2 and a.ndim == 2 and a.shape[1:] == arr.shape[1:] and a.shape[0] < arr.shape[0]:  # peak rows
        arr[...] = np.nan
        arr[:a.shape[0]] = a
    else:
        raise V.SnappingInputError(f"checkpoint variable {name!r} has shape {a.shape}, expected {arr.shape}")


def _failure_message(code: int, eng: Engine, node: int = -1) -> str:
    t = eng.t
    c = eng.ctl
    snode = eng.mdl[-2]  # arclength of each node from the held end (any links)
    where = f" (step {int(c[R.Q_NSTEPS])}, worst node {node}: s={snode[node]:.6g})" if node >= 0 else ""
    if code == K.RET_FAIL_NAN:
        return f"non-finite values (NaN/inf) in the state at t={t:.9g}{where}"
    if code == K.RET_FAIL_DT:
        return f"time-step underflow at t={t:.9g}: dt={c[R.Q_H]:.3g} < dt_min={c[R.Q_DTMIN]:.3g}{where}"
    if code == K.RET_FAIL_DRIFT:
        return (f"link-length drift past the bound at t={t:.9g}: relative link error "
                f"{eng.meas[K.M_LINKERR]:.3g} > max_link_error = {c[R.Q_MAXLINK]:.3g}{where}")
    if code == K.RET_FAIL_ENERGY:
        ebal = eng.meas[K.M_ENERGY]
        if eng.meas.size > K.NMEAS:  # (the balance the compiled loop bounds: E - W [+ D with a body])
            ebal = ebal - eng.meas[G.M_WORK] + (eng.meas[G.NMEAS_G + 1] if eng.meas.size > G.NMEAS_G else 0.0)
        de = abs(ebal - c[R.Q_E0])
        return (f"energy drift past the bound at t={t:.9g}: |E - E0| = {de:.3g} > "
                f"max_energy_drift={c[R.Q_MAXENERGY]:.3g}{where}")
    if code == K.RET_FAIL_REJECT:
        return (f"{int(c[R.Q_CONSREJ])} consecutive rejected steps at t={t:.9g} > max_rejections="
                f"{int(c[R.Q_MAXREJ])} (last dt={c[R.Q_H]:.3g}){where}")
    return f"unknown failure code {code}"


_compiled = False


def _warm_up() -> None:
    """Compile (or load from the numba cache) the kernels on a tiny problem, so that
    compilation is not counted in a run's wall time."""
    global _compiled
    if _compiled:
        return
    y0 = AG.state_to_angles(initial_state(0.5, 3, chords="exact"))
    eng = Engine(y0, 0.0, tol=1e-6, dt0=None, t_end=0.05, stop_fraction=0.0, thin=0.0, max_link_error=0.5,
                  snapshot_times=(0.01,))
    eng.loop(None)
    eng.pk[0, R.PK_TA], eng.pk[0, R.PK_TB] = eng.t - 0.5 * eng.HS[int(eng.ctl[R.Q_SLOT])], eng.t
    eng.ctl[R.Q_REFINE] = 1.0
    eng.refine()
    _compiled = True


def complete(opts, method: str):
    """The options with this method's defaults filled in (none: the first step is Hairer's)."""
    return opts


def _check_initial(state) -> None:
    """A given start state must have links close to 1/N (they are mapped to exactly 1/N
    in the same directions) and a finite energy: else SnappingInputError."""
    N = state.N
    l0 = state.link_lengths()
    err = float(np.max(np.abs(N * l0 - 1.0)))
    if not (np.all(l0 > 0.0) and err < 0.5):
        raise V.SnappingInputError(f"initial state: link lengths must be close to 1/N={1.0 / N:.6g} (largest relative "
                                   f"error {err:.3g}, at most 0.5 allowed)")
    with np.errstate(over="ignore", invalid="ignore"):
        ke = 0.5 * float(np.sum(state.vx ** 2 + state.vy ** 2)) / N
    if not np.isfinite(ke):
        raise V.SnappingInputError("initial state: non-finite accelerations, tension or energy "
                                   "(positions or velocities far too large)")


def setup(chi, N, method: str, opts, *, chords: str = "exact", initial=None, problem=None):
    """The input attributes and the engine of an angle-form run (``opts``: a validated
    :class:`RunOptions`). ``problem``: a general :class:`snapping.simulate.problem.Problem`
    (then ``chi``, ``chords`` and ``initial`` are not used)."""
    method = resolve_method(method)
    if problem is not None:
        y0 = problem.initial_angles()
        mdl = problem.model()
        t0 = 0.0
    else:
        state0 = initial_state(chi, N, chords) if initial is None else initial.copy()
        if initial is not None:  # a given state: the checks of the Euler-Richardson engine
            _check_initial(state0)
        y0 = AG.state_to_angles(state0)
        mdl = None
        t0 = state0.t
    inputs = {"chi": chi, "N": N, "method": method, **opts.input_attrs(), "chords": chords,
              "initial": "catenary" if initial is None else "snapshot"}
    if problem is not None:
        inputs.update({"chi": float("nan") if problem.chi is None else problem.chi, "initial": "problem",
                       "chords": problem.chords or "exact", "problem": problem})
    _warm_up()
    eng = Engine(y0, t0, mdl=mdl, **opts.engine_kwargs())
    inputs["dt0"] = eng.dt0
    return inputs, eng
