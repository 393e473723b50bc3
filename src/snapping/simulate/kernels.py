"""Compiled kernels of the N-link chain (numba, ``cache=True``, no fastmath).

Layout
------
A chain state is one float64 array ``Z`` of shape ``(7, N + 1)`` whose rows are
``x, y, vx, vy, ax, ay, sigma``; column ``i`` is node ``k = i + 1`` of the paper
(node 1, index 0, is the free end; node N+1, index N, the pin, stays at the
origin with zero velocity and acceleration). ``sigma[j]`` (``j < N``) is the
tension of link ``k = j + 1`` joining nodes ``k`` and ``k + 1``; ``sigma[N]`` is
unused (0).

Equations (the paper's appendix, nondimensional, rho = g = l = 1), with
``d_k = r_{k+1} - r_k`` and gravity along +e2:

* momentum, eq. (discretemo)::

      r_k'' = N^2 [sigma_k d_k - sigma_{k-1} d_{k-1}] + e2,   sigma_0 = 0

* tension, the link constraints |d_k|^2 = 1/N^2 differentiated twice, with
  |d_k|^2 replaced by 1/N^2 as in the paper (k < N)::

      N^2 sigma_{k+1} d_{k+1}.d_k - 2 sigma_k + N^2 sigma_{k-1} d_k.d_{k-1} = -|d_k'|^2

  and at the pin (the paper's ghost link, or directly from r_{N+1}'' = 0)::

      -sigma_N + N^2 sigma_{N-1} d_N.d_{N-1} = -|d_N'|^2 + d_N.e2

  A symmetric tridiagonal system, solved by the Thomas algorithm (pivots as
  ratios of minors, see :func:`rhs`): the forward elimination is fused with the
  link vectors and dot products (one pass), the back substitution with the
  accelerations (a second pass). O(N), no allocation.

  Replacing |d_k|^2 by 1/N^2 makes the scheme restore the link lengths: with
  g_k = (N^2 |d_k|^2 - 1)/2 one finds exactly g_k'' = -4 N^2 sigma_k g_k, so a
  chord error (from sampling the catenary, or from the time stepper) oscillates
  instead of growing.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# rows of a state array
RX, RY, RVX, RVY, RAX, RAY, RSIG = 0, 1, 2, 3, 4, 5, 6
NROWS = 7

# ---------------------------------------------------------------- measurements
# entries of the ``meas`` array filled by :func:`measure`
M_VMAX, M_SV, M_AMAX, M_SA, M_SIGMAX, M_KMAX, M_SK = 0, 1, 2, 3, 4, 5, 6
M_VEND, M_AEND, M_PFX, M_PFY, M_ENERGY, M_LINKERR, M_LINKERR0 = 7, 8, 9, 10, 11, 12, 13
M_LENGTH, M_FINITE = 14, 15
NMEAS = 16

# ---------------------------------------------------------------- record rows
# columns of the per-step record buffer, in the order of schema.STEP_VARS after t
(R_T, R_DT, R_VMAX, R_AMAX, R_SIGMAX, R_KMAX, R_SK, R_SA, R_SV, R_VEND, R_AEND,
 R_PFX, R_PFY, R_ENERGY, R_LINKERR, R_EPS) = range(16)
NREC = 16
RECORD_NAMES = ("t", "dt", "v_max", "a_max", "sigma_max", "kappa_max", "s_kappa_max", "s_a_max",
                "s_v_max", "v_end", "a_end", "pin_force_x", "pin_force_y", "energy", "link_error",
                "error_estimate")

# ---------------------------------------------------------------- control array
(C_T, C_DT, C_CUR, C_NSTEPS, C_NREJ, C_NRHS, C_NREC, C_TOL, C_FIXED, C_THIN, C_MAXLINK,
 C_DTMIN, C_STEPS_PER_CALL, C_TEND, C_TRET, C_VUP, C_VDOWN, C_STOPFRAC, C_E0, C_L0,
 C_LAST_V, C_LAST_A, C_LAST_S, C_LAST_K, C_DRIFT_LINK, C_DRIFT_LINK0, C_DRIFT_LEN, C_DRIFT_E,
 C_T_PEAKSTATE, C_DT_MIN_ACC, C_DT_MAX_ACC, C_EPS_MAX_ACC,
 C_MAXENERGY, C_MAXREJ, C_CONSREJ) = range(35)
NCTL = 35

# peak tracking: rows v, a, sigma, kappa; columns
P_TPREV, P_QPREV, P_TM1, P_QM1, P_T0, P_Q0, P_TP1, P_QP1, P_NEED = range(9)
NPK = 9
PEAK_QUANTITIES = ("v", "a", "sigma", "kappa")
_PEAK_MEAS = (M_VMAX, M_AMAX, M_SIGMAX, M_KMAX)

# return codes of :func:`advance`
RET_CALL_LIMIT, RET_RECORD_FULL, RET_T_RETURN, RET_V_UP, RET_V_DOWN = 0, 1, 2, 3, 4
RET_STOP, RET_END = 5, 6
RET_FAIL_NAN, RET_FAIL_DT, RET_FAIL_DRIFT, RET_FAIL_ENERGY, RET_FAIL_REJECT = 10, 11, 12, 13, 14

#: growth factor of the time step when the error estimate is exactly zero
#: (the published rule dt_new = 0.9 dt (tol/eps)^(1/2) is undefined there).
ZERO_ERROR_GROWTH = 2.0


@njit(cache=True, fastmath=False, boundscheck=False)
def rhs_thomas(N, Z, dx, dy, cp, dp):
    """Tension and accelerations of state ``Z`` with the textbook Thomas sweep
    (reference for :func:`rhs`, which computes the same thing faster).

    ``dx, dy, cp, dp`` are length-N work arrays (link vectors and the Thomas
    coefficients). Pass 1: link vectors, dot products and forward elimination;
    pass 2: back substitution and accelerations.
    """
    x = Z[RX]
    y = Z[RY]
    vx = Z[RVX]
    vy = Z[RVY]
    ax = Z[RAX]
    ay = Z[RAY]
    sig = Z[RSIG]
    n2 = float(N) * float(N)
    # ---- pass 1: forward elimination; row j (link k = j + 1)
    dxj = x[1] - x[0]
    dyj = y[1] - y[0]
    dvx = vx[1] - vx[0]
    dvy = vy[1] - vy[0]
    cprev = 0.0  # lower diagonal entry of row j (= upper entry of row j - 1)
    cpp = 0.0  # c'_{j-1}
    dpp = 0.0  # d'_{j-1}
    for j in range(N - 1):
        dx[j] = dxj
        dy[j] = dyj
        dxn = x[j + 2] - x[j + 1]
        dyn = y[j + 2] - y[j + 1]
        dvxn = vx[j + 2] - vx[j + 1]
        dvyn = vy[j + 2] - vy[j + 1]
        c = n2 * (dxj * dxn + dyj * dyn)
        r = -(dvx * dvx + dvy * dvy)
        inv = 1.0 / (-2.0 - cprev * cpp)
        cpp = c * inv
        dpp = (r - cprev * dpp) * inv
        cp[j] = cpp
        dp[j] = dpp
        cprev = c
        dxj = dxn
        dyj = dyn
        dvx = dvxn
        dvy = dvyn
    # last row (link N, at the pin)
    jl = N - 1
    dx[jl] = dxj
    dy[jl] = dyj
    r = -(dvx * dvx + dvy * dvy) + dyj
    s_next = (r - cprev * dpp) / (-1.0 - cprev * cpp)
    sig[jl] = s_next
    # ---- pass 2: back substitution and accelerations of nodes j + 1
    dxn = dxj
    dyn = dyj
    for j in range(N - 2, -1, -1):
        s = dp[j] - cp[j] * s_next
        sig[j] = s
        dxj = dx[j]
        dyj = dy[j]
        ax[j + 1] = n2 * (s_next * dxn - s * dxj)
        ay[j + 1] = n2 * (s_next * dyn - s * dyj) + 1.0
        s_next = s
        dxn = dxj
        dyn = dyj
    ax[0] = n2 * s_next * dxn
    ay[0] = n2 * s_next * dyn + 1.0
    ax[N] = 0.0
    ay[N] = 0.0
    sig[N] = 0.0


#: the minors p_j are rescaled by a power of two every BLOCK rows
BLOCK = 32


@njit(cache=True, fastmath=False, boundscheck=False)
def rhs(N, Z, dx, dy, cp, dp):
    """Tension and accelerations of state ``Z`` (rows 4, 5, 6 are overwritten).

    ``dx, dy, cp, dp`` are length-N work arrays (link vectors and the
    elimination coefficients). Pass 1: link vectors, dot products and forward
    elimination; pass 2: back substitution and accelerations.

    The forward elimination is Thomas's, with its pivots written as ratios of
    leading principal minors, m_j = p_j / p_{j-1}, where
    ``p_j = b_j p_{j-1} - c_{j-1}^2 p_{j-2}`` and the scaled right-hand side
    ``q_j = d'_j p_j`` obeys ``q_j = r_j p_{j-1} - c_{j-1} q_{j-1}``. Both are
    linear recurrences, so the division leaves the loop-carried dependency chain
    (the textbook sweep, :func:`rhs_thomas`, waits for one division per link);
    c'_j = c_j p_{j-1}/p_j and d'_j = q_j/p_j are then exactly Thomas's
    coefficients. The matrix is weakly diagonally dominant (|b_j| = 2, and
    |c| <= 1 for links of length 1/N), so |m_j| >= 1 and |p_j| does not decrease
    (up to the link-length error); p and q are rescaled together
    by a power of two (exact) every ``BLOCK`` rows against overflow. Same
    accuracy as the textbook sweep (relative differences ~1e-12 at N = 2000).
    """
    x = Z[RX]
    y = Z[RY]
    vx = Z[RVX]
    vy = Z[RVY]
    ax = Z[RAX]
    ay = Z[RAY]
    sig = Z[RSIG]
    n2 = float(N) * float(N)
    # ---- pass 1: forward elimination; row j (link k = j + 1)
    dxj = x[1] - x[0]
    dyj = y[1] - y[0]
    dvx = vx[1] - vx[0]
    dvy = vy[1] - vy[0]
    cprev = 0.0  # lower diagonal entry of row j (= upper entry of row j - 1)
    pm = 1.0  # p_{j-1}
    pmm = 0.0  # p_{j-2}
    q = 0.0  # q_{j-1}
    j0 = 0
    while j0 < N - 1:
        j1 = min(j0 + BLOCK, N - 1)
        for j in range(j0, j1):
            dx[j] = dxj
            dy[j] = dyj
            dxn = x[j + 2] - x[j + 1]
            dyn = y[j + 2] - y[j + 1]
            dvxn = vx[j + 2] - vx[j + 1]
            dvyn = vy[j + 2] - vy[j + 1]
            c = n2 * (dxj * dxn + dyj * dyn)
            r = -(dvx * dvx + dvy * dvy)
            p = -2.0 * pm - (cprev * cprev) * pmm
            q = r * pm - cprev * q
            inv = 1.0 / p
            cp[j] = c * pm * inv
            dp[j] = q * inv
            pmm = pm
            pm = p
            cprev = c
            dxj = dxn
            dyj = dyn
            dvx = dvxn
            dvy = dvyn
        e = math.frexp(pm)[1]
        sc = math.ldexp(1.0, -e)
        pm *= sc
        pmm *= sc
        q *= sc
        j0 = j1
    # last row (link N, at the pin): b = -1
    jl = N - 1
    dx[jl] = dxj
    dy[jl] = dyj
    r = -(dvx * dvx + dvy * dvy) + dyj
    p = -pm - (cprev * cprev) * pmm
    q = r * pm - cprev * q
    s_next = q / p
    sig[jl] = s_next
    # ---- pass 2: back substitution and accelerations of nodes j + 1
    dxn = dxj
    dyn = dyj
    for j in range(N - 2, -1, -1):
        s = dp[j] - cp[j] * s_next
        sig[j] = s
        dxj = dx[j]
        dyj = dy[j]
        ax[j + 1] = n2 * (s_next * dxn - s * dxj)
        ay[j + 1] = n2 * (s_next * dyn - s * dyj) + 1.0
        s_next = s
        dxn = dxj
        dyn = dyj
    ax[0] = n2 * s_next * dxn
    ay[0] = n2 * s_next * dyn + 1.0
    ax[N] = 0.0
    ay[N] = 0.0
    sig[N] = 0.0


@njit(cache=True, fastmath=False, boundscheck=False)
def measure(N, Z, rinv0, meas):
    """Per-step diagnostics of state ``Z`` into ``meas`` (see the ``M_*`` indices).

    Maxima over the chain of speed, acceleration, tension and |curvature| with
    the arclength s = (N - i)/N of the node where they occur, free-end speed and
    acceleration, the force of the chain on the pin (-sigma_N N d_N), the total
    energy (zero for the chain hanging at rest), the largest link-length error
    against 1/N and against the initial chords (``rinv0[j] = 1/|d_j(0)|^2``),
    the total length, and whether everything is finite.

    The curvature maximum is found without an arctangent per joint: the turning
    angle |theta_{k+1} - theta_k| in [0, pi] (the unwrapped difference) grows
    monotonically with ``q = sin^2`` for a positive dot product and with
    ``2 - q`` otherwise; one ``atan2`` at the maximum gives its value.
    """
    x = Z[RX]
    y = Z[RY]
    vx = Z[RVX]
    vy = Z[RVY]
    ax = Z[RAX]
    ay = Z[RAY]
    sig = Z[RSIG]
    fN = float(N)
    n2 = fN * fN
    vmax2 = -1.0
    iv = 0
    amax2 = -1.0
    ia = 0
    ke = 0.0
    sy = 0.0
    fin = 0.0
    for i in range(N):
        v2 = vx[i] * vx[i] + vy[i] * vy[i]
        a2 = ax[i] * ax[i] + ay[i] * ay[i]
        ke += v2
        sy += y[i]
        fin += a2
        if v2 > vmax2:
            vmax2 = v2
            iv = i
        if a2 > amax2:
            amax2 = a2
            ia = i
    # links and joints
    smax = -np.inf
    emax = -np.inf
    emin = np.inf
    rmax = -np.inf
    rmin = np.inf
    length = 0.0
    kbest = -1.0
    ik = -1
    kdot = 1.0
    kcr = 0.0
    dxp = x[1] - x[0]
    dyp = y[1] - y[0]
    lp = dxp * dxp + dyp * dyp
    for j in range(N - 1):
        dxn = x[j + 2] - x[j + 1]
        dyn = y[j + 2] - y[j + 1]
        ln = dxn * dxn + dyn * dyn
        e = n2 * lp
        if e > emax:
            emax = e
        if e < emin:
            emin = e
        rr = lp * rinv0[j]
        if rr > rmax:
            rmax = rr
        if rr < rmin:
            rmin = rr
        length += math.sqrt(lp)
        if sig[j] > smax:
            smax = sig[j]
        dot = dxp * dxn + dyp * dyn
        cr = dxp * dyn - dyp * dxn
        q = cr * cr / (lp * ln)
        key = q if dot > 0.0 else 2.0 - q
        if key > kbest:
            kbest = key
            ik = j
            kdot = dot
            kcr = cr
        dxp = dxn
        dyp = dyn
        lp = ln
    j = N - 1
    e = n2 * lp
    emax = max(emax, e)
    emin = min(emin, e)
    rr = lp * rinv0[j]
    rmax = max(rmax, rr)
    rmin = min(rmin, rr)
    length += math.sqrt(lp)
    if sig[j] > smax:
        smax = sig[j]
    meas[M_VMAX] = math.sqrt(vmax2)
    meas[M_SV] = (fN - iv) / fN
    meas[M_AMAX] = math.sqrt(amax2)
    meas[M_SA] = (fN - ia) / fN
    meas[M_SIGMAX] = smax
    if ik >= 0:
        meas[M_KMAX] = fN * math.atan2(abs(kcr), kdot)
        meas[M_SK] = (fN - (ik + 1)) / fN
    else:  # N = 1: no joint
        meas[M_KMAX] = 0.0
        meas[M_SK] = np.nan
    meas[M_VEND] = math.sqrt(vx[0] * vx[0] + vy[0] * vy[0])
    meas[M_AEND] = math.sqrt(ax[0] * ax[0] + ay[0] * ay[0])
    # force of the chain on the pin: -sigma_N N d_N with d_N = -r_N
    meas[M_PFX] = sig[N - 1] * fN * x[N - 1]
    meas[M_PFY] = sig[N - 1] * fN * y[N - 1]
    meas[M_ENERGY] = ke / (2.0 * fN) - sy / fN + (fN + 1.0) / (2.0 * fN)
    meas[M_LINKERR] = max(math.sqrt(emax) - 1.0, 1.0 - math.sqrt(emin))
    meas[M_LINKERR0] = max(math.sqrt(rmax) - 1.0, 1.0 - math.sqrt(rmin))
    meas[M_LENGTH] = length
    tot = fin + ke + sy + smax + length
    meas[M_FINITE] = 1.0 if (tot - tot) == 0.0 else 0.0


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
        elif stopfrac > 0.0 and vmax < stopfrac * pk[0, P_Q0]:
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


# ---------------------------------------------------------------- benchmarks
@njit(cache=True, fastmath=False, boundscheck=False)
def bench_rhs(N, Z, dx, dy, cp, dp, n_iter):
    """Evaluate the right-hand side ``n_iter`` times (for timing)."""
    for _ in range(n_iter):
        rhs(N, Z, dx, dy, cp, dp)
    return Z[RAX, 0]


@njit(cache=True, fastmath=False, boundscheck=False)
def bench_rhs_thomas(N, Z, dx, dy, cp, dp, n_iter):
    """Evaluate the textbook-Thomas right-hand side ``n_iter`` times (for timing)."""
    for _ in range(n_iter):
        rhs_thomas(N, Z, dx, dy, cp, dp)
    return Z[RAX, 0]


@njit(cache=True, fastmath=False, boundscheck=False)
def bench_rhs_measure(N, Z, dx, dy, cp, dp, rinv0, meas, n_iter):
    """Evaluate the right-hand side and the per-step measurements ``n_iter`` times."""
    for _ in range(n_iter):
        rhs(N, Z, dx, dy, cp, dp)
        measure(N, Z, rinv0, meas)
    return meas[0]


@njit(cache=True, fastmath=False, boundscheck=False)
def bench_measure(N, Z, rinv0, meas, n_iter):
    """Evaluate the per-step measurements ``n_iter`` times."""
    for _ in range(n_iter):
        measure(N, Z, rinv0, meas)
    return meas[0]
