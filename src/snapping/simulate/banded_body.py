"""Banded LU with partial pivoting for the stage matrix of the elastic line with a body
(:mod:`snapping.simulate.elastic_rodas_body`: 2 x 2 blocks reaching two nodes either side, interleaved
bandwidths 5 and 5; branch fastbody): :mod:`snapping.simulate.banded`'s fixed-bandwidth path
(``_band_lu_stage``, ``_band_solve_stage``) with these bandwidths, the loops' lengths compile-time constants
(the general ``band_lu`` with ``kl = ku = 5`` took 0.21 ms at N 947, 2N = 1894 rows).
"""

from __future__ import annotations

from numba import njit

__all__ = ["band_lu55", "band_solve55", "KL5", "KU5", "WROW5", "IDIAG5"]

#: the bandwidths (module constants: numba bakes them into the cached machine code)
KL5, KU5 = 5, 5
#: the fill-in bandwidth of U
MBW5 = KL5 + KU5
#: a factored row's width: lower band, upper band, fill-in, and (column IDIAG5) the reciprocal pivot
WROW5 = 2 * KL5 + KU5 + 2
IDIAG5 = 2 * KL5 + KU5 + 1


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def band_lu55(R, n, piv):
    """:func:`banded.band_lu` for ``kl = ku = 5`` (:func:`banded._band_lu_stage`'s loops with these
    bandwidths: the same operations as the general path, in the same order, so the same factors), rows
    of width :data:`WROW5`: the reciprocal pivots go to column :data:`IDIAG5`."""
    for k in range(n):
        if k + MBW5 >= n:  # the last rows: the general loop
            ilast = min(n - 1, k + KL5)
            p = k
            vmax = abs(R[k, KL5])
            for i in range(k + 1, ilast + 1):
                v = abs(R[i, k - i + KL5])
                if v > vmax:
                    vmax = v
                    p = i
            piv[k] = p
            if vmax == 0.0 or not (vmax - vmax == 0.0):
                return k + 1
            w = n - k
            if p != k:
                op = k - p + KL5
                for d in range(w):
                    tmp = R[k, KL5 + d]
                    R[k, KL5 + d] = R[p, op + d]
                    R[p, op + d] = tmp
            inv = 1.0 / R[k, KL5]
            R[k, IDIAG5] = inv
            for i in range(k + 1, ilast + 1):
                oi = k - i + KL5
                l = R[i, oi] * inv
                R[i, oi] = l
                for d in range(1, w):
                    R[i, oi + d] -= l * R[k, KL5 + d]
            continue
        p = k
        vmax = abs(R[k, KL5])
        for q in range(1, KL5 + 1):
            v = abs(R[k + q, KL5 - q])
            if v > vmax:
                vmax = v
                p = k + q
        piv[k] = p
        if vmax == 0.0 or not (vmax - vmax == 0.0):
            return k + 1
        if p != k:
            op = k - p + KL5
            for d in range(MBW5 + 1):
                tmp = R[k, KL5 + d]
                R[k, KL5 + d] = R[p, op + d]
                R[p, op + d] = tmp
        inv = 1.0 / R[k, KL5]
        R[k, IDIAG5] = inv
        for q in range(1, KL5 + 1):
            i = k + q
            oi = KL5 - q
            l = R[i, oi] * inv
            R[i, oi] = l
            for d in range(1, MBW5 + 1):
                R[i, oi + d] -= l * R[k, KL5 + d]
    return 0


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def band_solve55(R, n, piv, b):
    """Solve ``A x = b`` in place with the factors of :func:`band_lu55` (fixed-length loops; the back
    substitution by columns, multiplying by the reciprocal pivots)."""
    for k in range(n):
        pk = piv[k]
        if pk != k:
            tmp = b[k]
            b[k] = b[pk]
            b[pk] = tmp
        bk = b[k]
        if k + KL5 < n:
            for q in range(1, KL5 + 1):
                b[k + q] -= R[k + q, KL5 - q] * bk
        else:
            for i in range(k + 1, n):
                b[i] -= R[i, k - i + KL5] * bk
    # back substitution by columns: x_k, then its products out of the rows above (ten
    # independent updates, where the row form is a chain of ten dependent subtractions)
    for k in range(n - 1, -1, -1):
        xk = b[k] * R[k, IDIAG5]
        b[k] = xk
        if k >= MBW5:
            for d in range(1, MBW5 + 1):
                b[k - d] -= R[k - d, KL5 + d] * xk
        else:
            for d in range(1, k + 1):
                b[k - d] -= R[k - d, KL5 + d] * xk
