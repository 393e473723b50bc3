"""The held end's prescribed motion, compiled: ``r_p(t)``, its velocity and acceleration.

The held end (node N of :mod:`snapping.spatial.chain3d`) is fixed or moves as prescribed
(:class:`snapping.spatial.held3d.Pin3D` is the checked, user-facing form): its kind and
scalars sit in the model's parameter vector ``par`` (laid out here, in the lowest module that
reads it; :func:`snapping.spatial.chain3d.make_model` fills it), a circle's and a table's data
in a block appended to it (:func:`circle_data`, :func:`table_data`). :func:`pin3d` evaluates
it in the compiled kernels (the right-hand side, the measurements) and for Python alike, so
that what is run, recorded and reported is one function; :func:`breakpoints` lists the times
where its acceleration jumps (the steppers land on them).

Example
-------
>>> import numpy as np
>>> from snapping.spatial import motion3d as M
>>> par = np.zeros(M.NPAR); par[M.P_PIN] = M.PIN_PULL; par[M.P_T1] = 0.5   # a pull from 0 for 0.5
>>> par[M.P_AX:M.P_AZ + 1] = (0.0, -2.0, 1.0)
>>> [float(v) for v in M.pin3d(0.25, par)[6:]], M.breakpoints(par)
([0.0, -2.0, 1.0], [0.0, 0.5])
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..simulate.general import _spline

__all__ = ["pin3d", "circle_data", "table_data", "breakpoints", "PIN_FIXED", "PIN_PULL", "PIN_FLICK", "PIN_TABLE",
           "PIN_CIRCLE"]

# ---------------------------------------------------------------- the model's scalar parameters
#: gravity (3), the held end's kind, its acceleration (3; a data block's offset for a circle or a
#: table), start and duration, the reference plane's normal (3), the body block's offset (0: none)
P_GX, P_GY, P_GZ, P_PIN, P_AX, P_AY, P_AZ, P_T0, P_T1, P_NX, P_NY, P_NZ, P_BODY = range(13)
NPAR = 13
#: the held end's kinds (``par[P_PIN]``)
PIN_FIXED, PIN_PULL, PIN_FLICK, PIN_TABLE, PIN_CIRCLE = 0.0, 1.0, 2.0, 3.0, 4.0
TWO_PI = 2.0 * math.pi


def circle_data(radius: float, omega: float, a, b) -> np.ndarray:
    """The data block of :data:`PIN_CIRCLE`: ``[R, omega, a, b]`` (``a``: the unit vector
    from the circle's centre to the start, ``b = axis x a``)."""
    return np.concatenate([[radius, omega], np.asarray(a, dtype=float), np.asarray(b, dtype=float)])


def table_data(t, cx, cy, cz) -> np.ndarray:
    """The data block of :data:`PIN_TABLE`: ``[n, t_0..t_{n-1}, cx, cy, cz]``, ``c*`` the
    (4, n - 1) cubic coefficients of each coordinate (scipy ``CubicSpline.c``)."""
    t = np.asarray(t, dtype=float)
    return np.concatenate([[float(t.size)], t] + [np.asarray(c, dtype=float).ravel() for c in (cx, cy, cz)])


def breakpoints(par) -> list[float]:
    """Times where the held end's acceleration (or a derivative of it) jumps: steps land on
    them (the start and end of a pull, a flick or a circle's ramp; a table's last sample)."""
    kind = par[P_PIN]
    if kind == PIN_CIRCLE and par[P_T1] == 0.0:
        return []
    if kind in (PIN_PULL, PIN_FLICK, PIN_CIRCLE):
        return sorted({float(v) for v in (par[P_T0], par[P_T0] + par[P_T1]) if math.isfinite(v)})
    if kind == PIN_TABLE:
        o = int(par[P_AX])
        return [float(par[o + int(par[o])])]
    return []


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _circle(t, par):
    """The held end on a circle: the phase phi, its rate ramped from 0 to omega over T from t0
    by ``phi'' = (omega/T)(1 - cos(2 pi tau))``, tau = (t - t0)/T (T = 0: steady from t0 = 0,
    the held end moving from the start, no breakpoint),
    then ``r = R((cos phi - 1) a + sin phi b)`` (the start on the circle, at the origin)."""
    o = int(par[P_AX])
    R = par[o]
    w = par[o + 1]
    t0 = par[P_T0]
    T = par[P_T1]
    if T > 0.0 and t <= t0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if T > 0.0 and t <= t0 + T:
        tau = (t - t0) / T
        c2 = math.cos(TWO_PI * tau)
        ph = w * T * (0.5 * tau * tau + (c2 - 1.0) / (TWO_PI * TWO_PI))
        ph1 = w * (tau - math.sin(TWO_PI * tau) / TWO_PI)
        ph2 = (w / T) * (1.0 - c2)
    else:
        ph = w * (0.5 * T + (t - t0 - T))
        ph1 = w
        ph2 = 0.0
    cs = math.cos(ph)
    sn = math.sin(ph)
    ax, ay, az = par[o + 2], par[o + 3], par[o + 4]
    bx, by, bz = par[o + 5], par[o + 6], par[o + 7]
    tx, ty, tz = -sn * ax + cs * bx, -sn * ay + cs * by, -sn * az + cs * bz  # the tangent
    nx, ny, nz = cs * ax + sn * bx, cs * ay + sn * by, cs * az + sn * bz  # outward, from the centre
    v = R * ph1
    at = R * ph2
    ac = R * ph1 * ph1
    return (R * (nx - ax), R * (ny - ay), R * (nz - az), v * tx, v * ty, v * tz,
            at * tx - ac * nx, at * ty - ac * ny, at * tz - ac * nz)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _table(t, par):
    """The held end on cubic splines through samples (as the planar
    :func:`snapping.simulate.general.pin_kinematics`): the first piece's tangent before the
    first sample, constant velocity after the last (at the last sample: the left limit)."""
    o = int(par[P_AX])
    n = int(par[o])
    m = n - 1
    t_first = par[o + 1]
    t_last = par[o + n]
    c0 = o + 1 + n
    if t <= t_first:
        x, vx, ax = _spline(par, n, c0, 0, 0.0)
        y, vy, ay = _spline(par, n, c0 + 4 * m, 0, 0.0)
        z, vz, az = _spline(par, n, c0 + 8 * m, 0, 0.0)
        dt = t - t_first
        if dt == 0.0:
            return x, y, z, vx, vy, vz, ax, ay, az
        return x + vx * dt, y + vy * dt, z + vz * dt, vx, vy, vz, 0.0, 0.0, 0.0
    if t > t_last:
        u = t_last - par[o + m]
        x, vx, _ = _spline(par, n, c0, m - 1, u)
        y, vy, _ = _spline(par, n, c0 + 4 * m, m - 1, u)
        z, vz, _ = _spline(par, n, c0 + 8 * m, m - 1, u)
        dt = t - t_last
        return x + vx * dt, y + vy * dt, z + vz * dt, vx, vy, vz, 0.0, 0.0, 0.0
    i = np.searchsorted(par[o + 1:o + 1 + n], t) - 1
    if i < 0:
        i = 0
    u = t - par[o + 1 + i]
    x, vx, ax = _spline(par, n, c0, i, u)
    y, vy, ay = _spline(par, n, c0 + 4 * m, i, u)
    z, vz, az = _spline(par, n, c0 + 8 * m, i, u)
    return x, y, z, vx, vy, vz, ax, ay, az


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def pin3d(t, par):
    """(x, y, z, vx, vy, vz, ax, ay, az) of the held end at time t (left limits at breakpoints)."""
    kind = par[P_PIN]
    if kind == PIN_FIXED:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if kind == PIN_CIRCLE:
        return _circle(t, par)
    if kind == PIN_TABLE:
        return _table(t, par)
    ax = par[P_AX]
    ay = par[P_AY]
    az = par[P_AZ]
    t0 = par[P_T0]
    T = par[P_T1]
    if t <= t0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    tau = t - t0
    if kind == PIN_PULL:
        if t <= t0 + T:
            q = 0.5 * tau * tau
            return ax * q, ay * q, az * q, ax * tau, ay * tau, az * tau, ax, ay, az
        q = 0.5 * T * T + T * (tau - T)
        return ax * q, ay * q, az * q, ax * T, ay * T, az * T, 0.0, 0.0, 0.0
    # PIN_FLICK
    tau = min(tau, T)
    w = TWO_PI / T
    sn = math.sin(w * tau)
    v = (1.0 - math.cos(w * tau)) / w
    r = (tau - sn / w) / w
    a = sn if t < t0 + T else 0.0
    return ax * r, ay * r, az * r, ax * v, ay * v, az * v, ax * a, ay * a, az * a
