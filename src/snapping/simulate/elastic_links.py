"""The extensible line in link coordinates (``elastic.solve(..., method="rodas4-links")``): the
compiled right-hand side, its exact Jacobian, and the maps to and from the node state.

Why: in node coordinates a RODAS4 step that turns a link by ``theta' h`` lengthens it at
second order, and the stiff force (``EA/h`` per length) turns that into a longitudinal ringing
whose error control caps the steps at large wave speed c (the elastic guide, "What sets the
steps at large c"). In the link's own length and angle a turn does not stretch, and the stiff
force is a function of the length alone.

The state is link-interleaved, ``z[4j:4j+4] = (l_j, theta_j, l_j', theta_j')`` for links
j = 0..N-1 (link j joins node j and node j+1; index 0 at the free end), then ``z[4N] = W`` and
``z[4N+1] = D`` as in :mod:`snapping.simulate.elastic_kernels`. With ``u_j = (cos, sin) theta_j``,
``n_j = (-sin, cos) theta_j`` and ``d_j = r_{j+1} - r_j = l_j u_j``, the nodes follow from the
held end's position and velocity (``r_N``, ``v_N``):

    r_i = r_N - sum_{j >= i} l_j u_j,    v_i = v_N - sum_{j >= i} (l_j' u_j + l_j theta_j' n_j).

The node accelerations are the node model's, ``a_i = (T_i u_i - T_{i-1} u_{i-1})/m_i + g e_y``
(``a_N`` the held end's), and ``d_j'' = a_{j+1} - a_j = (l_j'' - l_j theta_j'^2) u_j +
(l_j theta_j'' + 2 l_j' theta_j') n_j``, so

    l_j'' = u_j . d_j'' + l_j theta_j'^2,    theta_j'' = (n_j . d_j'' - 2 l_j' theta_j')/l_j.

The tension is the node model's, a function of ``e_j = l_j/h_j - 1`` and ``edot_j = l_j'/h_j``
only. ``d_j''`` involves the forces of links j - 1, j, j + 1, so the Jacobian is block
tridiagonal in 4 x 4 link blocks with ``d(l, theta)/dt = (l', theta')`` above: the compact
layout of :mod:`snapping.simulate.elastic_stage` (``J[i, k, 0:4] = K``, ``J[i, k, 4:8] = C``,
link i's second derivatives by link ``i - 1 + k``'s lengths and angles, and their rates).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .. import _validate as V
from . import elastic_kernels as EK
from . import general as G

__all__ = ["rhs", "jacobian", "to_nodes", "from_nodes", "node_error", "min_length_ratio", "pin6_at", "LinkLine",
           "SHORT_LINK"]

#: a step is rejected where a link would be shorter than this fraction of its rest length
SHORT_LINK = 1e-3


@njit(cache=True, error_model="numpy")
def pin6_at(t, pinpar, pintab, out):
    """The held end's (x, y, vx, vy, ax, ay) at ``t`` into ``out``."""
    x, y, vx, vy, ax, ay = G.pin_kinematics(t, pinpar, pintab)
    out[0] = x
    out[1] = y
    out[2] = vx
    out[3] = vy
    out[4] = ax
    out[5] = ay


@njit(cache=True, error_model="numpy")
def _forces(N, z, h, ea, damp, tabe, tabt, T, E, ED, FV, gx, gy):
    """Tensions (as :func:`elastic_kernels.tensions`), the link forces ``G_j = T_j u_j`` into
    ``gx, gy``; returns the dissipation rate ``sum_j h_j (T_j - f_j) edot_j``."""
    diss = 0.0
    for j in range(N):
        e = z[4 * j] / h[j] - 1.0
        ed = z[4 * j + 2] / h[j]
        E[j] = e
        ED[j] = ed
        tj, FV[j] = EK.link_tension(e, ed, ea[j], damp[j], tabe, tabt)
        T[j] = tj
        diss += h[j] * (tj - FV[j]) * ed
        th = z[4 * j + 1]
        gx[j] = tj * math.cos(th)
        gy[j] = tj * math.sin(th)
    return diss


@njit(cache=True, error_model="numpy")
def _dacc(N, j, pin, invm, g, gx, gy):
    """``d_j'' = a_{j+1} - a_j`` from the link forces."""
    gxm = gx[j - 1] if j > 0 else 0.0
    gym = gy[j - 1] if j > 0 else 0.0
    ajx = (gx[j] - gxm) * invm[j]
    ajy = (gy[j] - gym) * invm[j]
    if j + 1 < N:
        return (gx[j + 1] - gx[j]) * invm[j + 1] - ajx, (gy[j + 1] - gy[j]) * invm[j + 1] - ajy
    return pin[4] - ajx, (pin[5] - g) - ajy


@njit(cache=True, error_model="numpy")
def rhs(N, z, pin, h, invm, ea, damp, tabe, tabt, g, dz, T, E, ED, FV, gx, gy):
    """``dz/dt`` of the link state ``z`` with the held end at ``pin = (x, y, vx, vy, ax, ay)``;
    ``T, E, ED, FV`` receive the tensions, strains, strain rates and elastic parts
    (:func:`elastic_kernels.tensions`), ``gx, gy`` the link forces."""
    diss = _forces(N, z, h, ea, damp, tabe, tabt, T, E, ED, FV, gx, gy)
    for j in range(N):
        l = z[4 * j]
        th = z[4 * j + 1]
        ld = z[4 * j + 2]
        thd = z[4 * j + 3]
        c = math.cos(th)
        s = math.sin(th)
        dax, day = _dacc(N, j, pin, invm, g, gx, gy)
        dz[4 * j] = ld
        dz[4 * j + 1] = thd
        dz[4 * j + 2] = c * dax + s * day + l * thd * thd
        dz[4 * j + 3] = (-s * dax + c * day - 2.0 * ld * thd) / l
    j = N - 1
    if T[j] > 0.0:
        dz[4 * N] = gx[j] * pin[2] + gy[j] * pin[3]
    else:
        dz[4 * N] = 0.0
    dz[4 * N + 1] = diss


@njit(cache=True, error_model="numpy")
def _slopes(j, z, h, ea, damp, tabe, tabt, T, E):
    """``(dT/dl, dT/dl')`` of link j (zero where it carries nothing)."""
    if T[j] == 0.0:
        return 0.0, 0.0
    _, fp = EK.law(E[j], ea[j], tabe, tabt)
    return fp / h[j], damp[j] / h[j]


@njit(cache=True, error_model="numpy")
def jacobian(N, z, pin, h, invm, ea, damp, tabe, tabt, g, T, E, ED, FV, gx, gy, J, gW, gD, cw):
    """The exact Jacobian of :func:`rhs` at ``z`` (``T, E, ED, FV, gx, gy`` those :func:`rhs`
    left there): the compact blocks ``J`` (N x 3 x 8), the W row's gradient by link N - 1's
    variables ``gW`` (4) and the D row's ``gD`` (4N); ``cw`` (4 x N) work space."""
    J[:] = 0.0
    for i in range(4 * N):
        gD[i] = 0.0
    for k in range(4):
        gW[k] = 0.0
    co = cw[0]
    si = cw[1]
    tls = cw[2]
    tvs = cw[3]
    for j in range(N):
        co[j] = math.cos(z[4 * j + 1])
        si[j] = math.sin(z[4 * j + 1])
        tl, tv = _slopes(j, z, h, ea, damp, tabe, tabt, T, E)
        tls[j] = tl
        tvs[j] = tv
    for j in range(N):
        l = z[4 * j]
        cj = co[j]
        sj = si[j]
        ld = z[4 * j + 2]
        thd = z[4 * j + 3]
        dax, day = _dacc(N, j, pin, invm, g, gx, gy)
        # d_j'' by the forces of links j-1, j, j+1 (coefficients alpha)
        for k in range(3):
            m = j - 1 + k
            if m < 0 or m >= N:
                continue
            if k == 0:
                a = invm[j]
            elif k == 2:
                a = invm[j + 1]
            else:
                a = -invm[j] - (invm[j + 1] if j + 1 < N else 0.0)
            tl = tls[m]
            tv = tvs[m]
            cm = co[m]
            sm = si[m]
            uu = cj * cm + sj * sm  # u_j . u_m
            un = -cj * sm + sj * cm  # u_j . n_m
            nu = -sj * cm + cj * sm  # n_j . u_m
            nn = sj * sm + cj * cm  # n_j . n_m
            tm = T[m]
            J[j, k, 0] += a * tl * uu
            J[j, k, 1] += a * tm * un
            J[j, k, 2] += a * tl * nu / l
            J[j, k, 3] += a * tm * nn / l
            J[j, k, 4] += a * tv * uu
            J[j, k, 6] += a * tv * nu / l
        # the explicit dependence on link j's own variables
        ud = cj * dax + sj * day
        nd = -sj * dax + cj * day
        J[j, 1, 0] += thd * thd
        J[j, 1, 1] += nd
        J[j, 1, 5] += 2.0 * l * thd
        J[j, 1, 2] += -(nd - 2.0 * ld * thd) / (l * l)
        J[j, 1, 3] += -ud / l
        J[j, 1, 6] += -2.0 * thd / l
        J[j, 1, 7] += -2.0 * ld / l
        # the D row
        if E[j] > 0.0:
            if T[j] > 0.0:
                gD[4 * j + 2] = 2.0 * damp[j] * ld / h[j]
            else:
                f, fp = EK.law(E[j], ea[j], tabe, tabt)
                gD[4 * j] = -fp * ld / h[j]
                gD[4 * j + 2] = -f
    j = N - 1
    if T[j] > 0.0:
        cj = co[j]
        sj = si[j]
        uvp = cj * pin[2] + sj * pin[3]
        gW[0] = tls[j] * uvp
        gW[1] = T[j] * (-sj * pin[2] + cj * pin[3])
        gW[2] = tvs[j] * uvp


@njit(cache=True, error_model="numpy")
def to_nodes(N, zl, pin, zn):
    """The node state (:mod:`elastic_kernels`' layout) of the link state ``zl`` with the held
    end at ``pin`` (x, y, vx, vy, ...), into ``zn``; W and D copied."""
    x = pin[0]
    y = pin[1]
    vx = pin[2]
    vy = pin[3]
    for j in range(N - 1, -1, -1):
        l = zl[4 * j]
        c = math.cos(zl[4 * j + 1])
        s = math.sin(zl[4 * j + 1])
        ld = zl[4 * j + 2]
        w = l * zl[4 * j + 3]
        x -= l * c
        y -= l * s
        vx -= ld * c - w * s
        vy -= ld * s + w * c
        zn[4 * j] = x
        zn[4 * j + 1] = y
        zn[4 * j + 2] = vx
        zn[4 * j + 3] = vy
    zn[4 * N] = zl[4 * N]
    zn[4 * N + 1] = zl[4 * N + 1]


@njit(cache=True, error_model="numpy")
def from_nodes(N, zn, pin, zl):
    """The link state of the node state ``zn`` (held end at ``pin``) into ``zl``; angles in
    (-pi, pi]; W and D copied."""
    for j in range(N):
        if j + 1 < N:
            x1, y1, vx1, vy1 = zn[4 * j + 4], zn[4 * j + 5], zn[4 * j + 6], zn[4 * j + 7]
        else:
            x1, y1, vx1, vy1 = pin[0], pin[1], pin[2], pin[3]
        dx = x1 - zn[4 * j]
        dy = y1 - zn[4 * j + 1]
        dvx = vx1 - zn[4 * j + 2]
        dvy = vy1 - zn[4 * j + 3]
        l = math.sqrt(dx * dx + dy * dy)
        ux = dx / l
        uy = dy / l
        zl[4 * j] = l
        zl[4 * j + 1] = math.atan2(dy, dx)
        zl[4 * j + 2] = ux * dvx + uy * dvy
        zl[4 * j + 3] = (-uy * dvx + ux * dvy) / l
    zl[4 * N] = zn[4 * N]
    zl[4 * N + 1] = zn[4 * N + 1]


@njit(cache=True, error_model="numpy")
def node_error(N, zl, U, zn0, zn1, tol):
    """The scaled max norm, in node values, of the link-state error ``U`` at ``zl`` (mapped
    to the nodes' positions and velocities to first order), each node value scaled by
    ``tol (1 + max(|zn0|, |zn1|))`` as :func:`elastic_rodas.rodas_step` scales; inf if not
    finite."""
    ex = 0.0
    ey = 0.0
    evx = 0.0
    evy = 0.0
    err = 0.0
    for j in range(N - 1, -1, -1):
        l = zl[4 * j]
        c = math.cos(zl[4 * j + 1])
        s = math.sin(zl[4 * j + 1])
        ld = zl[4 * j + 2]
        thd = zl[4 * j + 3]
        dl = U[4 * j]
        dth = U[4 * j + 1]
        dld = U[4 * j + 2]
        dthd = U[4 * j + 3]
        ex += dl * c - l * dth * s
        ey += dl * s + l * dth * c
        q = dl * thd + l * dthd
        evx += dld * c - ld * dth * s - q * s - l * thd * dth * c
        evy += dld * s + ld * dth * c + q * c - l * thd * dth * s
        for k, ek in ((0, ex), (1, ey), (2, evx), (3, evy)):
            i = 4 * j + k
            e = abs(ek) / (tol * (1.0 + max(abs(zn0[i]), abs(zn1[i]))))
            if not (e - e == 0.0):
                return np.inf
            if e > err:
                err = e
    for i in range(4 * N, 4 * N + 2):
        e = abs(U[i]) / (tol * (1.0 + max(abs(zn0[i]), abs(zn1[i]))))
        if not (e - e == 0.0):
            return np.inf
        if e > err:
            err = e
    return err


@njit(cache=True)
def min_length_ratio(N, zl, h):
    """The smallest ``l_j/h_j``."""
    r = np.inf
    for j in range(N):
        q = zl[4 * j] / h[j]
        if q < r:
            r = q
    return r


class LinkLine:
    """An :class:`ElasticLine` seen in link coordinates: ``from_nodes``, ``to_nodes``, ``rhs``,
    ``jacobian`` (compact), ``full_jacobian`` (dense), ``pin(t)`` (the held end's x, y, vx,
    vy, ax, ay)."""

    def __init__(self, line):
        from .elastic_rodas import pin_model

        self.line = line
        self.N = line.N
        self.pinpar, self.pintab = pin_model(line)
        self.work = tuple(np.zeros(line.N) for _ in range(6))

    def args(self):
        ln = self.line
        return ln.h, ln._invm, ln.ea, ln.damp, ln.tabe, ln.tabt, ln.g

    def pin(self, t):
        out = np.zeros(6)
        pin6_at(float(t), self.pinpar, self.pintab, out)
        return out

    def from_nodes(self, t, zn):
        """The link state of the node state ``zn`` at ``t``; a link shorter than
        ``SHORT_LINK`` of its rest length is bad input (its angle is undefined)."""
        zn = np.asarray(zn, dtype=float)
        if zn.shape != (4 * self.N + 2,):
            raise V.SnappingInputError(f"state has shape {zn.shape}; expected ({4 * self.N + 2},)")
        zl = np.empty_like(zn)
        from_nodes(self.N, zn, self.pin(t), zl)
        r = zl[0:4 * self.N:4] / self.line.h
        if not np.all(r >= SHORT_LINK):
            j = int(np.argmin(np.where(np.isnan(r), -np.inf, r)))
            raise V.SnappingInputError(f"state: link {j} has length {zl[4 * j]!r}, {r[j]:.3g} of its rest length; "
                                       f"link coordinates need every link longer than {SHORT_LINK:g} of it")
        return zl

    def to_nodes(self, t, zl):
        zn = np.empty_like(zl)
        to_nodes(self.N, zl, self.pin(t), zn)
        return zn

    def rhs(self, t, zl):
        dz = np.empty_like(zl)
        rhs(self.N, zl, self.pin(t), *self.args(), dz, *self.work)
        return dz

    def jacobian(self, t, zl):
        """(J compact N x 3 x 8, gW, gD) at (t, zl)."""
        N = self.N
        pin = self.pin(t)
        dz = np.empty_like(zl)
        rhs(N, zl, pin, *self.args(), dz, *self.work)
        J, gW, gD = np.zeros((N, 3, 8)), np.zeros(4), np.zeros(4 * N)
        jacobian(N, zl, pin, *self.args(), *self.work, J, gW, gD, np.zeros((4, N)))
        return J, gW, gD

    def full_jacobian(self, t, zl):
        """The dense Jacobian of :meth:`rhs` (for tests)."""
        N = self.N
        J, gW, gD = self.jacobian(t, zl)
        A = np.zeros((4 * N + 2, 4 * N + 2))
        for i in range(N):
            A[4 * i, 4 * i + 2] = A[4 * i + 1, 4 * i + 3] = 1.0
            for k in range(3):
                m = i - 1 + k
                if 0 <= m < N:
                    for r in range(2):
                        for c in range(2):
                            A[4 * i + 2 + r, 4 * m + c] = J[i, k, 2 * r + c]
                            A[4 * i + 2 + r, 4 * m + 2 + c] = J[i, k, 4 + 2 * r + c]
        A[4 * N, 4 * (N - 1):4 * N] = gW
        A[4 * N + 1, :4 * N] = gD
        return A
