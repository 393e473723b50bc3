"""Stepping the 3D chain: compiled, error-controlled DOP853 with dense output, to the snap.

The Dormand-Prince 8(5,3) pair of :mod:`snapping.simulate.rk` (its tableau, stage
combination ``end_state``, error norm ``step_error`` and dense-output
evaluation ``dense_eval`` are generic in the state and reused as they are; its step loop
``advance_rk`` and ``dense_build`` call the planar models' right-hand side, so this module
has its own loop, :func:`advance3d`, around :func:`snapping.spatial.chain3d.rhs3d`).

Per attempted step: 12 evaluations (first same as last); 3 more for the dense output of a
step a peak search needs, 1 per point of the search. Error control on the planar method's
quantities (each link's angle and angular-velocity errors, by vector length, so the norm does
not depend on the frame: :func:`snapping.spatial.error3d.step_error3d`, rtol = atol = ``tol``).
After each accepted step the state is projected back onto ``|e_j| = 1, e_j . u_j = 0`` (:func:`snapping.spatial.chain3d.project`);
the next step's first stage is the last stage of this one (at the unprojected end state,
which differs by the local error: ``reeval=True`` evaluates it again at the projected state,
one evaluation more per step).

Peaks (largest node speed, acceleration and tension), as the planar runs: sampled at every
accepted step; a record followed by a smaller sample brackets the peak between the
neighbouring steps, and it is located on the dense output by a bounded Brent search. The
automatic stop (the snap stop): once the largest node speed (relative to the held end,
after a moving end has settled) falls below ``stop_fraction`` of its peak.

Example
-------
>>> from snapping.spatial.starts3d import Problem3D
>>> from snapping.spatial.solve3d import run3d
>>> res = run3d(Problem3D.catenary(0.5, 20), tol=1e-8)
>>> 1.0 < res["t_snap_v"] < 2.0 and res["z_amp_final"] == 0.0
True
"""

from __future__ import annotations

import math
import time

import numpy as np
from numba import njit
from scipy.optimize import minimize_scalar

from ..simulate import rk as R
from ..simulate.layout import STOP_FLOOR
from . import chain3d as C
from .error3d import STAGE_BLOCK, step_error3d, step_error3d_components

__all__ = ["run3d", "Stepper3D"]

# ---------------------------------------------------------------- control array
(Q_T, Q_H, Q_SLOT, Q_NSTEPS, Q_NREJ, Q_NRHS, Q_NREC, Q_TOL, Q_TEND, Q_STOPFRAC, Q_DTMIN, Q_MAXREJ, Q_CONSREJ,
 Q_REJECTED, Q_TBRK, Q_LASTBRK, Q_REFINE, Q_NCALL, Q_CALLMAX, Q_REEVAL, Q_TSETTLE, Q_ARMED, Q_VRBASE,
 Q_VRPEAK, Q_MAXLINK, Q_VFLOOR) = range(26)
NQ = 26
# peak rows: v, a, sigma
(PK_SBEST, PK_TPREV, PK_TBEFORE, PK_NEED, PK_TA, PK_TB, PK_BEST, PK_TBEST) = range(8)
NPKR = 8
PEAK_MEAS = (C.M_VMAX, C.M_AMAX, C.M_SIGMAX)
PEAK_NAMES = ("v", "a", "sigma")
# return codes
RET_STOP, RET_END, RET_REFINE, RET_RECORD_FULL, RET_CALL_LIMIT, RET_BREAK = 0, 1, 2, 3, 4, 5
RET_FAIL_NAN, RET_FAIL_DT, RET_FAIL_REJECT, RET_FAIL_DRIFT = 10, 11, 12, 13
FAILURES = {RET_FAIL_NAN: "non-finite state", RET_FAIL_DT: "step-size underflow",
            RET_FAIL_REJECT: "too many consecutive rejections", RET_FAIL_DRIFT: "link error past max_link_error"}
#: record columns: t, dt, err, then chain3d.MEAS_NAMES
NREC = 3 + C.NMEAS
RECORD_NAMES = ("t", "dt", "err") + C.MEAS_NAMES
RECORD_CHUNK = 4096
PEAK_XTOL = 1e-10
#: error norm: 2 the links' angle and angular-velocity errors
#: (:func:`snapping.spatial.error3d.step_error3d`, the planar method's quantities), 1 per component
#: scaled by the link's norms (:func:`snapping.spatial.error3d.step_error3d_components`, the norm
#: before), 0 per component (:func:`snapping.simulate.rk.step_error`)
NORM_MODE = 2


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _stage_state3d(n, s, h, y0, Kst, out):
    """:func:`snapping.simulate.rk._stage_state` (``out = y0 + h sum_j A[s, j] K_j`` over the
    nonzero ``A[s, j]``, in the same order: bit for bit), in blocks of
    :data:`snapping.spatial.error3d.STAGE_BLOCK` elements, so that a block of ``out`` stays in
    the first-level cache over the stage's terms (the 3D state is 3 times the planar one and
    outgrows it)."""
    m = R._NZ[s]
    for i0 in range(0, n, STAGE_BLOCK):
        i1 = min(i0 + STAGE_BLOCK, n)
        ob = out[i0:i1]
        yb = y0[i0:i1]
        nb = i1 - i0
        j = R._NZC[s, 0]
        a = h * R.A_RK[s, j]
        Kj = Kst[j, i0:i1]
        for i in range(nb):
            ob[i] = yb[i] + a * Kj[i]
        for jj in range(1, m):
            j = R._NZC[s, jj]
            a = h * R.A_RK[s, j]
            Kj = Kst[j, i0:i1]
            for i in range(nb):
                ob[i] += a * Kj[i]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def step3d(N, t, h, y0, y1, Kst, ytmp, T, cp, dp, tol, par, hh, invm):
    """One DOP853 step of size h from y0 (Kst[0] = f(t, y0)) into y1; returns the scaled error."""
    n = y0.shape[0]
    for st in range(1, R.NS):
        _stage_state3d(n, st, h, y0, Kst, ytmp)
        C.rhs3d(N, t + R.C_RK[st] * h, ytmp, Kst[st], T, cp, dp, par, hh, invm)
    R.end_state(n, h, y0, Kst, y1)
    C.rhs3d(N, t + h, y1, Kst[R.NS], T, cp, dp, par, hh, invm)
    if NORM_MODE == 2:
        return step_error3d(N, h, tol, y0, y1, Kst, ytmp)
    if NORM_MODE == 1:
        return step_error3d_components(N, h, tol, y0, y1, Kst, ytmp)
    return R.step_error(n, h, tol, y0, y1, Kst, ytmp)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def dense_build3d(N, t, h, y0, y1, Kst, F, ytmp, T, cp, dp, par, hh, invm):
    """The 7 dense-output coefficient vectors F of a step (3 more evaluations; as
    :func:`snapping.simulate.rk.dense_build`, with the 3D right-hand side)."""
    n = y0.shape[0]
    for st in range(R.NS + 1, R.NSX):
        _stage_state3d(n, st, h, y0, Kst, ytmp)
        C.rhs3d(N, t + R.C_RK[st] * h, ytmp, Kst[st], T, cp, dp, par, hh, invm)
    for i in range(n):
        dy = y1[i] - y0[i]
        f0 = Kst[0, i]
        f1 = Kst[R.NS, i]
        F[0, i] = dy
        F[1, i] = h * f0 - dy
        F[2, i] = 2.0 * dy - h * (f1 + f0)
        for r in range(4):
            acc = 0.0
            for j in range(R.NSX):
                acc += R.D_RK[r, j] * Kst[j, i]
            F[3 + r, i] = h * acc


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def advance3d(N, Y0, Y1, KK, TS, HS, DOK, ytmp, T, cp, dp, ctl, rec, pk, meas, snode, par, hh, invm):
    """Step until something needs Python (a stop, a peak to locate, a full record, a
    breakpoint, the call limit or a failure); returns its code. Two step slots as
    :func:`snapping.simulate.rk.advance_rk`: ``ctl[Q_SLOT]`` is the last accepted step's,
    whose ``Y1`` is the current (projected) state."""
    n = Y0.shape[1]
    tol = ctl[Q_TOL]
    ctl[Q_NCALL] = 0.0
    while True:
        sl = int(ctl[Q_SLOT])
        ns = 1 - sl
        t = ctl[Q_T]
        h = ctl[Q_H]
        last = False
        rem = ctl[Q_TEND] - t
        if h >= rem * (1.0 - 1e-8):
            h = rem
            last = True
        elif h >= (ctl[Q_TBRK] - t) * (1.0 - 1e-8):
            h = ctl[Q_TBRK] - t
        y0 = Y0[ns]
        ycur = Y1[sl]
        for i in range(n):
            y0[i] = ycur[i]
        if t == ctl[Q_LASTBRK] or ctl[Q_REEVAL] != 0.0:
            te = np.nextafter(t, np.inf) if t == ctl[Q_LASTBRK] else t
            C.rhs3d(N, te, y0, KK[ns, 0], T, cp, dp, par, hh, invm)
            ctl[Q_NRHS] += 1.0
        else:
            for i in range(n):
                KK[ns, 0, i] = KK[sl, R.NS, i]
        err = step3d(N, t, h, y0, Y1[ns], KK[ns], ytmp, T, cp, dp, tol, par, hh, invm)
        ctl[Q_NRHS] += float(R.NS)
        if not (err - err == 0.0) or err > 1.0:
            fin = err - err == 0.0
            ctl[Q_H] = h * (max(R.MIN_FACTOR, R.SAFETY * err ** R.ERR_EXPONENT) if fin else R.MIN_FACTOR)
            ctl[Q_NREJ] += 1.0
            ctl[Q_REJECTED] = 1.0
            ctl[Q_CONSREJ] += 1.0
            if ctl[Q_H] < ctl[Q_DTMIN]:
                return RET_FAIL_DT if fin else RET_FAIL_NAN
            if ctl[Q_CONSREJ] > ctl[Q_MAXREJ]:
                return RET_FAIL_REJECT
            continue
        # ---- accept
        fac = R.MAX_FACTOR if err == 0.0 else min(R.MAX_FACTOR, R.SAFETY * err ** R.ERR_EXPONENT)
        if ctl[Q_REJECTED] != 0.0:
            fac = min(1.0, fac)
        ctl[Q_REJECTED] = 0.0
        ctl[Q_CONSREJ] = 0.0
        TS[ns] = t
        HS[ns] = h
        DOK[ns] = 0.0
        t = ctl[Q_TEND] if last else t + h
        at_brk = (not last) and abs(t - ctl[Q_TBRK]) <= 1e-13 * max(1.0, abs(t))
        if at_brk:
            t = ctl[Q_TBRK]
            ctl[Q_LASTBRK] = t
        ctl[Q_T] = t
        ctl[Q_SLOT] = float(ns)
        ctl[Q_H] = h * fac
        ctl[Q_NSTEPS] += 1.0
        ctl[Q_NCALL] += 1.0
        y1 = Y1[ns]
        # measure on the end state (its tensions T from the last stage), then project
        C.measure3d(N, t, y1, T, meas, snode, par, hh, invm)
        C.project(N, y1)
        for qi in range(3):
            q = meas[C.M_VMAX] if qi == 0 else (meas[C.M_AMAX] if qi == 1 else meas[C.M_SIGMAX])
            if q > pk[qi, PK_SBEST]:
                pk[qi, PK_SBEST] = q
                pk[qi, PK_TBEFORE] = pk[qi, PK_TPREV]
                pk[qi, PK_NEED] = 1.0
                if q > pk[qi, PK_BEST]:
                    pk[qi, PK_BEST] = q
                    pk[qi, PK_TBEST] = t
            elif pk[qi, PK_NEED] != 0.0:
                pk[qi, PK_NEED] = 0.0
                pk[qi, PK_TA] = pk[qi, PK_TBEFORE]
                pk[qi, PK_TB] = t
                ctl[Q_REFINE] = float(int(ctl[Q_REFINE]) | (1 << qi))
            pk[qi, PK_TPREV] = t
        # the snap stop: the largest node speed (relative to a settled moving end) falls
        if ctl[Q_TSETTLE] >= 0.0:
            vrel = meas[C.M_VREL]
            if ctl[Q_ARMED] == 0.0:
                if t >= ctl[Q_TSETTLE]:
                    ctl[Q_ARMED] = 1.0
                    ctl[Q_VRBASE] = vrel
                    ctl[Q_VRPEAK] = vrel
            elif vrel > ctl[Q_VRPEAK]:
                ctl[Q_VRPEAK] = vrel
            fell = ctl[Q_ARMED] != 0.0 and ctl[Q_VRPEAK] > ctl[Q_VRBASE] and vrel < ctl[Q_STOPFRAC] * ctl[Q_VRPEAK]
        else:
            fell = pk[0, PK_BEST] > ctl[Q_VFLOOR] and meas[C.M_VMAX] < ctl[Q_STOPFRAC] * pk[0, PK_BEST]
        nrec = int(ctl[Q_NREC])
        rec[nrec, 0] = t
        rec[nrec, 1] = h
        rec[nrec, 2] = err * tol
        for q in range(meas.shape[0]):
            rec[nrec, 3 + q] = meas[q]
        nrec += 1
        ctl[Q_NREC] = float(nrec)
        if meas[C.M_FINITE] == 0.0:
            return RET_FAIL_NAN
        if meas[C.M_LINKERR] > ctl[Q_MAXLINK]:
            return RET_FAIL_DRIFT
        if ctl[Q_STOPFRAC] > 0.0 and fell:
            return RET_STOP
        if last:
            return RET_END
        if at_brk:
            return RET_BREAK
        if ctl[Q_REFINE] != 0.0:
            return RET_REFINE
        if nrec >= rec.shape[0]:
            return RET_RECORD_FULL
        if ctl[Q_NCALL] >= ctl[Q_CALLMAX]:
            return RET_CALL_LIMIT


def record_names(mdl) -> tuple:
    """The record columns of a model's runs: :data:`RECORD_NAMES`, and with a body
    ``bending_energy`` and ``dissipated`` (:data:`snapping.spatial.chain3d.BODY_MEAS_NAMES`)."""
    return RECORD_NAMES + (C.BODY_MEAS_NAMES if C.nmeas(mdl[0]) > C.NMEAS else ())


class Stepper3D:
    """State and buffers of a 3D run (:func:`run3d` drives it)."""

    def __init__(self, mdl, y0, *, tol=1e-8, t_end=10.0, stop_fraction=0.5, reeval=False, dt_min=1e-14,
                 max_rejections=100, max_link_error=1e-6):
        par, h, invm = mdl
        N = h.size
        self.N, self.mdl = N, mdl
        self.snode = np.concatenate([np.cumsum(h[::-1])[::-1], [0.0]])
        n = len(y0)  # 6N + 1, or 6N + 2 with a body (D)
        self.Y0, self.Y1 = np.zeros((2, n)), np.zeros((2, n))
        self.KK = np.zeros((2, R.NSX, n))
        self.F = np.zeros((2, R.NI, n))
        self.TS, self.HS, self.DOK = np.zeros(2), np.zeros(2), np.zeros(2)
        self.ytmp = np.zeros(n)
        self.w, self.rw = C.Work(N), C.Work(N)
        self.meas = np.zeros(C.nmeas(par))
        self.rec = np.zeros((RECORD_CHUNK, 3 + self.meas.size))
        self.chunks: list[np.ndarray] = []
        self.breaks = [b for b in C.breakpoints(par) if b > 0.0]
        y = np.array(y0, dtype=float)
        C.project(N, y)
        self.Y1[0] = y
        t_eval = float(np.nextafter(0.0, np.inf)) if 0.0 in C.breakpoints(par) else 0.0
        w = self.w
        C.rhs3d(N, t_eval, y, self.KK[0, R.NS], w.T, w.cp, w.dp, par, h, invm)
        C.measure3d(N, 0.0, y, w.T, self.meas, self.snode, par, h, invm)
        self.meas0 = self.meas.copy()
        self.tol = tol
        c = np.zeros(NQ)
        c[Q_TOL], c[Q_TEND], c[Q_STOPFRAC], c[Q_DTMIN], c[Q_MAXREJ] = tol, t_end, stop_fraction, dt_min, max_rejections
        # the stop rule's floor (simulate.layout.STOP_FLOOR): above the start's own speed and STOP_FLOOR sqrt(g L)
        g = float(np.linalg.norm(par[C.P_GX:C.P_GZ + 1]))
        c[Q_VFLOOR] = max(self.meas[C.M_VMAX], STOP_FLOOR * np.sqrt(g * float(np.sum(h))))
        c[Q_REEVAL] = 1.0 if reeval else 0.0
        c[Q_LASTBRK] = np.nan
        c[Q_CALLMAX] = max(20, 20_000_000 // (R.NS * N))
        c[Q_MAXLINK] = max_link_error
        c[Q_NRHS] = 1.0
        settle = max([0.0] + C.breakpoints(par)) if par[C.P_PIN] != C.PIN_FIXED else -1.0
        c[Q_TSETTLE] = settle
        if settle == 0.0:
            c[Q_ARMED] = 1.0
            c[Q_VRBASE] = c[Q_VRPEAK] = self.meas[C.M_VREL]
        self.ctl = c
        c[Q_H] = self._initial_step(y, self.KK[0, R.NS].copy(), t_eval)
        pk = np.full((3, NPKR), np.nan)
        for qi, m in enumerate(PEAK_MEAS):
            pk[qi, [PK_SBEST, PK_BEST]] = self.meas[m]
            pk[qi, [PK_TPREV, PK_TBEFORE, PK_TBEST]] = 0.0
            pk[qi, PK_NEED] = 0.0
        self.pk = pk
        self.rec[0, 0] = 0.0
        self.rec[0, 3:] = self.meas
        c[Q_NREC] = 1.0

    def _initial_step(self, y0, f0, t0) -> float:
        """Hairer's starting step (Solving ODE I, II.4), in the run's norm: each link's
        ``e_j`` and ``u_j`` (and their rates) by their vector lengths, as
        :func:`snapping.spatial.error3d.step_error3d` (so that a rotated problem starts with
        the same step), ``W`` (``D``) by their own."""
        N = self.N

        def size(y):
            return np.concatenate([np.sqrt((y[:6 * N].reshape(2, 3, N) ** 2).sum(axis=1)).ravel(), np.abs(y[6 * N:])])

        sc = self.tol * (1.0 + size(y0))
        d0, d1 = np.max(size(y0) / sc), np.max(size(f0) / sc)
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        f1 = np.empty_like(y0)
        par, h, invm = self.mdl
        C.rhs3d(self.N, t0 + h0, y0 + h0 * f0, f1, self.rw.T, self.rw.cp, self.rw.dp, par, h, invm)
        self.ctl[Q_NRHS] += 1.0
        d2 = np.max(size(f1 - f0) / sc) / h0
        h1 = max(1e-6, h0 * 1e-3) if max(d1, d2) <= 1e-15 else (0.01 / max(d1, d2)) ** (1.0 / 8.0)
        return float(min(100.0 * h0, h1))

    @property
    def t(self) -> float:
        return float(self.ctl[Q_T])

    def drain(self) -> None:
        n = int(self.ctl[Q_NREC])
        if n:
            self.chunks.append(self.rec[:n].copy())
        self.ctl[Q_NREC] = 0.0

    def records(self) -> np.ndarray:
        self.drain()
        return np.concatenate(self.chunks) if self.chunks else np.zeros((0, self.rec.shape[1]))

    def state_at(self, t: float) -> np.ndarray:
        """The state at time t within the last two accepted steps (dense output; not projected)."""
        par, h, invm = self.mdl
        for slot in (int(self.ctl[Q_SLOT]), 1 - int(self.ctl[Q_SLOT])):
            t0, hs = self.TS[slot], self.HS[slot]
            if hs > 0.0 and t0 - 1e-14 * max(1.0, abs(t0)) <= t <= t0 + hs * (1 + 1e-12) + 1e-300:
                if self.DOK[slot] == 0.0:
                    w = self.rw
                    dense_build3d(self.N, t0, hs, self.Y0[slot], self.Y1[slot], self.KK[slot], self.F[slot],
                                  self.ytmp, w.T, w.cp, w.dp, par, h, invm)
                    self.ctl[Q_NRHS] += R.NSX - R.NS - 1
                    self.DOK[slot] = 1.0
                out = np.empty(self.Y0.shape[1])
                R.dense_eval(self.N, min(1.0, max(0.0, (t - t0) / hs)), self.Y0[slot], self.F[slot], out)
                return out
        raise RuntimeError(f"t={t!r} is outside the stored steps")  # pragma: no cover - internal

    def meas_at(self, t: float) -> np.ndarray:
        """The measurements at time t (dense output, one evaluation for the tensions)."""
        par, h, invm = self.mdl
        y = self.state_at(t)
        w = self.rw
        f = np.empty_like(y)
        C.rhs3d(self.N, t, y, f, w.T, w.cp, w.dp, par, h, invm)
        self.ctl[Q_NRHS] += 1.0
        meas = np.zeros(self.meas.size)
        C.measure3d(self.N, t, y, w.T, meas, self.snode, par, h, invm)
        return meas

    def refine(self) -> None:
        """Locate the flagged peaks on the dense output (bounded Brent search)."""
        bits = int(self.ctl[Q_REFINE])
        self.ctl[Q_REFINE] = 0.0
        pk = self.pk
        for qi in range(3):
            if not bits & (1 << qi):
                continue
            ta, tb = float(pk[qi, PK_TA]), float(pk[qi, PK_TB])
            if not tb > ta:
                continue
            m = PEAK_MEAS[qi]
            res = minimize_scalar(lambda tt: -self.meas_at(tt)[m], bounds=(ta, tb), method="bounded",
                                  options={"xatol": PEAK_XTOL * (tb - ta) + 1e-15 * abs(tb)})
            if -res.fun > pk[qi, PK_BEST]:
                pk[qi, PK_BEST] = float(-res.fun)
                pk[qi, PK_TBEST] = float(res.x)
                if qi == 0:
                    self.peak_meas = self.meas_at(float(res.x))
                    self.peak_state = (float(res.x), self.state_at(float(res.x)))

    def take_snapshots(self) -> None:
        """The requested snapshots at or before the current time (dense output of the last
        step, projected onto the unit links; ``snapshot_times`` sorted)."""
        pend = self.snapshot_times
        while pend and pend[0] <= self.t:
            ts = pend.pop(0)
            y = self.state_at(ts)
            C.project(self.N, y)
            self.snapshots.append((ts, "requested", y))
        # times to come: back to Python after every accepted step (its dense output); same steps
        self.ctl[Q_CALLMAX] = 1.0 if pend else self.callmax

    def loop(self, snapshot_times=()) -> int:
        par, h, invm = self.mdl
        w = self.w
        self.peak_meas, self.peak_state = self.meas0.copy(), (0.0, self.Y1[0].copy())
        self.snapshot_times = sorted(float(t) for t in snapshot_times if t > 0.0)
        self.snapshots = [(0.0, "requested", self.Y1[0].copy())] if 0.0 in snapshot_times else []
        self.callmax = float(self.ctl[Q_CALLMAX])
        self.take_snapshots()
        while True:
            while self.breaks and self.breaks[0] <= self.t:
                self.breaks.pop(0)
            self.ctl[Q_TBRK] = self.breaks[0] if self.breaks else np.inf
            code = advance3d(self.N, self.Y0, self.Y1, self.KK, self.TS, self.HS, self.DOK, self.ytmp, w.T, w.cp,
                             w.dp, self.ctl, self.rec, self.pk, self.meas, self.snode, par, h, invm)
            self.drain()
            if code < RET_FAIL_NAN and self.snapshot_times:
                self.take_snapshots()
            if self.ctl[Q_REFINE] != 0.0:
                self.refine()
            if code in (RET_REFINE, RET_RECORD_FULL, RET_CALL_LIMIT, RET_BREAK):
                continue
            return code

    def current_state(self) -> np.ndarray:
        return self.Y1[int(self.ctl[Q_SLOT])].copy()


def run3d(problem, *, tol: float = 1e-8, t_end: float | None = None, t_end_max: float = 10.0,
          stop_fraction: float = 0.5, reeval: bool = False, max_link_error: float = 1e-6,
          snapshot_times=()) -> dict:
    """Run a :class:`snapping.spatial.starts3d.Problem3D` to the snap (or to ``t_end``).

    Returns a dict: the peaks ``v_peak, a_peak, sigma_peak`` and their times ``t_snap_*``
    (located on the dense output), the measurements at the speed peak (``z_amp_snap``: the
    out-of-plane amplitude, ``vz_amp_snap``), the largest out-of-plane amplitude over the
    run, the final state's, the counts ``n_rhs, n_steps, n_rejected``, the wall time, the
    drifts of the energy balance ``E - W`` and (fixed end) of the angular momentum along
    gravity, the largest link error ``| |e_j| - 1 |`` at the end of an accepted step before
    its projection (what the projection removes; after it, links are unit to round-off), ``record`` (one row an accepted step, columns
    :data:`RECORD_NAMES`) and ``state`` (the final state ``[e, u, W]``), ``snapshots``: a list of
    ``(t, "requested", state)`` at the ``snapshot_times`` reached (dense output, projected;
    the steps are unchanged; :mod:`snapping.spatial.dataset3d` makes the run Dataset).
    """
    from .._validate import SnappingInputError

    if not (isinstance(tol, float | int) and 0.0 < tol < 1.0):
        raise SnappingInputError(f"tol={tol!r} is out of range: must lie in (0, 1)")
    if not 0.0 <= stop_fraction < 1.0:
        raise SnappingInputError(f"stop_fraction={stop_fraction!r} is out of range: must lie in [0, 1)")
    auto = t_end is None
    from .stiffness3d import check_cost3d

    check_cost3d(problem, None if auto else t_end)  # (a body's bending: CostWarning, or refused, before any work)
    st = Stepper3D(problem.model(), problem.initial_state(), tol=float(tol),
                   t_end=t_end_max if auto else float(t_end), stop_fraction=stop_fraction if auto else 0.0,
                   reeval=reeval, max_link_error=max_link_error)
    _warm()
    t0 = time.perf_counter()
    code = st.loop(snapshot_times)
    wall = time.perf_counter() - t0
    rec = st.records()
    names = record_names(st.mdl)
    col = {name: rec[:, i] for i, name in enumerate(names)}
    diss = col["dissipated"] if "dissipated" in col else 0.0
    out = {"status": "ok" if code < RET_FAIL_NAN else "failed", "stop_reason": {RET_STOP: "snap", RET_END: "t_end"}.get(
        code, FAILURES.get(code, str(code))), "t_final": st.t}
    for qi, name in enumerate(PEAK_NAMES):
        out[f"{name}_peak"] = float(st.pk[qi, PK_BEST])
        out[f"t_snap_{name}"] = float(st.pk[qi, PK_TBEST])
    pm = st.peak_meas
    out.update({"z_amp_snap": float(pm[C.M_ZAMP]), "vz_amp_snap": float(pm[C.M_VZAMP]),
                "v_end_snap": float(pm[C.M_VTIP]), "z_amp_max": float(col["z_amp"].max()),
                "z_amp_final": float(col["z_amp"][-1]), "vz_amp_max": float(col["vz_amp"].max()),
                "n_rhs": int(st.ctl[Q_NRHS]), "n_steps": int(st.ctl[Q_NSTEPS]), "n_rejected": int(st.ctl[Q_NREJ]),
                "wall_time": wall, "tol": float(tol), "N": st.N,
                "energy_drift": float(np.max(np.abs((col["energy"] - col["pin_work"] + diss)
                                                     - (col["energy"][0] - col["pin_work"][0])))),
                "angular_momentum_drift": float(np.max(np.abs(col["angular_momentum_g"]
                                                              - col["angular_momentum_g"][0]))),
                "link_error_max": float(col["link_error"].max()), "record": rec, "record_names": names, "state": st.current_state(),
                "peak_state": st.peak_state, "snapshots": st.snapshots})
    return out


_warmed = False


def _warm() -> None:
    """Compile (or load from numba's cache) the kernels on a tiny problem."""
    global _warmed
    if _warmed:
        return
    _warmed = True
    from .starts3d import Problem3D

    st = Stepper3D(Problem3D.catenary(0.5, 3).model(), Problem3D.catenary(0.5, 3).initial_state(), t_end=0.01,
                   stop_fraction=0.0)
    st.loop()
    st.state_at(st.t)
