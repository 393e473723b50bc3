"""The inextensible chain in space: link directions, the tridiagonal tension system, compiled.

N rigid links and N point masses in three dimensions: link lengths ``h_j``, node masses
``m_j`` (a tip mass is part of ``m_0``), gravity ``g = g ghat`` along any unit direction
``ghat`` (default ``(0, 1, 0)``: ``y`` grows downward, as in :mod:`snapping.simulate`), and
a held end (node N) that is fixed or moves as prescribed, ``r_p(t)`` with velocity ``v_p``
and acceleration ``A(t)`` (:mod:`snapping.spatial.motion3d`). Index j = 0 is the free end;
link j joins node j and node j + 1, ``d_j = r_{j+1} - r_j = h_j e_j`` with ``|e_j| = 1``.

Derivation (as :mod:`snapping.simulate.general`, with unit vectors in place of angles).
Node j moves by ``m_j r_j'' = T_j e_j - T_{j-1} e_{j-1} + m_j g`` (``T_{-1} = 0``), ``T_j``
the tension of link j. Write ``a_j = (T_j e_j - T_{j-1} e_{j-1})/m_j`` (node j's
acceleration less gravity). For a link j < N - 1, ``d_j'' = a_{j+1} - a_j`` (gravity
cancels); for the held link ``d_{N-1}'' = A - g - a_{N-1} = E - a_{N-1}`` with ``E = A - g``.
Differentiating ``|e_j|^2 = 1`` twice gives ``e_j . e_j'' = -|u_j|^2`` (``u_j = e_j'``), and
``e_j . d_j'' = h_j e_j . e_j''``. On ``e_j``, with ``C_j = e_j . e_{j+1}`` (the cosine
between neighbouring links; in the plane ``cos(theta_{j+1} - theta_j)``), these are the
tension rows::

    C_{j-1}/m_j T_{j-1} - (1/m_j + 1/m_{j+1}) T_j + C_j/m_{j+1} T_{j+1} = -h_j |u_j|^2
    C_{N-2}/m_{N-1} T_{N-2} - T_{N-1}/m_{N-1}                          = -h_{N-1} |u_{N-1}|^2 - E . e_{N-1}

symmetric (row j's coefficient of ``T_{j+1}`` and row j+1's of ``T_j`` are both
``C_j/m_{j+1}``), weakly diagonally dominant (``|C| <= 1``): ``-B^T M^{-1} B`` of the
constraint Jacobian B, solved by Thomas's elimination without pivoting in O(N). Then the
link accelerations are full vectors, ``e_j'' = d_j''/h_j``. The state is
``y = [e_x, e_y, e_z, u_x, u_y, u_z, W]`` (component-major, 6N + 1): ``W`` the work done by
the held end on the chain, ``W' = T_{N-1} e_{N-1} . v_p``, so that ``E(t) - W(t)`` is
conserved.

Keeping ``|e_j| = 1``. The rows make ``|e_j|^2 - 1`` and ``e_j . u_j`` constant under the
exact flow of this ODE on the manifold, but a Runge-Kutta step does not keep quadratic
invariants: each step leaves an error of the size of its local error (~tol), and these add
up over the steps (``e . u`` drifts, ``|e|`` drifts as its integral). So after every
accepted step the state is projected back (:func:`project`): ``e_j <- e_j/|e_j|``,
``u_j <- u_j - (e_j . u_j) e_j``, the orthogonal projection onto the manifold
``{|e_j| = 1, e_j . u_j = 0}`` in each link's coordinates. A projection after each step
keeps the method's order (Hairer, Lubich & Wanner, *Geometric Numerical Integration*,
Thm. IV.4.2: the projection moves the state by the local error's size), and it keeps every
link exactly ``h_j`` long to round-off. A parametrisation (two angles per link) would be
singular at its poles and need chart changes; four of six components per link is the price.

A planar state (``e_z = u_z = 0``, gravity and the held end's acceleration in the plane)
stays planar exactly: every ``z`` component of the right-hand side is a sum of products of
``z`` components, all zero, and the projection scales them.

Example
-------
>>> import numpy as np
>>> from snapping.spatial import chain3d as C
>>> N = 3
>>> mdl = C.make_model(np.full(N, 1 / N), np.full(N, float(N)))     # fixed end, g along +y
>>> y = np.zeros(6 * N + 1); y[N:2 * N] = -1.0                        # hanging straight down (e_y = -1), at rest
>>> w = C.Work(N); f = np.empty_like(y)
>>> C.rhs3d(N, 0.0, y, f, w.T, w.cp, w.dp, *mdl)
>>> np.round(w.T, 12).tolist()                                        # tension = weight below
[0.333333333333, 0.666666666667, 1.0]
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..simulate.general import BLOCK, _pow2_near
from . import forces3d as F3
# the held end's compiled motion and the layout of ``par`` (also importable from here: chain3d.pin3d, chain3d.P_BODY)
from .motion3d import (NPAR, P_AX, P_AY, P_AZ, P_BODY, P_GX, P_GY, P_GZ, P_NX, P_NY, P_NZ, P_PIN, P_T0, P_T1,
                       PIN_CIRCLE, PIN_FIXED, PIN_FLICK, PIN_PULL, PIN_TABLE, breakpoints, circle_data, pin3d,
                       table_data)

__all__ = ["Work", "make_model", "rhs3d", "measure3d", "project", "nodes_to_state", "state_to_nodes", "NMEAS",
           "MEAS_NAMES", "M_BEND", "M_DISS", "BODY_MEAS_NAMES", "nmeas"]

# ---------------------------------------------------------------- per-step measurements
(M_VMAX, M_AMAX, M_SIGMAX, M_VTIP, M_ATIP, M_ENERGY, M_WORK, M_LG, M_ZAMP, M_VZAMP, M_LINKERR, M_VREL,
 M_SV, M_FINITE) = range(14)
NMEAS = 14
#: names of the measurements (the columns of a 3D run's record after t, dt, err)
MEAS_NAMES = ("v_max", "a_max", "sigma_max", "v_end", "a_end", "energy", "pin_work", "angular_momentum_g",
              "z_amp", "vz_amp", "link_error", "v_rel_max", "s_v_max", "finite")
#: measurements of a run with a body (:mod:`snapping.spatial.forces3d`), after MEAS_NAMES
M_BEND, M_DISS = NMEAS, NMEAS + 1
BODY_MEAS_NAMES = ("bending_energy", "dissipated")


def nmeas(par) -> int:
    """The number of measurements of a model's runs (more with a body)."""
    return NMEAS + (len(BODY_MEAS_NAMES) if par[P_BODY] > 0.0 else 0)


class Work:
    """Work arrays of :func:`rhs3d` for N links: tensions ``T`` and Thomas's ``cp``, ``dp``."""

    def __init__(self, N: int):
        self.N = N
        self.T = np.zeros(N)
        self.cp = np.zeros(N)
        self.dp = np.zeros(N)


def make_model(h, invm, *, g=(0.0, 1.0, 0.0), pin=(PIN_FIXED, (0.0, 0.0, 0.0), 0.0, math.inf),
               normal=(0.0, 0.0, 1.0), body=None):
    """The model tuple ``(par, h, invm)`` of the compiled kernels (no checks: the
    :class:`snapping.spatial.starts3d.Problem3D` validates).

    ``g``: the gravity vector (magnitude times direction); ``pin = (kind, accel, t0, T[, data])``
    (:data:`PIN_FIXED`, :data:`PIN_PULL`: ``accel`` from t0 for T then constant velocity,
    :data:`PIN_FLICK`: ``accel sin(2 pi (t - t0)/T)`` for one period; :data:`PIN_CIRCLE` (T: its
    ramp) and :data:`PIN_TABLE` carry ``data`` (:func:`circle_data`, :func:`table_data`), which
    is appended to ``par`` after its scalars, its offset in ``par[P_AX]``); ``normal``: the unit
    normal of the reference plane whose out-of-plane amplitude is measured; ``body``: None
    (a chain), or the keywords of :func:`snapping.spatial.forces3d.extend_par` (``arrays``,
    ``signed``, ``wind``, ``tip_drag``): bending, damping and drag, appended after the pin's
    data, its offset in ``par[P_BODY]`` (0: no body); the model's state then has one
    component more (``D``, the energy dissipated).
    """
    kind, acc, t0, T, *data = pin
    data = np.asarray(data[0], dtype=float).ravel() if data and data[0] is not None else np.zeros(0)
    par = np.zeros(NPAR + data.size)
    par[P_GX:P_GZ + 1] = np.asarray(g, dtype=float)
    par[P_PIN] = kind
    par[P_AX:P_AZ + 1] = np.asarray(acc, dtype=float)
    if kind in (PIN_CIRCLE, PIN_TABLE):
        par[P_AX:P_AZ + 1] = (float(NPAR), 0.0, 0.0)  # (the offset of the pin's data block)
        par[NPAR:] = data
    par[P_T0], par[P_T1] = t0, T
    par[P_NX:P_NZ + 1] = np.asarray(normal, dtype=float)
    if body is not None:
        par[P_BODY] = float(par.size)  # (the offset of the body's block)
        par = F3.extend_par(par, np.size(h), **body)
    return par, np.ascontiguousarray(h, dtype=float), np.ascontiguousarray(invm, dtype=float)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _rows(N, y, h, invm, cp, dp, Ex, Ey, Ez):
    """The tension rows of :func:`rhs3d` without a body, ahead of the elimination (a loop
    that vectorises): ``cp_j`` the coupling ``(e_j . e_{j+1})/m_{j+1}`` (0 for the last
    link), ``dp_j`` the right-hand side ``-h_j |u_j|^2`` (less ``E . e`` for the last link);
    the same expressions as in :func:`rhs3d` (bit for bit)."""
    n3 = 3 * N
    ex = y[:N]
    ey = y[N:2 * N]
    ez = y[2 * N:n3]
    ux = y[n3:n3 + N]
    uy = y[n3 + N:n3 + 2 * N]
    uz = y[n3 + 2 * N:2 * n3]
    for j in range(N - 1):
        cp[j] = (ex[j] * ex[j + 1] + ey[j] * ey[j + 1] + ez[j] * ez[j + 1]) * invm[j + 1]
    for j in range(N):
        dp[j] = -h[j] * (ux[j] * ux[j] + uy[j] * uy[j] + uz[j] * uz[j])
    j = N - 1
    cp[j] = 0.0
    dp[j] -= Ex * ex[j] + Ey * ey[j] + Ez * ez[j]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _pass3(N, y, f, T, h, invm, Ex, Ey, Ez):
    """Pass 3 of :func:`rhs3d` without a body, the same expressions (bit for bit), one
    component at a time over slices, each link's two node accelerations formed afresh rather
    than carried over from the previous link (so that the loop vectorises)."""
    U = 3 * N
    for c in range(3):
        fo = f[U + c * N:U + (c + 1) * N]
        yo = y[c * N:(c + 1) * N]
        E = Ex if c == 0 else (Ey if c == 1 else Ez)
        if N == 1:
            fo[0] = (E - T[0] * yo[0] * invm[0]) * (1.0 / h[0])
            continue
        fo[0] = ((T[1] * yo[1] - T[0] * yo[0]) * invm[1] - T[0] * yo[0] * invm[0]) * (1.0 / h[0])
        for j in range(1, N - 1):
            Tm = T[j - 1]
            T0 = T[j]
            T1 = T[j + 1]
            fo[j] = ((T1 * yo[j + 1] - T0 * yo[j]) * invm[j + 1] - (T0 * yo[j] - Tm * yo[j - 1]) * invm[j]) * (1.0 / h[j])
        j = N - 1
        fo[j] = (E - (T[j] * yo[j] - T[j - 1] * yo[j - 1]) * invm[j]) * (1.0 / h[j])


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def rhs3d(N, t, y, f, T, cp, dp, par, h, invm):
    """Derivative ``f = [u, e'', W']`` of the state ``y`` (length 6N + 1) at time t; leaves the
    tensions in ``T``. Pass 1: the rows and Thomas's forward elimination; pass 2: back
    substitution; pass 3: node accelerations less gravity and ``e_j'' = d_j''/h_j``. Without a
    body the rows are formed ahead (:func:`_rows`) and pass 3 runs per component
    (:func:`_pass3`): the same expressions, loops that vectorise (7.5 us against 13.7 at
    N = 1000; ``benchmarks/bench_chain3d.py --parts cost``)."""
    n3 = 3 * N
    fo = f[:n3]  # (slices, here and in pass 3: the loops then vectorise)
    yo = y[n3:2 * n3]
    for i in range(n3):
        fo[i] = yo[i]
    px, py, pz, pvx, pvy, pvz, pax, pay, paz = pin3d(t, par)
    body = F3.has_body(par, int(par[P_BODY]))  # (a body: node forces F, their link accelerations a^F_j in the rows)
    pF = 0.0
    if body:
        pF, dD = F3.node_forces(N, y, par, int(par[P_BODY]), h, pvx, pvy, pvz, par[P_NX], par[P_NY], par[P_NZ])
        f[6 * N + 1] = dD
    Ex = pax - par[P_GX]
    Ey = pay - par[P_GY]
    Ez = paz - par[P_GZ]
    X = 0
    Y = N
    Z = 2 * N
    U = n3
    # ---- pass 1: row j: e_{j-1} T_{j-1} + b_j T_j + e_j T_{j+1} = r_j; Thomas's pivots as ratios of
    # leading minors p_j = b_j p_{j-1} - e_{j-1}^2 p_{j-2}, q_j = r_j p_{j-1} - e_{j-1} q_{j-1} (no
    # division in the recurrence; cp_j = e_j p_{j-1}/p_j, dp_j = q_j/p_j), rescaled by a power of two
    # every BLOCK rows (as snapping.simulate.general.general_rhs; the recurrences are homogeneous)
    eprev = 0.0
    pm = 1.0
    pmm = 0.0
    q = 0.0
    j0 = 0
    if not body:
        _rows(N, y, h, invm, cp, dp, Ex, Ey, Ez)
        while j0 < N:
            j1 = min(j0 + BLOCK, N)
            for j in range(j0, j1):
                e = cp[j]
                r = dp[j]
                b = -(invm[j] + invm[j + 1]) if j < N - 1 else -invm[j]
                p = b * pm - (eprev * eprev) * pmm
                q = r * pm - eprev * q
                inv = 1.0 / p
                cp[j] = e * pm * inv
                dp[j] = q * inv
                pmm = pm
                pm = p
                eprev = e
            sc = 1.0 / _pow2_near(pm)
            pm *= sc
            pmm *= sc
            q *= sc
            j0 = j1
    while j0 < N:
        j1 = min(j0 + BLOCK, N)
        for j in range(j0, j1):
            ux = y[U + X + j]
            uy = y[U + Y + j]
            uz = y[U + Z + j]
            r = -h[j] * (ux * ux + uy * uy + uz * uz)
            if body:
                fx, fy, fz = F3.link_accel(N, j, par, int(par[P_BODY]), invm)
                r -= fx * y[X + j] + fy * y[Y + j] + fz * y[Z + j]
            if j < N - 1:
                b = -(invm[j] + invm[j + 1])
                C = y[X + j] * y[X + j + 1] + y[Y + j] * y[Y + j + 1] + y[Z + j] * y[Z + j + 1]
                e = C * invm[j + 1]
            else:
                b = -invm[j]
                r -= Ex * y[X + j] + Ey * y[Y + j] + Ez * y[Z + j]
                e = 0.0
            p = b * pm - (eprev * eprev) * pmm
            q = r * pm - eprev * q
            inv = 1.0 / p
            cp[j] = e * pm * inv
            dp[j] = q * inv
            pmm = pm
            pm = p
            eprev = e
        sc = 1.0 / _pow2_near(pm)
        pm *= sc
        pmm *= sc
        q *= sc
        j0 = j1
    # ---- pass 2: back substitution
    Tn = dp[N - 1]
    T[N - 1] = Tn
    for j in range(N - 2, -1, -1):
        Tn = dp[j] - cp[j] * Tn
        T[j] = Tn
    # ---- pass 3: a_j = (T_j e_j - T_{j-1} e_{j-1})/m_j; e_j'' = (a_{j+1} - a_j)/h_j, held link (E - a)/h
    if not body:
        _pass3(N, y, f, T, h, invm, Ex, Ey, Ez)
    else:
        Tl = T[0]
        im = invm[0]
        ajx = Tl * y[X] * im
        ajy = Tl * y[Y] * im
        ajz = Tl * y[Z] * im
        for j in range(N - 1):
            im = invm[j + 1]
            T0 = T[j]
            T1 = T[j + 1]
            anx = (T1 * y[X + j + 1] - T0 * y[X + j]) * im
            any_ = (T1 * y[Y + j + 1] - T0 * y[Y + j]) * im
            anz = (T1 * y[Z + j + 1] - T0 * y[Z + j]) * im
            ih = 1.0 / h[j]
            f[U + X + j] = (anx - ajx) * ih
            f[U + Y + j] = (any_ - ajy) * ih
            f[U + Z + j] = (anz - ajz) * ih
            fx, fy, fz = F3.link_accel(N, j, par, int(par[P_BODY]), invm)
            f[U + X + j] += fx * ih
            f[U + Y + j] += fy * ih
            f[U + Z + j] += fz * ih
            ajx = anx
            ajy = any_
            ajz = anz
        j = N - 1
        ih = 1.0 / h[j]
        f[U + X + j] = (Ex - ajx) * ih
        f[U + Y + j] = (Ey - ajy) * ih
        f[U + Z + j] = (Ez - ajz) * ih
        fx, fy, fz = F3.link_accel(N, j, par, int(par[P_BODY]), invm)
        f[U + X + j] += fx * ih
        f[U + Y + j] += fy * ih
        f[U + Z + j] += fz * ih
    j = N - 1
    f[6 * N] = T[j] * (y[X + j] * pvx + y[Y + j] * pvy + y[Z + j] * pvz)
    if body:
        f[6 * N] -= pF


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def project(N, y):
    """Put the state back on the manifold: ``e_j <- e_j/|e_j|``, ``u_j <- u_j - (e_j.u_j) e_j``."""
    U = 3 * N
    for j in range(N):
        ex = y[j]
        ey = y[N + j]
        ez = y[2 * N + j]
        inv = 1.0 / math.sqrt(ex * ex + ey * ey + ez * ez)
        ex *= inv
        ey *= inv
        ez *= inv
        y[j] = ex
        y[N + j] = ey
        y[2 * N + j] = ez
        d = ex * y[U + j] + ey * y[U + N + j] + ez * y[U + 2 * N + j]
        y[U + j] -= d * ex
        y[U + N + j] -= d * ey
        y[U + 2 * N + j] -= d * ez


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def measure3d(N, t, y, T, meas, snode, par, h, invm):
    """Per-step diagnostics of the state y at t (``T``: its tensions, as left by :func:`rhs3d`):
    largest node speed (and the arclength of its node from the held end), acceleration and
    tension; the free end's speed and acceleration; the energy
    ``sum m_j (|v_j|^2/2 - g . r_j)``; the held end's work ``W``; the angular momentum about
    the held end along gravity, ``sum m_j ((r_j - r_p) x v_j) . ghat``; the out-of-plane
    amplitude ``max_j |(r_j - r_p) . nhat|`` and speed ``max_j |v_j . nhat|`` (``nhat``: the
    model's normal); the largest link error ``| |e_j| - 1 |``; the largest node speed
    relative to the held end; whether everything is finite."""
    px, py, pz, pvx, pvy, pvz, pax, pay, paz = pin3d(t, par)
    gx = par[P_GX]
    gy = par[P_GY]
    gz = par[P_GZ]
    gn = math.sqrt(gx * gx + gy * gy + gz * gz)
    ghx, ghy, ghz = (gx / gn, gy / gn, gz / gn) if gn > 0.0 else (0.0, 0.0, 0.0)
    nx = par[P_NX]
    ny = par[P_NY]
    nz = par[P_NZ]
    U = 3 * N
    # walk from the held end: relative position q_j = r_j - r_p, velocity v_j
    qx = 0.0
    qy = 0.0
    qz = 0.0
    vx = pvx
    vy = pvy
    vz = pvz
    vmax2 = 0.0
    iv = N
    vrel2 = 0.0
    ke = 0.0
    pe = 0.0
    lg = 0.0
    zamp = 0.0
    vzamp = 0.0
    lerr = 0.0
    for j in range(N - 1, -1, -1):
        ex = y[j]
        ey = y[N + j]
        ez = y[2 * N + j]
        hj = h[j]
        qx -= hj * ex
        qy -= hj * ey
        qz -= hj * ez
        vx -= hj * y[U + j]
        vy -= hj * y[U + N + j]
        vz -= hj * y[U + 2 * N + j]
        m = 1.0 / invm[j]
        v2 = vx * vx + vy * vy + vz * vz
        if v2 > vmax2:
            vmax2 = v2
            iv = j
        w2 = (vx - pvx) ** 2 + (vy - pvy) ** 2 + (vz - pvz) ** 2
        if w2 > vrel2:
            vrel2 = w2
        ke += m * v2
        pe -= m * (gx * (qx + px) + gy * (qy + py) + gz * (qz + pz))
        lg += m * (ghx * (qy * vz - qz * vy) + ghy * (qz * vx - qx * vz) + ghz * (qx * vy - qy * vx))
        za = abs(qx * nx + qy * ny + qz * nz)
        if za > zamp:
            zamp = za
        vza = abs(vx * nx + vy * ny + vz * nz)
        if vza > vzamp:
            vzamp = vza
        le = abs(math.sqrt(ex * ex + ey * ey + ez * ez) - 1.0)
        if le > lerr:
            lerr = le
    body = F3.has_body(par, int(par[P_BODY]))
    if body:  # (the body's node forces at this state, into the model's scratch)
        F3.node_forces(N, y, par, int(par[P_BODY]), h, pvx, pvy, pvz, nx, ny, nz)
    # accelerations a_j = (T_j e_j - T_{j-1} e_{j-1} + F_j)/m_j + g
    amax2 = 0.0
    smax = -np.inf
    atip = 0.0
    for j in range(N):
        Tj = T[j]
        sx = Tj * y[j]
        sy = Tj * y[N + j]
        sz = Tj * y[2 * N + j]
        if j > 0:
            Tm = T[j - 1]
            sx -= Tm * y[j - 1]
            sy -= Tm * y[N + j - 1]
            sz -= Tm * y[2 * N + j - 1]
        if body:
            fx, fy, fz = F3.node_force(N, j, par, int(par[P_BODY]))
            sx += fx
            sy += fy
            sz += fz
        im = invm[j]
        ax = sx * im + gx
        ay = sy * im + gy
        az = sz * im + gz
        a2 = ax * ax + ay * ay + az * az
        if a2 > amax2:
            amax2 = a2
        if j == 0:
            atip = math.sqrt(a2)
        if Tj > smax:
            smax = Tj
    meas[M_VMAX] = math.sqrt(vmax2)
    meas[M_SV] = snode[iv]
    meas[M_AMAX] = math.sqrt(amax2)
    meas[M_SIGMAX] = smax
    meas[M_VTIP] = math.sqrt(vx * vx + vy * vy + vz * vz)
    meas[M_ATIP] = atip
    meas[M_ENERGY] = 0.5 * ke + pe
    if body:
        vb = F3.bending_energy(N, y, par, int(par[P_BODY]), nx, ny, nz)
        meas[M_ENERGY] += vb
        meas[M_BEND] = vb
        meas[M_DISS] = y[6 * N + 1]
    meas[M_WORK] = y[6 * N]
    meas[M_LG] = lg
    meas[M_ZAMP] = zamp
    meas[M_VZAMP] = vzamp
    meas[M_LINKERR] = lerr
    meas[M_VREL] = math.sqrt(vrel2)
    tot = ke + pe + amax2 + smax + lg + y[6 * N]
    if body:
        tot += meas[M_ENERGY] + y[6 * N + 1]
    meas[M_FINITE] = 1.0 if (tot - tot) == 0.0 else 0.0


def nodes_to_state(r, v, h) -> np.ndarray:
    """The state ``[e, u, W = 0]`` of node positions ``r`` and velocities ``v`` ((N + 1, 3)
    each, row N the held end): ``e_j`` the unit chord, ``u_j`` the chord's relative velocity
    over ``h_j`` with its component along ``e_j`` removed (a rigid link cannot stretch)."""
    r = np.asarray(r, dtype=float)
    v = np.asarray(v, dtype=float)
    d = np.diff(r, axis=0)
    e = d / np.linalg.norm(d, axis=1)[:, None]
    u = np.diff(v, axis=0) / np.asarray(h, dtype=float)[:, None]
    u -= np.sum(u * e, axis=1)[:, None] * e
    return np.concatenate([e.T.ravel(), u.T.ravel(), [0.0]])


def state_to_nodes(y, h, pin=(0.0,) * 6):
    """Node positions and velocities ((N + 1, 3) each, row N the held end at ``pin[:3]`` with
    velocity ``pin[3:6]``) of the state y."""
    h = np.asarray(h, dtype=float)
    N = h.size
    e = y[:3 * N].reshape(3, N).T
    u = y[3 * N:6 * N].reshape(3, N).T
    r = np.zeros((N + 1, 3))
    v = np.zeros((N + 1, 3))
    r[N] = pin[:3]
    v[N] = pin[3:6]
    r[:N] = r[N] - np.cumsum((h[:, None] * e)[::-1], axis=0)[::-1]
    v[:N] = v[N] - np.cumsum((h[:, None] * u)[::-1], axis=0)[::-1]
    return r, v
