"""The elastic line's compiled RODAS4 with a :class:`~snapping.simulate.body.Body` (bending
stiffness and damping, natural curvature, drag, wind, a clamped held end): ``elastic.solve(problem
with a body, ..., method="rodas4")`` (branch rodasbody).

The method, error norm and step rule are :mod:`snapping.simulate.elastic_rodas`'s (RODAS4, the
same tableau, controller and dense output); what differs:

* the right-hand side is the springs' (:func:`elastic_kernels.rhs`) plus the body's
  (:func:`elastic_body.add_body`), as :meth:`elastic_body.LineBody.rhs` adds them;
* the Jacobian's node blocks reach two nodes either side (a bending moment at node i turns links
  i-1 and i): the springs' exact blocks (:func:`elastic_jacobian.jacobian`), a pushing line's compressed
  links' exact ones (:func:`compression_jacobian`: by differences, a link within the step of its rest
  length, as at the bottom of a stiff catenary, strain ~1e-7 at c = 300, got a spurious EA/2 and the
  steps fell 70-fold), plus the bending's and drag's, exact since branch fastbody
  (:mod:`elastic_body_jacobian`; before, central differences over the nodes coloured mod 5, the steps of
  :func:`elastic_body.body_jac_fd`: :func:`body_jacobian_fd`, kept for the tests), in the compact form ``B5[i, k, 0:4] = K``, ``B5[i, k, 4:8] = C`` (node i's accelerations by node
  ``i - 2 + k``'s positions, velocities; 2 x 2 row-major);
* the W row (the held end's power) gets the body's ``d/dz (M_N phi' - F_N . v_pin)``, which reaches
  nodes N-2 and N-1 (``gW`` holds nodes N-3..N-1: 12 entries), and the D row the body's
  ``d/dz (2R + D_compression - P_drag)`` (all nodes: drag), both exact too (the differences split the
  dissipation into per-node terms, :func:`local_dissipation`, each reaching one node either side, so that a
  colour's perturbed nodes, 5 apart, are told apart);
* the reduced stage matrix ``I - g^2 K - g C`` is a band of 2 x 2 blocks reaching two nodes either
  side: interleaved bandwidth 5 below and above, factored with partial pivoting
  (:func:`banded_body.band_lu55`, :func:`banded.band_lu`'s general path until branch fastbody; bending makes
  it non-symmetric in general, so the spring-only path's
  pivot-free block Thomas is not used); every factorisation counts as pivoted (``n_lu_pivoted``);
* the clamp's angle (a constant or the cubic spline of :class:`LineBody`, its piecewise
  polynomial evaluated compiled: :func:`clamp_at`) at each stage's time; a clamp given as samples makes
  the system non-autonomous (``df/dt`` by a forward difference, as for a moving held end).

Its step is compiled (:func:`body_accept`); the run's step loop and bookkeeping too since branch fastbody
(:mod:`elastic_body_advance`; before, :func:`elastic_solve.solve`'s Python loop, one call per accepted step),
the peaks refined by ``_Peaks.refine`` with this stepper. The plain line's ``"rodas4"`` (no body) is untouched.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import elastic_kernels as EK
from . import elastic_rodas as ER
from .banded_body import WROW5, band_lu55, band_solve55
from .elastic_body import _geometry, add_body
from .elastic_body_jacobian import body_terms_jacobian
from .elastic_jacobian import add_link_gradient, jacobian
from .force_drag import add_drag
from .rosenbrock import A_ST, C_NODE, C_ST, D_TIME, GAMMA

__all__ = ["RodasBodyStepper", "clamp_at", "body_rhs", "body_jacobian", "body_jacobian_fd", "local_dissipation", "body_accept",
           "KLB", "KUB", "WIDTHB", "NGW"]

#: the body's reduced stage matrix's bandwidths (2 x 2 blocks reaching nodes i-2..i+2, interleaved x, y)
KLB = KUB = 5
#: band storage width of :func:`banded_body.band_lu55` (room for the pivoting's fill-in and the reciprocal
#: pivots; :func:`banded.band_lu`'s general path, 2 KLB + KUB + 1 wide, until branch fastbody)
WIDTHB = WROW5
#: entries of the W row's gradient: nodes N-3..N-1
NGW = 12
#: the scalars of a body (``bd[7]``): tip drag, wind x, y, clamped, push, clamp kind (0 none, 1 a
#: constant angle, 2 the spline), the constant angle, the spline's last time and angle
(P_CD, P_WX, P_WY, P_CLAMPED, P_PUSH, P_CKIND, P_CANG, P_TLAST, P_ALAST) = range(9)


@njit(cache=True, error_model="numpy")
def clamp_at(t, sc, cx, cc):
    """``(ex, ey, phi')`` of :meth:`LineBody.clamp` at ``t``: the held link's unit direction (the
    clamp's angle + pi) and the angle's rate; the spline's pieces ``cx`` (breakpoints) and ``cc``
    (4 x pieces, scipy's PPoly coefficients), constant after its last time."""
    kind = sc[P_CKIND]
    if kind == 0.0:
        return 0.0, 0.0, 0.0
    if kind == 1.0:
        a = sc[P_CANG]
        ad = 0.0
    elif t >= sc[P_TLAST]:
        a = sc[P_ALAST]
        ad = 0.0
    else:
        npc = cc.shape[1]
        i = np.searchsorted(cx, t, side="right") - 1
        if i < 0:
            i = 0
        if i > npc - 1:
            i = npc - 1
        d = t - cx[i]
        a = ((cc[0, i] * d + cc[1, i]) * d + cc[2, i]) * d + cc[3, i]
        ad = (3.0 * cc[0, i] * d + 2.0 * cc[1, i]) * d + cc[2, i]
    return -math.cos(a), -math.sin(a), ad


@njit(cache=True, error_model="numpy")
def body_rhs(N, t, z, pin, h, invm, ea, damp, tabe, tabt, g, bd, dz, T, E, ED, FV, bs):
    """``LineBody.rhs``: the springs' rhs (leaving their ``T, E, ED, FV``) plus the body's."""
    Bl, K0L, El, CN, CT, KN, KT, sc, cx, cc = bd
    UX, UY, LN, OM, MM, FX, FY = bs[0], bs[1], bs[2], bs[3], bs[4], bs[5], bs[6]
    EK.rhs(N, z, pin, h, invm, ea, damp, tabe, tabt, g, dz, T, E, ED, FV)
    ex, ey, phid = clamp_at(t, sc, cx, cc)
    add_body(N, z, pin, invm, Bl, K0L, El, CN, CT, KN, KT, sc[P_CD], sc[P_WX], sc[P_WY], sc[P_CLAMPED] != 0.0, ex,
             ey, phid, sc[P_PUSH] != 0.0, h, ea, damp, UX, UY, LN, OM, MM, FX, FY, dz)


@njit(cache=True, error_model="numpy")
def local_dissipation(N, z, pin, El, CN, CT, KN, KT, sc, phid, push, h, ea, damp, UX, UY, LN, OM, DX, DY, Q):
    """The body's dissipation rate ``2R + D_compression - P_drag`` (``elastic_body.body_forces``' ``diss -
    p_drag``) split into per-node terms ``Q[0:N]`` (summing to it), each a function of its node and the
    nodes on either side: the bending damping at joint i (and the clamp's at node N-1), a compressed
    link j's damping at node j (with ``push``), the drag's power at its node. The geometry ``UX, UY, LN,
    OM`` of ``z`` (:func:`elastic_body._geometry`) on entry."""
    for i in range(N + 1):
        Q[i] = 0.0
        DX[i] = 0.0
        DY[i] = 0.0
    for i in range(1, N):
        dom = OM[i] - OM[i - 1]
        Q[i] += El[i] * dom * dom
    if sc[P_CLAMPED] != 0.0:
        dom = phid - OM[N - 1]
        Q[N - 1] += El[N] * dom * dom
    if push:
        for j in range(N):
            e = LN[j] / h[j] - 1.0
            if e > 0.0:
                continue
            vx1 = z[4 * j + 6] if j + 1 < N else pin[2]
            vy1 = z[4 * j + 7] if j + 1 < N else pin[3]
            ed = (UX[j] * (vx1 - z[4 * j + 2]) + UY[j] * (vy1 - z[4 * j + 3])) / h[j]
            f = ea[j] * e
            tt = f + damp[j] * ed
            if tt > 0.0:
                tt = 0.0
            Q[j] += h[j] * (tt - f) * ed
    add_drag(N, UX, UY, sc[P_WX], sc[P_WY], CN, CT, KN, KT, sc[P_CD], z[2:4 * N:4], z[3:4 * N:4], DX, DY)
    for j in range(N):
        Q[j] -= DX[j] * z[4 * j + 2] + DY[j] * z[4 * j + 3]


@njit(cache=True, error_model="numpy")
def _body_eval(N, t, zz, pin, h, ea, damp, bd, bs, Q):
    """The body's node forces (``bs[5], bs[6]``), its W rate ``M_N phi' - F_N . v_pin`` (returned) and
    per-node dissipation ``Q`` at ``zz``, without the compressed links' push (:func:`compression_jacobian`
    differentiates that exactly: a link a few 1e-7 from its rest length, the bottom of a stiff catenary,
    would be crossed by the differences' step and get a spurious EA/2)."""
    Bl, K0L, El, CN, CT, KN, KT, sc, cx, cc = bd
    UX, UY, LN, OM, MM, FX, FY, DX, DY = bs[0], bs[1], bs[2], bs[3], bs[4], bs[5], bs[6], bs[7], bs[8]
    ex, ey, phid = clamp_at(t, sc, cx, cc)
    # elastic_body.body_forces' bending (its arithmetic), the drag once: local_dissipation's, added after the
    # bending as body_forces adds it (the same numbers; one drag pass instead of two: 14 -> ~10 us at N 400)
    _geometry(N, zz, pin, UX, UY, LN, OM)
    for i in range(N + 1):
        FX[i] = 0.0
        FY[i] = 0.0
    MM[0] = 0.0
    for i in range(1, N):
        cr = UX[i - 1] * UY[i] - UY[i - 1] * UX[i]
        dt = UX[i - 1] * UX[i] + UY[i - 1] * UY[i]
        dom = OM[i] - OM[i - 1]
        MM[i] = Bl[i] * (math.atan2(cr, dt) - K0L[i]) + El[i] * dom
    if sc[P_CLAMPED] != 0.0:
        j = N - 1
        cr = UX[j] * ey - UY[j] * ex
        dt = UX[j] * ex + UY[j] * ey
        dom = phid - OM[j]
        MM[N] = Bl[N] * (math.atan2(cr, dt) - K0L[N]) + El[N] * dom
    else:
        MM[N] = 0.0
    for j in range(N):
        q = (MM[j + 1] - MM[j]) / LN[j]
        fx = -UY[j] * q
        fy = UX[j] * q
        FX[j + 1] += fx
        FY[j + 1] += fy
        FX[j] -= fx
        FY[j] -= fy
    local_dissipation(N, zz, pin, El, CN, CT, KN, KT, sc, phid, False, h, ea, damp, UX, UY, LN, OM, DX, DY, Q)
    for j in range(N):
        FX[j] += DX[j]
        FY[j] += DY[j]
    return MM[N] * phid - (FX[N] * pin[2] + FY[N] * pin[3])


@njit(cache=True, error_model="numpy")
def compression_jacobian(N, z, pin, h, invm, ea, damp, B5, gW, gD):
    """Add the compressed links' push (:func:`elastic_body.compression`: ``T = min(0, EA e + KV edot)``
    for ``e <= 0``, force ``+T u`` on node j) to the node blocks ``B5``, the W row ``gW`` and the D row
    ``gD``, exactly: the springs' formulas of :func:`elastic_jacobian.jacobian` with the linear law
    (``f = EA e``, slope EA) continued below the rest length."""
    for j in range(N):
        if j + 1 < N:
            x1, y1, vx1, vy1 = z[4 * j + 4], z[4 * j + 5], z[4 * j + 6], z[4 * j + 7]
        else:
            x1, y1, vx1, vy1 = pin[0], pin[1], pin[2], pin[3]
        dx = x1 - z[4 * j]
        dy = y1 - z[4 * j + 1]
        ln = math.sqrt(dx * dx + dy * dy)
        e = ln / h[j] - 1.0
        if e > 0.0:
            continue
        ux = dx / ln
        uy = dy / ln
        dvx = vx1 - z[4 * j + 2]
        dvy = vy1 - z[4 * j + 3]
        udv = ux * dvx + uy * dvy
        ed = udv / h[j]
        fp = ea[j]
        f = fp * e
        c = damp[j]
        tj = f + c * ed
        if tj > 0.0:
            tj = 0.0
        px = (dvx - udv * ux) / ln
        py = (dvy - udv * uy) / ln
        if tj < 0.0:
            gdx, gdy = 2.0 * c * ed * px, 2.0 * c * ed * py
            gvx, gvy = 2.0 * c * ed * ux, 2.0 * c * ed * uy
        else:
            gdx, gdy = -(fp * ed * ux + f * px), -(fp * ed * uy + f * py)
            gvx, gvy = -f * ux, -f * uy
        add_link_gradient(gD, N, j, gdx, gdy, gvx, gvy)
        if tj == 0.0:
            continue
        bl = EK.link_blocks(tj, fp, c, h[j], ln, ux, uy, dvx, dvy, udv)
        mj = invm[j]
        for q in range(8):
            B5[j, 2, q] -= mj * bl[q]
        if j + 1 < N:
            mk = invm[j + 1]
            for q in range(8):
                B5[j, 3, q] += mj * bl[q]
                B5[j + 1, 1, q] += mk * bl[q]
                B5[j + 1, 2, q] -= mk * bl[q]
        else:  # the W row: -(-T u) . v_pin, as the springs'
            q = tj / ln
            tdx = fp * ux / h[j] + c * px / h[j]
            tdy = fp * uy / h[j] + c * py / h[j]
            uvp = ux * pin[2] + uy * pin[3]
            gW[8] += -(q * (pin[2] - uvp * ux) + tdx * uvp)
            gW[9] += -(q * (pin[3] - uvp * uy) + tdy * uvp)
            gW[10] += -(c * ux / h[j]) * uvp
            gW[11] += -(c * uy / h[j]) * uvp


@njit(cache=True, error_model="numpy")
def _springs_part(N, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J3, gW4, bd, B5, gW, gD):
    """The springs' (:func:`elastic_jacobian.jacobian`) and the compressed links' (:func:`compression_jacobian`)
    part of :func:`body_jacobian` into ``B5, gW, gD`` (overwritten)."""
    jacobian(N, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J3, gW4, gD)
    for i in range(N):
        for k in range(5):
            for q in range(8):
                B5[i, k, q] = J3[i, k - 1, q] if 1 <= k <= 3 else 0.0
    for q in range(NGW):
        gW[q] = 0.0
    for q in range(4):
        gW[8 + q] = gW4[q]
    if bd[7][P_PUSH] != 0.0:
        compression_jacobian(N, z, pin, h, invm, ea, damp, B5, gW, gD)


@njit(cache=True, error_model="numpy")
def body_jacobian(N, t, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J3, gW4, bd, B5, gW, gD, bs, zz, GX, GY,
                  QP, Q, hmin):
    """The Jacobian of :func:`body_rhs` at ``(t, z)`` (``T, E, ED`` the springs' there): the node blocks
    ``B5`` (N x 5 x 8, see the module), the W row's gradient ``gW`` (nodes N-3..N-1) and the D row's ``gD``
    (4N). The springs' part exact (:func:`elastic_jacobian.jacobian` into ``J3, gW4``), the compressed links'
    (:func:`compression_jacobian`), the body's (bending, drag) exact too
    (:func:`elastic_body_jacobian.body_terms_jacobian`, branch fastbody; the coloured differences before,
    :func:`body_jacobian_fd`, ~20x its cost). ``zz, GX, GY, QP, Q, hmin``: the differences' (unused here)."""
    _body_jacobian(N, t, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J3, gW4, bd, B5, gW, gD, bs, False)


@njit(cache=True, error_model="numpy")
def _body_jacobian(N, t, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J3, gW4, bd, B5, gW, gD, bs, ready):
    """:func:`body_jacobian`; ``ready``: ``bs`` holds the geometry and moments of ``(t, z)`` (:func:`body_rhs`
    there came just before: :func:`body_f_and_jacobian`)."""
    _springs_part(N, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J3, gW4, bd, B5, gW, gD)
    Bl, K0L, El, CN, CT, KN, KT, sc, cx, cc = bd
    ex, ey, phid = clamp_at(t, sc, cx, cc)
    body_terms_jacobian(N, z, pin, invm, Bl, K0L, El, CN, CT, KN, KT, sc, ex, ey, phid, bs, B5, gW, gD,
                        np.empty((4, 4)), ready)


@njit(cache=True, error_model="numpy")
def body_jacobian_fd(N, t, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J3, gW4, bd, B5, gW, gD, bs, zz, GX, GY,
                  QP, Q, hmin):
    """:func:`body_jacobian` with the body's part by central differences (the method's Jacobian until
    branch fastbody, kept for the tests of the exact one), the nodes perturbed in colours mod 5, the steps of
    :func:`elastic_body.body_jac_fd` (``1e-6 hmin`` in position, ``2e-6`` of the shortest link where a
    link is shorter than ``hmin/2``; ``1e-6 (1 + |v|)`` in velocity)."""
    _springs_part(N, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J3, gW4, bd, B5, gW, gD)
    n = z.shape[0]
    for i in range(n):
        zz[i] = z[i]
    UX, UY, LN, OM = bs[0], bs[1], bs[2], bs[3]
    FX, FY = bs[5], bs[6]
    _geometry(N, z, pin, UX, UY, LN, OM)
    lmin = LN[0]
    for j in range(1, N):
        lmin = min(lmin, LN[j])
    hm = min(hmin, 2.0 * lmin)
    wp = 0.0
    for col in range(5):
        for comp in range(4):
            for sgn in (1.0, -1.0):
                for i in range(col, N, 5):
                    v = z[4 * i + comp]
                    e = 1e-6 * hm if comp < 2 else 1e-6 * (1.0 + abs(v))
                    zz[4 * i + comp] = v + sgn * e
                wv = _body_eval(N, t, zz, pin, h, ea, damp, bd, bs, Q)
                if sgn > 0.0:
                    wp = wv
                    for k in range(N):
                        GX[k] = FX[k]
                        GY[k] = FY[k]
                        QP[k] = Q[k]
                else:
                    wp -= wv
                    for k in range(N):
                        GX[k] -= FX[k]
                        GY[k] -= FY[k]
                        QP[k] -= Q[k]
            for i in range(col, N, 5):
                v = z[4 * i + comp]
                e = 1e-6 * hm if comp < 2 else 1e-6 * (1.0 + abs(v))
                zz[4 * i + comp] = v
                s2 = 1.0 / (2.0 * e)
                for k in range(max(0, i - 2), min(N, i + 3)):
                    kk = i - k + 2
                    if comp < 2:
                        B5[k, kk, comp] += GX[k] * invm[k] * s2
                        B5[k, kk, 2 + comp] += GY[k] * invm[k] * s2
                    else:
                        B5[k, kk, 4 + comp - 2] += GX[k] * invm[k] * s2
                        B5[k, kk, 6 + comp - 2] += GY[k] * invm[k] * s2
                acc = 0.0
                for k in range(max(0, i - 1), min(N, i + 2)):
                    acc += QP[k]
                gD[4 * i + comp] += acc * s2
                if i >= N - 3:
                    gW[4 * (i - N + 3) + comp] += wp * s2


@njit(cache=True, error_model="numpy")
def assemble_band5(N, B5, gh, ab):
    """``I - g^2 K - g C`` (``g = gh``) in :func:`banded_body.band_lu55`'s storage (row i, column j at
    ``ab[i, j - i + KLB]``), from the compact blocks ``B5``."""
    ab[:, :] = 0.0
    g2 = gh * gh
    for i in range(N):
        for k in range(5):
            jn = i - 2 + k
            if jn < 0 or jn >= N:
                continue
            for r in range(2):
                row = 2 * i + r
                for c in range(2):
                    v = -g2 * B5[i, k, 2 * r + c] - gh * B5[i, k, 4 + 2 * r + c]
                    if k == 2 and r == c:
                        v += 1.0
                    ab[row, 2 * jn + c - row + KLB] = v


@njit(cache=True, error_model="numpy")
def solve5(N, B5, gW, gD, gh, ab, piv, b, U, w):
    """``U = (I/gh - J)^{-1} b`` with the factors of ``I - g^2 K - g C`` in ``ab, piv``: the velocities
    from the reduced system (right side ``g b_v + g^2 K b_r``), the positions ``gh (b_r + U_v)``, then
    ``U_w = gh (b_w + gW . U)`` (nodes N-3..N-1) and ``U_d = gh (b_d + gD . U)``."""
    g2 = gh * gh
    for i in range(N):
        for r in range(2):
            acc = gh * b[4 * i + 2 + r]
            for k in range(5):
                jn = i - 2 + k
                if jn < 0 or jn >= N:
                    continue
                acc += g2 * (B5[i, k, 2 * r] * b[4 * jn] + B5[i, k, 2 * r + 1] * b[4 * jn + 1])
            w[2 * i + r] = acc
    band_solve55(ab, 2 * N, piv, w)
    for i in range(N):
        for r in range(2):
            uv = w[2 * i + r]
            U[4 * i + 2 + r] = uv
            U[4 * i + r] = gh * (b[4 * i + r] + uv)
    accd = 0.0
    for i in range(4 * N):
        accd += gD[i] * U[i]
    accw = 0.0
    for i in range(max(0, N - 3), N):
        for c in range(4):
            accw += gW[4 * (i - N + 3) + c] * U[4 * i + c]
    U[4 * N] = gh * (b[4 * N] + accw)
    U[4 * N + 1] = gh * (b[4 * N + 1] + accd)


@njit(cache=True, error_model="numpy")
def body_step(N, t, hs, z0, ft, auto, pins, h, invm, ea, damp, tabe, tabt, g, bd, B5, gW, gD, ab, piv, St, ytmp,
              btmp, w, z1, c23, tol, T, E, ED, FV, bs, ctl):
    """One RODAS4 step with the body (:func:`elastic_rodas.rodas_step`'s arithmetic; the stage
    matrix factored pivoted, :func:`assemble_band5`). Returns the scaled error (inf when the stage
    matrix is singular or a value not finite)."""
    n = z0.shape[0]
    gh = GAMMA * hs
    assemble_band5(N, B5, gh, ab)
    ctl[ER.C_NPIV] += 1.0
    if band_lu55(ab, 2 * N, piv) != 0:
        return np.inf
    cc = np.empty(5)
    for st in range(6):
        if st == 0:
            for i in range(n):
                btmp[i] = St[0, i]
        else:
            ER._comb(ytmp, z0, St, A_ST[st], st, n)
            ts = t if auto else t + C_NODE[st] * hs
            body_rhs(N, ts, ytmp, pins[st], h, invm, ea, damp, tabe, tabt, g, bd, btmp, T, E, ED, FV, bs)
            for j in range(st):
                cc[j] = C_ST[st, j] / hs
            ER._comb(btmp, btmp, St, cc, st, n)
        if not auto and D_TIME[st] != 0.0:
            dth = D_TIME[st] * hs
            for i in range(n):
                btmp[i] += dth * ft[i]
        solve5(N, B5, gW, gD, gh, ab, piv, btmp, St[1 + st], w)
    ER._comb(z1, z0, St, A_ST[5], 5, n)
    return ER.finish_step(z0, z1, St, c23, tol, n)


@njit(cache=True, error_model="numpy")
def body_f_and_jacobian(N, t, z, pinpar, pintab, pin, h, invm, ea, damp, tabe, tabt, g, bd, f, B5, gW, gD, T, E, ED,
                        FV, J3, gW4, bs, zz, GX, GY, QP, Q, hmin):
    """``f(t, z)`` and the Jacobian there (:func:`body_jacobian`, the springs' from the same tensions, the body's
    from the same geometry and moments); leaves the body's force on the held end in ``bs[5][N], bs[6][N]``
    (the Jacobian's scratch there stops at N - 1: :func:`elastic_body_advance.body_measure` reads them)."""
    ER.pin_at(t, pinpar, pintab, pin)
    body_rhs(N, t, z, pin, h, invm, ea, damp, tabe, tabt, g, bd, f, T, E, ED, FV, bs)
    _body_jacobian(N, t, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J3, gW4, bd, B5, gW, gD, bs, True)


@njit(cache=True, error_model="numpy")
def body_accept(N, y, St, B5, gW, gD, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g, bd, ytmp,
                btmp, w, ft, z1, y0d, c23, ctl, T, E, ED, FV, J3, gW4, bs, zz, GX, GY, QP, Q, hmin):
    """:func:`elastic_rodas.rodas_accept` with the body: attempts from ``(ctl[C_T], y)`` until one is
    accepted (the same step rule); returns 0, or 1 when the step fell below 1e-14 |t|."""
    n = y.shape[0]
    t = ctl[ER.C_T]
    tb = ctl[ER.C_TB]
    auto = ctl[ER.C_AUTO] != 0.0
    tol = ctl[ER.C_TOL]
    reject = False
    while True:
        hs, last, failed = ER.attempt_step(ctl, t, tb)
        if failed:
            return 1
        if auto:
            for s in range(6):
                ER.pin_at(t, pinpar, pintab, pins[s])
        else:
            for s in range(6):
                ER.pin_at(t + C_NODE[s] * hs, pinpar, pintab, pins[s])
            dt = 1e-7 * max(1.0, abs(t))
            ER.pin_at(t + dt, pinpar, pintab, pins[6])
            body_rhs(N, t + dt, y, pins[6], h, invm, ea, damp, tabe, tabt, g, bd, ft, T, E, ED, FV, bs)
            ctl[ER.C_NFEV] += 1.0
            for i in range(n):
                ft[i] = (ft[i] - St[0, i]) / dt
        ctl[ER.C_NLU] += 1.0
        ctl[ER.C_NFEV] += 5.0
        err = body_step(N, t, hs, y, ft, auto, pins, h, invm, ea, damp, tabe, tabt, g, bd, B5, gW, gD, ab, piv, St,
                        ytmp, btmp, w, z1, c23, tol, T, E, ED, FV, bs, ctl)
        if not ER.control_step(ctl, hs, err, reject):
            reject = True
            continue
        tn = tb if last else t + hs
        for i in range(n):
            y0d[i] = y[i]
            y[i] = z1[i]
        ctl[ER.C_TOLD] = t
        ctl[ER.C_T] = tn
        body_f_and_jacobian(N, tn, y, pinpar, pintab, pins[6], h, invm, ea, damp, tabe, tabt, g, bd, St[0], B5, gW,
                            gD, T, E, ED, FV, J3, gW4, bs, zz, GX, GY, QP, Q, hmin)
        ctl[ER.C_NFEV] += 1.0
        ctl[ER.C_NJEV] += 1.0
        if last:
            ctl[ER.C_STATUS] = ER.FINISHED
        return 0


def body_arrays(lb):
    """The compiled functions' body tuple ``bd`` of a :class:`elastic_body.LineBody` ``lb``:
    ``(Bl, K0L, El, CN, CT, KN, KT, scalars, spline breakpoints, spline coefficients)``."""
    sc = np.zeros(9)
    sc[P_CD], sc[P_WX], sc[P_WY] = lb.cd, lb.wx, lb.wy
    sc[P_CLAMPED], sc[P_PUSH] = float(lb.clamped), float(lb.push)
    cx, cc = np.zeros(2), np.zeros((4, 1))
    if lb.clamped:
        if lb._spline is None:
            sc[P_CKIND], sc[P_CANG] = 1.0, float(lb.body.clamp)
        else:
            sc[P_CKIND], sc[P_TLAST], sc[P_ALAST] = 2.0, lb._tlast, lb._alast
            cx, cc = np.ascontiguousarray(lb._spline.x, dtype=float), np.ascontiguousarray(lb._spline.c, dtype=float)
    f = lambda a: np.ascontiguousarray(a, dtype=float)  # noqa: E731
    return (f(lb.Bl), f(lb.K0L), f(lb.El), f(lb.CN), f(lb.CT), f(lb.KN), f(lb.KT), sc, cx, cc)


class RodasBodyStepper(ER.RodasStepper):
    """:class:`elastic_rodas.RodasStepper` for a line with a body (``line.body`` a
    :class:`LineBody`): the same interface and counts; every factorisation pivoted."""

    def __init__(self, line, t0, z0, t_bound, tol, h0=None, *, pivoted=True):
        if line.body is None:
            raise ValueError("RodasBodyStepper needs a line with a body (line.body)")
        N = line.N
        n = 4 * N + 2
        self.bd = body_arrays(line.body)
        self.B5, self.gW12, self.gDb = np.zeros((N, 5, 8)), np.zeros(NGW), np.zeros(4 * N)
        self.J3, self.gW4 = np.zeros((N, 3, 8)), np.zeros(4)
        self.ab5 = np.zeros((2 * N, WIDTHB))
        self.piv5 = np.zeros(2 * N, dtype=np.int64)
        self.bs = tuple(np.zeros(N + 1) for _ in range(9))
        self.zz = np.zeros(n)
        self.GX, self.GY, self.QP, self.Q = (np.zeros(N + 1) for _ in range(4))
        self.hmin = float(line.h.min())
        super().__init__(line, t0, z0, t_bound, tol, h0, pivoted=True)
        # (a clamp given as samples turns with time: the system is not autonomous)
        self.ctl[ER.C_AUTO] = float(line.pin.kind == "fixed" and self.bd[7][P_CKIND] != 2.0)

    def bargs(self):
        return (*self.args(), self.bd)

    def f_and_jacobian(self):
        body_f_and_jacobian(self.N, self.ctl[ER.C_T], self.y, self.pinpar, self.pintab, self.pins[6], *self.bargs(),
                            self.St[0], self.B5, self.gW12, self.gDb, *self.work, self.J3, self.gW4, self.bs, self.zz,
                            self.GX, self.GY, self.QP, self.Q, self.hmin)

    def _f(self, t, z, out):
        self.ctl[ER.C_NFEV] += 1.0
        pin = np.zeros(4)
        ER.pin_at(float(t), self.pinpar, self.pintab, pin)
        body_rhs(self.N, float(t), z, pin, *self.bargs(), out, *self.work, self.bs)

    def jacobian_dense(self):
        """The dense Jacobian (node rows, W and D rows) the method uses at the current state (tests)."""
        N = self.N
        n = 4 * N + 2
        J = np.zeros((n, n))
        for i in range(N):
            J[4 * i, 4 * i + 2] = J[4 * i + 1, 4 * i + 3] = 1.0
            for k in range(5):
                jn = i - 2 + k
                if 0 <= jn < N:
                    for r in range(2):
                        for c in range(2):
                            J[4 * i + 2 + r, 4 * jn + c] = self.B5[i, k, 2 * r + c]
                            J[4 * i + 2 + r, 4 * jn + 2 + c] = self.B5[i, k, 4 + 2 * r + c]
        for i in range(max(0, N - 3), N):
            J[4 * N, 4 * i:4 * i + 4] = self.gW12[4 * (i - N + 3):4 * (i - N + 4)]
        J[4 * N + 1, :4 * N] = self.gDb
        return J

    def step(self):
        if self.status != "running":
            raise RuntimeError("the stepper is not running")
        t = self.t
        if body_accept(self.N, self.y, self.St, self.B5, self.gW12, self.gDb, self.ab5, self.piv5, self.pins,
                       self.pinpar, self.pintab, *self.bargs(), self.ytmp, self.btmp, self.w, self.ft, self.z1,
                       self.y0d, self.c23, self.ctl, *self.work, self.J3, self.gW4, self.bs, self.zz, self.GX,
                       self.GY, self.QP, self.Q, self.hmin) != 0:
            return f"step size {self.ctl[ER.C_HFAIL]:.3g} too small at t = {t:.9g}"
        self._dense = ER.RodasDense(self.t_old, self.t, self.y0d.copy(), self.y.copy(), self.c23)
        self.y = self.y.copy()
        return None
