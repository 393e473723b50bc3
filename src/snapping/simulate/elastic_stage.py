"""The stage system of the elastic line's RODAS4 (:mod:`snapping.simulate.elastic_rodas`):
assembled from the Jacobian's blocks, factored, solved; compiled, O(N).

A stage solves ``(I/g - J) U = b`` (``g = gamma h``). With ``dr/dt = v`` the positions drop
out (:mod:`~snapping.simulate.elastic_rodas`) and what is left is the 2N x 2N velocity system

    A U_v = g b_v + g^2 K b_r,    A = I - g^2 K - g C,

``K = da/dr`` and ``C = da/dv`` the blocks of :func:`elastic_kernels.jac_blocks`: block
tridiagonal in 2 x 2 blocks (node i's rows reach nodes i - 1, i, i + 1).

**Why no pivoting is needed.** Scale the rows by the node masses (``M = diag(m_i I)``). Link
j's force on node j is ``G_j = T_j u_j`` (on node j + 1 the opposite), a function of
``d_j = r_{j+1} - r_j`` and of ``dv_j = v_{j+1} - v_j``, so

    M A = M + g^2 sum_j P_j^T A_j P_j + g sum_j P_j^T Bv_j P_j,   (P_j x = x_{j+1} - x_j),

with ``A_j = dG/dd = T/l (I - u u^T) + u (dT/dd)^T`` and ``Bv_j = dG/d(dv) = (c_j/h_j) u u^T``.
Without damping ``dT/dd = f'(e)/h u``, so ``A_j = T/l (I - u u^T) + f'/h u u^T``: symmetric, and
positive semidefinite because ``T >= 0`` (tension only; a slack link, or one whose damping
cancels its tension, contributes nothing at all) and ``f' >= 0`` (EA > 0; a table's
tensions never decrease). The held end is prescribed, so link N - 1 adds only to node
N - 1's diagonal block. Hence ``M A`` is symmetric positive definite (M is), and Gaussian
elimination without pivoting is stable on it (as Cholesky is); row scaling by M changes
nothing in an elimination without pivoting (the pivots of ``M A`` are ``m_i`` times
those of ``A``), so ``A`` itself is factored. Kelvin-Voigt damping adds
``c/(l h) u w^T`` to ``A_j`` (``w = dv - (u . dv) u``, the links' relative turning
velocity): a small skew part, of relative size ``c |w|/(l f')`` (for the grid damping about
zeta |w|/c_wave), and the symmetric part stays positive definite in practice.

:func:`factor` therefore runs the block LU (the "block Thomas" recursion: ``D_0 = A_00``,
``L_i = A_{i,i-1} D_{i-1}^{-1}``, ``D_i = A_ii - L_i A_{i-1,i}``) with a guard that each
Schur complement ``D_i`` is what a positive definite one is: ``(D_i)_00 > 0``,
``det D_i > 0`` (necessary for a positive definite symmetric part) and no entry larger
than :data:`GROWTH` times the largest of ``A_ii`` (a positive definite ``D_i`` lies below
``A_ii``); where the guard fails it factors the same matrix with partial pivoting instead
(:func:`snapping.simulate.banded.band_lu`, bandwidth 3 each side). The block LU costs
about a quarter of the pivoted band LU; its results differ from it by rounding only.
"""

from __future__ import annotations

from numba import njit

from .banded import band_lu, band_solve

__all__ = ["factor", "solve", "assemble_band", "KLE", "KUE", "WIDTH", "GROWTH", "NF", "PATH_BLOCK", "PATH_PIVOTED",
           "PATH_SINGULAR"]

#: the reduced stage matrix's bandwidths in band storage (2 x 2 blocks, interleaved x, y)
KLE = KUE = 3
WIDTH = 2 * KLE + KUE + 1
#: largest growth of a Schur complement's entries over its diagonal block's the pivot-free
#: factorisation accepts (1 for a symmetric positive definite matrix, up to rounding)
GROWTH = 2.0
#: numbers per node of the block factors: L_i (4), D_i^{-1} (4), A_{i,i+1} (4)
NF = 12
#: what :func:`factor` did
PATH_BLOCK, PATH_PIVOTED, PATH_SINGULAR = 0, 1, 2


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _entry(B, i, k, r, c, g, g2):
    """Row 2i + r, column 2(i - 1 + k) + c of ``I - g^2 K - g C`` (``B`` the compact blocks of
    :func:`elastic_rodas.jacobian`: ``B[i, k, 2r + c]`` of K, ``B[i, k, 4 + 2r + c]`` of C)."""
    v = -g2 * B[i, k, 2 * r + c] - g * B[i, k, 4 + 2 * r + c]
    if k == 1 and r == c:
        v += 1.0
    return v


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def assemble_band(N, B, gh, ab):
    """``I - g^2 K - g C`` (``g = gh``) in the band storage of :func:`banded.band_lu` (row i,
    column j at ``ab[i, j - i + KLE]``)."""
    ab[:, :] = 0.0
    g2 = gh * gh
    for i in range(N):
        for k in range(3):
            jn = i - 1 + k
            if jn < 0 or jn >= N:
                continue
            for r in range(2):
                row = 2 * i + r
                for c in range(2):
                    ab[row, 2 * jn + c - row + KLE] = _entry(B, i, k, r, c, gh, g2)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _block_lu(N, B, gh, F):
    """The pivot-free block LU into ``F`` (per node: L_i, D_i^{-1}, A_{i,i+1}, row-major 2 x 2);
    False where the guard fails."""
    g2 = gh * gh
    for i in range(N):
        a00 = _entry(B, i, 1, 0, 0, gh, g2)
        a01 = _entry(B, i, 1, 0, 1, gh, g2)
        a10 = _entry(B, i, 1, 1, 0, gh, g2)
        a11 = _entry(B, i, 1, 1, 1, gh, g2)
        big = max(max(abs(a00), abs(a01)), max(abs(a10), abs(a11)))
        if i > 0:
            # L = A_{i,i-1} D_{i-1}^{-1};  D_i = A_ii - L A_{i-1,i}
            b00 = _entry(B, i, 0, 0, 0, gh, g2)
            b01 = _entry(B, i, 0, 0, 1, gh, g2)
            b10 = _entry(B, i, 0, 1, 0, gh, g2)
            b11 = _entry(B, i, 0, 1, 1, gh, g2)
            p = F[i - 1]
            l00 = b00 * p[4] + b01 * p[6]
            l01 = b00 * p[5] + b01 * p[7]
            l10 = b10 * p[4] + b11 * p[6]
            l11 = b10 * p[5] + b11 * p[7]
            a00 -= l00 * p[8] + l01 * p[10]
            a01 -= l00 * p[9] + l01 * p[11]
            a10 -= l10 * p[8] + l11 * p[10]
            a11 -= l10 * p[9] + l11 * p[11]
            q = F[i]
            q[0], q[1], q[2], q[3] = l00, l01, l10, l11
        det = a00 * a11 - a01 * a10
        grow = max(max(abs(a00), abs(a01)), max(abs(a10), abs(a11)))
        if not (a00 > 0.0 and det > 0.0 and grow <= GROWTH * big):
            return False
        q = F[i]
        inv = 1.0 / det
        q[4], q[5], q[6], q[7] = a11 * inv, -a01 * inv, -a10 * inv, a00 * inv
        if i + 1 < N:
            q[8] = _entry(B, i, 2, 0, 0, gh, g2)
            q[9] = _entry(B, i, 2, 0, 1, gh, g2)
            q[10] = _entry(B, i, 2, 1, 0, gh, g2)
            q[11] = _entry(B, i, 2, 1, 1, gh, g2)
    return True


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def factor(N, B, gh, F, ab, piv, pivoted):
    """Factor ``I - g^2 K - g C``: the pivot-free block LU into ``F`` (``N x NF``) when its guard
    holds and ``pivoted`` is False, else the pivoted band LU into ``ab``, ``piv``. Returns
    :data:`PATH_BLOCK`, :data:`PATH_PIVOTED` or :data:`PATH_SINGULAR` (a zero or non-finite
    pivot)."""
    if not pivoted and _block_lu(N, B, gh, F):
        return PATH_BLOCK
    assemble_band(N, B, gh, ab)
    if band_lu(ab, 2 * N, KLE, KUE, piv) != 0:
        return PATH_SINGULAR
    return PATH_PIVOTED


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _rhs_v(N, B, gh, g2, b, i, r):
    """Row 2i + r of the reduced right side ``g b_v + g^2 K b_r``."""
    acc = gh * b[4 * i + 2 + r]
    for k in range(3):
        jn = i - 1 + k
        if jn < 0 or jn >= N:
            continue
        acc += g2 * (B[i, k, 2 * r] * b[4 * jn] + B[i, k, 2 * r + 1] * b[4 * jn + 1])
    return acc


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _block_solve(N, B, gh, F, b, U, w):
    """The reduced system with the block factors, its right side formed on the way (forward:
    ``y_i = w_i - L_i y_{i-1}``; back: ``x_i = D_i^{-1} (y_i - A_{i,i+1} x_{i+1})``), and the
    positions' stages ``gh (b_r + U_v)``."""
    g2 = gh * gh
    y0 = 0.0
    y1 = 0.0
    for i in range(N):
        z0 = _rhs_v(N, B, gh, g2, b, i, 0)
        z1 = _rhs_v(N, B, gh, g2, b, i, 1)
        if i > 0:
            q = F[i]
            z0 = z0 - (q[0] * y0 + q[1] * y1)
            z1 = z1 - (q[2] * y0 + q[3] * y1)
        w[2 * i] = z0
        w[2 * i + 1] = z1
        y0 = z0
        y1 = z1
    x0 = 0.0
    x1 = 0.0
    for i in range(N - 1, -1, -1):
        q = F[i]
        r0 = w[2 * i]
        r1 = w[2 * i + 1]
        if i + 1 < N:
            r0 -= q[8] * x0 + q[9] * x1
            r1 -= q[10] * x0 + q[11] * x1
        x0 = q[4] * r0 + q[5] * r1
        x1 = q[6] * r0 + q[7] * r1
        U[4 * i + 2] = x0
        U[4 * i + 3] = x1
        U[4 * i] = gh * (b[4 * i] + x0)
        U[4 * i + 1] = gh * (b[4 * i + 1] + x1)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def solve(N, B, gW, gD, dlo, dhi, gh, path, F, ab, piv, b, U, w):
    """``U = (I/gh - J)^{-1} b`` with the factors of :func:`factor` (``path`` its return):
    the velocities from the reduced system, the positions ``gh (b_r + U_v)``, then W and D
    (``U_w = gh (b_w + gW . U)``, ``U_d = gh (b_d + gD . U)``; ``gD`` is zero outside
    ``[dlo, dhi)``)."""
    if path == PATH_BLOCK:
        _block_solve(N, B, gh, F, b, U, w)
    else:
        g2 = gh * gh
        for i in range(N):
            for r in range(2):
                w[2 * i + r] = _rhs_v(N, B, gh, g2, b, i, r)
        band_solve(ab, 2 * N, KLE, KUE, piv, w)
        for i in range(N):
            for r in range(2):
                uv = w[2 * i + r]
                U[4 * i + 2 + r] = uv
                U[4 * i + r] = gh * (b[4 * i + r] + uv)
    accd = 0.0
    for i in range(dlo, dhi):
        accd += gD[i] * U[i]
    accw = 0.0
    for k in range(4):
        accw += gW[k] * U[4 * (N - 1) + k]
    U[4 * N] = gh * (b[4 * N] + accw)
    U[4 * N + 1] = gh * (b[4 * N + 1] + accd)
