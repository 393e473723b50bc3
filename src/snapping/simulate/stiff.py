"""A stiff (linearly implicit) integrator for chains with bending: RODAS4 with O(N) banded stage solves.

Why. The explicit method (``method="fast"``, DOP853) is stable only for steps below the
period of the fastest bending wave, ``dt ~ h^2 sqrt(lambda/B)``: bending stiffness makes
fine chains expensive exactly where the snap needs them fine. A linearly implicit
(Rosenbrock) method is L-stable: bending waves are resolved where the error control asks
for it and damped where it does not, and its step is set by accuracy only.

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

of lower and upper bandwidth 5 (per link: its a and T against the a of links j - 2 .. j + 2
and the T of links j - 1 .. j + 1): one banded LU per step (LAPACK ``dgbtrf``, O(N)) and
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
state) get their exact Jacobian rows in the stage direction: analytic when only bending
damping acts on them (``D' = sum eta_i/l_i (omega_i - omega_{i-1})^2``, ``W' = 0``), else
by one forward difference (one extra evaluation per stage: a moving pin or clamp, drag);
the time derivative ``f_t`` by one forward difference per step for a moving pin or
clamp.

The method. RODAS4 (Hairer and Wanner, *Solving ODEs II*, sec. VI.4; the coefficients of
``rodas.f``): 6 stages (6 evaluations per step), order 4 with an embedded order 3 error
estimate, stiffly accurate and L-stable, the standard error control
``h_new = h min(6, max(0.2, 0.9 err^{-1/4}))`` with the error norm
``rms(U_6/(tol (1 + max(|y_n|, |y_{n+1}|))))`` (relative and absolute ``tol``).
Peaks (v, a, sigma): the global maxima over accepted steps, then located between the
neighbouring steps by Brent's bounded search on the state at time t, obtained by one
RODAS4 step from the accepted step before (an interpolant as accurate as the steps).

Measured (``benchmarks/bench_stiff.py``, ``bench_stiff_single.py``; chi = 0.25, peaks to
1e-6; counts are right-hand-side evaluations, all included): the step is not set by the
bending stiffness, but by the bending waves the release excites. The catenary is not a
bending equilibrium (the free end and the hinge carry no moment), so releasing it
launches grid-scale bending waves; without bending damping they never decay, and an
error-controlled method must follow them. Undamped, this method needs more evaluations
than dop853 (N = 100, beta = 1e-6, 1e-4, 1e-2: 0.34, 0.55, 0.48 times dop853's
efficiency). With a little bending damping (``eta = sqrt(beta)/(2 N^2)``: damping ratio
about 1 for the shortest wave, negligible for the fall) the waves decay and the L-stable
steps pass over them: dop853/stiff evaluations 0.6-1.3 (N = 100), 2.8-2.9 (N = 300),
1.5 (N = 1000, beta = 1e-6), 11.3 (N = 1000, beta = 1e-4) and 17 (N = 1000, beta = 1e-2,
to t = 1.3, stiff at tol 2e-7: at tol 1e-6 its peaks are 1.8e-6 off).
Each step also costs a Jacobian (20 complex evaluations of the compiled rows) and a
banded LU, and the step loop is Python: per evaluation the method is 5-50x slower in
wall time than dop853's compiled loop (N = 1000, beta = 1e-2: 66 s against 86 s).

Integration status: :func:`solve` runs a problem to ``t_end`` (or to the snap by the
driver's rule ``v_max < stop_fraction * peak``) and returns the peaks, step and
evaluation counts, the final state and per-step records (time, v_max, a_max,
sigma_max, energy, W, D). It is *not* a method of :func:`snapping.simulate.run` yet:
no Engine (checkpoints, snapshots, Dataset records, progress), see the module's tests and
``benchmarks/bench_stiff.py``.
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.linalg import lapack
from numba import njit
from scipy.optimize import minimize_scalar

from . import forced as FR
from . import general as G
from . import kernels as K

__all__ = ["Residual", "StageMatrix", "solve", "RODAS4"]

#: RODAS4 (Hairer-Wanner, rodas.f): gamma, nodes c_i, d_i (time-derivative weights), the
#: stage sums a_ij (Y_i = y + sum a_ij U_j) and c_ij (b_i = f(Y_i) + sum c_ij/h U_j + d_i h f_t);
#: y_new = y + sum a_6j U_j + U_6, error estimate U_6
RODAS4 = {
    "gamma": 0.25,
    "c": (0.0, 0.386, 0.21, 0.63, 1.0, 1.0),
    "d": (0.25, -0.1043, 0.1035, -0.0362, 0.0, 0.0),
    "a": ((), (1.544,), (0.9466785280815826, 0.2557011698983284),
          (3.314825187068521, 2.896124015972201, 0.9986419139977817),
          (1.221224509226641, 6.019134481288629, 12.53708332932087, -0.687886036105895),
          (1.221224509226641, 6.019134481288629, 12.53708332932087, -0.687886036105895, 1.0)),
    "C": ((), (-5.6688,), (-2.430093356833875, -0.2063599157091915),
          (-0.1073529058151375, -9.594562251023355, -20.47028614809616),
          (7.496443313967647, -10.24680431464352, -33.99990352819905, 11.7089089320616),
          (8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054)),
}

KL = KU = 5  # bandwidths of the interleaved stage matrix
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


@njit(cache=True, fastmath=False, error_model="numpy")
def _matvec(N, Dv, x, out):
    """``out += sum_k Dv[k, i] x[link of colour k near row i]`` (the coloured columns times x)."""
    for i in range(2 * N):
        j = i // 2
        acc = 0.0
        for k in range(NCOL):
            d = (k - j) % NCOL
            if d > 2:
                d -= NCOL
            lk = j + d
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
            d = (k - j) % NCOL
            if d > 2:
                d -= NCOL
            lk = j + d
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
        # their Jacobian rows: analytic when only damping acts on them (a fixed held end and
        # clamp, no drag: W' = 0, D' = sum El_i (omega_i - omega_{i-1})^2), else a difference
        self.quad_fd = self.quad and ((not self.autonomous) or par[FR.P_HASDRAG] != 0.0)
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


class _Stepper:
    """RODAS4 steps on the chain (the state, its derivative and its Jacobian at the step's start)."""

    def __init__(self, res: Residual, tol: float):
        self.res, self.tol = res, tol
        self.N = res.N
        self.nstep = self.nrej = self.njac = self.nlu = self.nsolve = self.nrhs_q = 0

    def step(self, t, y, f0, D, h, ft=None):
        """One RODAS4 step of size h from (t, y) with ``f0 = f(t, y)`` and the Jacobian ``D``
        there; returns ``(y_new, err)`` (err the scaled error norm)."""
        res, N = self.res, self.N
        tab = RODAS4
        g = tab["gamma"]
        gh = g * h
        sm = StageMatrix(res, D, gh)
        self.nlu += 1
        U = []
        n = y.size
        for i in range(6):
            if i == 0:
                fi = f0
            else:
                Yi = y.copy()
                for j, a in enumerate(tab["a"][i]):
                    Yi += a * U[j]
                fi = np.empty(n)
                res.rhs(t + tab["c"][i] * h, Yi, fi)
            b = fi.copy()
            for j, cc in enumerate(tab["C"][i]):
                b += (cc / h) * U[j]
            if ft is not None and tab["d"][i] != 0.0:
                b += (tab["d"][i] * h) * ft
            Uth, Uom = sm.solve(b[:N], b[N:2 * N])
            self.nsolve += 1
            Ui = np.empty(n)
            Ui[:N] = Uth
            Ui[N:2 * N] = Uom
            # W, D: (1/(gamma h)) U_q - dq'/dx U_x = b_q, the directional derivative by a difference
            bq = b[2 * N:]
            if res.quad and not res.quad_fd:  # dD'/domega U_omega, exact
                El, om = res.El, y[N:2 * N]
                bq = bq.copy()
                bq[1] += 2.0 * float(np.dot(El[1:N] * (om[1:] - om[:-1]), Uom[1:] - Uom[:-1]))
                if res.clamped:
                    _, phid = FR.clamp_angle(t, res.par, res.tab)
                    bq[1] -= 2.0 * El[N] * (phid - om[N - 1]) * Uom[N - 1]
            elif res.quad:
                ux = Ui[:2 * N]
                nu = np.sqrt(np.mean(ux * ux))
                if nu > 0.0:
                    dl = 1e-7 * (1.0 + np.sqrt(np.mean(y[:2 * N] ** 2))) / nu
                    yp = y.copy()
                    yp[:2 * N] += dl * ux
                    fp = np.empty(n)
                    res.rhs(t, yp, fp)
                    self.nrhs_q += 1
                    bq = bq + (fp[2 * N:] - f0[2 * N:]) / dl
            Ui[2 * N:] = gh * bq
            U.append(Ui)
        ynew = y.copy()
        for j, a in enumerate(tab["a"][5]):
            ynew += a * U[j]
        ynew += U[5]
        sc = self.tol * (1.0 + np.maximum(np.abs(y), np.abs(ynew)))
        err = math.sqrt(float(np.mean((U[5] / sc) ** 2)))
        return ynew, err

    def time_derivative(self, t, y, f0):
        if self.res.autonomous:
            return None
        dt = 1e-7 * max(1.0, abs(t))
        f1 = np.empty_like(y)
        self.res.rhs(t + dt, y, f1)
        self.nrhs_q += 1
        return (f1 - f0) / dt


def solve(problem, t_end: float | None = None, tol: float = 1e-8, *, h0: float = 1e-4, stop_fraction: float = 0.5,
          t_end_max: float = 10.0, max_steps: int = 200000, refine: bool = True, records: bool = True,
          dt_fixed: float | None = None) -> dict:
    """Integrate ``problem`` with RODAS4 and banded O(N) stage solves (see the module).

    Runs to ``t_end``, or without it to the snap by the driver's rule (``v_max`` below
    ``stop_fraction`` of its running peak after the peak; at ``t_end_max`` at the latest).
    Returns a dict: the peaks ``v_peak, a_peak, sigma_peak`` and their times ``t_snap_v,
    t_snap_a, t_snap_sigma`` (located between steps when ``refine``), ``n_steps,
    n_rejected``, ``n_rhs`` (right-hand-side evaluations of the steps: 5 per attempted
    step, 1 per accepted step (its end, which starts the next), 2 at the start),
    ``n_rhs_extra`` (W/D directional derivatives and ``f_t``), ``n_rhs_refine`` (peak
    location; all evaluations: ``n_rhs + n_rhs_extra + n_rhs_refine``), ``n_jac``
    (Jacobians: 20 complex evaluations of the rows each), ``n_lu``
    (banded factorisations), ``n_solves`` (banded solves), ``wall``, ``t``, ``y`` (final
    state) and, with ``records``, ``rec``: an array (steps + 1, 7) of ``t, v_max, a_max,
    sigma_max, energy, W, D`` at the accepted steps. ``dt_fixed``: every step of that size,
    no error control (order studies).

    >>> from snapping.simulate import Body, Problem
    >>> from snapping.simulate import stiff
    >>> o = stiff.solve(Problem.catenary(0.25, 8, body=Body(bending=1e-3)), 0.1, 1e-6)
    >>> o["stop"], o["n_rhs"] == 5 * (o["n_steps"] + o["n_rejected"]) + o["n_steps"] + 2, round(o["t"], 12)
    ('t_end', True, 0.1)
    """
    mdl, y = body_model(problem)
    res = Residual(mdl)
    st = _Stepper(res, float(tol))
    N = res.N
    w0 = time.perf_counter()
    t = 0.0
    f = np.empty_like(y)
    res.rhs(t, y, f)
    m = res.measure(t, y)
    rec = [(t, *m)]
    best = [(m[q], 0) for q in range(3)]  # (value, index into hist)
    hist = [(t, y.copy(), None)]  # accepted states (t, y, D) -- D filled when the step from it is taken
    D = res.jacobian(t, y, f)
    st.njac += 1
    hist[0] = (t, y.copy(), D)
    h = float(h0 if dt_fixed is None else dt_fixed)
    nrej_row = 0
    vpeak = m[0]
    tstop = t_end if t_end is not None else t_end_max
    stopped = "t_end"
    bps = sorted(b for b in G.breakpoints(mdl) if 0.0 <= b < tstop)
    tl = t  # (the time the next step starts from: t, or its right limit at a breakpoint)
    while t < tstop:
        if st.nstep >= max_steps:
            stopped = "max_steps"
            break
        if t + h >= tstop:
            h = tstop - t
        nb = [b for b in bps if b > t]
        if nb and t + h > nb[0]:
            h = nb[0] - t  # (land on the held end's breakpoints)
        if t in bps and tl != np.nextafter(t, np.inf):  # a step from a breakpoint: its right limit
            tl = np.nextafter(t, np.inf)
            res.rhs(tl, y, f)
            D = res.jacobian(tl, y, f)
            st.njac += 1
            hist[-1] = (tl, y.copy(), D)
        ft = st.time_derivative(tl, y, f)
        ynew, err = st.step(tl, y, f, D, h, ft)
        if dt_fixed is not None:
            err = 0.0 if np.all(np.isfinite(ynew)) else math.inf
        if not (err <= 1.0) or not np.all(np.isfinite(ynew)):
            st.nrej += 1
            nrej_row += 1
            fac = 0.2 if not math.isfinite(err) else max(0.2, 0.9 * err ** -0.25)
            h *= fac
            if h < 1e-14:
                raise RuntimeError(f"stiff.solve: step size underflow at t={t}")
            continue
        fac = min(6.0, max(0.2, 0.9 * (max(err, 1e-10)) ** -0.25))
        if nrej_row:
            fac = min(fac, 1.0)
        nrej_row = 0
        t = t + h if t + h < tstop else tstop
        if nb and abs(t - nb[0]) <= 4e-16 * max(1.0, abs(t)):
            t = nb[0]
        tl = t
        y = ynew
        st.nstep += 1
        res.rhs(t, y, f)
        par, hh, invm, invh, snode, _ = mdl
        FR.forced_measure(N, t, y, res.c, res.s, res.sig, res.Z, res.rinv0, res.meas, par, hh, invm, invh, snode,
                          res.tab)
        mm = res.meas
        m = (mm[K.M_VMAX], mm[K.M_AMAX], mm[K.M_SIGMAX], mm[K.M_ENERGY], y[2 * N], y[2 * N + 1])
        D = res.jacobian(t, y, f)
        st.njac += 1
        hist.append((t, y.copy(), D))
        if records:
            rec.append((t, *m))
        for q in range(3):
            if m[q] > best[q][0]:
                best[q] = (m[q], len(hist) - 1)
        if m[0] > vpeak:
            vpeak = m[0]
        elif t_end is None and m[0] < stop_fraction * vpeak and best[0][1] > 0:
            stopped = "snap"
            break
        # keep only what a peak search can need: the bracket around each running best
        keep = {i for b in best for i in (b[1] - 1, b[1], b[1] + 1)} | {len(hist) - 1}
        for i in range(len(hist) - 1):
            if i not in keep and hist[i] is not None:
                hist[i] = None
        h = h * fac if dt_fixed is None else float(dt_fixed)
    nrhs_steps = res.nrhs
    nq_steps = st.nrhs_q
    out = {"n_steps": st.nstep, "n_rejected": st.nrej, "n_jac": st.njac, "n_lu": st.nlu, "n_solves": st.nsolve,
           "t": t, "y": y, "stop": stopped, "tol": tol, "N": N}
    names = ("v", "a", "sigma")
    for q in range(3):
        val, i = best[q]
        tq = hist[i][0]
        if refine and 0 < i < len(hist) - 1:
            val, tq = _locate(res, st, hist, i, q)
        out[f"{names[q]}_peak"] = float(val)
        out[f"t_snap_{names[q]}"] = float(tq)
    out["n_rhs_refine"] = res.nrhs - nrhs_steps
    out["n_rhs_extra"] = nq_steps
    out["n_rhs"] = nrhs_steps - nq_steps
    out["wall"] = time.perf_counter() - w0
    if records:
        out["rec"] = np.array(rec)
    return out


def _locate(res, st, hist, i, q):
    """Maximise quantity q on [t_{i-1}, t_{i+1}]: the state at t by one RODAS4 step from the
    accepted state before t (Brent's bounded search)."""
    (ta, ya, Da), (tb, yb, Db), (tc, _, _) = hist[i - 1], hist[i], hist[i + 1]
    fa = np.empty_like(ya)
    res.rhs(ta, ya, fa)
    fb = np.empty_like(yb)
    res.rhs(tb, yb, fb)

    def state(tt):
        if tt <= ta:
            return ya
        if tt <= tb:
            ys, ts, fs, Ds = ya, ta, fa, Da
        else:
            ys, ts, fs, Ds = yb, tb, fb, Db
        if tt == ts:
            return ys
        ft = st.time_derivative(ts, ys, fs)
        yn, _ = st.step(ts, ys, fs, Ds, tt - ts, ft)
        return yn

    def negq(tt):
        return -res.measure(tt, state(tt))[q]

    best_v, best_t = -negq(tb), tb
    r = minimize_scalar(negq, bounds=(ta, tc), method="bounded", options={"xatol": 1e-10 * max(1.0, tc)})
    if -r.fun > best_v:
        best_v, best_t = -r.fun, float(r.x)
    return best_v, best_t
