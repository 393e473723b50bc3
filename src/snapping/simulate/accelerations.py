"""Tension and accelerations of a chain state, the paper's appendix equations (see
:mod:`snapping.simulate.kernels`): the fused two-pass Thomas solve (:func:`rhs`) and the textbook
sweep it is checked and timed against (:func:`rhs_thomas`). Compiled with numba (``cache=True``).
"""

from __future__ import annotations

import math

from numba import njit

from .layout import RAX, RAY, RSIG, RVX, RVY, RX, RY


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
