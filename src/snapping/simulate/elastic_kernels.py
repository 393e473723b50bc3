"""Compiled kernels of the extensible line (:mod:`snapping.simulate.elastic`): the node
forces, their banded Jacobian, and the per-state measures.

The state vector is node-interleaved, ``z[4i:4i+4] = (x_i, y_i, vx_i, vy_i)`` for the N free
nodes i = 0..N-1 (index 0 the free end, as everywhere in :mod:`snapping.simulate`), then
``z[4N] = W`` (work done on the line by the held end since t = 0) and ``z[4N+1] = D``
(energy dissipated by the Kelvin-Voigt damping since t = 0). Node N, the held end, is
prescribed: its position and velocity are arguments. The Jacobian of the node part is
block tridiagonal (4 x 4 blocks), so its bandwidth is 7 on either side.

Link j joins nodes j and j+1, with ``d_j = r_{j+1} - r_j``, ``l_j = |d_j|``, rest length
``h_j``, strain ``e_j = l_j/h_j - 1`` and strain rate ``edot_j = d_j . (v_{j+1} - v_j)/(l_j h_j)``.
Its tension is ``T_j = max(0, f_j(e_j) + c_j edot_j)`` while ``e_j > 0`` and 0 otherwise
(tension-only: a slack link carries nothing), with ``f_j(e) = EA_j e`` or the table's
piecewise-linear curve (``law``). The force on node j is ``+T_j d_j/l_j``, on node j+1 the
opposite.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: number of measures written by :func:`measure` (see ``MEASURE_NAMES``)
MEASURE_NAMES = ("v_max", "iv", "a_max", "ia", "sigma_max", "isig", "sigma_min", "imin", "v_end", "a_end",
                 "pin_force_x", "pin_force_y", "kinetic", "gravity", "elastic_energy", "strain_max", "n_slack",
                 "kappa_max", "ik", "kappa_max_interior")
NMEAS = len(MEASURE_NAMES)
#: ``kappa_max_interior`` leaves out the joints (nodes) fewer than this many links from the free end, as the
#: chain's (:data:`snapping.simulate.general.KAPPA_TIP_JOINTS`, the same value; not imported: no cycle)
KAPPA_TIP_JOINTS = 8


@njit(cache=True)
def law(e, ea, tabe, tabt):
    """(f(e), f'(e)) of one link: linear ``ea e`` when the table is empty, else the table's
    piecewise-linear curve (strains ``tabe`` from 0, tensions ``tabt`` from 0), extended
    beyond its last point with the last segment's slope. ``e`` must be > 0."""
    n = tabe.size
    if n == 0:
        return ea * e, ea
    k = np.searchsorted(tabe, e) - 1
    if k < 0:
        k = 0
    if k > n - 2:
        k = n - 2
    slope = (tabt[k + 1] - tabt[k]) / (tabe[k + 1] - tabe[k])
    return tabt[k] + slope * (e - tabe[k]), slope


@njit(cache=True)
def link_tension(e, ed, ea, damp, tabe, tabt):
    """``(T, f)`` of one link at strain ``e`` and strain rate ``ed``: the law's ``f(e)`` (:func:`law`)
    plus the damping ``damp ed``, cut at 0 (a link pushes nothing); both 0 for a slack link (e <= 0)."""
    if e > 0.0:
        f, _ = law(e, ea, tabe, tabt)
        t = f + damp * ed
        return (t if t > 0.0 else 0.0), f
    return 0.0, 0.0


@njit(cache=True)
def law_energy(e, ea, tabe, tabt, tabw):
    """The elastic energy per rest length, the integral of f from 0 to ``e`` (> 0); ``tabw``
    holds its values at the table's strains."""
    n = tabe.size
    if n == 0:
        return 0.5 * ea * e * e
    k = np.searchsorted(tabe, e) - 1
    if k < 0:
        k = 0
    if k > n - 2:
        k = n - 2
    slope = (tabt[k + 1] - tabt[k]) / (tabe[k + 1] - tabe[k])
    f = tabt[k] + slope * (e - tabe[k])
    return tabw[k] + 0.5 * (e - tabe[k]) * (tabt[k] + f)


@njit(cache=True)
def tensions(N, z, pin, h, ea, damp, tabe, tabt, T, E, ED, FV):
    """Link tensions ``T``, strains ``E``, strain rates ``ED`` and the elastic parts ``FV = f(e)``
    (0 where slack) of the state ``z`` with the held end at ``pin = (x, y, vx, vy)``."""
    for j in range(N):
        x0 = z[4 * j]
        y0 = z[4 * j + 1]
        vx0 = z[4 * j + 2]
        vy0 = z[4 * j + 3]
        if j + 1 < N:
            x1 = z[4 * j + 4]
            y1 = z[4 * j + 5]
            vx1 = z[4 * j + 6]
            vy1 = z[4 * j + 7]
        else:
            x1 = pin[0]
            y1 = pin[1]
            vx1 = pin[2]
            vy1 = pin[3]
        dx = x1 - x0
        dy = y1 - y0
        ln = math.sqrt(dx * dx + dy * dy)
        e = ln / h[j] - 1.0
        ed = (dx * (vx1 - vx0) + dy * (vy1 - vy0)) / (ln * h[j])
        E[j] = e
        ED[j] = ed
        T[j], FV[j] = link_tension(e, ed, ea[j], damp[j], tabe, tabt)


@njit(cache=True, error_model="numpy")
def rhs(N, z, pin, h, invm, ea, damp, tabe, tabt, g, dz, T, E, ED, FV):
    """The time derivative ``dz`` of the state: velocities, accelerations
    ``(sum of link forces)/m_i + g e2``, the held end's power ``T_{N-1} d_{N-1}.v_pin/l_{N-1}``
    and the dissipation rate ``sum_j h_j (T_j - f_j(e_j)) edot_j`` (>= 0); ``T, E, ED, FV``
    receive :func:`tensions`.

    The arithmetic is :func:`tensions`' and, per node, ``(0 - F_{i-1}/m_i) + F_i/m_i`` with
    ``F_j = T_j u_j`` (zero for a slack link), in loops without branches where the divisions
    are (the geometry first, into ``dz``'s acceleration slots, then the law, then the
    forces), so that the compiler can vectorise them."""
    for j in range(N - 1):
        dx = z[4 * j + 4] - z[4 * j]
        dy = z[4 * j + 5] - z[4 * j + 1]
        ln = math.sqrt(dx * dx + dy * dy)
        e = ln / h[j] - 1.0
        E[j] = e
        ED[j] = (dx * (z[4 * j + 6] - z[4 * j + 2]) + dy * (z[4 * j + 7] - z[4 * j + 3])) / (ln * h[j])
        lu = h[j] * (1.0 + e)
        dz[4 * j + 2] = dx / lu
        dz[4 * j + 3] = dy / lu
    j = N - 1
    dx = pin[0] - z[4 * j]
    dy = pin[1] - z[4 * j + 1]
    ln = math.sqrt(dx * dx + dy * dy)
    e = ln / h[j] - 1.0
    E[j] = e
    ED[j] = (dx * (pin[2] - z[4 * j + 2]) + dy * (pin[3] - z[4 * j + 3])) / (ln * h[j])
    lu = h[j] * (1.0 + e)
    dz[4 * j + 2] = dx / lu
    dz[4 * j + 3] = dy / lu
    diss = 0.0
    for j in range(N):
        tj, FV[j] = link_tension(E[j], ED[j], ea[j], damp[j], tabe, tabt)
        T[j] = tj
        # (also where the damping cancels the tension, T = 0 < f: there the rate is -h f edot)
        diss += h[j] * (tj - FV[j]) * ED[j]
        if tj == 0.0:
            dz[4 * j + 2] = 0.0
            dz[4 * j + 3] = 0.0
        else:
            dz[4 * j + 2] = tj * dz[4 * j + 2]
            dz[4 * j + 3] = tj * dz[4 * j + 3]
    fx0 = 0.0
    fy0 = 0.0
    for i in range(N):
        fx = dz[4 * i + 2]
        fy = dz[4 * i + 3]
        dz[4 * i] = z[4 * i + 2]
        dz[4 * i + 1] = z[4 * i + 3]
        dz[4 * i + 2] = (0.0 - fx0 * invm[i]) + fx * invm[i]
        dz[4 * i + 3] = ((0.0 - fy0 * invm[i]) + fy * invm[i]) + g
        fx0 = fx
        fy0 = fy
    # the held end's power on the line, and the dissipation rate
    j = N - 1
    if T[j] > 0.0:
        ln = h[j] * (1.0 + E[j])
        dz[4 * N] = T[j] * ((pin[0] - z[4 * j]) * pin[2] + (pin[1] - z[4 * j + 1]) * pin[3]) / ln
    else:
        dz[4 * N] = 0.0
    dz[4 * N + 1] = diss


@njit(cache=True)
def jac_blocks(N, z, pin, h, invm, ea, damp, tabe, tabt, B, T, E, ED, FV):
    """The Jacobian of the node part of :func:`rhs` as blocks ``B[i, k]`` (4 x 4), the
    derivative of node i's rows by node ``i - 1 + k``'s (x, y, vx, vy); blocks that would
    reach node -1 or the held end stay zero. The W and D rows are left out (zero): the
    Newton iteration of an implicit method converges for them regardless, as nothing
    depends on them."""
    tensions(N, z, pin, h, ea, damp, tabe, tabt, T, E, ED, FV)
    jac_given(N, z, pin, h, invm, ea, damp, tabe, tabt, B, T, E)


@njit(cache=True, error_model="numpy")
def link_blocks(tj, fp, c, hj, ln, ux, uy, dvx, dvy, udv):
    """A taut link's force derivative blocks ``(a00, a01, a10, a11, b00, b01, b10, b11)``:
    ``A = dG/dd = T/l (I - u u^T) + u (dT/dd)^T`` and ``Bv = dG/d(dv) = u (dT/d(dv))^T``, ``G = T u``
    (``fp`` the law's slope, ``c`` the damping, ``udv = u . dv``)."""
    # dT/dd and dT/d(dv)
    tdx = fp * ux / hj + c * (dvx - udv * ux) / (ln * hj)
    tdy = fp * uy / hj + c * (dvy - udv * uy) / (ln * hj)
    tvx = c * ux / hj
    tvy = c * uy / hj
    q = tj / ln
    return (q * (1.0 - ux * ux) + ux * tdx, -q * ux * uy + ux * tdy, -q * uy * ux + uy * tdx,
            q * (1.0 - uy * uy) + uy * tdy, ux * tvx, ux * tvy, uy * tvx, uy * tvy)


@njit(cache=True, error_model="numpy")
def jac_given(N, z, pin, h, invm, ea, damp, tabe, tabt, B, T, E):
    """:func:`jac_blocks` with the tensions ``T`` and strains ``E`` of ``z`` given (by
    :func:`tensions` or :func:`rhs` at the same state: a Rosenbrock method's Jacobian is
    taken where the next step's first evaluation was)."""
    B[:] = 0.0
    for i in range(N):
        B[i, 1, 0, 2] = 1.0
        B[i, 1, 1, 3] = 1.0
    for j in range(N):
        tj = T[j]
        if tj == 0.0:
            continue  # slack (or the damping cancels the tension): no force, no derivative
        ln = h[j] * (1.0 + E[j])
        x1 = z[4 * j + 4] if j + 1 < N else pin[0]
        y1 = z[4 * j + 5] if j + 1 < N else pin[1]
        vx1 = z[4 * j + 6] if j + 1 < N else pin[2]
        vy1 = z[4 * j + 7] if j + 1 < N else pin[3]
        ux = (x1 - z[4 * j]) / ln
        uy = (y1 - z[4 * j + 1]) / ln
        dvx = vx1 - z[4 * j + 2]
        dvy = vy1 - z[4 * j + 3]
        _, fp = law(E[j], ea[j], tabe, tabt)
        c = damp[j]
        udv = ux * dvx + uy * dvy
        a00, a01, a10, a11, b00, b01, b10, b11 = link_blocks(tj, fp, c, h[j], ln, ux, uy, dvx, dvy, udv)
        # node j: acc += G/m_j, G depends on r_{j+1} - r_j and v_{j+1} - v_j
        mj = invm[j]
        for sgn, k in ((-1.0, 1), (1.0, 2)):
            if k == 2 and j + 1 >= N:
                continue
            s = sgn * mj
            B[j, k, 2, 0] += s * a00
            B[j, k, 2, 1] += s * a01
            B[j, k, 3, 0] += s * a10
            B[j, k, 3, 1] += s * a11
            B[j, k, 2, 2] += s * b00
            B[j, k, 2, 3] += s * b01
            B[j, k, 3, 2] += s * b10
            B[j, k, 3, 3] += s * b11
        if j + 1 < N:  # node j+1: acc -= G/m_{j+1}
            mk = invm[j + 1]
            for sgn, k in ((1.0, 0), (-1.0, 1)):
                s = sgn * mk
                B[j + 1, k, 2, 0] += s * a00
                B[j + 1, k, 2, 1] += s * a01
                B[j + 1, k, 3, 0] += s * a10
                B[j + 1, k, 3, 1] += s * a11
                B[j + 1, k, 2, 2] += s * b00
                B[j + 1, k, 2, 3] += s * b01
                B[j + 1, k, 3, 2] += s * b10
                B[j + 1, k, 3, 3] += s * b11


@njit(cache=True)
def measure(N, z, pin, h, m, ea, damp, tabe, tabt, tabw, g, snode, dz, T, E, ED, FV, out):
    """Per-state measures (``MEASURE_NAMES``): speed, acceleration and tension maxima (with
    their node or link index), the smallest tension, the free end's speed and
    acceleration, the force of the line on the held end, kinetic, gravity
    (``g sum m_i (s_i - y_i)``, zero hanging at rest unstretched) and elastic energies,
    the largest strain, the number of slack links, the largest curvature and its node
    (:func:`curvature_max`). ``dz`` receives :func:`rhs`."""
    rhs(N, z, pin, h, 1.0 / m, ea, damp, tabe, tabt, g, dz, T, E, ED, FV)
    measure_given(N, z, pin, h, m, ea, tabe, tabt, tabw, g, snode, dz, T, E, out)


@njit(cache=True, error_model="numpy")
def measure_given(N, z, pin, h, m, ea, tabe, tabt, tabw, g, snode, dz, T, E, out):
    """:func:`measure` with :func:`rhs`'s ``dz``, ``T`` and ``E`` of the state ``z`` given
    (the invariant part of a step's bookkeeping: a Rosenbrock step ends with f there)."""
    vmax = -1.0
    iv = 0
    amax = -1.0
    ia = 0
    ke = 0.0
    pe = 0.0
    for i in range(N):
        vx = z[4 * i + 2]
        vy = z[4 * i + 3]
        ax = dz[4 * i + 2]
        ay = dz[4 * i + 3]
        v2 = vx * vx + vy * vy
        a2 = ax * ax + ay * ay
        ke += 0.5 * m[i] * v2
        pe += g * m[i] * (snode[i] - z[4 * i + 1])
        if v2 > vmax:
            vmax = v2
            iv = i
        if a2 > amax:
            amax = a2
            ia = i
    smax = -1.0
    isig = 0
    smin = np.inf
    imin = 0
    emax = -np.inf
    ue = 0.0
    nslack = 0
    for j in range(N):
        if T[j] > smax:
            smax = T[j]
            isig = j
        if T[j] < smin:
            smin = T[j]
            imin = j
        if E[j] > emax:
            emax = E[j]
        if E[j] > 0.0:
            ue += h[j] * law_energy(E[j], ea[j], tabe, tabt, tabw)
        if T[j] == 0.0:
            nslack += 1
    j = N - 1
    ln = h[j] * (1.0 + E[j])
    out[0] = math.sqrt(vmax)
    out[1] = iv
    out[2] = math.sqrt(amax)
    out[3] = ia
    out[4] = smax
    out[5] = isig
    out[6] = smin
    out[7] = imin
    out[8] = math.sqrt(z[2] * z[2] + z[3] * z[3])
    out[9] = math.sqrt(dz[2] * dz[2] + dz[3] * dz[3])
    out[10] = T[j] * (z[4 * j] - pin[0]) / ln
    out[11] = T[j] * (z[4 * j + 1] - pin[1]) / ln
    out[12] = ke
    out[13] = pe
    out[14] = ue
    out[15] = emax
    out[16] = nslack
    kap, ik, kin = curvature_max_both(N, z, pin, h)
    out[17] = kap
    out[18] = ik
    out[19] = kin


@njit(cache=True, error_model="numpy")
def curvature_max(N, z, pin, h):
    """``(kappa, i)``: the largest discrete curvature over the line and its node, the chain's
    (:func:`snapping.simulate.chain.curvature_profile`, ``general.general_measure``): at node
    ``i = j + 1`` (1..N-1) the turning angle ``phi`` in [0, pi] between links j and j+1 over the
    mean of their *rest* lengths, ``2 phi/(h_j + h_{j+1})``: the bending strain per unit
    material length (the inextensible chain's lengths are its rest lengths; the stretched
    line's geometric curvature is this over the joint's stretch ``1 + e``). ``(0.0, 0)`` with
    one link (no joint). ``phi = atan2(|d_j x d_j+1|, d_j . d_j+1)`` only where its bound
    ``pi/2 sin(phi)`` (``cos(phi) > 0``) can beat the best so far."""
    kbest, ik, _ = curvature_max_both(N, z, pin, h)
    return kbest, ik


@njit(cache=True, error_model="numpy")
def curvature_max_both(N, z, pin, h):
    """``(kappa, i, kappa_interior)``: :func:`curvature_max`'s two, the same floats, and the largest
    curvature over the joints at least :data:`KAPPA_TIP_JOINTS` links from the free end (nodes
    ``i >= KAPPA_TIP_JOINTS``; the chain's ``kappa_max_interior``, ``general.general_measure``; NaN with
    fewer than ``KAPPA_TIP_JOINTS + 1`` links). A joint's atan2 is skipped only where its bound beats
    neither best (the interior one counting from node ``KAPPA_TIP_JOINTS`` on)."""
    kbest = -1.0
    kin = -1.0
    ik = -1
    dxp = (z[4] if N > 1 else pin[0]) - z[0]
    dyp = (z[5] if N > 1 else pin[1]) - z[1]
    lp = dxp * dxp + dyp * dyp
    for j in range(N - 1):
        x2 = z[4 * j + 8] if j + 2 < N else pin[0]
        y2 = z[4 * j + 9] if j + 2 < N else pin[1]
        dxn = x2 - z[4 * j + 4]
        dyn = y2 - z[4 * j + 5]
        ln = dxn * dxn + dyn * dyn
        C = dxp * dxn + dyp * dyn
        Sn = abs(dxp * dyn - dyp * dxn)
        hb = 2.0 / (h[j] + h[j + 1])
        bound = 0.5 * math.pi * Sn * hb
        skip = C > 0.0 and kbest >= 0.0 and bound * bound <= kbest * kbest * lp * ln
        if skip and j + 1 >= KAPPA_TIP_JOINTS:
            skip = kin >= 0.0 and bound * bound <= kin * kin * lp * ln
        if not skip:
            kap = math.atan2(Sn, C) * hb
            if kap > kbest:
                kbest = kap
                ik = j + 1
            if j + 1 >= KAPPA_TIP_JOINTS and kap > kin:
                kin = kap
        dxp = dxn
        dyp = dyn
        lp = ln
    kin = kin if kin >= 0.0 else np.nan
    if ik < 0:
        return 0.0, 0, kin
    return kbest, ik, kin


def block_band_pattern(N: int, width: int) -> tuple:
    """CSC structure of a Jacobian of ``width`` (odd) 4 x 4 blocks per node row, centred on the
    diagonal, over the 4N + 2 state (the W and D rows and columns empty): ``(indices, indptr,
    order)`` so that ``csc_matrix((blocks.ravel()[order], indices, indptr))``, ``blocks`` of shape
    ``(N, width, 4, 4)`` (block ``[i, k]``: node i's rows by node ``i - width//2 + k``'s columns;
    those outside the line dropped), is the matrix."""
    import scipy.sparse as sp

    i, k, r, c = np.meshgrid(np.arange(N), np.arange(width), np.arange(4), np.arange(4), indexing="ij")
    col_node = i - width // 2 + k
    rows = (4 * i + r).ravel()
    cols = (4 * col_node + c).ravel()
    keep = np.flatnonzero(((col_node >= 0) & (col_node < N)).ravel())
    n = 4 * N + 2
    M = sp.coo_matrix((keep + 1.0, (rows[keep], cols[keep])), shape=(n, n)).tocsc()
    M.sort_indices()
    return M.indices.copy(), M.indptr.copy(), M.data.astype(np.int64) - 1
