"""The paper's Euler-Richardson stepping loop (:func:`advance`): adaptive steps, stop rules, peak
tracking and the per-step record, until something needs Python. Compiled with numba
(``cache=True``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .accelerations import rhs
from .layout import (C_CONSREJ, C_CUR, C_DRIFT_E, C_DRIFT_LEN, C_DRIFT_LINK, C_DRIFT_LINK0, C_DT, C_DTMIN,
                     C_DT_MAX_ACC, C_DT_MIN_ACC, C_E0, C_EPS_MAX_ACC, C_FIXED, C_L0, C_LAST_A, C_LAST_K, C_LAST_S,
                     C_LAST_V, C_MAXENERGY, C_MAXLINK, C_MAXREJ, C_NREC, C_NREJ, C_NRHS, C_NSTEPS, C_STEPS_PER_CALL,
                     C_STOPFRAC, C_T, C_TEND, C_VFLOOR, C_THIN, C_TOL, C_TRET, C_T_PEAKSTATE, C_VDOWN, C_VUP, M_AEND, M_AMAX,
                     M_ENERGY, M_FINITE, M_KMAX, M_LENGTH, M_LINKERR, M_LINKERR0, M_PFX, M_PFY, M_SA, M_SIGMAX, M_SIGMIN, M_SK,
                     M_SSIGMIN, M_SV, M_VEND, M_VMAX, NROWS, P_NEED, P_Q0, P_QM1, P_QP1, P_QPREV, P_T0, P_TM1, P_TP1, P_TPREV,
                     RAX, RAY, RET_CALL_LIMIT, RET_END, RET_FAIL_DRIFT, RET_FAIL_DT, RET_FAIL_ENERGY, RET_FAIL_NAN,
                     RET_FAIL_REJECT, RET_RECORD_FULL, RET_STOP, RET_T_RETURN, RET_V_DOWN, RET_V_UP, RVX, RVY, RX, RY,
                     R_AEND, R_AMAX, R_DT, R_ENERGY, R_EPS, R_KMAX, R_LINKERR, R_PFX, R_PFY, R_SA, R_SIGMAX, R_SIGMIN, R_SK,
                     R_SSIGMIN, R_SV, R_T, R_VEND, R_VMAX)
from .measures import measure


#: growth factor of the time step when the error estimate is exactly zero
#: (the published rule dt_new = 0.9 dt (tol/eps)^(1/2) is undefined there).
ZERO_ERROR_GROWTH = 2.0


@njit(cache=True, fastmath=False, boundscheck=False)
def _write_record(rec, n, t, dt, eps, meas):
    rec[n, R_T] = t
    rec[n, R_DT] = dt
    rec[n, R_VMAX] = meas[M_VMAX]
    rec[n, R_AMAX] = meas[M_AMAX]
    rec[n, R_SIGMAX] = meas[M_SIGMAX]
    rec[n, R_KMAX] = meas[M_KMAX]
    rec[n, R_SK] = meas[M_SK]
    rec[n, R_SA] = meas[M_SA]
    rec[n, R_SV] = meas[M_SV]
    rec[n, R_VEND] = meas[M_VEND]
    rec[n, R_AEND] = meas[M_AEND]
    rec[n, R_PFX] = meas[M_PFX]
    rec[n, R_PFY] = meas[M_PFY]
    rec[n, R_ENERGY] = meas[M_ENERGY]
    rec[n, R_LINKERR] = meas[M_LINKERR]
    rec[n, R_EPS] = eps
    rec[n, R_SIGMIN] = meas[M_SIGMIN]
    rec[n, R_SSIGMIN] = meas[M_SSIGMIN]


@njit(cache=True, fastmath=False, boundscheck=False)
def _changed(q, last, thin):
    return abs(q - last) > thin * abs(last)


@njit(cache=True, fastmath=False, boundscheck=False)
def advance(N, S, H, dx, dy, cp, dp, rinv0, ctl, rec, pk, PS, meas):
    """Advance the chain with the paper's Euler-Richardson scheme until something
    needs Python (a return code ``RET_*``).

    ``S`` (2, 7, N+1): current and next state, ``ctl[C_CUR]`` says which is
    current; ``H`` (7, N+1): the half-step state; ``PS`` (7, N+1): copy of the
    state at the running peak of the maximum speed; ``rec``: the per-step record
    buffer (``ctl[C_NREC]`` rows used); ``pk`` (4, 9): the three steps around the
    running peak of v_max, a_max, sigma_max, kappa_max (dense, independent of
    record thinning). ``S[cur]`` must hold the accelerations and tension of its
    positions and velocities (first same as last: 2 RHS evaluations per accepted
    step, 1 per step rejected on the half-step error estimate).

    One step from t with dt (the paper's appendix, after Gatland):

    1. half step: r_h = r + v dt/2, v_h = v + a dt/2; evaluate a_h;
    2. eps = (dt/2) max_k max(|v_h,k - v_k|, |a_h,k - a_k|) (eq. "error");
    3. reject if eps > tol (adaptive mode): dt <- 0.9 dt (tol/eps)^(1/2), retry;
    4. full step: r(t+dt) = r + v_h dt, v(t+dt) = v + a_h dt; evaluate a(t+dt);
    5. next dt = 0.9 dt (tol/eps)^(1/2) (eq. "dtau"); ZERO_ERROR_GROWTH * dt if eps = 0.

    The step is clipped to land on ``ctl[C_TEND]``; in fixed mode
    (``ctl[C_FIXED] = 1``) every step is accepted and dt is kept.
    """
    tol = ctl[C_TOL]
    fixed = ctl[C_FIXED] != 0.0
    thin = ctl[C_THIN]
    maxlink = ctl[C_MAXLINK]
    dtmin = ctl[C_DTMIN]
    limit = int(ctl[C_STEPS_PER_CALL])
    tend = ctl[C_TEND]
    tret = ctl[C_TRET]
    vup = ctl[C_VUP]
    vdown = ctl[C_VDOWN]
    stopfrac = ctl[C_STOPFRAC]
    e0 = ctl[C_E0]
    l0 = ctl[C_L0]
    cap = rec.shape[0]
    cur = int(ctl[C_CUR])
    t = ctl[C_T]
    dt = ctl[C_DT]
    nrec = int(ctl[C_NREC])
    ncall = 0
    code = RET_CALL_LIMIT
    while True:
        A = S[cur]
        B = S[1 - cur]
        # ---- clip to the end time
        last = False
        h = dt
        rem = tend - t
        if h >= rem * (1.0 - 1e-8):
            h = rem
            last = True
        # ---- half step
        hh = 0.5 * h
        for i in range(N):
            H[RX, i] = A[RX, i] + hh * A[RVX, i]
            H[RY, i] = A[RY, i] + hh * A[RVY, i]
            H[RVX, i] = A[RVX, i] + hh * A[RAX, i]
            H[RVY, i] = A[RVY, i] + hh * A[RAY, i]
        rhs(N, H, dx, dy, cp, dp)
        ctl[C_NRHS] += 1.0
        # ---- error estimate, eq. (error)
        m2 = 0.0
        for i in range(N):
            ux = H[RVX, i] - A[RVX, i]
            uy = H[RVY, i] - A[RVY, i]
            u2 = ux * ux + uy * uy
            wx = H[RAX, i] - A[RAX, i]
            wy = H[RAY, i] - A[RAY, i]
            w2 = wx * wx + wy * wy
            if not u2 <= m2:  # (u2 > m2, and a NaN propagates into eps)
                m2 = u2
            if not w2 <= m2:
                m2 = w2
        eps = hh * math.sqrt(m2)
        if not (eps - eps == 0.0):
            code = RET_FAIL_NAN
            break
        if not fixed and eps > tol:
            dt = 0.9 * h * math.sqrt(tol / eps)
            ctl[C_NREJ] += 1.0
            ctl[C_CONSREJ] += 1.0
            if dt < dtmin:
                code = RET_FAIL_DT
                break
            if ctl[C_CONSREJ] > ctl[C_MAXREJ]:
                code = RET_FAIL_REJECT
                break
            continue
        ctl[C_CONSREJ] = 0.0
        # ---- full step into B
        for i in range(N):
            B[RX, i] = A[RX, i] + h * H[RVX, i]
            B[RY, i] = A[RY, i] + h * H[RVY, i]
            B[RVX, i] = A[RVX, i] + h * H[RAX, i]
            B[RVY, i] = A[RVY, i] + h * H[RAY, i]
        rhs(N, B, dx, dy, cp, dp)
        ctl[C_NRHS] += 1.0
        # ---- accept
        t = tend if last else t + h
        cur = 1 - cur
        ctl[C_NSTEPS] += 1.0
        ncall += 1
        if h < ctl[C_DT_MIN_ACC]:
            ctl[C_DT_MIN_ACC] = h
        if h > ctl[C_DT_MAX_ACC] and not last:
            ctl[C_DT_MAX_ACC] = h
        if eps > ctl[C_EPS_MAX_ACC]:
            ctl[C_EPS_MAX_ACC] = eps
        if not fixed:
            if eps > 0.0:
                dt = 0.9 * h * math.sqrt(tol / eps)
            else:
                dt = ZERO_ERROR_GROWTH * h
        measure(N, B, rinv0, meas)
        # ---- running peaks (dense, every accepted step)
        for qi in range(4):
            if qi == 0:
                q = meas[M_VMAX]
            elif qi == 1:
                q = meas[M_AMAX]
            elif qi == 2:
                q = meas[M_SIGMAX]
            else:
                q = meas[M_KMAX]
            if q > pk[qi, P_Q0]:
                pk[qi, P_TM1] = pk[qi, P_TPREV]
                pk[qi, P_QM1] = pk[qi, P_QPREV]
                pk[qi, P_T0] = t
                pk[qi, P_Q0] = q
                pk[qi, P_TP1] = np.nan
                pk[qi, P_QP1] = np.nan
                pk[qi, P_NEED] = 1.0
            elif pk[qi, P_NEED] != 0.0:
                pk[qi, P_TP1] = t
                pk[qi, P_QP1] = q
                pk[qi, P_NEED] = 0.0
                if qi == 0:  # the previous state (now in A) is the running peak of v_max
                    for r in range(NROWS):
                        for i in range(N + 1):
                            PS[r, i] = A[r, i]
                    ctl[C_T_PEAKSTATE] = pk[0, P_T0]
            pk[qi, P_TPREV] = t
            pk[qi, P_QPREV] = q
        # ---- invariants
        if meas[M_LINKERR] > ctl[C_DRIFT_LINK]:
            ctl[C_DRIFT_LINK] = meas[M_LINKERR]
        if meas[M_LINKERR0] > ctl[C_DRIFT_LINK0]:
            ctl[C_DRIFT_LINK0] = meas[M_LINKERR0]
        dl = abs(meas[M_LENGTH] - l0) / l0
        if dl > ctl[C_DRIFT_LEN]:
            ctl[C_DRIFT_LEN] = dl
        de = abs(meas[M_ENERGY] - e0)
        if de > ctl[C_DRIFT_E]:
            ctl[C_DRIFT_E] = de
        # ---- why stop here?
        vmax = meas[M_VMAX]
        code = -1
        if meas[M_FINITE] == 0.0:
            code = RET_FAIL_NAN
        elif meas[M_LINKERR] > maxlink:
            code = RET_FAIL_DRIFT
        elif de > ctl[C_MAXENERGY]:
            code = RET_FAIL_ENERGY
        elif not fixed and dt < dtmin:
            code = RET_FAIL_DT
        elif stopfrac > 0.0 and pk[0, P_Q0] > ctl[C_VFLOOR] and vmax < stopfrac * pk[0, P_Q0]:
            code = RET_STOP
        elif last:
            code = RET_END
        elif t >= tret:
            code = RET_T_RETURN
        elif vmax >= vup:
            code = RET_V_UP
        elif vdown > 0.0 and vmax < vdown * pk[0, P_Q0]:
            code = RET_V_DOWN
        # ---- record (thinned by relative change; always the last step)
        if (thin == 0.0 or code == RET_STOP or code == RET_END or code >= RET_FAIL_NAN
                or _changed(vmax, ctl[C_LAST_V], thin) or _changed(meas[M_AMAX], ctl[C_LAST_A], thin)
                or _changed(meas[M_SIGMAX], ctl[C_LAST_S], thin) or _changed(meas[M_KMAX], ctl[C_LAST_K], thin)):
            _write_record(rec, nrec, t, h, eps, meas)
            nrec += 1
            ctl[C_LAST_V] = vmax
            ctl[C_LAST_A] = meas[M_AMAX]
            ctl[C_LAST_S] = meas[M_SIGMAX]
            ctl[C_LAST_K] = meas[M_KMAX]
        if code >= 0:
            break
        if nrec >= cap:
            code = RET_RECORD_FULL
            break
        if ncall >= limit:
            code = RET_CALL_LIMIT
            break
    ctl[C_T] = t
    ctl[C_DT] = dt
    ctl[C_CUR] = float(cur)
    ctl[C_NREC] = float(nrec)
    return code
