"""The banded system of a chain with bending, for the stiff method (:mod:`snapping.simulate.stiff`).

The structure (why a stage costs O(N)). The state is ``y = [theta, omega, W, D]``
(:mod:`snapping.simulate.forced`; ``omega = theta'``). The accelerations ``a = theta''``
and tensions ``T`` are the solution ``x = (a, T)`` of the linear system ``R(theta, omega,
x) = M(theta) x - g(theta, omega, t) = 0`` whose rows, per link j, are::

    angle row   h_j a_j - S_j/m_{j+1} T_{j+1} + S_{j-1}/m_j T_{j-1} - a^F_j . n_j      = 0
    tension row C_{j-1}/m_j T_{j-1} + b_j T_j + C_j/m_{j+1} T_{j+1} + h_j omega_j^2 + a^F_j . t_j = 0

(``a^F_j = F_{j+1}/m_{j+1} - F_j/m_j``; the held link's rows with ``E = A - g e2`` added to
``a^F``). With the unknowns interleaved per link, ``x = (a_0, T_0, a_1, T_1, ...)``, the
tension rows are tridiagonal in T, the angle rows diagonal in a and bidiagonal in T, so
``M = dR/dx`` is banded (bandwidth 2). The bending node forces ``F`` come from the node
moments ``M_i = B_i/l_i (theta_i - theta_{i-1} - kappa0_i l_i) + eta_i/l_i (omega_i -
omega_{i-1})`` as couples on the two nodes of each link, so ``a^F_j`` depends on
``theta_{j-2} .. theta_{j+2}`` (and the same omegas): ``R_theta = dR/dtheta`` and
``R_omega = dR/domega`` at fixed x are banded too (five links wide). The Jacobian of the
ODE, ``da/dtheta = -P M^{-1} R_theta`` (P picks the a-entries), is dense: it contains the
inverse of the tension matrix. It is never formed. A Rosenbrock stage solves
``(I/(gamma h) - J) U = b`` with ``J = [[0, I], [da/dtheta, da/domega]]``; eliminating
``U_theta = gamma h (b_theta + U_omega)`` and writing ``U_omega = gamma h (b_omega - w_a)``
with ``w = M^{-1}[R_theta (b_theta + U_omega)/alpha + R_omega U_omega]`` (``alpha =
1/(gamma h)``) gives one banded system in the interleaved unknowns::

    [M + ((gamma h)^2 R_theta + gamma h R_omega) P] w = gamma h [R_theta (b_theta + gamma h b_omega) + R_omega b_omega]

of lower bandwidth 5 and upper bandwidth 4 (per link: its a and T against the a of links
j - 2 .. j + 2 and the T of links j - 1 .. j + 1; the tension row 2j + 1 reaches column
2j - 4, the angle row 2j column 2j + 4): one banded LU per step (LAPACK ``dgbtrf``, O(N)) and
one banded solve per stage (``dgbtrs``, O(N)). The derivatives ``M``, ``R_theta``,
``R_omega`` are exact: complex-step derivatives of a transcription of the rows
(:meth:`Residual.R` in numpy, ``_rows`` compiled), five colours per variable (columns five
links apart touch no common row): 20 complex evaluations of the rows per Jacobian, no
subtraction error. The Jacobian is taken at every accepted step (RODAS4 needs it exact).

What the Jacobian leaves out. Air drag: the node velocities are sums over the chain
(``v_j = v_{j+1} - h_j omega_j n_j``), so drag couples every omega to every node and is not
banded; it is left out of ``J``. RODAS4 with an approximate Jacobian loses order (it is a
Rosenbrock method, not a W-method), so with strong drag the step sizes grow; the results
stay error-controlled. The work and dissipation components ``W, D`` (quadratures of the
state) get their exact Jacobian rows in the stage direction: analytic with a fixed held end
and clamp (``W' = 0``, ``D' = sum eta_i/l_i (omega_i - omega_{i-1})^2 - p``, the drag's power
``p`` by its exact O(N) gradient, :func:`snapping.simulate.forced.drag_power_gradient`), else
by one forward difference (one extra evaluation per stage: a moving pin or clamp);
the time derivative ``f_t`` by one forward difference per step for a moving pin or
clamp.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.linalg import lapack

from . import forced as FR
from . import general as G
from . import kernels as K

__all__ = ["Residual", "StageMatrix", "body_model", "dense_ode_jacobian", "KL", "KU", "NCOL"]

KL, KU = 5, 4  # bandwidths of the interleaved stage matrix (rows of a link: 2j, 2j + 1)
NCOL = 5  # colours: links 5 apart share no row
_EPS_CS = 1e-30  # complex-step size


def body_model(problem):
    """The model tuple with a body block (:mod:`snapping.simulate.forced`) and the initial
    state ``[theta, omega, W, D]`` of a problem (one without a body gets an empty block:
    the same equations as :mod:`snapping.simulate.general`)."""
    mdl = problem.model()
    N = problem.N
    if mdl[0][G.P_KIND] == G.KIND_UNIFORM:
        mdl = G.make_model(problem.links.h, 1.0 / problem.links.m, g=problem.gravity, **problem.pin.model_args())
    if mdl[0][G.P_KIND] != G.KIND_BODY:
        mdl = FR.make_body_model(mdl, {})
    y0 = np.zeros(2 * N + 2)
    a = problem.initial_angles()
    y0[:a.size] = a
    return mdl, y0


@njit(cache=True, fastmath=False, error_model="numpy")
def _rows(N, th, om, a, T, h, invm, invm_next, invh, Bl, K0L, El, clamped, hasbend, phi, phid, pax, payg, M, FX, FY,
          out, C0, S0, Cd0, Sd0):
    """:meth:`Residual.R` for one complex state whose angles are ``theta + i delta`` with a
    tiny delta (a complex step), compiled: ``cos(theta + i delta) = cos theta - i delta sin
    theta`` from the real ``C0, S0`` (cos, sin of theta) and ``Cd0, Sd0`` (of theta_{j+1} -
    theta_j), exact to rounding for |delta| <= 1e-20. Scratch ``M, FX, FY`` (N + 1)."""
    for i in range(N + 1):
        M[i] = 0.0
        FX[i] = 0.0
        FY[i] = 0.0
    if hasbend:
        for i in range(1, N):
            M[i] = Bl[i] * ((th[i] - th[i - 1]) - K0L[i]) + El[i] * (om[i] - om[i - 1])
        if clamped:
            M[N] = Bl[N] * ((phi - th[N - 1]) - K0L[N]) + El[N] * (phid - om[N - 1])
        for j in range(N):
            fq = (M[j + 1] - M[j]) * invh[j]
            dl = th[j].imag
            cj = complex(C0[j], -S0[j] * dl)
            sj = complex(S0[j], C0[j] * dl)
            FX[j + 1] += -sj * fq
            FY[j + 1] += cj * fq
            FX[j] -= -sj * fq
            FY[j] -= cj * fq
    for j in range(N):
        dl = th[j].imag
        cj = complex(C0[j], -S0[j] * dl)
        sj = complex(S0[j], C0[j] * dl)
        afx = FX[j + 1] * invm_next[j] - FX[j] * invm[j]
        afy = FY[j + 1] * invm_next[j] - FY[j] * invm[j]
        if j == N - 1:
            afx += pax
            afy += payg
        rt = -(invm[j] + invm_next[j]) * T[j] + h[j] * om[j] * om[j] + (afx * cj + afy * sj)
        ra = h[j] * a[j] - (cj * afy - sj * afx)
        if j < N - 1:
            dl = th[j + 1].imag - th[j].imag
            cd = complex(Cd0[j], -Sd0[j] * dl)
            sd = complex(Sd0[j], Cd0[j] * dl)
            rt += cd * invm[j + 1] * T[j + 1]
            ra -= sd * invm[j + 1] * T[j + 1]
        if j > 0:
            dl = th[j].imag - th[j - 1].imag
            cd = complex(Cd0[j - 1], -Sd0[j - 1] * dl)
            sd = complex(Sd0[j - 1], Cd0[j - 1] * dl)
            rt += cd * invm[j] * T[j - 1]
            ra += sd * invm[j] * T[j - 1]
        out[2 * j] = ra
        out[2 * j + 1] = rt


@njit(cache=True, fastmath=False, error_model="numpy")
def _jacobian(N, th, om, a, T, h, invm, invm_next, invh, Bl, K0L, El, clamped, hasbend, phi, phid, pax, payg, D):
    """The coloured complex-step columns of :meth:`Residual.jacobian`, compiled."""
    M = np.zeros(N + 1, dtype=np.complex128)
    FX = np.zeros(N + 1, dtype=np.complex128)
    FY = np.zeros(N + 1, dtype=np.complex128)
    out = np.zeros(2 * N, dtype=np.complex128)
    x = np.zeros((4, N), dtype=np.complex128)
    x[0, :] = th
    x[1, :] = om
    x[2, :] = a
    x[3, :] = T
    C0 = np.cos(th.real)
    S0 = np.sin(th.real)
    Cd0 = np.cos(th.real[1:] - th.real[:-1])
    Sd0 = np.sin(th.real[1:] - th.real[:-1])
    for v in range(4):
        for k in range(NCOL):
            for j in range(k, N, NCOL):
                x[v, j] += 1j * _EPS_CS
            _rows(N, x[0], x[1], x[2], x[3], h, invm, invm_next, invh, Bl, K0L, El, clamped, hasbend, phi, phid, pax,
                  payg, M, FX, FY, out, C0, S0, Cd0, Sd0)
            for i in range(2 * N):
                D[v, k, i] = out[i].imag / _EPS_CS
            for j in range(k, N, NCOL):
                x[v, j] -= 1j * _EPS_CS  # (exact: the real part is untouched)


@njit(cache=True, inline="always")
def colour_link(j, k):
    """The link of colour ``k`` within two links of link ``j`` (``j - 2 .. j + 2``; it may lie
    outside ``0 .. N - 1``): the column of the coloured Jacobian ``D[., k, row of j]``."""
    d = (k - j) % NCOL
    if d > 2:
        d -= NCOL
    return j + d


@njit(cache=True, fastmath=False, error_model="numpy")
def _matvec(N, Dv, x, out):
    """``out += sum_k Dv[k, i] x[link of colour k near row i]`` (the coloured columns times x)."""
    for i in range(2 * N):
        j = i // 2
        acc = 0.0
        for k in range(NCOL):
            lk = colour_link(j, k)
            if 0 <= lk < N:
                acc += Dv[k, i] * x[lk]
        out[i] += acc


@njit(cache=True, fastmath=False, error_model="numpy")
def _assemble(N, D, gh, ab):
    """The stage matrix in LAPACK band storage (``A[i, j]`` at ``ab[KL + KU + i - j, j]``):
    column a_l (2l) ``dR/da + (gh)^2 dR/dtheta + gh dR/domega``, column T_l (2l + 1) ``dR/dT``."""
    for i in range(2 * N):
        j = i // 2
        for k in range(NCOL):
            lk = colour_link(j, k)
            if 0 <= lk < N:
                ab[KL + KU + i - 2 * lk, 2 * lk] = D[2, k, i] + gh * gh * D[0, k, i] + gh * D[1, k, i]
                ab[KL + KU + i - 2 * lk - 1, 2 * lk + 1] = D[3, k, i]


class Residual:
    """The rows ``R(theta, omega, a, T; t)`` of the accelerations and tensions (numpy,
    complex-safe: the derivatives are complex steps), their exact banded derivatives, and
    the model's compiled right-hand side and measurements."""

    def __init__(self, mdl):
        self.mdl = mdl
        par, h, invm, invh, snode, tab = mdl
        N = h.size
        self.N = N
        self.par, self.h, self.invm, self.invh = par, h, invm, invh
        self.tab = tab.copy()  # (the kernels' scratch lives in the table: one per instance)
        o = int(par[FR.P_BOFF])
        n1 = N + 1
        self.Bl = tab[o + FR.B_BL * n1:o + (FR.B_BL + 1) * n1].copy()
        self.K0L = tab[o + FR.B_K0L * n1:o + (FR.B_K0L + 1) * n1].copy()
        self.El = tab[o + FR.B_EL * n1:o + (FR.B_EL + 1) * n1].copy()
        self.clamped = par[FR.P_CLAMP] != 0.0
        self.hasbend = par[FR.P_HASBEND] != 0.0
        self.invm_next = np.append(invm[1:], 0.0)
        self.autonomous = par[G.P_PIN] == G.PIN_FIXED and int(par[FR.P_CNK]) == 0
        # W, D have dynamics: work of a moving held end or clamp, dissipation by damping or drag
        self.quad = (not self.autonomous) or self.clamped or bool(np.any(self.El != 0.0)) or par[FR.P_HASDRAG] != 0.0
        # their Jacobian rows: analytic with a fixed held end and clamp (W' = 0, D' = sum El_i
        # (omega_i - omega_{i-1})^2 - p, the drag's power p by its exact gradient), else a difference
        self.quad_fd = self.quad and not self.autonomous
        self.hasdrag = par[FR.P_HASDRAG] != 0.0
        w = G.Work(N)
        self.c, self.s, self.S, self.cp, self.dp, self.sig = w.c, w.s, w.S, w.cp, w.dp, w.sig
        self.Z = np.zeros((7, N + 1))
        self.rinv0 = np.zeros(N)
        self.meas = np.zeros(FR.NMEAS_B)
        self.nrhs = 0
        # colour bookkeeping: for row i (link j = i // 2) and colour k, the link of colour k
        # within two links of j, and the band positions of its a- and T-columns
        rows = np.arange(2 * N)
        j = rows // 2
        self.cidx = []
        for k in range(NCOL):
            d = (k - j) % NCOL
            d = np.where(d > 2, d - NCOL, d)
            lk = j + d
            ok = (lk >= 0) & (lk < N)
            r = rows[ok]
            lk = lk[ok]
            self.cidx.append((r, lk, KL + KU + r - 2 * lk, 2 * lk, KL + KU + r - 2 * lk - 1, 2 * lk + 1))

    # -- the compiled right-hand side (the one every method uses)
    def rhs(self, t, y, f):
        par, h, invm, invh, snode, _ = self.mdl
        FR.forced_rhs(self.N, t, y, f, self.c, self.s, self.S, self.cp, self.dp, self.sig, par, h, invm, invh, snode,
                      self.tab)
        self.nrhs += 1

    def measure(self, t, y):
        """``(v_max, a_max, sigma_max, energy, W, D)`` at (t, y) (one evaluation)."""
        f = np.empty_like(y)
        self.rhs(t, y, f)
        par, h, invm, invh, snode, _ = self.mdl
        FR.forced_measure(self.N, t, y, self.c, self.s, self.sig, self.Z, self.rinv0, self.meas, par, h, invm, invh,
                          snode, self.tab)
        m = self.meas
        N = self.N
        return (m[K.M_VMAX], m[K.M_AMAX], m[K.M_SIGMAX], m[K.M_ENERGY], y[2 * N], y[2 * N + 1])

    # -- the rows, complex-safe
    def R(self, t, th, om, a, T):
        """The interleaved residual ``(angle row j, tension row j)_j`` (zero at the
        accelerations and tensions of :func:`snapping.simulate.forced.forced_rhs`; no drag).
        Arguments may carry leading axes (several states at once: the colours of a Jacobian)."""
        N = self.N
        h, invm, invh = self.h, self.invm, self.invh
        dt = np.result_type(th, om, a, T, 1.0)
        th, om, a, T = (np.asarray(x, dtype=dt) for x in np.broadcast_arrays(th, om, a, T))
        c = np.cos(th)
        s = np.sin(th)
        lead = th.shape[:-1]
        FX = np.zeros(lead + (N + 1,), dtype=dt)
        FY = np.zeros(lead + (N + 1,), dtype=dt)
        if self.hasbend:
            M = np.zeros(lead + (N + 1,), dtype=dt)
            M[..., 1:N] = (self.Bl[1:N] * ((th[..., 1:] - th[..., :-1]) - self.K0L[1:N])
                           + self.El[1:N] * (om[..., 1:] - om[..., :-1]))
            if self.clamped:
                phi, phid = FR.clamp_angle(t, self.par, self.tab)
                M[..., N] = self.Bl[N] * ((phi - th[..., N - 1]) - self.K0L[N]) + self.El[N] * (phid - om[..., N - 1])
            fq = (M[..., 1:] - M[..., :-1]) * invh
            fx = -s * fq
            fy = c * fq
            FX[..., 1:] += fx
            FY[..., 1:] += fy
            FX[..., :-1] -= fx
            FY[..., :-1] -= fy
        _, _, _, _, pax, pay = G.pin_kinematics(t, self.par, self.tab)
        afx = FX[..., 1:] * self.invm_next - FX[..., :N] * invm
        afy = FY[..., 1:] * self.invm_next - FY[..., :N] * invm
        afx[..., N - 1] += pax
        afy[..., N - 1] += pay - self.par[G.P_G]
        dth = th[..., 1:] - th[..., :-1]
        e = np.cos(dth) * invm[1:]
        Sd = np.sin(dth) * invm[1:]
        rowT = -(invm + self.invm_next) * T + h * om * om + (afx * c + afy * s)
        rowT[..., :-1] += e * T[..., 1:]
        rowT[..., 1:] += e * T[..., :-1]
        rowA = h * a - (c * afy - s * afx)
        rowA[..., :-1] -= Sd * T[..., 1:]
        rowA[..., 1:] += Sd * T[..., :-1]
        out = np.empty(lead + (2 * N,), dtype=np.result_type(rowA, rowT))
        out[..., 0::2] = rowA
        out[..., 1::2] = rowT
        return out

    def jacobian(self, t, y, f, compiled=True):
        """The exact derivatives of :meth:`R` at the state y with its accelerations ``f[N:2N]``
        and tensions (``self.sig``, from the evaluation that gave f): an array (4, NCOL, 2N),
        the columns of colour k of ``dR/dtheta, dR/domega, dR/da, dR/dT`` (complex steps;
        compiled, or with ``compiled=False`` the five colours of a variable in one vectorised
        numpy evaluation of :meth:`R`)."""
        N = self.N
        D = np.empty((4, NCOL, 2 * N))
        if compiled:
            phi, phid = FR.clamp_angle(t, self.par, self.tab) if self.clamped else (0.0, 0.0)
            _, _, _, _, pax, pay = G.pin_kinematics(t, self.par, self.tab)
            _jacobian(N, y[:N].astype(complex), y[N:2 * N].astype(complex), f[N:2 * N].astype(complex),
                      self.sig.astype(complex), self.h, self.invm, self.invm_next, self.invh, self.Bl, self.K0L,
                      self.El, self.clamped, self.hasbend, phi, phid, pax, pay - self.par[G.P_G], D)
            return D
        base = [y[:N], y[N:2 * N], f[N:2 * N], self.sig.copy()]
        E = np.zeros((NCOL, N))
        for k in range(NCOL):
            E[k, k::NCOL] = 1.0
        for v in range(4):
            args = list(base)
            args[v] = base[v] + (1j * _EPS_CS) * E
            D[v] = self.R(t, *args).imag / _EPS_CS
        return D

    def matvec(self, D, v, x):
        """``(dR/d var) x`` for var index v (0 theta, 1 omega) from the coloured columns."""
        out = np.zeros(2 * self.N)
        _matvec(self.N, D[v], x, out)
        return out

    def matvec_numpy(self, D, v, x):
        """:meth:`matvec` in numpy (tests)."""
        out = np.zeros(2 * self.N)
        for k in range(NCOL):
            r, lk = self.cidx[k][0], self.cidx[k][1]
            out[r] += D[v, k, r] * x[lk]
        return out


class StageMatrix:
    """The banded stage matrix ``M + ((gamma h)^2 R_theta + gamma h R_omega) P`` in LAPACK
    band storage, factored (``dgbtrf``), and its solves: :meth:`solve` returns the stage
    increments ``(U_theta, U_omega)`` of ``(I/(gamma h) - J) U = b``."""

    def __init__(self, res: Residual, D, gh: float):
        N = res.N
        self.res, self.D, self.gh = res, D, gh
        ab = np.zeros((2 * KL + KU + 1, 2 * N))
        _assemble(N, D, gh, ab)
        self.ab = ab
        self.lu, self.piv, info = lapack.dgbtrf(ab, KL, KU)
        if info != 0:
            raise np.linalg.LinAlgError(f"stage matrix singular (dgbtrf info {info})")

    def dense(self):
        """The stage matrix as a dense array (tests)."""
        n = self.ab.shape[1]
        A = np.zeros((n, n))
        for i in range(n):
            for j in range(max(0, i - KL), min(n, i + KU + 1)):
                A[i, j] = self.ab[KL + KU + i - j, j]
        return A

    def solve(self, bth, bom):
        res, D, gh = self.res, self.D, self.gh
        rhs = gh * (res.matvec(D, 0, bth + gh * bom) + res.matvec(D, 1, bom))
        w, info = lapack.dgbtrs(self.lu, KL, KU, rhs, self.piv)
        if info != 0:
            raise np.linalg.LinAlgError(f"dgbtrs info {info}")
        Uom = gh * (bom - w[0::2])
        Uth = gh * (bth + Uom)
        return Uth, Uom


def dense_ode_jacobian(res: Residual, t, y, D):
    """The dense Jacobian ``[[0, I], [da/dtheta, da/domega]]`` of the angle part from the
    banded derivatives (``-P M^{-1} R_theta``; O(N^3), tests only)."""
    N = res.N
    n = 2 * N

    def full(v):
        A = np.zeros((n, N))
        for k in range(NCOL):
            r, lk = res.cidx[k][0], res.cidx[k][1]
            A[r, lk] = D[v, k, r]
        return A

    M = np.zeros((n, n))
    for k in range(NCOL):
        r, lk = res.cidx[k][0], res.cidx[k][1]
        M[r, 2 * lk] = D[2, k, r]
        M[r, 2 * lk + 1] = D[3, k, r]
    Rth, Rom = full(0), full(1)
    Ath = -np.linalg.solve(M, Rth)[0::2]
    Aom = -np.linalg.solve(M, Rom)[0::2]
    J = np.zeros((n, n))
    J[:N, N:] = np.eye(N)
    J[N:, :N] = Ath
    J[N:, N:] = Aom
    return J
