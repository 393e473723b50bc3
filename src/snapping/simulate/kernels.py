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

# One idea a module (a pure split of the former kernels.py; every name is importable from here as before):
#   layout         the array layouts (state rows, measurements, record columns, control array, peaks, return codes)
#   accelerations  rhs, rhs_thomas: tension and accelerations of a state
#   measures       measure: the per-step diagnostics
#   stepping       advance: the Euler-Richardson step loop
# The benchmarks of the kernels stay here.
from numba import njit

from .accelerations import BLOCK, rhs, rhs_thomas  # noqa: F401
from .layout import (C_CONSREJ, C_CUR, C_DRIFT_E, C_DRIFT_LEN, C_DRIFT_LINK, C_DRIFT_LINK0, C_DT, C_DTMIN,
                     C_DT_MAX_ACC, C_DT_MIN_ACC, C_E0, C_EPS_MAX_ACC, C_FIXED, C_L0, C_LAST_A, C_LAST_K, C_LAST_S,
                     C_LAST_V, C_MAXENERGY, C_MAXLINK, C_MAXREJ, C_NREC, C_NREJ, C_NRHS, C_NSTEPS, C_STEPS_PER_CALL,
                     C_STOPFRAC, C_T, C_TEND, C_VFLOOR, C_THIN, C_TOL, C_TRET, C_T_PEAKSTATE, C_VDOWN, C_VUP, M_AEND, M_AMAX,
                     M_ENERGY, M_FINITE, M_KMAX, M_LENGTH, M_LINKERR, M_LINKERR0, M_PFX, M_PFY, M_SA, M_SIGMAX, M_SK,
                     M_SIGMIN, M_SSIGMIN, M_SV, M_VEND, M_VMAX, NCTL, NMEAS, NPK, NREC, NROWS, PEAK_QUANTITIES, P_NEED, P_Q0, P_QM1, P_QP1,
                     P_QPREV, P_T0, P_TM1, P_TP1, P_TPREV, RAX, RAY, RECORD_NAMES, RET_CALL_LIMIT, RET_END,
                     RET_FAIL_DRIFT, RET_FAIL_DT, RET_FAIL_ENERGY, RET_FAIL_NAN, RET_FAIL_REJECT, RET_RECORD_FULL,
                     RET_STOP, RET_T_RETURN, RET_V_DOWN, RET_V_UP, RSIG, RVX, RVY, RX, RY, STOP_FLOOR, R_AEND, R_AMAX, R_DT,
                     R_ENERGY, R_EPS, R_KMAX, R_LINKERR, R_PFX, R_PFY, R_SA, R_SIGMAX, R_SIGMIN, R_SK, R_SSIGMIN, R_SV, R_T, R_VEND, R_VMAX,
                     _PEAK_MEAS)  # noqa: F401
from .measures import measure  # noqa: F401
from .stepping import ZERO_ERROR_GROWTH, _changed, _write_record, advance  # noqa: F401


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
