"""The Jacobian of the elastic line's RODAS4 (:mod:`snapping.simulate.elastic_rodas`), exact and
compiled: the node blocks of :func:`snapping.simulate.elastic_kernels.jac_blocks` in compact
form and the rows of the two integrals W (the held end's work) and D (the damping's
dissipation), which ``jac_blocks`` leaves out and a Rosenbrock method needs (or the two
integrals lose order).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import elastic_kernels as EK

__all__ = ["jacobian", "wd_gradients", "gradient_span", "full_jacobian"]


@njit(cache=True, error_model="numpy")
def wd_gradients(N, z, pin, h, ea, damp, tabe, tabt, T, E, ED, FV, gW, gD):
    """The gradients of the W row (the held end's power ``T u . v_pin`` of link N-1) and of
    the D row (``sum_j h_j (T_j - f_j) edot_j``) by the node state (x, y, vx, vy per node):
    ``gW`` (4 entries, node N-1's), ``gD`` (4N). ``T, E, ED, FV`` are those of ``z``
    (:func:`elastic_kernels.tensions`). (:func:`jacobian`'s, its node blocks discarded.)"""
    J = np.zeros((N, 3, 8))
    jacobian(N, z, pin, h, np.ones(N), ea, damp, tabe, tabt, T, E, ED, J, gW, gD)


@njit(cache=True, error_model="numpy")
def _add_block(J, i, k, s, a00, a01, a10, a11, b00, b01, b10, b11):
    J[i, k, 0] += s * a00
    J[i, k, 1] += s * a01
    J[i, k, 2] += s * a10
    J[i, k, 3] += s * a11
    J[i, k, 4] += s * b00
    J[i, k, 5] += s * b01
    J[i, k, 6] += s * b10
    J[i, k, 7] += s * b11


@njit(cache=True, error_model="numpy")
def add_link_gradient(gD, N, j, gdx, gdy, gvx, gvy):
    """Link j's part of the D row's gradient: ``-(gdx, gdy, gvx, gvy)`` on node j's position and
    velocity, ``+`` on node j + 1's (none for the held end)."""
    gD[4 * j] -= gdx
    gD[4 * j + 1] -= gdy
    gD[4 * j + 2] -= gvx
    gD[4 * j + 3] -= gvy
    if j + 1 < N:
        gD[4 * j + 4] += gdx
        gD[4 * j + 5] += gdy
        gD[4 * j + 6] += gvx
        gD[4 * j + 7] += gvy


@njit(cache=True, error_model="numpy")
def jacobian(N, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, J, gW, gD):
    """The Jacobian the method uses, from the tensions ``T``, strains ``E`` and strain rates
    ``ED`` of ``z`` (those :func:`elastic_kernels.rhs` left): the node blocks of
    :func:`elastic_kernels.jac_blocks` in compact form, ``J[i, k, 0:4] = K`` and
    ``J[i, k, 4:8] = C`` (node i's accelerations by node ``i - 1 + k``'s positions and
    velocities, 2 x 2 row-major; the identity of ``dr/dt = v`` is implicit), and the W and D
    rows of :func:`wd_gradients`, in one pass over the links with the same arithmetic as
    those two (so the same numbers)."""
    for i in range(4 * N):
        gD[i] = 0.0
    for k in range(4):
        gW[k] = 0.0
    J[:] = 0.0
    for j in range(N):
        if E[j] <= 0.0:
            continue
        ln = h[j] * (1.0 + E[j])
        if j + 1 < N:
            x1, y1, vx1, vy1 = z[4 * j + 4], z[4 * j + 5], z[4 * j + 6], z[4 * j + 7]
        else:
            x1, y1, vx1, vy1 = pin[0], pin[1], pin[2], pin[3]
        ux = (x1 - z[4 * j]) / ln
        uy = (y1 - z[4 * j + 1]) / ln
        dvx = vx1 - z[4 * j + 2]
        dvy = vy1 - z[4 * j + 3]
        udv = ux * dvx + uy * dvy
        px = (dvx - udv * ux) / ln
        py = (dvy - udv * uy) / ln
        ed = ED[j]
        c = damp[j]
        tj = T[j]
        # the D row (wd_gradients)
        if tj > 0.0:
            gdx, gdy = 2.0 * c * ed * px, 2.0 * c * ed * py
            gvx, gvy = 2.0 * c * ed * ux, 2.0 * c * ed * uy
        else:
            f, fp = EK.law(E[j], ea[j], tabe, tabt)
            gdx, gdy = -(fp * ed * ux + f * px), -(fp * ed * uy + f * py)
            gvx, gvy = -f * ux, -f * uy
        add_link_gradient(gD, N, j, gdx, gdy, gvx, gvy)
        if tj == 0.0:
            continue
        # the node blocks (jac_given)
        _, fp = EK.law(E[j], ea[j], tabe, tabt)
        a00, a01, a10, a11, b00, b01, b10, b11 = EK.link_blocks(tj, fp, c, h[j], ln, ux, uy, dvx, dvy, udv)
        mj = invm[j]
        _add_block(J, j, 1, -1.0 * mj, a00, a01, a10, a11, b00, b01, b10, b11)
        if j + 1 < N:
            _add_block(J, j, 2, 1.0 * mj, a00, a01, a10, a11, b00, b01, b10, b11)
            mk = invm[j + 1]
            _add_block(J, j + 1, 0, 1.0 * mk, a00, a01, a10, a11, b00, b01, b10, b11)
            _add_block(J, j + 1, 1, -1.0 * mk, a00, a01, a10, a11, b00, b01, b10, b11)
        else:  # the W row (wd_gradients)
            q = tj / ln
            tdx = fp * ux / h[j] + c * px / h[j]
            tdy = fp * uy / h[j] + c * py / h[j]
            uvp = ux * pin[2] + uy * pin[3]
            gW[0] = -(q * (pin[2] - uvp * ux) + tdx * uvp)
            gW[1] = -(q * (pin[3] - uvp * uy) + tdy * uvp)
            gW[2] = -(c * ux / h[j]) * uvp
            gW[3] = -(c * uy / h[j]) * uvp


@njit(cache=True, error_model="numpy")
def gradient_span(N, gD):
    """``[lo, hi)``, the indices outside which ``gD`` is zero (the D row's reach: the damped
    taut links; empty without damping)."""
    lo = 4 * N
    hi = 0
    for i in range(4 * N):
        if gD[i] != 0.0:
            lo = min(lo, i)
            hi = i + 1
    return lo, max(lo, hi)


def full_jacobian(line, t, z):
    """The dense Jacobian the method uses at (t, z): ``jac_blocks``'s node part with the W and
    D rows of :func:`wd_gradients` (for tests against differences)."""
    J = line.jac(t, z).toarray()
    N = line.N
    gW, gD = np.zeros(4), np.zeros(4 * N)
    T, E, ED, FV = (np.zeros(N) for _ in range(4))
    EK.tensions(N, z, line.pin_state(t), line.h, line.ea, line.damp, line.tabe, line.tabt, T, E, ED, FV)
    wd_gradients(N, z, line.pin_state(t), line.h, line.ea, line.damp, line.tabe, line.tabt, T, E, ED, FV, gW, gD)
    J[4 * N, 4 * (N - 1):4 * N] = gW
    J[4 * N + 1, :4 * N] = gD
    return J
