"""The error norms of the 3D stepper's DOP853 steps (:mod:`snapping.spatial.solve3d`).

Error control on the planar method's quantities (:func:`step_error3d`, the stepper's norm:
max norm over links, rtol = atol = ``tol``): each link's angle and angular-velocity errors,
the parts of its ``e_j`` and ``u_j`` estimates normal to ``e_j`` (what the projection
:func:`snapping.spatial.chain3d.project` leaves), by vector length, so the norm does not
depend on the frame. The norm before it, per component scaled by the link's norms
(:func:`step_error3d_components`), is kept for comparison;
:data:`snapping.spatial.solve3d.NORM_MODE` chooses. Both read the stages ``Kst`` of
:mod:`snapping.simulate.rk`'s Dormand-Prince 8(5,3) pair (its tableau and its component error
:func:`snapping.simulate.rk.scaled_error`) and return the scaled error of a step (accept if
<= 1; inf if not finite).

Example
-------
>>> import numpy as np
>>> from snapping.simulate import rk as R
>>> from snapping.spatial.error3d import step_error3d
>>> N = 2; y = np.zeros(6 * N + 1); y[:N] = 1.0                     # two links along x, at rest
>>> K = np.zeros((R.NSX, y.size))                                    # no rates: no error
>>> float(step_error3d(N, 0.1, 1e-8, y, y, K, np.zeros(y.size)))
0.0
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..simulate import rk as R

__all__ = ["step_error3d", "step_error3d_components"]

#: elements a block of the stage arithmetic (:func:`snapping.spatial.solve3d._stage_state3d`) and of
#: the error estimates (:func:`step_error3d`): the output block stays in cache
STAGE_BLOCK = 1024


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def step_error3d(N, h, tol, y0, y1, Kst, ytmp):
    """The scaled error of a step (accept if <= 1), the planar method's quantity in 3D.

    Hairer's DOP853 estimates (the 5th- and 3rd-order error vectors ``E5, E3`` of
    :func:`snapping.simulate.rk.scaled_error`) of each link's direction ``e_j`` and rate
    ``u_j``, taken as 3-vectors and projected onto the plane normal to ``e_j`` (at the step's
    end): the parts along ``e_j`` (a drift of ``|e_j|`` off 1 and of ``e_j . u_j`` off 0) are
    what :func:`snapping.spatial.chain3d.project` removes after the step, so they are not an
    error of the solution. What is left is the error of the link's angle (``|P E5(e_j)|``, the
    planar method's angle error) and of its angular velocity (``|P E5(u_j)|``: for a planar
    motion ``u_j = omega_j n x e_j``, and the error of ``omega_j``), scaled as the planar norm
    scales them: by ``tol (1 + |e_j|)`` and ``tol (1 + |u_j|)`` (the larger at the step's two
    ends). Error per link ``|h| |E5|^2 / sqrt(|E5|^2 + 0.01 |E3|^2)`` (Hairer's combination with
    the squares summed over the vector's components); ``W`` (and ``D`` with a body): per
    component, their own size. The maximum over links and components; inf if not finite.
    Uses ``ytmp`` and ``Kst[NSX - 2:]`` (dense-output stages, free during a step) as scratch."""
    n3 = 3 * N
    n6 = 2 * n3
    ah = abs(h)
    e5v = ytmp
    e3v = Kst[R.NSX - 1]  # (scratch: the last dense-output stage, which dense_build3d fills afresh)
    for i0 in range(0, n6, STAGE_BLOCK):  # (the estimates of all e, u components first, in cache blocks)
        i1 = min(i0 + STAGE_BLOCK, n6)
        nb = i1 - i0
        b5 = e5v[i0:i1]
        b3 = e3v[i0:i1]
        for i in range(nb):
            b5[i] = 0.0
            b3[i] = 0.0
        for jj in range(R._E5NZ.size):
            k = R._E5NZ[jj]
            c = R.E5_RK[k]
            Kk = Kst[k, i0:i1]
            for i in range(nb):
                b5[i] += c * Kk[i]
        for jj in range(R._E3NZ.size):
            k = R._E3NZ[jj]
            c = R.E3_RK[k]
            Kk = Kst[k, i0:i1]
            for i in range(nb):
                b3[i] += c * Kk[i]
    out = Kst[R.NSX - 2]  # (scratch as e3v: each link's two terms, then their maximum)
    for part in range(2):  # (over slices, branch-free: vectorises)
        o = part * n3
        vx0, vy0, vz0 = y0[o:o + N], y0[o + N:o + 2 * N], y0[o + 2 * N:o + n3]
        vx1, vy1, vz1 = y1[o:o + N], y1[o + N:o + 2 * N], y1[o + 2 * N:o + n3]
        ex1, ey1, ez1 = y1[:N], y1[N:2 * N], y1[2 * N:n3]
        p5x, p5y, p5z = e5v[o:o + N], e5v[o + N:o + 2 * N], e5v[o + 2 * N:o + n3]
        p3x, p3y, p3z = e3v[o:o + N], e3v[o + N:o + 2 * N], e3v[o + 2 * N:o + n3]
        ob = out[part * N:(part + 1) * N]
        for j in range(N):
            ex = ex1[j]
            ey = ey1[j]
            ez = ez1[j]
            inv = 1.0 / math.sqrt(ex * ex + ey * ey + ez * ez)
            ex *= inv
            ey *= inv
            ez *= inv
            a0 = vx0[j] * vx0[j] + vy0[j] * vy0[j] + vz0[j] * vz0[j]
            a1 = vx1[j] * vx1[j] + vy1[j] * vy1[j] + vz1[j] * vz1[j]
            isc = 1.0 / (tol * (1.0 + math.sqrt(max(a0, a1))))
            d5 = p5x[j] * ex + p5y[j] * ey + p5z[j] * ez
            d3 = p3x[j] * ex + p3y[j] * ey + p3z[j] * ez
            qx = (p5x[j] - d5 * ex) * isc
            qy = (p5y[j] - d5 * ey) * isc
            qz = (p5z[j] - d5 * ez) * isc
            s5 = qx * qx + qy * qy + qz * qz
            qx = (p3x[j] - d3 * ex) * isc
            qy = (p3y[j] - d3 * ey) * isc
            qz = (p3z[j] - d3 * ez) * isc
            s3 = qx * qx + qy * qy + qz * qz
            d = s5 + 0.01 * s3
            v = ah * s5 / math.sqrt(d)
            ob[j] = v if d > 0.0 else (0.0 if d == 0.0 else np.inf)
    err = 0.0
    for i in range(2 * N):
        v = out[i]
        err = v if not (v <= err) else err
    for i in range(n6, y0.shape[0]):  # W (and D with a body): their own size
        v = R.scaled_error(Kst, i, y0[i], y1[i], h, tol)
        if not (v <= err):
            err = v
    return err if err - err == 0.0 else np.inf


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def step_error3d_components(N, h, tol, y0, y1, Kst, ytmp):
    """The former scaled error of a step (kept for comparison, ``NORM_MODE = 1``) (accept if <= 1): Hairer's DOP853 estimate of every
    component (as :func:`snapping.simulate.rk.scaled_error`), scaled per link by
    ``tol (1 + |e_j|)`` for the three components of ``e_j`` and ``tol (1 + |u_j|)`` for those
    of ``u_j`` (the larger at the step's two ends), maximum over the components. The norm of
    the link's vector, not each component's own size: a component that passes through zero
    while the link turns fast (``|u_j|`` large) would otherwise ask for a relative accuracy
    the planar method (whose angular velocity is the link's ``|u_j|``) never asks for."""
    n3 = 3 * N
    for j in range(N):
        a0 = 0.0
        a1 = 0.0
        b0 = 0.0
        b1 = 0.0
        for c in range(3):
            i = c * N + j
            a0 += y0[i] * y0[i]
            a1 += y1[i] * y1[i]
            b0 += y0[n3 + i] * y0[n3 + i]
            b1 += y1[n3 + i] * y1[n3 + i]
        se = math.sqrt(max(a0, a1))
        su = math.sqrt(max(b0, b1))
        for c in range(3):
            ytmp[c * N + j] = se
            ytmp[n3 + c * N + j] = su
    n = y0.shape[0]
    for i in range(2 * n3, n):  # W (and D with a body): their own size
        ytmp[i] = max(abs(y0[i]), abs(y1[i]))
    for i in range(n):  # (rk's branch-free component error with |y| := the link's norm: vectorises)
        ytmp[i] = R.scaled_error(Kst, i, ytmp[i], ytmp[i], h, tol)
    err = 0.0
    for i in range(n):
        if ytmp[i] > err:
            err = ytmp[i]
    return err if err - err == 0.0 else np.inf
