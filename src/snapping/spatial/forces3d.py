"""A line's body in space: bending, Kelvin-Voigt damping and air drag as 3D node forces (numba).

The force families of :mod:`snapping.simulate.force_bending` and
:mod:`snapping.simulate.force_drag` for the chain of :mod:`snapping.spatial.chain3d`
(links ``e_j``, rates ``u_j = e_j'``; node i joins link i - 1 and link i; index 0 the free
end, node N the held end). Nondimensional, the units of :class:`snapping.simulate.Body`.

Bending. The turning angle at node i is the angle between its two links,
``psi_i = atan2(|e_{i-1} x e_i|, e_{i-1} . e_i)`` in [0, pi], and the bending energy is the
planar model's, ``V_b = sum_{i=1}^{N-1} (B_i/l_i) psi_i^2/2`` (``l_i = (h_{i-1} + h_i)/2``):
in a plane ``psi_i = |theta_i - theta_{i-1}|``, so a planar run in space is the planar run.
Its gradient on the unit sphere, ``d psi/d e_i = -(e_{i-1} - c e_i)/s`` (``c``, ``s``: the
cosine and sine of psi), gives the moment ``M_i = (B_i/l_i) psi_i`` and the generalised
force ``+M_i (e_{i-1} - c e_i)/s`` on link i (and symmetrically on link i - 1), with
``psi/s`` bounded (1 at psi = 0): the force is smooth through a straight node. It is
applied as a couple of node forces (``+G/h`` on the link's upper node, ``-G/h`` on its
lower): the virtual work of ``G . delta e``. At psi = pi (a node folded back on itself) the
energy has a cone point; the force there is bounded (``B pi/l``) but its direction is
undefined: the kernel gives none at that exact point.

Kelvin-Voigt damping: the dissipation function ``R = sum_i (eta_i/l_i) psi_i'^2/2`` with
``psi_i' = -(e_{i-1} . u_i + e_i . u_{i-1})/s``, the rate of the turning angle (objective:
a rigid rotation leaves it zero). It does not damp a turn of the plane of bending at a
constant angle: that would need a material frame along the line (see the guide on what a
twisting rope needs). At a straight node (s = 0 exactly) its direction is undefined and it
is left out (measure zero; near it the force is continuous in a plane, bounded in space).

Natural curvature kappa0 needs a direction to curl in. A chain has no material frame, so
in space it has one only in a plane: with a natural curvature, the turning angle is the
signed one about the reference plane's normal ``n``,
``psi_i = atan2(n . (e_{i-1} x e_i), e_{i-1} . e_i)`` (exactly the planar
``theta_i - theta_{i-1}``), and :class:`snapping.spatial.starts3d.Problem3D` accepts it
only for a planar problem (which stays exactly planar).

Drag: as :mod:`snapping.simulate.force_drag` with vectors: node j (j < N) of velocity
``v_j`` (``v_N`` the held end's, ``v_j = v_{j+1} - h_j u_j``), relative to the wind
``u = v_j - w`` (a 3-vector); tangent ``tau_j`` the unit bisector of its links (``e_0`` at
the free end, ``e_j`` where the links fold back exactly); ``F_j = -(c_n l_j |u_n| + k_n
l_j) u_n - (c_t l_j |u_t| + k_t l_j) u_t`` and ``-c_d |u| u`` at the tip.

Energy: the held end takes the force on node N (the bending couple of the held link) and
does the work ``-F_N . v_p`` more; the dissipation rate is ``2R - sum_j F^drag_j . v_j``
(wind's work negative), integrated as the state's last component ``D``
(:func:`snapping.spatial.chain3d.rhs3d`).

Layout: the body extends the model's parameter vector ``par`` after the chain's
scalars and the held end's data, at ``o = par[chain3d.P_BODY]``: :data:`NBS` scalars (``has bending``, ``has drag``,
``signed``, wind ``wx, wy, wz``, tip drag ``c_d``), then node arrays of N + 1 (``Bl = B/l,
K0L = kappa0 l, El = eta/l, CN, CT, KN, KT`` each times ``l``, then the scratch ``FX, FY,
FZ, VX, VY, VZ``). The scratch lives in the model: one model serves one evaluation at a
time (as the planar body model).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["NBS", "extend_par", "node_forces", "link_accel", "bending_energy", "node_force_arrays",
           "forces_at", "has_body"]

# body scalars (after the chain's), then node arrays
(S_HASBEND, S_HASDRAG, S_SIGNED, S_WX, S_WY, S_WZ, S_TIPCD) = range(7)
NBS = 7
(A_BL, A_K0L, A_EL, A_CN, A_CT, A_KN, A_KT, A_FX, A_FY, A_FZ, A_VX, A_VY, A_VZ) = range(13)
NA_IN = 7
NA = 13
_IN_NAMES = ("Bl", "K0L", "El", "CN", "CT", "KN", "KT")


def extend_par(par, N: int, arrays: dict, *, signed: bool = False, wind=(0.0, 0.0, 0.0), tip_drag: float = 0.0):
    """``par`` (the chain's scalars) extended by a body block (``arrays``: the names ``Bl, K0L, El,
    CN, CT, KN, KT``, N + 1 each by node, already the node's share as in
    :meth:`snapping.simulate.body.Body.model`). No checks (:class:`Problem3D` validates)."""
    n1 = N + 1
    blk = np.zeros(NBS + NA * n1)
    for k, name in enumerate(_IN_NAMES):
        blk[NBS + k * n1:NBS + (k + 1) * n1] = np.asarray(arrays.get(name, np.zeros(n1)), dtype=float)
    blk[S_HASBEND] = float(bool(np.any(blk[NBS:NBS + 3 * n1] != 0.0)))
    blk[S_HASDRAG] = float(bool(np.any(blk[NBS + 3 * n1:NBS + NA_IN * n1] != 0.0)) or tip_drag != 0.0)
    blk[S_SIGNED] = float(signed)
    w = np.zeros(3)
    w[:len(wind)] = np.asarray(wind, dtype=float)
    blk[S_WX:S_WZ + 1] = w
    blk[S_TIPCD] = float(tip_drag)
    return np.concatenate([np.asarray(par, dtype=float), blk])


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def has_body(par, o):
    return o > 0


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _arr(par, o, N, k):
    b = o + NBS + k * (N + 1)
    return par[b:b + N + 1]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _turn(N, y, i, signed, nx, ny, nz):
    """(psi, gax, gay, gaz, gbx, gby, gbz, ok): the turning angle at node i and its gradients
    with respect to the link directions a = e_{i-1} and b = e_i (tangent to the unit sphere);
    ``ok`` False where the direction is undefined (unsigned, s = 0)."""
    X = 0
    Y = N
    Z = 2 * N
    ax = y[X + i - 1]
    ay = y[Y + i - 1]
    az = y[Z + i - 1]
    bx = y[X + i]
    by = y[Y + i]
    bz = y[Z + i]
    c = ax * bx + ay * by + az * bz
    cx = ay * bz - az * by
    cy = az * bx - ax * bz
    cz = ax * by - ay * bx
    if signed:
        S = nx * cx + ny * cy + nz * cz
        psi = math.atan2(S, c)
        den = 1.0 / (S * S + c * c)
        # d psi/da = -(c (n x b) + S b)/den, d psi/db = (c (n x a) - S a)/den, projected on the tangents
        gax = -(c * (ny * bz - nz * by) + S * bx) * den
        gay = -(c * (nz * bx - nx * bz) + S * by) * den
        gaz = -(c * (nx * by - ny * bx) + S * bz) * den
        gbx = (c * (ny * az - nz * ay) - S * ax) * den
        gby = (c * (nz * ax - nx * az) - S * ay) * den
        gbz = (c * (nx * ay - ny * ax) - S * az) * den
        d = gax * ax + gay * ay + gaz * az
        gax -= d * ax
        gay -= d * ay
        gaz -= d * az
        d = gbx * bx + gby * by + gbz * bz
        gbx -= d * bx
        gby -= d * by
        gbz -= d * bz
        return psi, gax, gay, gaz, gbx, gby, gbz, True
    s = math.sqrt(cx * cx + cy * cy + cz * cz)
    psi = math.atan2(s, c)
    if not s > 0.0:
        return psi, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, False
    inv = -1.0 / s
    return (psi, (bx - c * ax) * inv, (by - c * ay) * inv, (bz - c * az) * inv, (ax - c * bx) * inv,
            (ay - c * by) * inv, (az - c * bz) * inv, True)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _bend(N, y, par, o, h, nx, ny, nz, FX, FY, FZ):
    """Add the bending and damping couples; returns the dissipation rate 2R."""
    Bl = _arr(par, o, N, A_BL)
    K0L = _arr(par, o, N, A_K0L)
    El = _arr(par, o, N, A_EL)
    signed = par[o + S_SIGNED] != 0.0
    U = 3 * N
    diss = 0.0
    for i in range(1, N):
        if Bl[i] == 0.0 and El[i] == 0.0:
            continue
        psi, gax, gay, gaz, gbx, gby, gbz, ok = _turn(N, y, i, signed, nx, ny, nz)
        if not ok:
            continue  # (straight or folded back exactly: no direction; the stiffness force is 0 or undefined)
        rate = (gax * y[U + i - 1] + gay * y[U + N + i - 1] + gaz * y[U + 2 * N + i - 1]
                + gbx * y[U + i] + gby * y[U + N + i] + gbz * y[U + 2 * N + i])
        M = Bl[i] * (psi - K0L[i]) + El[i] * rate
        diss += El[i] * rate * rate
        # link i - 1 (a): G_a = -M g_a, +G/h on node i, -G/h on node i - 1
        f = -M / h[i - 1]
        FX[i] += f * gax
        FY[i] += f * gay
        FZ[i] += f * gaz
        FX[i - 1] -= f * gax
        FY[i - 1] -= f * gay
        FZ[i - 1] -= f * gaz
        # link i (b): +G/h on node i + 1, -G/h on node i
        f = -M / h[i]
        FX[i + 1] += f * gbx
        FY[i + 1] += f * gby
        FZ[i + 1] += f * gbz
        FX[i] -= f * gbx
        FY[i] -= f * gby
        FZ[i] -= f * gbz
    return diss


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _drag(N, y, par, o, h, pvx, pvy, pvz, FX, FY, FZ):
    """Add the drag forces; returns their power sum_j F_j . v_j."""
    CN = _arr(par, o, N, A_CN)
    CT = _arr(par, o, N, A_CT)
    KN = _arr(par, o, N, A_KN)
    KT = _arr(par, o, N, A_KT)
    VX = _arr(par, o, N, A_VX)
    VY = _arr(par, o, N, A_VY)
    VZ = _arr(par, o, N, A_VZ)
    U = 3 * N
    VX[N] = pvx
    VY[N] = pvy
    VZ[N] = pvz
    for j in range(N - 1, -1, -1):
        hj = h[j]
        VX[j] = VX[j + 1] - hj * y[U + j]
        VY[j] = VY[j + 1] - hj * y[U + N + j]
        VZ[j] = VZ[j + 1] - hj * y[U + 2 * N + j]
    wx = par[o + S_WX]
    wy = par[o + S_WY]
    wz = par[o + S_WZ]
    cd = par[o + S_TIPCD]
    p = 0.0
    for j in range(N):
        tx = y[j]
        ty = y[N + j]
        tz = y[2 * N + j]
        if j > 0:
            bx = y[j - 1] + tx
            by = y[N + j - 1] + ty
            bz = y[2 * N + j - 1] + tz
            nb = math.sqrt(bx * bx + by * by + bz * bz)
            if nb > 1e-12:
                inb = 1.0 / nb
                tx = bx * inb
                ty = by * inb
                tz = bz * inb
        ux = VX[j] - wx
        uy = VY[j] - wy
        uz = VZ[j] - wz
        ut = ux * tx + uy * ty + uz * tz
        utx = ut * tx
        uty = ut * ty
        utz = ut * tz
        unx = ux - utx
        uny = uy - uty
        unz = uz - utz
        un = math.sqrt(unx * unx + uny * uny + unz * unz)
        an = CN[j] * un + KN[j]
        at = CT[j] * abs(ut) + KT[j]
        fx = -an * unx - at * utx
        fy = -an * uny - at * uty
        fz = -an * unz - at * utz
        if j == 0 and cd != 0.0:
            u = math.sqrt(ux * ux + uy * uy + uz * uz)
            fx -= cd * u * ux
            fy -= cd * u * uy
            fz -= cd * u * uz
        FX[j] += fx
        FY[j] += fy
        FZ[j] += fz
        p += fx * VX[j] + fy * VY[j] + fz * VZ[j]
    return p


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def node_forces(N, y, par, o, h, pvx, pvy, pvz, nx, ny, nz):
    """Gather the body's node forces into the scratch ``FX, FY, FZ`` (N + 1; zeroed first).
    Returns ``(p_held, dD)``: ``F_N . v_p`` (the force on the held end, times its velocity:
    the held end's power is ``T e . v_p - p_held``) and the dissipation rate."""
    FX = _arr(par, o, N, A_FX)
    FY = _arr(par, o, N, A_FY)
    FZ = _arr(par, o, N, A_FZ)
    for j in range(N + 1):
        FX[j] = 0.0
        FY[j] = 0.0
        FZ[j] = 0.0
    diss = 0.0
    pdrag = 0.0
    if par[o + S_HASBEND] != 0.0:
        diss = _bend(N, y, par, o, h, nx, ny, nz, FX, FY, FZ)
    if par[o + S_HASDRAG] != 0.0:
        pdrag = _drag(N, y, par, o, h, pvx, pvy, pvz, FX, FY, FZ)
    return FX[N] * pvx + FY[N] * pvy + FZ[N] * pvz, diss - pdrag


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def link_accel(N, j, par, o, invm):
    """``a^F_j = F_{j+1}/m_{j+1} - F_j/m_j`` of link j (the held link: ``-F_{N-1}/m_{N-1}``),
    from the forces :func:`node_forces` left in the scratch."""
    b = o + NBS
    n1 = N + 1
    fx = b + A_FX * n1
    fy = b + A_FY * n1
    fz = b + A_FZ * n1
    im = invm[j]
    ax = -par[fx + j] * im
    ay = -par[fy + j] * im
    az = -par[fz + j] * im
    if j < N - 1:
        im = invm[j + 1]
        ax += par[fx + j + 1] * im
        ay += par[fy + j + 1] * im
        az += par[fz + j + 1] * im
    return ax, ay, az


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def node_force(N, j, par, o):
    """The body's force on node j (from the scratch)."""
    b = o + NBS
    n1 = N + 1
    return par[b + A_FX * n1 + j], par[b + A_FY * n1 + j], par[b + A_FZ * n1 + j]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def bending_energy(N, y, par, o, nx, ny, nz):
    """``V_b = sum_i (B_i/l_i) (psi_i - kappa0_i l_i)^2/2``."""
    if par[o + S_HASBEND] == 0.0:
        return 0.0
    Bl = _arr(par, o, N, A_BL)
    K0L = _arr(par, o, N, A_K0L)
    signed = par[o + S_SIGNED] != 0.0
    v = 0.0
    for i in range(1, N):
        if Bl[i] == 0.0:
            continue
        psi = _turn(N, y, i, signed, nx, ny, nz)[0]
        d = psi - K0L[i]
        v += Bl[i] * d * d
    return 0.5 * v


def node_force_arrays(N: int, par, o: int) -> np.ndarray:
    """The scratch node forces ((N + 1, 3)) as a copy (after an evaluation)."""
    return np.column_stack([np.array(_arr(par, o, N, k)) for k in (A_FX, A_FY, A_FZ)])


def forces_at(N: int, y, par, o: int, h, pin_velocity=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0)):
    """``(F, p_held, dD)``: the body's node forces ((N + 1, 3)) of the state ``y`` (a numpy entry
    point for tests and the Dataset; on a copy of ``par``)."""
    par = np.array(par, dtype=float)
    p, d = node_forces(N, np.asarray(y, dtype=float), par, o, np.asarray(h, dtype=float), *map(float, pin_velocity),
                       *map(float, normal))
    return node_force_arrays(N, par, o), p, d
