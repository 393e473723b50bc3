"""Drag in RODAS4's stage solves: what it buys in steps and accuracy, and what it would cost (``dragjac``, issue 24).

RODAS4 (:mod:`snapping.simulate.stiff`, the Python reference stepper, rms norm) solves its stages with
the banded Jacobian of :mod:`snapping.simulate.stiff_system`, which leaves air drag out (the node
velocities are sums over the chain). This probe runs the nylon line's graded levels (as
``probe_nylon_grid.py`` builds them) with four stage solves:

* ``banded``: today's (drag left out of J);
* ``dense``: the exact Jacobian with drag, dense (O(N^3); the reference): the rows' drag part
  differentiated by complex steps in every angle and angular velocity, with the node velocities
  summed from the held end inside;
* ``aug``: the same exact stage solve in O(N): the node velocities' perturbations ``z_j = dV_j`` as
  two more unknowns per link, ``z_j - z_{j+1} = h_j (dω_j (sin, -cos) + ω_j dθ_j (cos, sin))``, the
  drag forces local in ``z`` and the tangents, so the stage matrix stays banded (4 unknowns per link,
  ``(w_a, w_T, z_x, z_y)``, bandwidths ``KL_AUG, KU_AUG``: one ``dgbtrf`` per step, one ``dgbtrs``
  per stage, as today, on a wider band);
* ``corrK``: today's banded solve, then K defect corrections with the exact stage matrix
  (``U += S_b^{-1} (b - S U)``, S dense here);
* ``corrfdK``: the same corrections with ``J U`` by one forward difference of the compiled right side
  along U: O(N), one evaluation and one banded solve more per stage and correction, no new LU.

It prints the steps, rejections and the peaks (nondimensional) of each, and (``--costs``) the
times of the two band shapes' LU and solve on a given number of links (LAPACK, the engine's
compiled band code, one band code with compile-time lengths for both): the compiled step's extra cost.

Usage::

    python benchmarks/probe_drag_jacobian.py --level -1 --modes banded aug dense corr1 --norm rms
    python benchmarks/probe_drag_jacobian.py --level 0 --modes banded aug corrfd1
    python benchmarks/probe_drag_jacobian.py --level -1 --modes aug --tol 1e-5
    python benchmarks/probe_drag_jacobian.py --costs 2127
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import os
import time
from pathlib import Path

import numpy as np
import scipy.linalg as sla
from scipy.linalg import lapack

from snapping import caps
from snapping import caps_runs as CR
from snapping.simulate import forced as FR
from snapping.simulate import general as G
from snapping.simulate import stiff
from snapping.simulate.stiff_system import KL, KU, NCOL, Residual, StageMatrix, colour_link

_spec = importlib.util.spec_from_file_location("probe_nylon_grid", Path(__file__).with_name("probe_nylon_grid.py"))
_grid = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_grid)

EPS = 1e-30  # complex step
KL_AUG, KU_AUG = 9, 8  # the augmented stage matrix's bandwidths (4 unknowns per link)


def _cabs(x):
    """|x| for a real x carrying a complex step (the sign of the real part)."""
    return np.where(np.real(x) >= 0.0, x, -x)


class DragResidual(Residual):
    """:class:`Residual` with the rows' drag part: :meth:`Rd` (complex-safe numpy transcription of
    :func:`snapping.simulate.force_drag.add_drag`), the dense (:meth:`dense_jacobian`) and local
    (:meth:`local_drag`) derivatives."""

    def __init__(self, mdl):
        super().__init__(mdl)
        par, h, invm, invh, snode, tab = mdl
        o, n1 = int(par[FR.P_BOFF]), self.N + 1
        self.CN, self.CT, self.KN, self.KT = (tab[o + b * n1:o + (b + 1) * n1].copy()
                                              for b in (FR.B_CN, FR.B_CT, FR.B_KN, FR.B_KT))
        self.wx, self.wy, self.cd = par[FR.P_WX], par[FR.P_WY], par[FR.P_TIPCD]

    def velocities(self, t, th, om):
        _, _, pvx, pvy, _, _ = G.pin_kinematics(t, self.par, self.tab)
        w = om * self.h
        lead = np.broadcast_shapes(th.shape[:-1], om.shape[:-1])
        VX = np.zeros(lead + (self.N + 1,), dtype=np.result_type(th, om))
        VY = np.zeros_like(VX)
        VX[..., :-1] = np.cumsum((np.sin(th) * w)[..., ::-1], axis=-1)[..., ::-1]
        VY[..., :-1] = -np.cumsum((np.cos(th) * w)[..., ::-1], axis=-1)[..., ::-1]
        return VX + pvx, VY + pvy

    def Rd(self, th, VX, VY):
        """The drag's part of the interleaved rows at angles ``th`` and node velocities ``VX, VY``."""
        N = self.N
        c, s = np.cos(th), np.sin(th)
        lead = np.broadcast_shapes(th.shape[:-1], VX.shape[:-1], VY.shape[:-1])
        dt = np.result_type(th, VX, VY)
        tx = np.broadcast_to(c, lead + (N,)).astype(dt)
        ty = np.broadcast_to(s, lead + (N,)).astype(dt)
        bx, by = c[..., :-1] + c[..., 1:], s[..., :-1] + s[..., 1:]
        nb = np.sqrt(bx * bx + by * by)
        ok = np.real(nb) > 1e-12
        nbs = np.where(ok, nb, 1.0)
        tx[..., 1:] = np.where(ok, bx / nbs, tx[..., 1:])
        ty[..., 1:] = np.where(ok, by / nbs, ty[..., 1:])
        ux, uy = VX[..., :N] - self.wx, VY[..., :N] - self.wy
        ut = ux * tx + uy * ty
        utx, uty = ut * tx, ut * ty
        unx, uny = ux - utx, uy - uty
        an = self.CN[:N] * _cabs(ux * ty - uy * tx) + self.KN[:N]
        at = self.CT[:N] * _cabs(ut) + self.KT[:N]
        fx = -an * unx - at * utx
        fy = -an * uny - at * uty
        if self.cd != 0.0:
            u = np.sqrt(ux[..., 0] ** 2 + uy[..., 0] ** 2)
            fx[..., 0] -= self.cd * u * ux[..., 0]
            fy[..., 0] -= self.cd * u * uy[..., 0]
        afx = np.zeros(lead + (N,), dtype=dt)
        afy = np.zeros_like(afx)
        afx[..., :-1] += fx[..., 1:] * self.invm_next[:-1]
        afy[..., :-1] += fy[..., 1:] * self.invm_next[:-1]
        afx -= fx * self.invm
        afy -= fy * self.invm
        out = np.empty(lead + (2 * N,), dtype=dt)
        out[..., 0::2] = -(c * afy - s * afx)
        out[..., 1::2] = afx * c + afy * s
        return out

    def R_full(self, t, th, om, a, T):
        """The rows with drag (zero at the compiled right side's accelerations and tensions)."""
        VX, VY = self.velocities(t, th, om)
        return self.R(t, th, om, a, T) + self.Rd(th, VX, VY)

    def dense_drag(self, t, y):
        """``d Rd / d(theta, omega)`` (2N x 2N), the node velocities summed inside: complex steps."""
        N = self.N
        th, om = y[:N], y[N:2 * N]
        E = (1j * EPS) * np.eye(N)
        out = np.empty((2 * N, 2 * N))
        VX, VY = self.velocities(t, th + E, om)
        out[:, :N] = (self.Rd(th + E, VX, VY).imag / EPS).T
        VX, VY = self.velocities(t, th, om + E)
        out[:, N:] = (self.Rd(th, VX, VY).imag / EPS).T
        return out

    def local_drag(self, t, y):
        """The coloured columns (NCOL, 2N) of ``d Rd/d theta`` at fixed node velocities and of
        ``d Rd/d VX``, ``d Rd/d VY`` (nodes 0 .. N - 1): banded, complex steps."""
        N = self.N
        th, om = y[:N], y[N:2 * N]
        VX, VY = self.velocities(t, th, om)
        E = np.zeros((NCOL, N))
        for k in range(NCOL):
            E[k, k::NCOL] = 1.0
        En = np.zeros((NCOL, N + 1))
        En[:, :N] = E
        Dth = self.Rd(th + (1j * EPS) * E, VX, VY).imag / EPS
        Dvx = self.Rd(th, VX + (1j * EPS) * En, VY).imag / EPS
        Dvy = self.Rd(th, VX, VY + (1j * EPS) * En).imag / EPS
        return Dth, Dvx, Dvy

    def jacobian(self, t, y, f, compiled=True):
        D = super().jacobian(t, y, f, compiled).view(JacArr)
        D.t, D.y = t, y.copy()
        return D


class JacArr(np.ndarray):
    """The coloured banded derivatives, carrying the state they were taken at (``t``, ``y``)."""


def _full(res, D, v):
    n, N = 2 * res.N, res.N
    A = np.zeros((n, N))
    for k in range(NCOL):
        r, lk = res.cidx[k][0], res.cidx[k][1]
        A[r, lk] = D[v, k, r]
    return A


def dense_stage_matrix(res: DragResidual, D, gh):
    """``I/(gamma h) - J`` with J the exact Jacobian of the angle part, drag included (dense)."""
    N = res.N
    n = 2 * N
    M = np.zeros((n, n))
    for k in range(NCOL):
        r, lk = res.cidx[k][0], res.cidx[k][1]
        M[r, 2 * lk] = D[2, k, r]
        M[r, 2 * lk + 1] = D[3, k, r]
    Rx = np.hstack([_full(res, D, 0), _full(res, D, 1)]) + res.dense_drag(D.t, D.y)
    A = -np.linalg.solve(M, Rx)[0::2]
    S = np.zeros((n, n))
    S[:N, :N] = np.eye(N) / gh
    S[:N, N:] = -np.eye(N)
    S[N:, :] = -A
    S[N:, N:] += np.eye(N) / gh
    return S


class DenseStage:
    """Stage solves with the exact dense Jacobian (the reference)."""

    def __init__(self, res, D, gh):
        self.N = res.N
        self.lu = sla.lu_factor(dense_stage_matrix(res, D, gh))

    def solve(self, bth, bom):
        U = sla.lu_solve(self.lu, np.concatenate([bth, bom]))
        return U[:self.N], U[self.N:]


class CorrStage:
    """Today's banded solve, then ``K`` defect corrections with the exact stage matrix."""
    K = 1

    def __init__(self, res, D, gh):
        self.N = res.N
        self.b = StageMatrix(res, D, gh)
        self.S = dense_stage_matrix(res, D, gh)

    def solve(self, bth, bom):
        N = self.N
        b = np.concatenate([bth, bom])
        U = np.concatenate(self.b.solve(bth, bom))
        for _ in range(self.K):
            r = b - self.S @ U
            d = self.b.solve(r[:N], r[N:])
            U[:N] += d[0]
            U[N:] += d[1]
        return U[:N], U[N:]


class CorrFDStage:
    """Today's banded solve, then ``K`` defect corrections whose residual takes ``J U`` by one forward
    difference of the compiled right side along U (O(N): one evaluation and one banded solve more
    per stage and correction, no new factorisation; what a compiled engine would do)."""
    K = 1

    def __init__(self, res, D, gh):
        self.res, self.N, self.gh = res, res.N, gh
        self.b = StageMatrix(res, D, gh)
        self.t, self.y = D.t, D.y
        self.f0 = np.empty_like(self.y)
        res.rhs(self.t, self.y, self.f0)

    def solve(self, bth, bom):
        N, gh, res, y = self.N, self.gh, self.res, self.y
        Uth, Uom = self.b.solve(bth, bom)
        for _ in range(self.K):
            u = np.concatenate([Uth, Uom])
            nu = np.sqrt(np.mean(u * u))
            if not nu > 0.0:
                break
            dl = 1e-7 * (1.0 + np.sqrt(np.mean(y[:2 * N] ** 2))) / nu
            yp = y.copy()
            yp[:2 * N] += dl * u
            fp = np.empty_like(y)
            res.rhs(self.t, yp, fp)
            Ju = (fp[N:2 * N] - self.f0[N:2 * N]) / dl
            rth = bth - (Uth / gh - Uom)
            rom = bom - (Uom / gh - Ju)
            dth, dom = self.b.solve(rth, rom)
            Uth, Uom = Uth + dth, Uom + dom
        return Uth, Uom


def aug_matrix(res: DragResidual, D, gh):
    """The augmented stage matrix (4N x 4N) in LAPACK band storage (``KL_AUG``, ``KU_AUG``), and
    the local drag derivatives it used."""
    N = res.N
    t, y = D.t, D.y
    th, om = y[:N], y[N:2 * N]
    c, s, h = np.cos(th), np.sin(th), res.h
    Dth, Dvx, Dvy = res.local_drag(t, y)
    ab = np.zeros((2 * KL_AUG + KU_AUG + 1, 4 * N))
    ro = KL_AUG + KU_AUG

    def put(i, j, v):
        ab[ro + i - j, j] += v

    for k in range(NCOL):
        r, lk = res.cidx[k][0], res.cidx[k][1]
        ra = 4 * (r // 2) + (r % 2)  # the R row's place among the augmented rows
        put(ra, 4 * lk, D[2, k, r] + gh * gh * (D[0, k, r] + Dth[k, r]) + gh * D[1, k, r])
        put(ra, 4 * lk + 1, D[3, k, r])
        put(ra, 4 * lk + 2, -Dvx[k, r])
        put(ra, 4 * lk + 3, -Dvy[k, r])
    j = np.arange(N)
    put(4 * j + 2, 4 * j + 2, 1.0)
    put(4 * j + 3, 4 * j + 3, 1.0)
    put(4 * j[:-1] + 2, 4 * j[:-1] + 6, -1.0)
    put(4 * j[:-1] + 3, 4 * j[:-1] + 7, -1.0)
    put(4 * j + 2, 4 * j, h * (gh * s + gh * gh * om * c))
    put(4 * j + 3, 4 * j, h * (-gh * c + gh * gh * om * s))
    return ab, Dth


class AugStage:
    """The exact stage solve in O(N): the banded system in (w_a, w_T, z_x, z_y) per link."""

    def __init__(self, res, D, gh):
        self.res, self.D, self.gh = res, D, gh
        ab, self.Dth = aug_matrix(res, D, gh)
        self.lu, self.piv, info = lapack.dgbtrf(ab, KL_AUG, KU_AUG)
        if info != 0:
            raise np.linalg.LinAlgError(f"augmented stage matrix singular (info {info})")
        N = res.N
        self.th, self.om = D.y[:N], D.y[N:2 * N]

    def solve(self, bth, bom):
        res, D, gh, N = self.res, self.D, self.gh, self.res.N
        x = bth + gh * bom
        rR = gh * (res.matvec(D, 0, x) + res.matvec(D, 1, bom))
        for k in range(NCOL):  # the drag's own angle derivative at fixed velocities
            r, lk = res.cidx[k][0], res.cidx[k][1]
            rR[r] += gh * self.Dth[k, r] * x[lk]
        c, s, h, om = np.cos(self.th), np.sin(self.th), res.h, self.om
        rhs = np.empty(4 * N)
        rhs[0::4] = rR[0::2]
        rhs[1::4] = rR[1::2]
        rhs[2::4] = h * (s * gh * bom + om * c * gh * x)
        rhs[3::4] = h * (-c * gh * bom + om * s * gh * x)
        w, info = lapack.dgbtrs(self.lu, KL_AUG, KU_AUG, rhs, self.piv)
        Uom = gh * (bom - w[0::4])
        Uth = gh * (bth + Uom)
        return Uth, Uom


def stage_class(mode):
    if mode == "banded":
        return StageMatrix
    if mode == "dense":
        return DenseStage
    if mode == "aug":
        return AugStage
    if mode.startswith("corrfd"):
        return type(f"CorrFD{mode[6:]}", (CorrFDStage,), {"K": int(mode[6:])})
    if mode.startswith("corr"):
        return type(f"Corr{mode[4:]}", (CorrStage,), {"K": int(mode[4:])})
    raise ValueError(f"mode {mode!r}: banded, dense, aug, corrK or corrfdK")


class _MaxNorm:
    """numpy for :mod:`snapping.simulate.stiff` with ``mean`` the maximum: its error norm
    ``sqrt(mean(e^2))`` becomes the compiled engine's max norm (``mean`` is used nowhere else there
    with a fixed held end)."""

    def __getattr__(self, name):
        return getattr(np, name)

    mean = staticmethod(np.max)


@contextlib.contextmanager
def stage_solves(mode, norm="rms"):
    """:func:`snapping.simulate.stiff.solve` with ``mode``'s stage solves and :class:`DragResidual`
    (``norm="max"``: the error in the max norm, as the compiled engine's)."""
    orig = stiff.StageMatrix, stiff.Residual, stiff.np
    stiff.StageMatrix, stiff.Residual = stage_class(mode), DragResidual
    if norm == "max":
        stiff.np = _MaxNorm()
    try:
        yield
    finally:
        stiff.StageMatrix, stiff.Residual, stiff.np = orig


def nylon_problem(chi, level):
    sp = caps.spec("nylon-monofilament")
    on = tuple(m for m in CR.MECHANISMS[:-1] if sp.has(m))
    h = _grid.links(chi, CR.bending_length(sp), level)
    return CR.problem(sp, chi, h.size, on, damping=CR.GRADED_DAMPING, omega_min=0.0, h=h)


def fixed_band(kl, ku):
    """A band LU with partial pivoting and its solve whose loops have the compile-time lengths of
    ``kl, ku`` (the layout of :func:`snapping.simulate.banded.band_lu`'s stage path: rows of width
    ``2 kl + ku + 2``, the reciprocal pivots in the last column, back substitution by columns), to
    time the augmented shape as the engine's fixed-length path would run it."""
    from numba import njit

    mbw, idiag = kl + ku, 2 * kl + ku + 1

    @njit(fastmath=False, boundscheck=False, error_model="numpy")
    def lu(R, n, piv):
        for k in range(n):
            last = k + mbw >= n
            qmax = min(kl, n - 1 - k) if last else kl
            w = min(mbw + 1, n - k) if last else mbw + 1
            p = k
            vmax = abs(R[k, kl])
            for q in range(1, qmax + 1):
                v = abs(R[k + q, kl - q])
                if v > vmax:
                    vmax = v
                    p = k + q
            piv[k] = p
            if vmax == 0.0 or not (vmax - vmax == 0.0):
                return k + 1
            if p != k:
                op = k - p + kl
                for d in range(w):
                    tmp = R[k, kl + d]
                    R[k, kl + d] = R[p, op + d]
                    R[p, op + d] = tmp
            inv = 1.0 / R[k, kl]
            R[k, idiag] = inv
            for q in range(1, qmax + 1):
                oi = kl - q
                m = R[k + q, oi] * inv
                R[k + q, oi] = m
                for d in range(1, w):
                    R[k + q, oi + d] -= m * R[k, kl + d]
        return 0

    @njit(fastmath=False, boundscheck=False, error_model="numpy")
    def solve(R, n, piv, b):
        for k in range(n):
            pk = piv[k]
            if pk != k:
                tmp = b[k]
                b[k] = b[pk]
                b[pk] = tmp
            bk = b[k]
            for q in range(1, min(kl, n - 1 - k) + 1):
                b[k + q] -= R[k + q, kl - q] * bk
        for k in range(n - 1, -1, -1):
            xk = b[k] * R[k, idiag]
            b[k] = xk
            for d in range(1, min(mbw, k) + 1):
                b[k - d] -= R[k - d, kl + d] * xk

    return lu, solve


def costs(N, reps=30):
    """CPU seconds of one LU and one solve of today's band (2N, 5, 4) and the augmented (4N, 9, 8):
    LAPACK's ``dgbtrf``/``dgbtrs`` and the engine's compiled :func:`snapping.simulate.banded.band_lu`
    and ``band_solve`` (today's band by its fixed-length stage path, the augmented by the general one)."""
    from snapping.simulate import banded as BD

    rng = np.random.default_rng(0)
    out = {}
    for name, n, kl, ku in (("banded", 2 * N, KL, KU), ("aug", 4 * N, KL_AUG, KU_AUG)):
        ab = np.zeros((2 * kl + ku + 1, n))
        ab[kl:] = rng.standard_normal((kl + ku + 1, n))
        ab[kl + ku] += 20.0  # (diagonally dominant)
        b = rng.standard_normal(n)
        c0 = time.process_time()
        for _ in range(reps):
            lu, piv, _ = lapack.dgbtrf(ab, kl, ku)
        c1 = time.process_time()
        for _ in range(reps):
            lapack.dgbtrs(lu, kl, ku, b, piv)
        c2 = time.process_time()
        out[f"{name} LAPACK"] = ((c1 - c0) / reps, (c2 - c1) / reps)
        w = BD.WROW if (kl, ku) == (KL, KU) else 2 * kl + ku + 1
        R0 = np.zeros((n, w))  # by rows: A[i, j] at R[i, j - i + kl]
        for d in range(-kl, ku + 1):
            i = np.arange(max(0, -d), min(n, n - d))
            R0[i, d + kl] = ab[kl + ku - d, i + d]
        pv = np.zeros(n, dtype=np.int64)
        R = R0.copy()
        BD.band_lu(R, n, kl, ku, pv)  # (compile)
        x = b.copy()
        BD.band_solve(R, n, kl, ku, pv, x)
        c0 = time.process_time()
        for _ in range(reps):
            R[:] = R0
            BD.band_lu(R, n, kl, ku, pv)
        c1 = time.process_time()
        for _ in range(reps):
            x[:] = b
            BD.band_solve(R, n, kl, ku, pv, x)
        c2 = time.process_time()
        out[f"{name} compiled"] = ((c1 - c0) / reps, (c2 - c1) / reps)
        flu, fsv = fixed_band(kl, ku)
        R = np.zeros((n, 2 * kl + ku + 2))
        R[:, :R0.shape[1]] = R0
        R0f = R.copy()
        flu(R, n, pv)
        fsv(R, n, pv, x)
        c0 = time.process_time()
        for _ in range(reps):
            R[:] = R0f
            flu(R, n, pv)
        c1 = time.process_time()
        for _ in range(reps):
            x[:] = b
            fsv(R, n, pv, x)
        c2 = time.process_time()
        ref = lapack.dgbtrs(lu, kl, ku, b, piv)[0]
        assert np.allclose(x, ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max()), "fixed-length band solve"
        out[f"{name} fixed-length"] = ((c1 - c0) / reps, (c2 - c1) / reps)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--chi", type=float, default=0.1)
    p.add_argument("--level", type=int, default=-1)
    p.add_argument("--tol", type=float, default=1e-3)
    p.add_argument("--modes", nargs="*", default=["banded", "aug"])
    p.add_argument("--norm", choices=("rms", "max"), default="max",
                   help="the error norm: max (the compiled engine's, default) or rms (stiff.solve's own)")
    p.add_argument("--costs", type=int, default=0, help="time the LAPACK band shapes on this many links")
    a = p.parse_args(argv)
    if a.costs:
        for name, (lu, sv) in costs(a.costs, 300 if a.costs < 1000 else 30).items():
            print(f"{name}: LU {1e6 * lu:.0f} us, solve {1e6 * sv:.0f} us ({a.costs} links)")
        print(f"load {os.getloadavg()[0]:.1f}")
        return 0
    pr = nylon_problem(a.chi, a.level)
    print(f"nylon-monofilament, chi = {a.chi:g}, level {a.level} ({pr.N} links), tol {a.tol:g}; "
          f"load {os.getloadavg()[0]:.1f}")
    print("| stage solve | CPU s | steps | rejected | v | a | sigma |")
    print("|---|---|---|---|---|---|---|")
    for m in a.modes:
        c0 = time.process_time()
        with stage_solves(m, a.norm):
            o = stiff.solve(pr, tol=a.tol, records=False)
        print(f"| {m} | {time.process_time() - c0:.1f} | {o['n_steps']} | {o['n_rejected']} | {o['v_peak']:.5g} | "
              f"{o['a_peak']:.5g} | {o['sigma_peak']:.5g} |", flush=True)
    print(f"load {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
