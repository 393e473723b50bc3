"""The link-angle equations with node forces (bending, drag, ...), compiled (numba).

The equations of :mod:`snapping.simulate.general` with arbitrary node forces ``F_j``
(j < N; a force on the held end is taken by it). Node j moves by
``m_j r_j'' = T_j t_j - T_{j-1} t_{j-1} + m_j g e2 + F_j``, so ``d_j'' = r_{j+1}'' - r_j''``
gains ``a^F_j = F_{j+1}/m_{j+1} - F_j/m_j`` (with ``F_N/m_N := 0``: for the held link
``d_{N-1}'' = A - r_{N-1}''`` gains ``-F_{N-1}/m_{N-1}``). Projected on ``t_j`` it moves to the
right-hand side of the tension rows, on ``n_j`` it adds to the angle rows::

    C_{j-1}/m_j T_{j-1} - (1/m_j + 1/m_{j+1}) T_j + C_j/m_{j+1} T_{j+1} = -h_j theta_j'^2 - a^F_j.t_j
    h_j theta_j'' = S_j T_{j+1}/m_{j+1} - S_{j-1} T_{j-1}/m_j + a^F_j.n_j

(the held row with ``E + a^F_{N-1}``, ``E = A - g e2``, where general has ``E``). The
system stays tridiagonal, symmetric and weakly diagonally dominant: Thomas's algorithm,
O(N), no allocation (scratch arrays live in the model's table, see below).

Force families, one module each, gathered in :func:`node_forces` (a new force is one
module and one call there): :mod:`snapping.simulate.force_bending` (bending stiffness,
natural curvature, Kelvin-Voigt damping, a clamped held end) and
:mod:`snapping.simulate.force_drag` (quadratic and linear drag, wind, a tip body).

Energy: the state is ``y = [theta (N), theta' (N), W, D]``: ``W`` the work done on the
chain by the held end, at the rate ``(T_{N-1} t_{N-1} - Q_{N-1}/h_{N-1} n_{N-1}).v_p +
M_N phi'`` (the force of the held end on the held link, whose bending couple lands on the
held end, and the clamp's torque times its rate of turn), and ``D`` the energy dissipated,
at the rate ``2R - sum_j F^drag_j.v_j`` (bending damping plus drag; the wind's work counts
negative). Then ``kinetic + gravity + V_b - W + D`` is constant; the measured ``energy`` of
such a run is ``kinetic + gravity + V_b`` and the stepper's energy check uses the balance.

Model: the tuple of :mod:`snapping.simulate.general` with ``par[P_KIND] = KIND_BODY``,
``par`` extended by the body's scalars (indices ``P_BOFF`` ...) and ``tab`` by the body
block at ``par[P_BOFF]``: ``NB_IN`` node arrays (``Bl, K0L, El, CN, CT, KN, KT``, N + 1
each), ``NB_SCR`` scratch node arrays (``FX, FY, VX, VY, MM, AN``), and the clamp's angle
table at ``par[P_CLOFF]`` (``t`` then the cubic coefficients) when it moves. Because the
scratch lives in the model, one model tuple serves one evaluation at a time (each engine
builds its own with :meth:`snapping.simulate.problem.Problem.model`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import angles as AG
from . import force_bending as FB
from . import force_drag as FD
from . import general as G
from . import kernels as K

__all__ = ["KIND_BODY", "make_body_model", "forced_rhs", "forced_measure", "node_forces", "clamp_angle",
           "M_BEND", "M_DISS", "NMEAS_B", "NREC_B", "RECORD_NAMES_B", "evaluate_rhs", "drag_power_gradient"]

KIND_BODY = G.KIND_BODY

# the body's scalars, after general's
(P_BOFF, P_HASBEND, P_HASDRAG, P_CLAMP, P_ALPHA, P_CNK, P_CLOFF, P_WX, P_WY, P_TIPCD) = range(G.NPAR, G.NPAR + 10)
NPAR_B = G.NPAR + 10
# node arrays of the body block, in order
(B_BL, B_K0L, B_EL, B_CN, B_CT, B_KN, B_KT, B_FX, B_FY, B_VX, B_VY, B_MM, B_AN) = range(13)
NB_IN = 7
NB_SCR = 6

# measurements and record columns beyond general's
M_BEND, M_DISS = G.NMEAS_G, G.NMEAS_G + 1
NMEAS_B = G.NMEAS_G + 2
RECORD_NAMES_B = ("bending_energy", "dissipated")
NREC_B = G.NREC_G + len(RECORD_NAMES_B)


def make_body_model(mdl, arrays: dict, *, clamped: bool = False, alpha: float = 0.0, clamp_table=None,
                    wind=(0.0, 0.0), tip_drag: float = 0.0):
    """The body model from a general model tuple and the body's node arrays (``arrays``: the
    names ``Bl, K0L, El, CN, CT, KN, KT``, N + 1 each, zero where absent). ``alpha``: the
    clamp's link angle (with ``clamp_table = (t, c)``, a cubic spline's knots and
    coefficients, added to it). No checks: :class:`snapping.simulate.body.Body` validates."""
    par, h, invm, invh, snode, tab = mdl
    N = h.size
    n1 = N + 1
    par2 = np.zeros(NPAR_B)
    par2[:G.NPAR] = par
    par2[G.P_KIND] = KIND_BODY
    block = np.zeros((NB_IN + NB_SCR) * n1)
    for k, name in enumerate(("Bl", "K0L", "El", "CN", "CT", "KN", "KT")):
        block[k * n1:(k + 1) * n1] = np.asarray(arrays.get(name, np.zeros(n1)), dtype=float)
    par2[P_BOFF] = tab.size
    par2[P_HASBEND] = float(bool(np.any(block[:3 * n1] != 0.0)) or clamped)
    par2[P_HASDRAG] = float(bool(np.any(block[3 * n1:NB_IN * n1] != 0.0)) or tip_drag != 0.0)
    par2[P_CLAMP] = float(clamped)
    par2[P_ALPHA] = alpha
    par2[P_WX], par2[P_WY] = float(wind[0]), float(wind[1])
    par2[P_TIPCD] = tip_drag
    parts = [tab, block]
    if clamp_table is not None:
        tt, cc = clamp_table
        tt = np.asarray(tt, dtype=float)
        par2[P_CNK] = tt.size
        par2[P_CLOFF] = tab.size + block.size
        parts.append(np.concatenate([tt, np.asarray(cc, dtype=float).ravel()]))
    return par2, h, invm, invh, snode, np.concatenate(parts)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def clamp_angle(t, par, tab):
    """(phi, phi') of the clamp at time t (a link angle): constant, or a cubic spline through
    samples (constant before the first and after the last)."""
    a = par[P_ALPHA]
    n = int(par[P_CNK])
    if n == 0:
        return a, 0.0
    o = int(par[P_CLOFF])
    m = n - 1
    if t <= tab[o]:
        i = 0
        u = 0.0
        outside = True
    elif t >= tab[o + n - 1]:
        i = m - 1
        u = tab[o + n - 1] - tab[o + i]
        outside = True
    else:
        i = np.searchsorted(tab[o:o + n], t) - 1
        if i < 0:
            i = 0
        u = t - tab[o + i]
        outside = False
    c0 = tab[o + n + i]
    c1 = tab[o + n + m + i]
    c2 = tab[o + n + 2 * m + i]
    c3 = tab[o + n + 3 * m + i]
    v = ((c0 * u + c1) * u + c2) * u + c3
    d = (3.0 * c0 * u + 2.0 * c1) * u + c2
    return a + v, (0.0 if outside else d)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def node_forces(N, t, y, c, s, par, h, invh, tab, pvx, pvy):
    """Gather every force family's node forces into the scratch ``FX, FY`` (zeroed first).
    Returns ``(p_clamp, diss, p_drag, Q_last)``: the clamp's power, the damping's
    dissipation rate, the drag's power and the held link's generalised force."""
    o = int(par[P_BOFF])
    n1 = N + 1
    FX = tab[o + B_FX * n1:o + (B_FX + 1) * n1]
    FY = tab[o + B_FY * n1:o + (B_FY + 1) * n1]
    for j in range(n1):
        FX[j] = 0.0
        FY[j] = 0.0
    pcl = 0.0
    diss = 0.0
    qlast = 0.0
    pdrag = 0.0
    if par[P_HASBEND] != 0.0:
        phi, phid = clamp_angle(t, par, tab)
        pcl, diss, qlast = FB.add_bending(N, y, c, s, invh, tab[o + B_BL * n1:o + (B_BL + 1) * n1],
                                          tab[o + B_K0L * n1:o + (B_K0L + 1) * n1],
                                          tab[o + B_EL * n1:o + (B_EL + 1) * n1], par[P_CLAMP] != 0.0, phi, phid,
                                          tab[o + B_MM * n1:o + (B_MM + 1) * n1], FX, FY)
    if par[P_HASDRAG] != 0.0:
        VX = tab[o + B_VX * n1:o + (B_VX + 1) * n1]
        VY = tab[o + B_VY * n1:o + (B_VY + 1) * n1]
        FD.node_velocities(N, y, c, s, h, pvx, pvy, VX, VY)
        pdrag = FD.add_drag(N, c, s, par[P_WX], par[P_WY], tab[o + B_CN * n1:o + (B_CN + 1) * n1],
                            tab[o + B_CT * n1:o + (B_CT + 1) * n1], tab[o + B_KN * n1:o + (B_KN + 1) * n1],
                            tab[o + B_KT * n1:o + (B_KT + 1) * n1], par[P_TIPCD], VX, VY, FX, FY)
    return pcl, diss, pdrag, qlast


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def drag_power_gradient(N, t, y, c, s, par, h, tab, g):
    """The gradient of the drag's power ``sum_j F^drag_j.v_j`` (the dissipation rate's drag
    part, ``D' = 2R - p``) in the state at fixed time t: ``g[:N] = dp/dtheta``, ``g[N:2N] =
    dp/domega`` (:func:`snapping.simulate.force_drag.drag_power_gradient`, exact, O(N)); the
    cos/sin of y's angles into ``c, s``, the node velocities into the table's scratch."""
    AG.sincos(N, y, c, s)
    _, _, pvx, pvy, _, _ = G.pin_kinematics(t, par, tab)
    o = int(par[P_BOFF])
    n1 = N + 1
    VX = tab[o + B_VX * n1:o + (B_VX + 1) * n1]
    VY = tab[o + B_VY * n1:o + (B_VY + 1) * n1]
    FD.node_velocities(N, y, c, s, h, pvx, pvy, VX, VY)
    FD.drag_power_gradient(N, y, c, s, h, par[P_WX], par[P_WY], tab[o + B_CN * n1:o + (B_CN + 1) * n1],
                           tab[o + B_CT * n1:o + (B_CT + 1) * n1], tab[o + B_KN * n1:o + (B_KN + 1) * n1],
                           tab[o + B_KT * n1:o + (B_KT + 1) * n1], par[P_TIPCD], VX, VY, g)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def forced_rhs(N, t, y, f, c, s, S, cp, dp, sig, par, h, invm, invh, snode, tab):
    """Derivative ``f = [theta', theta'', W', D']`` of ``y`` (length 2N + 2) at time t; leaves
    cos/sin in ``c``/``s``, ``S_j/m_{j+1}`` in ``S`` and the tensions in ``sig`` (as
    :func:`snapping.simulate.general.general_rhs`)."""
    AG.sincos(N, y, c, s)
    for j in range(N):
        f[j] = y[N + j]
    g = par[G.P_G]
    px, py, pvx, pvy, pax, pay = G.pin_kinematics(t, par, tab)
    pcl, diss, pdrag, qlast = node_forces(N, t, y, c, s, par, h, invh, tab, pvx, pvy)
    o = int(par[P_BOFF])
    n1 = N + 1
    FX = tab[o + B_FX * n1:o + (B_FX + 1) * n1]
    FY = tab[o + B_FY * n1:o + (B_FY + 1) * n1]
    AN = tab[o + B_AN * n1:o + (B_AN + 1) * n1]
    # forward elimination (Thomas), rows j = 0 .. N-2
    eprev = 0.0
    cprev = 0.0
    dprev = 0.0
    for j in range(N - 1):
        cj = c[j]
        sj = s[j]
        cn = c[j + 1]
        sn = s[j + 1]
        imn = invm[j + 1]
        im = invm[j]
        S[j] = (sn * cj - cn * sj) * imn
        afx = FX[j + 1] * imn - FX[j] * im
        afy = FY[j + 1] * imn - FY[j] * im
        AN[j] = cj * afy - sj * afx
        w = y[N + j]
        r = -h[j] * (w * w) - (afx * cj + afy * sj)
        e = (cn * cj + sn * sj) * imn
        inv = 1.0 / (-(im + imn) - eprev * cprev)
        cprev = e * inv
        dprev = (r - eprev * dprev) * inv
        cp[j] = cprev
        dp[j] = dprev
        eprev = e
    jl = N - 1
    cj = c[jl]
    sj = s[jl]
    afx = pax - FX[jl] * invm[jl]
    afy = (pay - g) - FY[jl] * invm[jl]
    AN[jl] = cj * afy - sj * afx
    w = y[N + jl]
    r = -h[jl] * (w * w) - (afx * cj + afy * sj)
    Tn = (r - eprev * dprev) / (-invm[jl] - eprev * cprev)
    sig[jl] = Tn
    for j in range(N - 2, -1, -1):
        sig[j] = dp[j] - cp[j] * sig[j + 1]
    for k in range(N):
        acc = AN[k]
        if k < N - 1:
            acc += S[k] * sig[k + 1]
        if k >= 1:
            acc -= S[k - 1] * sig[k - 1]
        f[N + k] = acc * invh[k]
    fq = qlast * invh[jl]
    f[2 * N] = (Tn * cj + fq * sj) * pvx + (Tn * sj - fq * cj) * pvy + pcl
    f[2 * N + 1] = diss - pdrag


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def forced_measure(N, t, y, c, s, sig, Z, rinv0, meas, par, h, invm, invh, snode, tab):
    """The diagnostics of :func:`snapping.simulate.general.general_measure` with the node
    forces in the accelerations and the force on the held end, ``energy`` = kinetic +
    gravity + bending, and ``meas[M_BEND]`` (bending energy), ``meas[M_DISS]`` (D)."""
    G.general_measure(N, t, y, c, s, sig, Z, rinv0, meas, par, h, invm, invh, snode, tab)
    pvx = Z[K.RVX, N]
    pvy = Z[K.RVY, N]
    pcl, diss, pdrag, qlast = node_forces(N, t, y, c, s, par, h, invh, tab, pvx, pvy)
    o = int(par[P_BOFF])
    n1 = N + 1
    FX = tab[o + B_FX * n1:o + (B_FX + 1) * n1]
    FY = tab[o + B_FY * n1:o + (B_FY + 1) * n1]
    amax2 = -1.0
    ia = 0
    for j in range(N):
        Z[K.RAX, j] += FX[j] * invm[j]
        Z[K.RAY, j] += FY[j] * invm[j]
        a2 = Z[K.RAX, j] ** 2 + Z[K.RAY, j] ** 2
        if a2 > amax2:
            amax2 = a2
            ia = j
    meas[K.M_AMAX] = math.sqrt(amax2)
    meas[K.M_SA] = snode[ia]
    meas[K.M_AEND] = math.sqrt(Z[K.RAX, 0] ** 2 + Z[K.RAY, 0] ** 2)
    fq = qlast * invh[N - 1]
    meas[K.M_PFX] += -fq * s[N - 1]
    meas[K.M_PFY] += fq * c[N - 1]
    vb = 0.0
    if par[P_HASBEND] != 0.0:
        phi, phid = clamp_angle(t, par, tab)
        vb = FB.bending_energy(N, y, tab[o + B_BL * n1:o + (B_BL + 1) * n1], tab[o + B_K0L * n1:o + (B_K0L + 1) * n1],
                               par[P_CLAMP] != 0.0, phi)
    meas[K.M_ENERGY] += vb
    meas[M_BEND] = vb
    meas[M_DISS] = y[2 * N + 1]
    tot = meas[K.M_ENERGY] + meas[K.M_AMAX] + y[2 * N + 1]
    if not (tot - tot == 0.0):
        meas[K.M_FINITE] = 0.0


def evaluate_rhs(t: float, y: np.ndarray, mdl) -> np.ndarray:
    """``[theta', theta'', W', D']`` at (t, y) from :func:`forced_rhs`, on a copy of the model's
    table (a numpy entry point for tests and linearisations; not the dense check, which is
    written independently in ``tests/test_bending_drag.py``)."""
    par, h, invm, invh, snode, tab = mdl
    N = h.size
    tab = tab.copy()
    f = np.empty(2 * N + 2)
    w = G.Work(N)
    forced_rhs(N, t, np.asarray(y, dtype=float), f, w.c, w.s, w.S, w.cp, w.dp, w.sig, par, h, invm, invh, snode,
               tab)
    return f
