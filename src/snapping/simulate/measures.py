"""Per-step diagnostics of a chain state (:func:`measure`): maximum speed, acceleration, tension and
curvature and where they are, the free end, the pin force, energy, link errors (the ``M_*``
entries of :mod:`snapping.simulate.layout`). Compiled with numba (``cache=True``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .layout import (M_AEND, M_AMAX, M_ENERGY, M_FINITE, M_KMAX, M_LENGTH, M_LINKERR, M_LINKERR0, M_PFX, M_PFY, M_SA,
                     M_SIGMAX, M_SIGMIN, M_SK, M_SSIGMIN, M_SV, M_VEND, M_VMAX, RAX, RAY, RSIG, RVX, RVY, RX, RY)


@njit(cache=True, fastmath=False, boundscheck=False)
def measure(N, Z, rinv0, meas):
    """Per-step diagnostics of state ``Z`` into ``meas`` (see the ``M_*`` indices).

    Maxima over the chain of speed, acceleration, tension and |curvature| with
    the arclength s = (N - i)/N of the node where they occur, the minimum tension
    with the arclength of its link's midpoint, free-end speed and
    acceleration, the force of the chain on the pin (-sigma_N N d_N), the total
    energy (zero for the chain hanging at rest), the largest link-length error
    against 1/N and against the initial chords (``rinv0[j] = 1/|d_j(0)|^2``),
    the total length, and whether everything is finite.

    The curvature maximum is found without an arctangent per joint: the turning
    angle |theta_{k+1} - theta_k| in [0, pi] (the unwrapped difference) grows
    monotonically with ``q = sin^2`` for a positive dot product and with
    ``2 - q`` otherwise; one ``atan2`` at the maximum gives its value.
    """
    x = Z[RX]
    y = Z[RY]
    vx = Z[RVX]
    vy = Z[RVY]
    ax = Z[RAX]
    ay = Z[RAY]
    sig = Z[RSIG]
    fN = float(N)
    n2 = fN * fN
    vmax2 = -1.0
    iv = 0
    amax2 = -1.0
    ia = 0
    ke = 0.0
    sy = 0.0
    fin = 0.0
    for i in range(N):
        v2 = vx[i] * vx[i] + vy[i] * vy[i]
        a2 = ax[i] * ax[i] + ay[i] * ay[i]
        ke += v2
        sy += y[i]
        fin += a2
        if v2 > vmax2:
            vmax2 = v2
            iv = i
        if a2 > amax2:
            amax2 = a2
            ia = i
    # links and joints
    smax = -np.inf
    smin = np.inf
    jmin = 0
    emax = -np.inf
    emin = np.inf
    rmax = -np.inf
    rmin = np.inf
    length = 0.0
    kbest = -1.0
    ik = -1
    kdot = 1.0
    kcr = 0.0
    dxp = x[1] - x[0]
    dyp = y[1] - y[0]
    lp = dxp * dxp + dyp * dyp
    for j in range(N - 1):
        dxn = x[j + 2] - x[j + 1]
        dyn = y[j + 2] - y[j + 1]
        ln = dxn * dxn + dyn * dyn
        e = n2 * lp
        if e > emax:
            emax = e
        if e < emin:
            emin = e
        rr = lp * rinv0[j]
        if rr > rmax:
            rmax = rr
        if rr < rmin:
            rmin = rr
        length += math.sqrt(lp)
        if sig[j] > smax:
            smax = sig[j]
        if sig[j] < smin:
            smin = sig[j]
            jmin = j
        dot = dxp * dxn + dyp * dyn
        cr = dxp * dyn - dyp * dxn
        q = cr * cr / (lp * ln)
        key = q if dot > 0.0 else 2.0 - q
        if key > kbest:
            kbest = key
            ik = j
            kdot = dot
            kcr = cr
        dxp = dxn
        dyp = dyn
        lp = ln
    j = N - 1
    e = n2 * lp
    emax = max(emax, e)
    emin = min(emin, e)
    rr = lp * rinv0[j]
    rmax = max(rmax, rr)
    rmin = min(rmin, rr)
    length += math.sqrt(lp)
    if sig[j] > smax:
        smax = sig[j]
    if sig[j] < smin:
        smin = sig[j]
        jmin = j
    meas[M_VMAX] = math.sqrt(vmax2)
    meas[M_SV] = (fN - iv) / fN
    meas[M_AMAX] = math.sqrt(amax2)
    meas[M_SA] = (fN - ia) / fN
    meas[M_SIGMAX] = smax
    meas[M_SIGMIN] = smin
    meas[M_SSIGMIN] = (fN - jmin - 0.5) / fN  # the midpoint of link jmin (s_link)
    if ik >= 0:
        meas[M_KMAX] = fN * math.atan2(abs(kcr), kdot)
        meas[M_SK] = (fN - (ik + 1)) / fN
    else:  # N = 1: no joint
        meas[M_KMAX] = 0.0
        meas[M_SK] = np.nan
    meas[M_VEND] = math.sqrt(vx[0] * vx[0] + vy[0] * vy[0])
    meas[M_AEND] = math.sqrt(ax[0] * ax[0] + ay[0] * ay[0])
    # force of the chain on the pin: -sigma_N N d_N with d_N = -r_N
    meas[M_PFX] = sig[N - 1] * fN * x[N - 1]
    meas[M_PFY] = sig[N - 1] * fN * y[N - 1]
    meas[M_ENERGY] = ke / (2.0 * fN) - sy / fN + (fN + 1.0) / (2.0 * fN)
    meas[M_LINKERR] = max(math.sqrt(emax) - 1.0, 1.0 - math.sqrt(emin))
    meas[M_LINKERR0] = max(math.sqrt(rmax) - 1.0, 1.0 - math.sqrt(rmin))
    meas[M_LENGTH] = length
    tot = fin + ke + sy + smax + length
    meas[M_FINITE] = 1.0 if (tot - tot) == 0.0 else 0.0
