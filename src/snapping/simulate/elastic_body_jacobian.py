"""The exact Jacobian of the extensible line's body terms (bending, bending damping, drag; branch
fastbody), for :func:`snapping.simulate.elastic_rodas_body.body_jacobian`.

The terms are :func:`elastic_rodas_body._body_eval`'s (``elastic_body.body_forces`` without the
compressed links' push, which :func:`elastic_rodas_body.compression_jacobian` differentiates): the
node forces, the held end's power ``M_N phi' - F_N . v_pin`` and the dissipation ``2R - P_drag``.
Their derivatives, written out (``d_j = r_{j+1} - r_j``, ``L_j = |d_j|``, the link's unit vector
``u_j``, ``g_j = (-d_jy, d_jx)/L_j^2 = dtheta_j/dd_j``, ``omega_j = d_j x dv_j / L_j^2``):

* ``d omega_j = a_j . dd_j + g_j . d(dv_j)`` with ``a_j = (dv_y - 2 d_x omega_j, -dv_x - 2 d_y omega_j)/L_j^2``;
  ``dg_j/dd_j = [[2 d_x d_y, d_y^2 - d_x^2], [d_y^2 - d_x^2, -2 d_x d_y]]/L_j^4``;
* the node moment ``M_i = Bl_i (psi_i - K0L_i) + El_i (omega_i - omega_{i-1})``, ``dpsi_i = g_i . dd_i -
  g_{i-1} . dd_{i-1}`` (the clamp's ``M_N``: ``psi_N = phi - theta_{N-1}``, ``omega_N = phi'``): its
  gradient reaches nodes i-1, i, i+1;
* the link's couple ``T_j = (M_{j+1} - M_j) g_j``, ``+T_j`` on node j+1 and ``-T_j`` on node j:
  ``dT_j = g_j dQ_j + Q_j dg_j`` (nodes j-1..j+2);
* the drag at node j, ``F = -(CN |u x tau| + KN) u_n - (CT |u . tau| + KT) u_t [- c_d |u| u]``,
  ``u = v_j - wind``: ``dF/du`` and ``dF/dtau`` at fixed tau and u, the tangent ``tau`` (the unit
  bisector ``b/|b|`` of ``u_{j-1}, u_j``, or ``u_j``) through ``dtau = (I - tau tau^T)/|b| db``,
  ``du_j = (I - u_j u_j^T)/L_j dd_j``;
* the dissipation's gradient ``2 El_i dom_i d(dom_i)`` and ``-(dF_j^T v_j + F_j . dv_j)``.

The kinks (``|u x tau|``, ``|u . tau|``, the bisector's switch to link j's direction) are taken on
their side (the sign at the point), as the rhs is. Checked against the coloured central differences
(:func:`elastic_rodas_body.body_jacobian_fd`) and differences of the rhs in
tests/test_elastic_rodas_body.py.
"""

from __future__ import annotations

import math

from numba import njit

from .elastic_body import _geometry

__all__ = ["body_terms_jacobian", "bending_jacobian", "drag_jacobian"]


@njit(cache=True, error_model="numpy", inline="always")
def _mgrad(i, N, Bl, El, clamped, GLX, GLY, AX, AY, s, dq, base):
    """Add ``s dM_i/d(node n)`` (position x, y, velocity x, y) into ``dq[n - base]`` for the nodes
    n it reaches (i-1, i, i+1; the held end N left out). ``M_0 = 0``; ``M_N`` the clamp's (0 at a hinge)."""
    if i <= 0:
        return
    if i >= N:
        if not clamped:
            return
        j = N - 1
        n = j - base
        if 0 <= n < 4:
            dq[n, 0] += s * (Bl[N] * GLX[j] + El[N] * AX[j])
            dq[n, 1] += s * (Bl[N] * GLY[j] + El[N] * AY[j])
            dq[n, 2] += s * El[N] * GLX[j]
            dq[n, 3] += s * El[N] * GLY[j]
        return
    ppx = Bl[i] * GLX[i] + El[i] * AX[i]
    ppy = Bl[i] * GLY[i] + El[i] * AY[i]
    pmx = Bl[i] * GLX[i - 1] + El[i] * AX[i - 1]
    pmy = Bl[i] * GLY[i - 1] + El[i] * AY[i - 1]
    vpx = El[i] * GLX[i]
    vpy = El[i] * GLY[i]
    vmx = El[i] * GLX[i - 1]
    vmy = El[i] * GLY[i - 1]
    n = i - 1 - base
    if 0 <= n < 4:
        dq[n, 0] += s * pmx
        dq[n, 1] += s * pmy
        dq[n, 2] += s * vmx
        dq[n, 3] += s * vmy
    n = i - base
    if 0 <= n < 4:
        dq[n, 0] -= s * (ppx + pmx)
        dq[n, 1] -= s * (ppy + pmy)
        dq[n, 2] -= s * (vpx + vmx)
        dq[n, 3] -= s * (vpy + vmy)
    if i + 1 < N:
        n = i + 1 - base
        if 0 <= n < 4:
            dq[n, 0] += s * ppx
            dq[n, 1] += s * ppy
            dq[n, 2] += s * vpx
            dq[n, 3] += s * vpy


@njit(cache=True, error_model="numpy", inline="always")
def _om_grad(l, N, s, GLX, GLY, AX, AY, gD):
    """Add ``s d(omega_l)`` (nodes l and l+1; the held end left out) to the D row ``gD``."""
    gD[4 * l] -= s * AX[l]
    gD[4 * l + 1] -= s * AY[l]
    gD[4 * l + 2] -= s * GLX[l]
    gD[4 * l + 3] -= s * GLY[l]
    if l + 1 < N:
        gD[4 * l + 4] += s * AX[l]
        gD[4 * l + 5] += s * AY[l]
        gD[4 * l + 6] += s * GLX[l]
        gD[4 * l + 7] += s * GLY[l]


@njit(cache=True, error_model="numpy")
def bending_jacobian(N, z, pin, invm, Bl, K0L, El, clamped, ex, ey, phid, UX, UY, LN, OM, MM, GLX, GLY, AX, AY, B5,
                     gW, gD, dq, have_mm=False):
    """Add the bending's (stiffness, damping, the clamp's) derivatives to the node blocks ``B5`` (N x 5 x 8,
    :mod:`elastic_rodas_body`'s layout), the W row ``gW`` (nodes N-3..N-1) and the D row ``gD``. The
    geometry ``UX, UY, LN, OM`` of ``z`` on entry; ``GLX, GLY, AX, AY`` (N + 1) and ``dq`` (4 x 4) scratch, ``MM``
    the node moments (N + 1: computed here, or with ``have_mm`` those :func:`elastic_body.body_forces` left
    there at this state: the atan2s of an evaluation not done twice)."""
    for j in range(N):
        if j + 1 < N:
            vx1 = z[4 * j + 6]
            vy1 = z[4 * j + 7]
        else:
            vx1 = pin[2]
            vy1 = pin[3]
        dvx = vx1 - z[4 * j + 2]
        dvy = vy1 - z[4 * j + 3]
        L = LN[j]
        dx = UX[j] * L
        dy = UY[j] * L
        L2 = dx * dx + dy * dy
        GLX[j] = -dy / L2
        GLY[j] = dx / L2
        AX[j] = (dvy - 2.0 * dx * OM[j]) / L2
        AY[j] = (-dvx - 2.0 * dy * OM[j]) / L2
    if not have_mm:  # (elastic_body.body_forces' moments, its arithmetic)
        MM[0] = 0.0
        for i in range(1, N):
            cr = UX[i - 1] * UY[i] - UY[i - 1] * UX[i]
            dt = UX[i - 1] * UX[i] + UY[i - 1] * UY[i]
            MM[i] = Bl[i] * (math.atan2(cr, dt) - K0L[i]) + El[i] * (OM[i] - OM[i - 1])
        MM[N] = 0.0
        if clamped:
            j = N - 1
            cr = UX[j] * ey - UY[j] * ex
            dt = UX[j] * ex + UY[j] * ey
            MM[N] = Bl[N] * (math.atan2(cr, dt) - K0L[N]) + El[N] * (phid - OM[j])
    for j in range(N):
        # T_j = Q_j g_j (+T_j on node j+1, -T_j on node j), Q_j = M_{j+1} - M_j: the gradients of M_j
        # (nodes j-1, j, j+1: "a") and M_{j+1} (nodes j, j+1, j+2: "b"), as _mgrad adds them
        ppxa = ppya = pmxa = pmya = vpxa = vpya = vmxa = vmya = 0.0
        if j >= 1:
            bl = Bl[j]
            el = El[j]
            ppxa = bl * GLX[j] + el * AX[j]
            ppya = bl * GLY[j] + el * AY[j]
            pmxa = bl * GLX[j - 1] + el * AX[j - 1]
            pmya = bl * GLY[j - 1] + el * AY[j - 1]
            vpxa = el * GLX[j]
            vpya = el * GLY[j]
            vmxa = el * GLX[j - 1]
            vmya = el * GLY[j - 1]
        ppxb = ppyb = pmxb = pmyb = vpxb = vpyb = vmxb = vmyb = 0.0
        i = j + 1
        if i < N or clamped:
            bl = Bl[i]
            el = El[i]
            pmxb = bl * GLX[j] + el * AX[j]
            pmyb = bl * GLY[j] + el * AY[j]
            vmxb = el * GLX[j]
            vmyb = el * GLY[j]
            if i < N:
                ppxb = bl * GLX[i] + el * AX[i]
                ppyb = bl * GLY[i] + el * AY[i]
                vpxb = el * GLX[i]
                vpyb = el * GLY[i]
        dq[0, 0] = -pmxa
        dq[0, 1] = -pmya
        dq[0, 2] = -vmxa
        dq[0, 3] = -vmya
        dq[1, 0] = pmxb + (ppxa + pmxa)
        dq[1, 1] = pmyb + (ppya + pmya)
        dq[1, 2] = vmxb + (vpxa + vmxa)
        dq[1, 3] = vmyb + (vpya + vmya)
        dq[2, 0] = -(ppxb + pmxb) - ppxa
        dq[2, 1] = -(ppyb + pmyb) - ppya
        dq[2, 2] = -(vpxb + vmxb) - vpxa
        dq[2, 3] = -(vpyb + vmyb) - vpya
        dq[3, 0] = ppxb
        dq[3, 1] = ppyb
        dq[3, 2] = vpxb
        dq[3, 3] = vpyb
        q = MM[j + 1] - MM[j]
        gx = GLX[j]
        gy = GLY[j]
        L = LN[j]
        ux = UX[j]
        uy = UY[j]
        il2 = 1.0 / (L * L)
        dgxx = 2.0 * ux * uy * il2 * q  # q dg/dd_j
        dgxy = (uy * uy - ux * ux) * il2 * q
        dgyy = -dgxx
        lo = 1 if j == 0 else 0
        hi = min(4, N - j + 1)  # (columns j-1+nn < N)
        for nn in range(lo, hi):
            col = j - 1 + nn
            kxx = gx * dq[nn, 0]
            kxy = gx * dq[nn, 1]
            kyx = gy * dq[nn, 0]
            kyy = gy * dq[nn, 1]
            if nn == 2:
                kxx += dgxx
                kxy += dgxy
                kyx += dgxy
                kyy += dgyy
            elif nn == 1:
                kxx -= dgxx
                kxy -= dgxy
                kyx -= dgxy
                kyy -= dgyy
            cxx = gx * dq[nn, 2]
            cxy = gx * dq[nn, 3]
            cyx = gy * dq[nn, 2]
            cyy = gy * dq[nn, 3]
            w = -invm[j]  # row j: -T_j
            k = nn + 1
            B5[j, k, 0] += w * kxx
            B5[j, k, 1] += w * kxy
            B5[j, k, 2] += w * kyx
            B5[j, k, 3] += w * kyy
            B5[j, k, 4] += w * cxx
            B5[j, k, 5] += w * cxy
            B5[j, k, 6] += w * cyx
            B5[j, k, 7] += w * cyy
            if j + 1 < N:  # row j+1: +T_j
                w = invm[j + 1]
                k = nn
                B5[j + 1, k, 0] += w * kxx
                B5[j + 1, k, 1] += w * kxy
                B5[j + 1, k, 2] += w * kyx
                B5[j + 1, k, 3] += w * kyy
                B5[j + 1, k, 4] += w * cxx
                B5[j + 1, k, 5] += w * cxy
                B5[j + 1, k, 6] += w * cyx
                B5[j + 1, k, 7] += w * cyy
            else:  # the held end: W' gets -T_{N-1} . v_pin
                m = 4 * (col - N + 3)
                if m < 0:
                    continue
                gW[m] -= pin[2] * kxx + pin[3] * kyx
                gW[m + 1] -= pin[2] * kxy + pin[3] * kyy
                gW[m + 2] -= pin[2] * cxx + pin[3] * cyx
                gW[m + 3] -= pin[2] * cxy + pin[3] * cyy
    if clamped:  # W' gets M_N phi'
        for a in range(4):
            for b in range(4):
                dq[a, b] = 0.0
        _mgrad(N, N, Bl, El, clamped, GLX, GLY, AX, AY, phid, dq, N - 1)
        for c in range(4):
            gW[8 + c] += dq[0, c]
    # D: the bending damping's 2R = sum El_i dom_i^2 (the clamp's dom_N = phi' - omega_{N-1})
    for i in range(1, N):
        s = 2.0 * El[i] * (OM[i] - OM[i - 1])
        _om_grad(i, N, s, GLX, GLY, AX, AY, gD)
        _om_grad(i - 1, N, -s, GLX, GLY, AX, AY, gD)
    if clamped:
        s = 2.0 * El[N] * (phid - OM[N - 1])
        _om_grad(N - 1, N, -s, GLX, GLY, AX, AY, gD)


@njit(cache=True, error_model="numpy")
def drag_jacobian(N, z, invm, CN, CT, KN, KT, cd, wx, wy, UX, UY, LN, B5, gD):
    """Add the drag's derivatives (:func:`force_drag.add_drag`'s law at the nodes 0..N-1) to the node
    blocks ``B5`` and the D row ``gD`` (``-F_j . v_j``). The geometry ``UX, UY, LN`` of ``z`` on entry."""
    for j in range(N):
        tx = UX[j]
        ty = UY[j]
        bis = False
        nb = 1.0
        if j > 0:
            bx = UX[j - 1] + tx
            by = UY[j - 1] + ty
            nb = math.sqrt(bx * bx + by * by)
            if nb > 1e-12:
                tx = bx / nb
                ty = by / nb
                bis = True
        vx = z[4 * j + 2]
        vy = z[4 * j + 3]
        ux = vx - wx
        uy = vy - wy
        ut = ux * tx + uy * ty
        cr = ux * ty - uy * tx
        an = CN[j] * abs(cr) + KN[j]
        at = CT[j] * abs(ut) + KT[j]
        unx = ux - ut * tx
        uny = uy - ut * ty
        fx = -an * unx - at * ut * tx
        fy = -an * uny - at * ut * ty
        scr = 1.0 if cr > 0.0 else (-1.0 if cr < 0.0 else 0.0)
        # dF/du at fixed tau: -CN s_cr un m^T - an (I - tau tau^T) - (CT |ut| + at) tau tau^T, m = (ty, -tx)
        ccn = CN[j] * scr
        ctt = CT[j] * abs(ut) + at
        uxx = -ccn * unx * ty - an * (1.0 - tx * tx) - ctt * tx * tx
        uxy = ccn * unx * tx + an * tx * ty - ctt * tx * ty
        uyx = -ccn * uny * ty + an * tx * ty - ctt * tx * ty
        uyy = ccn * uny * tx - an * (1.0 - ty * ty) - ctt * ty * ty
        if j == 0 and cd != 0.0:
            u = math.sqrt(ux * ux + uy * uy)
            fx -= cd * u * ux
            fy -= cd * u * uy
            if u > 0.0:
                uxx -= cd * (u + ux * ux / u)
                uxy -= cd * ux * uy / u
                uyx -= cd * ux * uy / u
                uyy -= cd * (u + uy * uy / u)
        w = invm[j]
        B5[j, 2, 4] += w * uxx
        B5[j, 2, 5] += w * uxy
        B5[j, 2, 6] += w * uyx
        B5[j, 2, 7] += w * uyy
        gD[4 * j + 2] -= vx * uxx + vy * uyx + fx
        gD[4 * j + 3] -= vx * uxy + vy * uyy + fy
        # dF/dtau at fixed u: -un (CN s_cr (-uy, ux))^T + (an - at)(tau u^T + ut I) - CT |ut| tau u^T
        d = an - at
        e = CT[j] * abs(ut)
        txx = ccn * unx * uy + d * (tx * ux + ut) - e * tx * ux
        txy = -ccn * unx * ux + d * tx * uy - e * tx * uy
        tyx = ccn * uny * uy + d * ty * ux - e * ty * ux
        tyy = -ccn * uny * ux + d * (ty * uy + ut) - e * ty * uy
        # dtau/dd: P_tau P_u / (|b| L) (bisector, both links), or P_u / L (link j's direction)
        for side in range(2):
            l = j - 1 + side
            if l < 0 or (side == 0 and not bis):
                continue
            ax = UX[l]
            ay = UY[l]
            s = 1.0 / LN[l]
            pxx = (1.0 - ax * ax) * s  # P_u / L
            pxy = -ax * ay * s
            pyy = (1.0 - ay * ay) * s
            if bis:
                qxx = (1.0 - tx * tx) / nb
                qxy = -tx * ty / nb
                qyy = (1.0 - ty * ty) / nb
                mxx = qxx * pxx + qxy * pxy
                mxy = qxx * pxy + qxy * pyy
                myx = qxy * pxx + qyy * pxy
                myy = qxy * pxy + qyy * pyy
            else:
                mxx, mxy, myx, myy = pxx, pxy, pxy, pyy
            # dF/dd_l = (dF/dtau)(dtau/dd_l)
            kxx = txx * mxx + txy * myx
            kxy = txx * mxy + txy * myy
            kyx = tyx * mxx + tyy * myx
            kyy = tyx * mxy + tyy * myy
            for end in range(2):  # d_l = r_{l+1} - r_l
                col = l + end
                if col >= N:
                    continue
                sg = 1.0 if end == 1 else -1.0
                k = col - j + 2
                B5[j, k, 0] += sg * w * kxx
                B5[j, k, 1] += sg * w * kxy
                B5[j, k, 2] += sg * w * kyx
                B5[j, k, 3] += sg * w * kyy
                gD[4 * col] -= sg * (vx * kxx + vy * kyx)
                gD[4 * col + 1] -= sg * (vx * kxy + vy * kyy)


@njit(cache=True, error_model="numpy")
def body_terms_jacobian(N, z, pin, invm, Bl, K0L, El, CN, CT, KN, KT, sc, ex, ey, phid, bs, B5, gW, gD, dq,
                        ready=False):
    """Add the derivatives of :func:`elastic_rodas_body._body_eval`'s terms (the body without the
    compressed links' push) to ``B5``, ``gW``, ``gD``: :func:`bending_jacobian` and
    :func:`drag_jacobian`. ``sc`` the body's scalars (tip drag, wind, clamped: indices 0..3 of
    :mod:`elastic_rodas_body`'s ``P_*``), ``(ex, ey, phid)`` the clamp at the time; ``bs`` the nine
    N + 1 scratch arrays, ``dq`` a 4 x 4 one. ``ready``: ``bs[0:5]`` hold the geometry and moments of this
    state (an evaluation of the body's forces at it, :func:`elastic_body.body_forces`, came just before)."""
    UX, UY, LN, OM, MM = bs[0], bs[1], bs[2], bs[3], bs[4]
    if not ready:
        _geometry(N, z, pin, UX, UY, LN, OM)
    bending_jacobian(N, z, pin, invm, Bl, K0L, El, sc[3] != 0.0, ex, ey, phid, UX, UY, LN, OM, MM, bs[5], bs[6],
                     bs[7], bs[8], B5, gW, gD, dq, ready)
    drag_jacobian(N, z, invm, CN, CT, KN, KT, sc[0], sc[1], sc[2], UX, UY, LN, B5, gD)
