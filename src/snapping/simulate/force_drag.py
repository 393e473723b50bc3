"""Air drag as node forces (numba, ``cache=True``): one force family of
:mod:`snapping.simulate.forced`.

Node j (j < N; the held end's own drag is taken by the held end) moves with velocity
``v_j`` (``v_N`` the held end's, ``v_j = v_{j+1} - h_j theta_j' n_j``) through air moving
with the uniform wind ``w``; ``u = v_j - w`` is its velocity relative to the air. Its
tangent ``tau_j`` is the unit bisector of its two links, ``(t_{j-1} + t_j)/|t_{j-1} + t_j|``
(the link's own tangent ``t_0`` at the free end, and ``t_j`` where the two links fold back
on each other exactly); ``u_t = (u.tau) tau``, ``u_n = u - u_t``. Over its share of length
``l_j`` (``(h_{j-1} + h_j)/2``, ``h_0/2`` at the free end) the line pulls it with::

    F_j = -(c_n l_j |u_n| + k_n l_j) u_n - (c_t l_j |u_t| + k_t l_j) u_t   [ - c_d |u| u at j = 0 ]

quadratic normal (cylinder cross-flow) and tangential (skin friction) parts, linear
(Stokes) parts, and a body drag ``c_d`` on the free end's tip body. Coefficients are
nondimensional: per unit length ``c_n`` in units of ``lambda/L`` (a line falling broadside
has the terminal speed ``sqrt(lambda g / c_n)``, 1/sqrt(c_n) nondimensional), ``k_n`` in
units of ``lambda sqrt(g/L)``, ``c_d`` in units of ``M/L``.

Arrays (length N + 1, by node, each already times ``l_j``): ``CN, CT, KN, KT``; ``VX, VY``
scratch for the node velocities; ``FX, FY`` the node forces (added to).

The power's gradient (:func:`drag_power_gradient`: the stiff method's dissipation row, whose
stage terms need ``dp/dtheta`` and ``dp/domega``; O(N), exact). Write node j's force with its
relative velocity's components ``q = u.tau`` and ``c = u x tau`` (``u_n = c n'``, ``n' = (tau_y,
-tau_x)``): ``F_j = -phi_n(c) n' - phi_t(q) tau [- c_d |u| u]``, ``phi_n(c) = (c_n l_j |c| + k_n l_j)
c``, ``phi_t(q) = (c_t l_j |q| + k_t l_j) q``; its power ``P_j = F_j.v_j``. Then, with ``V_n =
v_j.n'``, ``V_t = v_j.tau``::

    dP_j/du   = -(phi_n' V_n + phi_n) n' - (phi_t' V_t + phi_t) tau [- c_d ((u.v_j)/|u| u + |u| (v_j + u))]
    dP_j/dpsi = -phi_n' q V_n - phi_n V_t + phi_t' c V_t + phi_t V_n

(``psi`` the tangent's angle: ``dtau = -n' dpsi``, ``dn' = tau dpsi``; ``phi_n' = 2 c_n l_j |c| +
k_n l_j``). The bisector's angle is the mean of its links' (``dpsi/dtheta_{j-1} = dpsi/dtheta_j =
1/2``; the free end's and a fold's own link: 1). The velocity ``v_j = v_N + sum_{l >= j} h_l
omega_l (sin theta_l, -cos theta_l)`` gives, with ``G_l = sum_{j <= l} dP_j/du``::

    dp/domega_l = h_l (sin theta_l, -cos theta_l).G_l
    dp/dtheta_l = h_l omega_l (cos theta_l, sin theta_l).G_l + (the tangents' dP_j/dpsi dpsi/dtheta_l)
"""

from __future__ import annotations

import math

from numba import njit

__all__ = ["node_velocities", "add_drag", "drag_power_gradient"]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def node_velocities(N, y, c, s, h, pvx, pvy, VX, VY):
    """Node velocities from the held end's ``(pvx, pvy)`` and the angular velocities."""
    VX[N] = pvx
    VY[N] = pvy
    for j in range(N - 1, -1, -1):
        w = y[N + j] * h[j]
        VX[j] = VX[j + 1] + s[j] * w
        VY[j] = VY[j + 1] - c[j] * w


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _tangent(c, s, j):
    """The unit tangent at node ``j`` (cos/sin ``c, s`` of the link angles): link j's, or for j > 0
    the bisector of links j - 1 and j where they are not opposite; ``(tx, ty, bisector?)``."""
    tx = c[j]
    ty = s[j]
    if j > 0:
        bx = c[j - 1] + tx
        by = s[j - 1] + ty
        nb = math.sqrt(bx * bx + by * by)
        if nb > 1e-12:
            inb = 1.0 / nb
            return bx * inb, by * inb, True
    return tx, ty, False


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def add_drag(N, c, s, wx, wy, CN, CT, KN, KT, cd, VX, VY, FX, FY):
    """Add the drag forces (velocities ``VX, VY`` from :func:`node_velocities`); returns their
    power ``sum_j F_j.v_j`` (<= 0 without wind)."""
    p = 0.0
    for j in range(N):
        tx, ty, _ = _tangent(c, s, j)
        ux = VX[j] - wx
        uy = VY[j] - wy
        ut = ux * tx + uy * ty
        utx = ut * tx
        uty = ut * ty
        unx = ux - utx
        uny = uy - uty
        un = abs(ux * ty - uy * tx)  # (|u_n| = |u x tau|, tau a unit vector)
        an = CN[j] * un + KN[j]
        at = CT[j] * abs(ut) + KT[j]
        fx = -an * unx - at * utx
        fy = -an * uny - at * uty
        if j == 0 and cd != 0.0:
            u = math.sqrt(ux * ux + uy * uy)
            fx -= cd * u * ux
            fy -= cd * u * uy
        FX[j] += fx
        FY[j] += fy
        p += fx * VX[j] + fy * VY[j]
    return p


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def drag_power_gradient(N, y, c, s, h, wx, wy, CN, CT, KN, KT, cd, VX, VY, g):
    """The gradient of :func:`add_drag`'s power at fixed time (the held end's velocity fixed):
    ``g[:N] = dp/dtheta``, ``g[N:2N] = dp/domega`` (see the module's notes), from the cos/sin
    ``c, s`` of the angles ``y[:N]`` and the node velocities ``VX, VY`` of
    :func:`node_velocities`. O(N), no allocation."""
    for j in range(N):
        g[j] = 0.0
    gx = 0.0  # G_l: the velocity derivatives summed from the free end
    gy = 0.0
    for j in range(N):
        tx, ty, half = _tangent(c, s, j)
        vx = VX[j]
        vy = VY[j]
        ux = vx - wx
        uy = vy - wy
        q = ux * tx + uy * ty
        cr = ux * ty - uy * tx
        vn = vx * ty - vy * tx
        vt = vx * tx + vy * ty
        acr = abs(cr)
        aq = abs(q)
        phn = (CN[j] * acr + KN[j]) * cr
        dphn = 2.0 * CN[j] * acr + KN[j]
        pht = (CT[j] * aq + KT[j]) * q
        dpht = 2.0 * CT[j] * aq + KT[j]
        an = dphn * vn + phn
        at = dpht * vt + pht
        dux = -an * ty - at * tx
        duy = an * tx - at * ty
        if j == 0 and cd != 0.0:
            u = math.sqrt(ux * ux + uy * uy)
            if u > 0.0:
                uv = (ux * vx + uy * vy) / u
                dux -= cd * (uv * ux + u * (vx + ux))
                duy -= cd * (uv * uy + u * (vy + uy))
        dpsi = -dphn * q * vn - phn * vt + dpht * cr * vt + pht * vn
        if half:
            g[j - 1] += 0.5 * dpsi
            g[j] += 0.5 * dpsi
        else:
            g[j] += dpsi
        gx += dux
        gy += duy
        hj = h[j]
        g[j] += hj * y[N + j] * (c[j] * gx + s[j] * gy)
        g[N + j] = hj * (s[j] * gx - c[j] * gy)
