"""The compiled RODAS4 step loop of the stiff method (``method="rodas4"``, alias ``"stiff"``).

The method and the banded stage solves are those of :mod:`snapping.simulate.stiff` (the
Python reference, :func:`snapping.simulate.stiff.solve`) and
:mod:`snapping.simulate.stiff_system` (the rows, their derivatives, the
stage matrix in LAPACK band storage): here they are one numba loop (:func:`advance_rodas`)
that shares the bookkeeping of every accepted step with DOP853
(:func:`snapping.simulate.rk.after_attempt_with`: records, peaks, invariants, the stop
rules), so the two methods differ only in how a step is taken.

A step (Hairer and Wanner, *Solving ODEs II*, sec. VI.4, ``rodas.f``): the Jacobian at the
step's start (:func:`jacobian_at`, once per accepted step: ten real forward-mode
derivatives of the compiled rows, one per colour and variable, equal to the complex steps
of :mod:`snapping.simulate.stiff_system` to rounding), the banded stage matrix of lower
bandwidth 5 and upper 4 factored by Gaussian elimination with partial pivoting
(:func:`band_lu`, O(N); loops of fixed length, the reciprocal pivots kept for the
solves), six stages (five new evaluations; a stage's solve is one fused pass for its right
side and one forward and one column-wise back substitution), the error
estimate ``U_6`` in the max norm of DOP853 (``|U_6,i| / (tol (1 + max(|y_i|, |y_new,i|)))``; an
angular velocity's scale floored at the roundoff of its estimate, :func:`omega_floor`), the new
state, and on acceptance one evaluation there (the next step's ``f``). The
continuous extension of order 3 (``rodas.f``'s CONTRO: ``y(t0 + s h) = (1 - s) y0 + s (y1 +
(1 - s)(c2 + s c3))`` with ``c2, c3`` fixed combinations of ``U_1 .. U_5``) gives the state
between steps at no cost (:func:`dense_eval`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import forced as FR
from . import general as G
from . import models as MD
from . import rk as R
from . import stiff as ST
from .stiff import RODAS4
from . import stiff_system as SS
from .stiff_system import colour_link

from .banded import IDIAG, KL, KU, WROW, _band_solve_stage, band_lu, band_solve  # noqa: F401 (re-exported)

#: the colours, written out here: numba bakes module constants into this module's cached
#: machine code, which is keyed on this file alone (a change in stiff_system must change
#: this file too, or the import fails)
NCOL = 5
if NCOL != SS.NCOL:  # pragma: no cover - a guard for editors
    raise ImportError("rosenbrock's NCOL differs from stiff_system's: update both")

__all__ = ["band_lu", "band_solve", "assemble", "WROW", "rodas_step", "advance_rodas", "dense_eval", "jacobian_at",
           "NSTG",
           "ERR_EXPONENT", "MAX_FACTOR", "D2", "D3", "omega_floor", "ROUND"]

GAMMA = RODAS4["gamma"]
C_NODE = np.array(RODAS4["c"])
D_TIME = np.array(RODAS4["d"])
A_ST = np.zeros((6, 6))
C_ST = np.zeros((6, 6))
for _i in range(6):
    for _j, _v in enumerate(RODAS4["a"][_i]):
        A_ST[_i, _j] = _v
    for _j, _v in enumerate(RODAS4["C"][_i]):
        C_ST[_i, _j] = _v
#: the dense output's weights of U_1 .. U_5 (rodas.f, METH = 1: D21 .. D25, D31 .. D35)
D2 = np.array([10.12623508344586, -7.487995877610167, -34.80091861555747, -7.992771707568823, 1.025137723295662])
D3 = np.array([-0.6762803392801253, 6.087714651680015, 16.43084320892478, 24.76722511418386, -6.594389125716872])
#: the unit roundoff of the error norm's floor (:func:`omega_floor`; twice the double's eps),
#: written out here as NCOL is (numba bakes it into this module's cache)
ROUND = 4.440892098500626e-16
if ROUND != ST.ROUND:  # pragma: no cover - a guard for editors
    raise ImportError("rosenbrock's ROUND differs from stiff's: update both")
#: the step-size rule of an error estimate of order 3 (rodas.f: at most 6x larger)
ERR_EXPONENT = -0.25
MAX_FACTOR = 6.0
#: rows of a step slot's stage array: f at the start, U_1 .. U_6, f at the end
NSTG = 8
S_F0, S_F1 = 0, 7
#: the engine's counters (``cnt``): Jacobians, factorisations, evaluations of the W/D rows'
#: differences and of f_t (in n_rhs too), singular stage matrices
(CN_JAC, CN_LU, CN_EXTRA, CN_SING) = range(4)
NCNT = 4
#: the flags of ``rp``: clamped, bending, W/D have dynamics, their rows by differences, autonomous,
#: drag (with RP_QUAD and not RP_QFD: the dissipation row's drag part by its exact gradient), the
#: stage solves corrected once for what the banded Jacobian leaves out (drag: :func:`_stage_correct`)
(RP_CLAMP, RP_BEND, RP_QUAD, RP_QFD, RP_AUTO, RP_DRAG, RP_DCORR) = range(7)
NRP = 7


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def assemble(N, D, gh, A):
    """The stage matrix (:func:`stiff_system._assemble`) stored by rows for :func:`band_lu`:
    row i, column j at ``A[i, j - i + KL]``; the rest of A zeroed."""
    for i in range(A.shape[0]):
        for d in range(A.shape[1]):
            A[i, d] = 0.0
    gh2 = gh * gh
    k = 0
    for lk in range(N):  # (column by column, as _stage_solve)
        for i in range(max(0, 2 * lk - 4), min(2 * N, 2 * lk + 6)):
            A[i, 2 * lk - i + KL] = D[2, k, i] + gh2 * D[0, k, i] + gh * D[1, k, i]
            A[i, 2 * lk + 1 - i + KL] = D[3, k, i]
        k += 1
        if k == NCOL:
            k = 0


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _rows_tangent(N, var, d, om, T, h, invm, invm_next, invh, Bl, El, clamped, hasbend, C0, S0, Cd0, Sd0, fq, afx,
                  afy, dM, dFX, dFY, out):
    """The derivative of the rows (:func:`stiff_system._rows`) at fixed a and T along the
    direction ``d`` of the angles (``var`` 0) or of the angular velocities (``var`` 1), by
    the chain rule in real arithmetic (forward mode: what the complex step of ``_rows``
    computes in its imaginary parts), from the base point's ``fq`` (the bending moments'
    differences over the link lengths) and ``afx, afy`` (the node forces' accelerations)."""
    th_dir = var == 0
    for i in range(N + 1):
        dM[i] = 0.0
        dFX[i] = 0.0
        dFY[i] = 0.0
    if hasbend:
        cf = Bl if th_dir else El
        for i in range(1, N):
            dM[i] = cf[i] * (d[i] - d[i - 1])
        if clamped:
            dM[N] = -cf[N] * d[N - 1]
        for j in range(N):
            dfq = (dM[j + 1] - dM[j]) * invh[j]
            if th_dir:
                gx = -(C0[j] * d[j] * fq[j] + S0[j] * dfq)
                gy = -S0[j] * d[j] * fq[j] + C0[j] * dfq
            else:
                gx = -S0[j] * dfq
                gy = C0[j] * dfq
            dFX[j + 1] += gx
            dFY[j + 1] += gy
            dFX[j] -= gx
            dFY[j] -= gy
    for j in range(N):
        cj = C0[j]
        sj = S0[j]
        dafx = dFX[j + 1] * invm_next[j] - dFX[j] * invm[j]
        dafy = dFY[j + 1] * invm_next[j] - dFY[j] * invm[j]
        if th_dir:
            dj = d[j]
            drt = dafx * cj - afx[j] * sj * dj + dafy * sj + afy[j] * cj * dj
            dra = -(cj * dafy - sj * dj * afy[j] - sj * dafx - cj * dj * afx[j])
            if j < N - 1:
                e = (d[j + 1] - dj) * invm[j + 1] * T[j + 1]
                drt -= Sd0[j] * e
                dra -= Cd0[j] * e
            if j > 0:
                e = (dj - d[j - 1]) * invm[j] * T[j - 1]
                drt -= Sd0[j - 1] * e
                dra += Cd0[j - 1] * e
        else:
            drt = 2.0 * h[j] * om[j] * d[j] + dafx * cj + dafy * sj
            dra = -(cj * dafy - sj * dafx)
        out[2 * j] = dra
        out[2 * j + 1] = drt


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def jacobian_at(N, t, y, f, sig, Dj, mdl, barr, rp):
    """The coloured banded derivatives of the rows (:meth:`stiff_system.Residual.jacobian`)
    at (t, y) with the accelerations ``f[N:2N]`` and tensions ``sig`` of y, into ``Dj``:
    ``dR/dtheta`` and ``dR/domega`` along the five colours of each (:func:`_rows_tangent`:
    the chain rule in real arithmetic, equal to the complex steps of ``_rows`` to rounding),
    ``dR/da`` and ``dR/dT`` in closed form (the rows are linear in a and T, and the node
    forces depend on neither)."""
    par, h, invm, invh, snode, tab = mdl
    phi = 0.0
    phid = 0.0
    if rp[RP_CLAMP] != 0.0:
        phi, phid = FR.clamp_angle(t, par, tab)
    _, _, _, _, pax, pay = G.pin_kinematics(t, par, tab)
    payg = pay - par[G.P_G]
    invm_next = barr[3, :N]
    Bl = barr[0]
    K0L = barr[1]
    El = barr[2]
    th = y[:N]
    om = y[N:2 * N]
    C0 = np.cos(th)
    S0 = np.sin(th)
    Cd0 = np.cos(y[1:N] - y[:N - 1])
    Sd0 = np.sin(y[1:N] - y[:N - 1])
    clamped = rp[RP_CLAMP] != 0.0
    hasbend = rp[RP_BEND] != 0.0
    # the base point: bending moments, node forces and their accelerations (as _rows)
    Mb = np.zeros(N + 1)
    FX = np.zeros(N + 1)
    FY = np.zeros(N + 1)
    fq = np.zeros(N)
    if hasbend:
        for i in range(1, N):
            Mb[i] = Bl[i] * ((th[i] - th[i - 1]) - K0L[i]) + El[i] * (om[i] - om[i - 1])
        if clamped:
            Mb[N] = Bl[N] * ((phi - th[N - 1]) - K0L[N]) + El[N] * (phid - om[N - 1])
        for j in range(N):
            fq[j] = (Mb[j + 1] - Mb[j]) * invh[j]
            FX[j + 1] += -S0[j] * fq[j]
            FY[j + 1] += C0[j] * fq[j]
            FX[j] -= -S0[j] * fq[j]
            FY[j] -= C0[j] * fq[j]
    afx = np.empty(N)
    afy = np.empty(N)
    for j in range(N):
        afx[j] = FX[j + 1] * invm_next[j] - FX[j] * invm[j]
        afy[j] = FY[j + 1] * invm_next[j] - FY[j] * invm[j]
    afx[N - 1] += pax
    afy[N - 1] += payg
    dM = np.empty(N + 1)
    dFX = np.empty(N + 1)
    dFY = np.empty(N + 1)
    d = np.zeros(N)
    out = np.empty(2 * N)
    for v in range(2):
        for k in range(NCOL):
            for j in range(k, N, NCOL):
                d[j] = 1.0
            _rows_tangent(N, v, d, om, sig, h, invm, invm_next, invh, Bl, El, clamped, hasbend, C0, S0, Cd0, Sd0, fq,
                          afx, afy, dM, dFX, dFY, out)
            for i in range(2 * N):
                Dj[v, k, i] = out[i]
            for j in range(k, N, NCOL):
                d[j] = 0.0
    for v in range(2, 4):
        for k in range(NCOL):
            for i in range(2 * N):
                Dj[v, k, i] = 0.0
    k = 0
    for j in range(N):  # link j has colour k = j mod 5
        Dj[2, k, 2 * j] = h[j]  # angle row: h_j a_j
        Dj[3, k, 2 * j + 1] = -(invm[j] + invm_next[j])  # tension row: its own tension
        k += 1
        if k == NCOL:
            k = 0
    for j in range(N - 1):  # row j against T_{j+1} (colour of j + 1), row j + 1 against T_j (colour of j)
        kn = (j + 1) % NCOL
        kj = j % NCOL
        Dj[3, kn, 2 * j] = -Sd0[j] * invm[j + 1]
        Dj[3, kn, 2 * j + 1] = Cd0[j] * invm[j + 1]
        Dj[3, kj, 2 * j + 2] = Sd0[j] * invm[j + 1]
        Dj[3, kj, 2 * j + 3] = Cd0[j] * invm[j + 1]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _stage_solve(N, Dj, gh, ab, piv, b, U, rhs, tmp):
    """The angle part of ``(I/(gamma h) - J) U = b`` (:meth:`stiff_system.StageMatrix.solve`):
    the right side ``gh [R_theta (b_theta + gh b_omega) + R_omega b_omega]`` in one pass over
    the links (the two coloured products with the columns of ``Dj``, fused), then the banded solve."""
    for i in range(2 * N):
        rhs[i] = 0.0
    D0 = Dj[0]
    D1 = Dj[1]
    k = 0
    for l in range(N):
        zl = gh * b[N + l]
        xl = gh * (b[l] + zl)
        if 2 <= l and l + 3 <= N:
            i0 = 2 * l - 4
            for d in range(10):
                rhs[i0 + d] += D0[k, i0 + d] * xl + D1[k, i0 + d] * zl
        else:
            for i in range(max(0, 2 * l - 4), min(2 * N, 2 * l + 6)):
                rhs[i] += D0[k, i] * xl + D1[k, i] * zl
        k += 1
        if k == NCOL:
            k = 0
    _band_solve_stage(ab, 2 * N, piv, rhs)
    for j in range(N):
        uom = gh * (b[N + j] - rhs[2 * j])
        U[N + j] = uom
        U[j] = gh * (b[j] + uom)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _rhs_along(N, t, y0, U, ytmp, tmp, c, s, S, cp, dp, sig, mdl):
    """The right side into ``tmp`` at ``y0`` moved along the angle part of ``U`` (its first 2N rows)
    by the step of the forward differences along U, ``dl = 1e-7 (1 + rms(y0)) / rms(U)`` (rms over the
    2N rows), in ``ytmp``; returns ``dl``, or -1.0 without evaluating when ``rms(U)`` is not > 0."""
    n = y0.shape[0]
    n2 = 2 * N
    nu = 0.0
    ny = 0.0
    for i in range(n2):
        nu += U[i] * U[i]
        ny += y0[i] * y0[i]
    nu = math.sqrt(nu / n2)
    if not nu > 0.0:
        return -1.0
    dl = 1e-7 * (1.0 + math.sqrt(ny / n2)) / nu
    for i in range(n):
        ytmp[i] = y0[i] + dl * U[i] if i < n2 else y0[i]
    MD.model_rhs(N, t, ytmp, tmp, c, s, S, cp, dp, sig, mdl)
    return dl


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _stage_correct(N, t, y0, f0, Dj, gh, ab, piv, b, U, ytmp, rhs, tmp, c, s, S, cp, dp, sig, mdl):
    """One defect correction of the angle part of a stage ``U`` solved with the banded Jacobian
    (which leaves drag out, :func:`jacobian_at`): ``J U`` by one forward difference of the right
    side along U at the step's start (the scaling of the W/D rows' differences), the residual of
    the exact stage equation ``r = b - (U/(gamma h) - J U)``, and ``U += S_b^{-1} r`` by one more
    banded solve (no new factorisation). Returns the evaluations made (0 or 1)."""
    n2 = 2 * N
    dl = _rhs_along(N, t, y0, U, ytmp, tmp, c, s, S, cp, dp, sig, mdl)
    if dl < 0.0:
        return 0
    for j in range(N):  # (the residual into tmp: theta rows, then omega rows with J U's acceleration part)
        tmp[N + j] = b[N + j] - (U[N + j] / gh - (tmp[N + j] - f0[N + j]) / dl)
        tmp[j] = b[j] - (U[j] / gh - U[N + j])
    _stage_solve(N, Dj, gh, ab, piv, tmp, ytmp, rhs, tmp)
    for i in range(n2):
        U[i] += ytmp[i]
    return 1


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def omega_floor(N, j, Dj, y, hl):
    """The roundoff floor of the error estimate of link j's angular velocity (the error
    norm's scale of that component is ``max(tol (1 + |omega_j|), floor)``): rounding the
    angles and angular velocities of a state to doubles (``eps |theta_l|``, ``eps
    |omega_l|``) moves link j's acceleration by ``eps S_j`` with ``S_j = sum_l |da_j/dtheta_l|
    |theta_l| + |da_j/domega_l| |omega_l|``, and a stage solve passes at most ``1/(c_j + 2
    sqrt(k_j))`` of it to omega_j (``k_j = sum_l |da_j/dtheta_l|``, ``c_j = sum_l
    |da_j/domega_l|``: the local stiffness and damping; the largest gamma h / (1 + c gamma h + k
    (gamma h)^2) over h). The derivatives are the angle row's (``da_j/dx_l = -(dR_2j/dx_l)/h_j``,
    the tension coupling left out), from the step's Jacobian ``Dj``. It is ~eps |theta|
    sqrt(k), i.e. eps |theta| omega_max for the shortest bending wave: far below tol on
    ordinary chains (at the catenary, N = 100 and 1000, beta = 1e-2: 2e-12 and 2e-10 with grid
    damping, twice that without), but ~2e-6 on a link of 1.7e-7 with beta = 7.2e-8, where no step
    size brings the estimate below tol = 1e-7 (``tests/test_tiplinks.py``)."""
    s = 0.0
    kth = 0.0
    kom = 0.0
    for k in range(NCOL):
        lk = colour_link(j, k)
        if 0 <= lk < N:
            a0 = abs(Dj[0, k, 2 * j])
            a1 = abs(Dj[1, k, 2 * j])
            kth += a0
            kom += a1
            s += a0 * abs(y[lk]) + a1 * abs(y[N + lk])
    ih = 1.0 / hl[j]
    den = kom * ih + 2.0 * math.sqrt(kth * ih)
    return ROUND * s * ih / den if den > 0.0 else 0.0


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def rodas_step(N, t, h, y0, y1, St, ft, Dj, ab, piv, ytmp, btmp, rhs, tmp, c, s, S, cp, dp, sig, tol, mdl, barr, rp,
               cnt):
    """One RODAS4 step of size h from (t, y0) with ``St[S_F0] = f(t, y0)``, the Jacobian
    ``Dj`` there and (non-autonomous problems) ``ft`` the time derivative of f: the stages
    ``U_1 .. U_6`` into ``St[1:7]``, the new state into ``y1``. Returns the scaled error in
    the max norm (NaN or inf: a failed step), and the number of evaluations it made."""
    n = y0.shape[0]
    n2 = 2 * N
    gh = GAMMA * h
    nev = 0
    assemble(N, Dj, gh, ab)
    cnt[CN_LU] += 1.0
    if band_lu(ab, n2, KL, KU, piv) != 0:
        cnt[CN_SING] += 1.0
        return np.inf, nev
    f0 = St[S_F0]
    ch = np.empty(6)
    par, hh, invm, invh, snode, tab = mdl
    El = barr[2]
    # the drag's power gradient at the step's start (the dissipation row's stage terms, exact)
    dexact = rp[RP_QUAD] != 0.0 and rp[RP_QFD] == 0.0 and rp[RP_DRAG] != 0.0
    gq = np.empty(n2 if dexact else 0)
    if dexact:
        FR.drag_power_gradient(N, t, y0, c, s, par, hh, tab, gq)
    for st in range(6):
        U = St[1 + st]
        if st == 0:
            for i in range(n):
                btmp[i] = f0[i]
        else:
            for i in range(n):
                acc = y0[i]
                for j in range(st):
                    acc += A_ST[st, j] * St[1 + j, i]
                ytmp[i] = acc
            MD.model_rhs(N, t + C_NODE[st] * h, ytmp, btmp, c, s, S, cp, dp, sig, mdl)
            nev += 1
            for j in range(st):  # (the divisions once per stage, not per component)
                ch[j] = C_ST[st, j] / h
            for i in range(n):
                acc = btmp[i]
                for j in range(st):
                    acc += ch[j] * St[1 + j, i]
                btmp[i] = acc
        if rp[RP_AUTO] == 0.0 and D_TIME[st] != 0.0:
            dh = D_TIME[st] * h
            for i in range(n):
                btmp[i] += dh * ft[i]
        _stage_solve(N, Dj, gh, ab, piv, btmp, U, rhs, tmp)
        if rp[RP_DCORR] != 0.0:
            k = _stage_correct(N, t, y0, f0, Dj, gh, ab, piv, btmp, U, ytmp, rhs, tmp, c, s, S, cp, dp, sig, mdl)
            nev += k
            cnt[CN_EXTRA] += float(k)
        bw = btmp[n2]
        bd = btmp[n2 + 1]
        if rp[RP_QUAD] != 0.0 and rp[RP_QFD] == 0.0:  # dD'/dx U_x, exact (W' = 0)
            acc = 0.0
            for j in range(1, N):
                acc += El[j] * (y0[N + j] - y0[N + j - 1]) * (U[N + j] - U[N + j - 1])
            bd += 2.0 * acc
            if rp[RP_CLAMP] != 0.0:
                _, phid = FR.clamp_angle(t, par, tab)
                bd -= 2.0 * El[N] * (phid - y0[n2 - 1]) * U[n2 - 1]
            if dexact:  # D' = 2R - p: minus the drag power's gradient along U_x
                acc = 0.0
                for i in range(n2):
                    acc += gq[i] * U[i]
                bd -= acc
        elif rp[RP_QUAD] != 0.0:  # by one forward difference along U_x
            dl = _rhs_along(N, t, y0, U, ytmp, tmp, c, s, S, cp, dp, sig, mdl)
            if not dl < 0.0:
                nev += 1
                cnt[CN_EXTRA] += 1.0
                bw += (tmp[n2] - f0[n2]) / dl
                bd += (tmp[n2 + 1] - f0[n2 + 1]) / dl
        U[n2] = gh * bw
        U[n2 + 1] = gh * bd
    err = 0.0
    for i in range(n):
        acc = y0[i]
        for j in range(5):
            acc += A_ST[5, j] * St[1 + j, i]
        y1[i] = acc + St[6, i]
    for i in range(n):
        sc = tol * (1.0 + max(abs(y0[i]), abs(y1[i])))
        e = abs(St[6, i]) / sc
        if not (e - e == 0.0):
            return np.inf, nev
        if e > err:
            if N <= i < n2:  # (the roundoff floor only where it could set the maximum: the same max)
                e = abs(St[6, i]) / max(sc, omega_floor(N, i - N, Dj, y0, hh))
            if e > err:
                err = e
    return err, nev


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def dense_eval(x, y0, y1, St, out):
    """The continuous extension of order 3 at the fraction x in [0, 1] of a step."""
    n = y0.shape[0]
    for i in range(n):
        c2 = 0.0
        c3 = 0.0
        for j in range(5):
            c2 += D2[j] * St[1 + j, i]
            c3 += D3[j] * St[1 + j, i]
        out[i] = y0[i] * (1.0 - x) + x * (y1[i] + (1.0 - x) * (c2 + x * c3))


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def time_derivative(N, t, y, f0, ft, ytmp, c, s, S, cp, dp, sig, mdl):
    """``ft = (f(t + dt, y) - f0)/dt``, dt = 1e-7 max(1, |t|) (a moving held end or clamp)."""
    dt = 1e-7 * max(1.0, abs(t))
    MD.model_rhs(N, t + dt, y, ft, c, s, S, cp, dp, sig, mdl)
    for i in range(y.shape[0]):
        ft[i] = (ft[i] - f0[i]) / dt


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def advance_rodas(N, Y0, Y1, KK, TS, HS, DOK, ytmp, c, s, S, cp, dp, sig, Z, rinv0, ctl, rec, pk, meas, mdl,
                  Dj, ab, piv, btmp, rhs, tmp, ft, barr, rp, cnt):
    """Advance the chain with RODAS4 until something needs Python (the return codes and
    the two step slots of :func:`snapping.simulate.rk.advance_rk`; ``KK[slot]`` holds f at
    the step's start, its stages ``U_1 .. U_6`` and f at its end). ``Dj`` is the Jacobian
    at the current state (taken after every accepted step, and again at the right limit
    of a breakpoint of the held end's motion)."""
    n = Y0.shape[1]
    tol = ctl[R.Q_TOL]
    ctl[R.Q_NCALL] = 0.0
    while True:
        sl = int(ctl[R.Q_SLOT])
        ns = 1 - sl
        h, last = R.step_size(ctl)
        y0 = Y0[ns]
        ycur = Y1[sl]
        for i in range(n):
            y0[i] = ycur[i]
        t = ctl[R.Q_T]
        extra = 0.0
        if t == ctl[R.Q_LASTBRK]:
            # a step from a breakpoint of the held end's motion: f and J just after it
            t = np.nextafter(t, np.inf)
            MD.model_rhs(N, t, y0, KK[ns, S_F0], c, s, S, cp, dp, sig, mdl)
            extra += 1.0
            jacobian_at(N, t, y0, KK[ns, S_F0], sig, Dj, mdl, barr, rp)
            cnt[CN_JAC] += 1.0
        else:
            for i in range(n):
                KK[ns, S_F0, i] = KK[sl, S_F1, i]
        if rp[RP_AUTO] == 0.0:
            time_derivative(N, t, y0, KK[ns, S_F0], ft, ytmp, c, s, S, cp, dp, sig, mdl)
            extra += 1.0
            cnt[CN_EXTRA] += 1.0
        err, nev = rodas_step(N, t, h, y0, Y1[ns], KK[ns], ft, Dj, ab, piv, ytmp, btmp, rhs, tmp, c, s, S, cp, dp,
                              sig, tol, mdl, barr, rp, cnt)
        extra += float(nev)
        if R.accepted(err):
            tn = ctl[R.Q_TEND] if last else ctl[R.Q_T] + h
            # f at the new state (the next step's first stage; c, s, sig then belong to it)
            MD.model_rhs(N, tn, Y1[ns], KK[ns, S_F1], c, s, S, cp, dp, sig, mdl)
            extra += 1.0
            jacobian_at(N, tn, Y1[ns], KK[ns, S_F1], sig, Dj, mdl, barr, rp)
            cnt[CN_JAC] += 1.0
        code = R.after_attempt_with(N, err, h, last, ns, Y1[ns], TS, HS, DOK, c, s, sig, Z, rinv0, ctl, rec, pk,
                                    meas, mdl, ERR_EXPONENT, MAX_FACTOR, extra)
        if code >= 0:
            return code
