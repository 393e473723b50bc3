"""The link-angle equations of a general chain, compiled (numba, ``cache=True``).

Any planar chain of N rigid links and N point masses: link lengths ``h_j``, node masses
``m_j`` (a tip mass is part of ``m_0``), gravity ``g e2`` of any magnitude (``y`` grows
downward), and a held end (node N) that is fixed or moves as prescribed, ``r_p(t)``
with velocity ``v_p`` and acceleration ``A(t)``. Index j = 0 is the free end; link j
joins node j and node j + 1 with ``d_j = r_{j+1} - r_j = h_j t_j``,
``t_j = (cos theta_j, sin theta_j)``, ``n_j = (-sin theta_j, cos theta_j)``.

Derivation (the rows of :mod:`snapping.simulate.angles` generalised). Node j moves by
``m_j r_j'' = T_j t_j - T_{j-1} t_{j-1} + m_j g e2`` (``T_{-1} = 0``), with ``T_j`` the
tension of link j. For a link j < N - 1, ``d_j'' = r_{j+1}'' - r_j''``
``= T_{j+1} t_{j+1}/m_{j+1} - T_j t_j (1/m_j + 1/m_{j+1}) + T_{j-1} t_{j-1}/m_j``, while
``d_j = h_j t_j`` gives ``d_j'' = h_j (theta_j'' n_j - theta_j'^2 t_j)``. On ``t_j``
(``C_j = t_{j+1}.t_j = cos(theta_{j+1} - theta_j)``) these are the tension rows, on ``n_j``
(``S_j = t_{j+1}.n_j = sin(theta_{j+1} - theta_j)``) the angular accelerations::

    C_{j-1}/m_j T_{j-1} - (1/m_j + 1/m_{j+1}) T_j + C_j/m_{j+1} T_{j+1} = -h_j theta_j'^2
    h_j theta_j'' = S_j T_{j+1}/m_{j+1} - S_{j-1} T_{j-1}/m_j

For the held link (j = N - 1), ``d_{N-1}'' = A - r_{N-1}''``, so with ``E = A - g e2``::

    C_{N-2}/m_{N-1} T_{N-2} - T_{N-1}/m_{N-1} = -h_{N-1} theta_{N-1}'^2 - E.t_{N-1}
    h_{N-1} theta_{N-1}'' = E.n_{N-1} - S_{N-2} T_{N-2}/m_{N-1}

The system is symmetric (row j's coefficient of ``T_{j+1}`` and row j+1's of ``T_j`` are
both ``C_j/m_{j+1}``) and weakly diagonally dominant, ``-B^T M^{-1} B`` of the constraint
Jacobian B, so the Thomas elimination is stable: O(N), no allocation. With
``h_j = m_j = 1/N``, ``g = 1`` and a fixed pin it is the paper's chain
(:func:`snapping.simulate.angles.angle_rhs`, whose tensions are the same ``T_j``).

The held end does work on the chain at the rate ``P = T_{N-1} t_{N-1}.v_p`` (the force
of the held link on the chain, times the velocity of the held end). It is integrated with
the state, as a last component ``W``, so that the energy balance ``E(t) - W(t) = E(0)``
is a conservation law the stepper can be checked against (``W = 0`` for a fixed pin).

Layout: the state is ``y = [theta (N), theta' (N), W]`` (length 2N + 1); the model is a
tuple ``mdl = (par, h, invm, invh, snode, tab)`` of float64 arrays built by
:meth:`snapping.simulate.problem.Problem.model`: scalar parameters (indices ``P_*``),
link lengths, inverse node masses, inverse link lengths, the arclength of each node
from the held end, and the pin-motion table. ``par[P_KIND] == KIND_UNIFORM`` marks the paper's chain, for which
:func:`snapping.simulate.models.model_rhs` and :func:`~snapping.simulate.models.model_measure` call the uniform kernels of
:mod:`snapping.simulate.angles` unchanged (bit for bit the runs of before).

Pin motions (``par[P_PIN]``): ``PIN_FIXED``; ``PIN_PULL``: acceleration ``(ax, ay)`` from
``t0`` for a duration ``T`` (``inf``: for ever), then constant velocity; ``PIN_FLICK``:
acceleration ``(ax, ay) sin(2 pi (t - t0)/T)`` for one period (C^2 everywhere; the end is
displaced by ``(ax, ay) T^2/(2 pi)`` and at rest again); ``PIN_TABLE``: a cubic spline
through samples of ``r_p(t)`` (``tab = [t_i, x coefficients, y coefficients]``), then
constant velocity after the last sample.

Example
-------
>>> import numpy as np
>>> from snapping.simulate import general as G
>>> N = 3
>>> h = np.full(N, 1 / N); invm = np.full(N, float(N))
>>> mdl = G.make_model(h, invm)                        # fixed pin, g = 1
>>> y = np.zeros(2 * N + 1); y[:N] = -np.pi / 2         # hanging straight down, at rest
>>> w = G.Work(N); f = np.empty(2 * N + 1)
>>> G.general_rhs(N, 0.0, y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, *mdl)
>>> np.round(w.sig, 12).tolist()                        # tension = weight below
[0.333333333333, 0.666666666667, 1.0]
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import angles as AG
from . import kernels as K

#: rows between power-of-two rescalings of the leading minors (node masses within a factor
#: 1e12 of each other keep them far from overflow: |p_j/p_{j-1}| <= 2 max(1/m), and a block
#: stays inside the range of :func:`_pow2_near` while 2 max(1/m) < 2^60 and min(1/m) > 2^-63)
BLOCK = 16
#: 2^52 + 1: Veltkamp's splitting constant that keeps one significant bit (:func:`_pow2_near`)
_SPLIT1 = 4503599627370497.0
#: array indices in the hot loops of :func:`general_rhs` are cast to this unsigned type:
#: numba indexes with a signed integer through a wraparound select (negative counts from the
#: end), which costs integer work, a register for each array's length and spills in loops
#: that touch ten arrays; an unsigned index is used as it is (the indices here are >= 0)
_U = np.uint64

__all__ = [
    "Work", "make_model", "general_rhs", "general_measure", "pin_kinematics",
    "general_to_Z", "NMEAS_G", "NREC_G", "M_PX", "M_PY", "M_PVX", "M_PVY", "M_WORK", "M_VREL", "M_KIN", "KAPPA_TIP_JOINTS", "RECORD_NAMES_G",
    "settle_time",
]

# ---------------------------------------------------------------- the model's scalar parameters
P_KIND, P_G, P_PIN, P_AX, P_AY, P_T0, P_T1, P_NKNOT, P_EOFF = range(9)
NPAR = 9
KIND_UNIFORM, KIND_GENERAL = 0.0, 1.0
#: a chain with node forces (bending, drag): :mod:`snapping.simulate.forced`, state ``[theta, theta', W, D]``
KIND_BODY = 2.0
PIN_FIXED, PIN_PULL, PIN_FLICK, PIN_TABLE = 0.0, 1.0, 2.0, 3.0

# ---------------------------------------------------------------- measurements beyond kernels.NMEAS
M_PX, M_PY, M_PVX, M_PVY, M_WORK, M_VREL, M_KIN = range(K.NMEAS, K.NMEAS + 7)
NMEAS_G = K.NMEAS + 7
#: record columns beyond kernels.RECORD_NAMES (the same quantities as M_PX .. M_KIN)
RECORD_NAMES_G = ("pin_x", "pin_y", "pin_vx", "pin_vy", "pin_work", "v_rel_max", "kappa_max_interior")
#: ``kappa_max_interior`` (``M_KIN``) leaves out the joints fewer than this many links from the free end:
#: there the discrete chain has a boundary layer in the node index, not in arclength (measured,
#: docs/guide/regimes.md "The curvature peak"): at its first joint the turning angle over the mean link
#: is 1.29x the curvature a few joints in at every resolution (ideal chain, chi 0.3, 284 to 1968 links),
#: the excess falling as ~0.18/k^2 at the k-th joint (0.3% at the 8th)
KAPPA_TIP_JOINTS = 8
NREC_G = K.NREC + len(RECORD_NAMES_G)

TWO_PI = 2.0 * math.pi


class Work:
    """Work arrays of :func:`general_rhs` for N links (as :class:`snapping.simulate.angles.Work`)."""

    def __init__(self, N: int):
        self.N = N
        self.c = np.zeros(N)
        self.s = np.zeros(N)
        self.S = np.zeros(max(N - 1, 1))
        self.cp = np.zeros(N)
        self.dp = np.zeros(N)
        self.sig = np.zeros(N)


def make_model(h, invm, *, g: float = 1.0, pin=(PIN_FIXED, 0.0, 0.0, 0.0, math.inf), table=None,
               uniform: bool = False):
    """The model tuple ``(par, h, invm, invh, snode, tab)`` of the compiled kernels (no checks:
    :class:`snapping.simulate.problem.Problem` validates and calls this).

    ``pin = (kind, ax, ay, t0, T)`` for the presets; ``table = (t, cx, cy)`` with ``cx``,
    ``cy`` of shape (4, n - 1) the cubic coefficients (scipy ``CubicSpline.c``) for
    ``PIN_TABLE``.
    """
    h = np.ascontiguousarray(h, dtype=float)
    invm = np.ascontiguousarray(invm, dtype=float)
    N = h.size
    snode = np.zeros(N + 1)
    snode[:N] = np.cumsum(h[::-1])[::-1]  # node j: sum of the links between it and the held end
    par = np.zeros(NPAR)
    par[P_KIND] = KIND_UNIFORM if uniform else KIND_GENERAL
    par[P_G] = g
    kind, ax, ay, t0, T = pin
    par[P_PIN], par[P_AX], par[P_AY], par[P_T0], par[P_T1] = kind, ax, ay, t0, T
    if table is not None:
        tt, cx, cy = table
        tt = np.asarray(tt, dtype=float)
        par[P_NKNOT] = tt.size
        tab = np.concatenate([tt, np.asarray(cx, dtype=float).ravel(), np.asarray(cy, dtype=float).ravel()])
    else:
        tab = np.zeros(1)
    par[P_EOFF] = g * float(np.sum(snode[:N] / invm))
    return par, h, invm, 1.0 / h, snode, tab


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _spline(tab, n, off, i, u):
    """Value, first and second derivative of the cubic piece i at local time u."""
    m = n - 1
    c0 = tab[off + i]
    c1 = tab[off + m + i]
    c2 = tab[off + 2 * m + i]
    c3 = tab[off + 3 * m + i]
    return ((c0 * u + c1) * u + c2) * u + c3, (3.0 * c0 * u + 2.0 * c1) * u + c2, 6.0 * c0 * u + 2.0 * c1


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def pin_kinematics(t, par, tab):
    """(x, y, vx, vy, ax, ay) of the held end at time t.

    At a breakpoint (:func:`breakpoints`, where the acceleration jumps) this is the left
    limit, what a step that ends there uses; a step that starts there evaluates at
    ``nextafter(t, inf)``, the right limit (as :meth:`snapping.simulate.pin.PinMotion.kinematics`
    reports the motion at t)."""
    kind = par[P_PIN]
    if kind == PIN_FIXED:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    ax = par[P_AX]
    ay = par[P_AY]
    t0 = par[P_T0]
    T = par[P_T1]
    if kind == PIN_PULL:
        if t <= t0:
            return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        tau = t - t0
        if t <= t0 + T:  # (not tau <= T: the breakpoint t0 + T is where the pull ends, as breakpoints() says)
            q = 0.5 * tau * tau
            return ax * q, ay * q, ax * tau, ay * tau, ax, ay
        q = 0.5 * T * T + T * (tau - T)
        return ax * q, ay * q, ax * T, ay * T, 0.0, 0.0
    if kind == PIN_FLICK:
        if t <= t0:
            return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        tau = min(t - t0, T)
        w = TWO_PI / T
        sn = math.sin(w * tau)
        cs = math.cos(w * tau)
        v = (1.0 - cs) / w
        r = (tau - sn / w) / w
        a = sn if t < t0 + T else 0.0
        return ax * r, ay * r, ax * v, ay * v, ax * a, ay * a
    # PIN_TABLE: cubic pieces on [t_i, t_{i+1}], constant velocity after the last knot
    n = int(par[P_NKNOT])
    m = n - 1
    if t <= tab[0]:  # (t = 0: the first piece's start; before it, its tangent)
        x, vx, axx = _spline(tab, n, n, 0, 0.0)
        y, vy, ayy = _spline(tab, n, n + 4 * m, 0, 0.0)
        if t == tab[0]:
            return x, y, vx, vy, axx, ayy
        dt = t - tab[0]
        return x + vx * dt, y + vy * dt, vx, vy, 0.0, 0.0
    if t > tab[n - 1]:  # (at the last knot itself: the last piece's end, the left limit)
        i = m - 1
        u = tab[n - 1] - tab[i]
        x, vx, _ = _spline(tab, n, n, i, u)
        y, vy, _ = _spline(tab, n, n + 4 * m, i, u)
        dt = t - tab[n - 1]
        return x + vx * dt, y + vy * dt, vx, vy, 0.0, 0.0
    i = np.searchsorted(tab[:n], t) - 1
    if i < 0:
        i = 0
    u = t - tab[i]
    x, vx, axx = _spline(tab, n, n, i, u)
    y, vy, ayy = _spline(tab, n, n + 4 * m, i, u)
    return x, y, vx, vy, axx, ayy


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy", inline="always")
def _pow2_near(x):
    """The power of two nearest x, with x's sign (x rounded to one significant bit by
    Veltkamp's splitting; exact in round-to-nearest for 2^-1022 <= |x| < 2^970): a few
    inlined flops where ``math.frexp``/``math.ldexp`` are two calls into the runtime."""
    v = x * _SPLIT1
    return v - (v - x)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def general_rhs(N, t, y, f, c, s, S, cp, dp, sig, par, h, invm, invh, snode, tab):
    """Derivative ``f = [theta', theta'', W']`` of the state ``y`` (length 2N + 1) at time t.

    Leaves cos/sin of the angles in ``c``/``s``, ``S_j/m_{j+1}`` in ``S`` (both terms of
    ``h_k theta_k''`` are such a product times a tension) and the tensions in ``sig``.
    Pass 0: trigonometry; pass 1: coefficients and the forward elimination with Thomas's
    pivots as ratios of leading minors, ``p_j = b_j p_{j-1} - e_{j-1}^2 p_{j-2}`` and
    ``q_j = r_j p_{j-1} - e_{j-1} q_{j-1}`` (no division in the recurrence, so that the
    divisions ``1/p_j`` pipeline; as :func:`snapping.simulate.angles.angle_rhs`), rescaled
    by a power of two every ``BLOCK`` rows (any power of two: the recurrences are
    homogeneous in (p, q), so the results do not depend on which, to the bit); pass 2:
    back substitution fused with the angular accelerations. The loops index with unsigned
    integers (``_U``), which numba uses without its wraparound select.
    """
    AG.sincos(N, y, c, s)
    for jj in range(N):
        f[_U(jj)] = y[_U(N + jj)]
    g = par[P_G]
    px, py, pvx, pvy, pax, pay = pin_kinematics(t, par, tab)
    ex = pax
    ey = pay - g
    jl = N - 1
    if N == 1:
        w = y[1]
        T = (h[0] * w * w + ex * c[0] + ey * s[0]) / invm[0]
        sig[0] = T
        f[1] = (ey * c[0] - ex * s[0]) / h[0]
        f[2] = T * (c[0] * pvx + s[0] * pvy)
        return
    # ---- pass 1: rows j = 0 .. N-2, e_{j-1} T_{j-1} + b_j T_j + e_j T_{j+1} = r_j
    eprev = 0.0  # e_{j-1} = C_{j-1}/m_j
    im = invm[0]
    pm = 1.0
    pmm = 0.0
    q = 0.0
    j0 = 0
    while j0 < N - 1:
        j1 = min(j0 + BLOCK, N - 1)
        for jj in range(j0, j1):
            i = _U(jj)  # (row j = jj)
            i1 = _U(jj + 1)
            cj = c[i]
            sj = s[i]
            cn = c[i1]
            sn = s[i1]
            C = cn * cj + sn * sj
            imn = invm[i1]
            S[i] = (sn * cj - cn * sj) * imn
            w = y[_U(N + jj)]
            r = -h[i] * (w * w)
            p = -(im + imn) * pm - (eprev * eprev) * pmm
            q = r * pm - eprev * q
            e = C * imn
            inv = 1.0 / p
            cp[i] = e * pm * inv
            dp[i] = q * inv
            pmm = pm
            pm = p
            eprev = e
            im = imn
        sc = 1.0 / _pow2_near(pm)  # (exact: the reciprocal of a power of two)
        pm *= sc
        pmm *= sc
        q *= sc
        j0 = j1
    # last row (the held link): e_{N-2} T_{N-2} - T_{N-1}/m_{N-1} = r
    w = y[N + jl]
    r = -h[jl] * (w * w) - (ex * c[jl] + ey * s[jl])
    p = -invm[jl] * pm - (eprev * eprev) * pmm
    q = r * pm - eprev * q
    Tn = q / p
    sig[jl] = Tn
    f[2 * N] = Tn * (c[jl] * pvx + s[jl] * pvy)
    # ---- pass 2: back substitution; theta'' of link j + 1 once T_j is known
    j = N - 2  # (link j + 1 = N - 1 is the held link)
    Tj = dp[j] - cp[j] * Tn
    sig[j] = Tj
    f[N + jl] = ((ey * c[jl] - ex * s[jl]) - S[j] * Tj) * invh[jl]
    Tnn = Tn  # T_{j+2}
    Tn = Tj
    for jj in range(N - 3, -1, -1):
        i = _U(jj)  # (row j = jj; link k = jj + 1)
        i1 = _U(jj + 1)
        Tj = dp[i] - cp[i] * Tn
        sig[i] = Tj
        f[_U(N + jj + 1)] = (S[i1] * Tnn - S[i] * Tj) * invh[i1]
        Tnn = Tn
        Tn = Tj
    f[N] = S[0] * Tnn * invh[0]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def general_to_Z(N, t, y, c, s, sig, Z, par, h, invm, invh, snode, tab):
    """Fill the (7, N + 1) position-form state Z (x, y, vx, vy, ax, ay, tension) from the
    state y with its c, s, sig (as left by :func:`general_rhs`); column N is the held end."""
    g = par[P_G]
    px, py, pvx, pvy, pax, pay = pin_kinematics(t, par, tab)
    Z[K.RX, N] = px
    Z[K.RY, N] = py
    Z[K.RVX, N] = pvx
    Z[K.RVY, N] = pvy
    Z[K.RAX, N] = pax
    Z[K.RAY, N] = pay
    Z[K.RSIG, N] = 0.0
    x = px
    yy = py
    vx = pvx
    vy = pvy
    for j in range(N - 1, -1, -1):
        hj = h[j]
        w = y[N + j] * hj
        x -= c[j] * hj
        yy -= s[j] * hj
        vx += s[j] * w
        vy -= c[j] * w
        Z[K.RX, j] = x
        Z[K.RY, j] = yy
        Z[K.RVX, j] = vx
        Z[K.RVY, j] = vy
        Z[K.RSIG, j] = sig[j]
    for j in range(N):
        sx = sig[j] * c[j]
        sy = sig[j] * s[j]
        if j > 0:
            sx -= sig[j - 1] * c[j - 1]
            sy -= sig[j - 1] * s[j - 1]
        Z[K.RAX, j] = invm[j] * sx
        Z[K.RAY, j] = invm[j] * sy + g


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def general_measure(N, t, y, c, s, sig, Z, rinv0, meas, par, h, invm, invh, snode, tab):
    """The per-step diagnostics of :func:`snapping.simulate.kernels.measure` for a general
    chain (``meas`` of length :data:`NMEAS_G`): maxima of speed, acceleration, tension and
    curvature (turning angle over the mean of the two adjacent link lengths) with the
    arclength of their node from the held end, the free end's speed and acceleration, the
    force of the chain on the held end (``-T_{N-1} t_{N-1}``), the energy
    ``sum m_j (|v_j|^2/2 - g y_j) + g sum m_j s_j`` (zero hanging at rest from the origin),
    link errors ``| |t_j| - 1 |``, the length, the held end's position, velocity and
    work done on the chain (``y[2N]``), and the largest node speed relative to the held end
    ``max_j |v_j - v_p|`` (what the stop rule judges, :func:`settle_time`). ``rinv0`` is
    unused (links are exact)."""
    general_to_Z(N, t, y, c, s, sig, Z, par, h, invm, invh, snode, tab)
    g = par[P_G]
    vmax2 = -1.0
    iv = 0
    amax2 = -1.0
    ia = 0
    ke = 0.0
    pe = 0.0
    fin = 0.0
    pvx = Z[K.RVX, N]
    pvy = Z[K.RVY, N]
    vrel2 = 0.0
    for i in range(N):
        vx = Z[K.RVX, i]
        vy = Z[K.RVY, i]
        axx = Z[K.RAX, i]
        ayy = Z[K.RAY, i]
        v2 = vx * vx + vy * vy
        a2 = axx * axx + ayy * ayy
        mi = 1.0 / invm[i]
        ke += mi * v2
        pe += mi * Z[K.RY, i]
        fin += a2
        if v2 > vmax2:
            vmax2 = v2
            iv = i
        w2 = (vx - pvx) * (vx - pvx) + (vy - pvy) * (vy - pvy)
        if w2 > vrel2:
            vrel2 = w2
        if a2 > amax2:
            amax2 = a2
            ia = i
    smax = -np.inf
    smin = np.inf
    jmin = 0
    emax = 0.0
    length = 0.0
    for j in range(N):
        if sig[j] > smax:
            smax = sig[j]
        if sig[j] < smin:
            smin = sig[j]
            jmin = j
        ln = math.sqrt(c[j] * c[j] + s[j] * s[j])
        e = abs(ln - 1.0)
        if e > emax:
            emax = e
        length += h[j] * ln
    # curvature: turning angle phi_j at node j + 1 over (h_j + h_{j+1})/2; phi from atan2 only
    # where its bound pi/2 |sin phi| (cos phi > 0) can beat the best so far (kin: the best at
    # the joints at least KAPPA_TIP_JOINTS links from the free end)
    kbest = -1.0
    ik = -1
    kin = -1.0
    for j in range(N - 1):
        C = c[j + 1] * c[j] + s[j + 1] * s[j]
        Sn = abs(s[j + 1] * c[j] - c[j + 1] * s[j])
        hb = 2.0 / (h[j] + h[j + 1])
        if C > 0.0 and 0.5 * math.pi * Sn * hb <= kbest and (j + 1 < KAPPA_TIP_JOINTS or 0.5 * math.pi * Sn * hb <= kin):
            continue
        kap = math.atan2(Sn, C) * hb
        if kap > kbest:
            kbest = kap
            ik = j
        if j + 1 >= KAPPA_TIP_JOINTS and kap > kin:
            kin = kap
    L = snode[0]
    meas[K.M_VMAX] = math.sqrt(vmax2)
    meas[K.M_SV] = snode[iv]
    meas[K.M_AMAX] = math.sqrt(amax2)
    meas[K.M_SA] = snode[ia]
    meas[K.M_SIGMAX] = smax
    meas[K.M_SIGMIN] = smin
    meas[K.M_SSIGMIN] = 0.5 * (snode[jmin] + snode[jmin + 1])  # the midpoint of link jmin
    if ik >= 0:
        meas[K.M_KMAX] = kbest
        meas[K.M_SK] = snode[ik + 1]
    else:
        meas[K.M_KMAX] = 0.0
        meas[K.M_SK] = np.nan
    meas[M_KIN] = kin if kin >= 0.0 else np.nan  # (NaN: a chain of fewer than KAPPA_TIP_JOINTS + 1 links)
    meas[K.M_VEND] = math.sqrt(Z[K.RVX, 0] ** 2 + Z[K.RVY, 0] ** 2)
    meas[K.M_AEND] = math.sqrt(Z[K.RAX, 0] ** 2 + Z[K.RAY, 0] ** 2)
    meas[K.M_PFX] = -sig[N - 1] * c[N - 1]
    meas[K.M_PFY] = -sig[N - 1] * s[N - 1]
    meas[K.M_ENERGY] = 0.5 * ke - g * pe + par[P_EOFF]
    meas[K.M_LINKERR] = emax
    meas[K.M_LINKERR0] = emax
    meas[K.M_LENGTH] = length / L if L > 0.0 else length
    meas[M_PX] = Z[K.RX, N]
    meas[M_PY] = Z[K.RY, N]
    meas[M_PVX] = Z[K.RVX, N]
    meas[M_PVY] = Z[K.RVY, N]
    meas[M_WORK] = y[2 * N]
    meas[M_VREL] = math.sqrt(vrel2)
    tot = fin + ke + pe + smax + length + y[2 * N]
    meas[K.M_FINITE] = 1.0 if (tot - tot) == 0.0 else 0.0


def breakpoints(mdl) -> list[float]:
    """Times where the held end's acceleration jumps (the steppers land on them): the start
    and end of a pull or a flick (a flick's acceleration is continuous, its third derivative
    is not), the last sample of a table (constant velocity after it)."""
    par, tab = mdl[0], mdl[-1]
    kind = par[P_PIN]
    if kind in (PIN_PULL, PIN_FLICK):
        return [float(v) for v in (par[P_T0], par[P_T0] + par[P_T1]) if math.isfinite(v)]
    if kind == PIN_TABLE:
        return [float(tab[int(par[P_NKNOT]) - 1])]
    return []


def settle_time(mdl) -> float:
    """The time from which the held end's acceleration no longer changes (its last
    breakpoint), or -1 for a fixed held end.

    The automatic stop rule and the snap detection judge the chain's motion relative to
    the held end, and only from this time on: while the held end is still being driven
    (a flick, a finite pull, a table of samples), a fall of the chain's speed can be the
    held end slowing down, not the snap. After it the held end moves with constant
    acceleration (an endless pull: in its frame, the chain falls under the changed gravity
    ``g e2 - A``) or constant velocity (a Galilean frame), and the motion relative to it
    is the chain's own, so its snap is a rise and fall of ``max_j |v_j - v_p|``. A fixed
    held end (-1) keeps the rule on ``v_max`` from t = 0 (they are the same)."""
    par = mdl[0]
    if par[P_KIND] == KIND_UNIFORM or par[P_PIN] == PIN_FIXED:
        return -1.0
    return max([0.0] + breakpoints(mdl))


def uniform_model(N: int):
    """The model tuple of the paper's chain (dispatches to the uniform kernels)."""
    return make_model(np.full(N, 1.0 / N), np.full(N, float(N)), uniform=True)


def state_dim(mdl) -> int:
    """Length of the state vector of a model with N links: 2N (uniform), 2N + 1, or 2N + 2 (with a body)."""
    par, h = mdl[0], mdl[1]
    return 2 * h.size + (0 if par[P_KIND] == KIND_UNIFORM else 1) + (1 if par[P_KIND] == KIND_BODY else 0)


def dense_reference_rhs(t: float, y: np.ndarray, mdl) -> np.ndarray:
    """``[theta', theta'', W']`` by a dense solve of the rows above (numpy, O(N^3); for tests)."""
    par, h, invm, invh, snode, tab = mdl
    N = h.size
    th, om = y[:N], y[N:2 * N]
    _, _, pvx, pvy, pax, pay = pin_kinematics(t, par, tab)
    ex, ey = pax, pay - par[P_G]
    A = np.zeros((N, N))
    r = -h * om**2
    for j in range(N):
        A[j, j] = -(invm[j] + invm[j + 1]) if j < N - 1 else -invm[j]
        if j + 1 < N:
            A[j, j + 1] = A[j + 1, j] = math.cos(th[j + 1] - th[j]) * invm[j + 1]
    r[N - 1] -= ex * math.cos(th[N - 1]) + ey * math.sin(th[N - 1])
    T = np.linalg.solve(A, r)
    Sd = np.sin(np.diff(th))
    acc = np.zeros(N)
    for j in range(N):
        lo = Sd[j - 1] * T[j - 1] * invm[j] if j >= 1 else 0.0
        if j == N - 1:
            acc[j] = ((ey * math.cos(th[j]) - ex * math.sin(th[j])) - lo) / h[j]
        else:
            acc[j] = (Sd[j] * T[j + 1] * invm[j + 1] - lo) / h[j]
    W = T[N - 1] * (math.cos(th[N - 1]) * pvx + math.sin(th[N - 1]) * pvy)
    return np.concatenate([om, acc, [W]])


