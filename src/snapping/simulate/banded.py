"""Banded LU with partial pivoting and its solves, compiled, for the stage matrix of the
stiff method (:mod:`snapping.simulate.rosenbrock`; the matrix is
:mod:`snapping.simulate.stiff_system`'s, of lower bandwidth ``KL`` = 5 and upper ``KU`` = 4).

Storage by rows: ``A[i, j]`` at ``R[i, j - i + kl]``, the last kl columns room for the
fill-in (LAPACK's ``dgbtrf`` and ``dgbtrs``, laid out so that a row's operations run on
contiguous memory). :func:`band_lu` and :func:`band_solve` take any bandwidths; with the
stage matrix's they run :func:`_band_lu_stage` and :func:`_band_solve_stage`, whose loops
have compile-time lengths, which keep the reciprocal pivots in one more column
(:data:`WROW` wide rows) and substitute backwards by columns (ten independent updates per
unknown where the row form is a chain of ten dependent subtractions).
"""

from __future__ import annotations

from numba import njit

from . import stiff_system as SS

__all__ = ["band_lu", "band_solve", "KL", "KU", "WROW", "IDIAG"]

#: the stage matrix's bandwidths, written out here: numba bakes module constants into this
#: module's cached machine code, which is keyed on this file alone (a change in
#: stiff_system must change this file too, or the import fails)
KL, KU = 5, 4
if (KL, KU) != (SS.KL, SS.KU):  # pragma: no cover - a guard for editors
    raise ImportError("banded's KL, KU differ from stiff_system's: update both")

#: width of a row of the factored stage matrix: lower band, upper band, the fill-in and
#: (column ``IDIAG``) the reciprocal of the pivot, for the solves' multiplications
WROW = 2 * KL + KU + 2
IDIAG = 2 * KL + KU + 1


#: the fill-in bandwidth of the stage matrix's U
MBW = KL + KU


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _band_lu_stage(R, n, piv):
    """:func:`band_lu` for the stage matrix's bandwidths (``KL``, ``KU``: compile-time
    constants, so the loops of the rows away from the end have fixed lengths; the same
    operations in the same order, so the same factors), rows of width :data:`WROW`: the
    reciprocal pivots go to column ``IDIAG``."""
    for k in range(n):
        if k + MBW >= n:  # the last rows: the general loop
            ilast = min(n - 1, k + KL)
            p = k
            vmax = abs(R[k, KL])
            for i in range(k + 1, ilast + 1):
                v = abs(R[i, k - i + KL])
                if v > vmax:
                    vmax = v
                    p = i
            piv[k] = p
            if vmax == 0.0 or not (vmax - vmax == 0.0):
                return k + 1
            w = n - k
            if p != k:
                op = k - p + KL
                for d in range(w):
                    tmp = R[k, KL + d]
                    R[k, KL + d] = R[p, op + d]
                    R[p, op + d] = tmp
            inv = 1.0 / R[k, KL]
            R[k, IDIAG] = inv
            for i in range(k + 1, ilast + 1):
                oi = k - i + KL
                l = R[i, oi] * inv
                R[i, oi] = l
                for d in range(1, w):
                    R[i, oi + d] -= l * R[k, KL + d]
            continue
        p = k
        vmax = abs(R[k, KL])
        for q in range(1, KL + 1):
            v = abs(R[k + q, KL - q])
            if v > vmax:
                vmax = v
                p = k + q
        piv[k] = p
        if vmax == 0.0 or not (vmax - vmax == 0.0):
            return k + 1
        if p != k:
            op = k - p + KL
            for d in range(MBW + 1):
                tmp = R[k, KL + d]
                R[k, KL + d] = R[p, op + d]
                R[p, op + d] = tmp
        inv = 1.0 / R[k, KL]
        R[k, IDIAG] = inv
        for q in range(1, KL + 1):
            i = k + q
            oi = KL - q
            l = R[i, oi] * inv
            R[i, oi] = l
            for d in range(1, MBW + 1):
                R[i, oi + d] -= l * R[k, KL + d]
    return 0


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _band_solve_stage(R, n, piv, b):
    """:func:`band_solve` for the stage matrix's bandwidths (fixed-length loops)."""
    for k in range(n):
        pk = piv[k]
        if pk != k:
            tmp = b[k]
            b[k] = b[pk]
            b[pk] = tmp
        bk = b[k]
        if k + KL < n:
            for q in range(1, KL + 1):
                b[k + q] -= R[k + q, KL - q] * bk
        else:
            for i in range(k + 1, n):
                b[i] -= R[i, k - i + KL] * bk
    # back substitution by columns: x_k, then its products out of the rows above (ten
    # independent updates, where the row form is a chain of ten dependent subtractions)
    for k in range(n - 1, -1, -1):
        xk = b[k] * R[k, IDIAG]
        b[k] = xk
        if k >= MBW:
            for d in range(1, MBW + 1):
                b[k - d] -= R[k - d, KL + d] * xk
        else:
            for d in range(1, k + 1):
                b[k - d] -= R[k - d, KL + d] * xk


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def band_lu(A, n, kl, ku, piv):
    """LU with partial pivoting of the n x n band matrix stored by rows: ``A[i, j]`` at
    ``R[i, j - i + kl]`` (width ``2 kl + ku + 1``: the last kl columns are room for the
    fill-in and zero on entry). On return the multipliers are below the diagonal, U above
    (upper bandwidth kl + ku), ``piv[k]`` the row swapped with row k (LAPACK's ``dgbtrf``,
    laid out so that the row operations run on contiguous memory). Returns 0, or k + 1 when
    the k-th pivot is zero or not finite. With the stage matrix's ``KL, KU`` the rows need
    :data:`WROW` columns (one more: the reciprocal pivots)."""
    if kl == KL and ku == KU:
        return _band_lu_stage(A, n, piv)
    R = A
    m = kl + ku
    for k in range(n):
        ilast = min(n - 1, k + kl)
        p = k
        vmax = abs(R[k, kl])
        for i in range(k + 1, ilast + 1):
            v = abs(R[i, k - i + kl])
            if v > vmax:
                vmax = v
                p = i
        piv[k] = p
        if vmax == 0.0 or not (vmax - vmax == 0.0):
            return k + 1
        w = min(n - 1, k + m) - k + 1  # columns k .. k + w - 1
        if p != k:
            op = k - p + kl
            for d in range(w):
                tmp = R[k, kl + d]
                R[k, kl + d] = R[p, op + d]
                R[p, op + d] = tmp
        inv = 1.0 / R[k, kl]
        for i in range(k + 1, ilast + 1):
            oi = k - i + kl
            l = R[i, oi] * inv
            R[i, oi] = l
            if l != 0.0:
                for d in range(1, w):
                    R[i, oi + d] -= l * R[k, kl + d]
    return 0


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def band_solve(A, n, kl, ku, piv, b):
    """Solve ``A x = b`` in place with the factors of :func:`band_lu`."""
    if kl == KL and ku == KU:
        _band_solve_stage(A, n, piv, b)
        return
    R = A
    m = kl + ku
    for k in range(n):
        p = piv[k]
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp
        bk = b[k]
        for i in range(k + 1, min(n - 1, k + kl) + 1):
            b[i] -= R[i, k - i + kl] * bk
    for k in range(n - 1, -1, -1):
        acc = b[k]
        for d in range(1, min(n - 1, k + m) - k + 1):
            acc -= R[k, kl + d] * b[k + d]
        b[k] = acc / R[k, kl]
