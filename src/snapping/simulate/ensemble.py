"""Ensembles: several chains of the same N (e.g. a sweep over chi) in one vectorised kernel.

Every member is a full DOP853 angle-form run (:mod:`snapping.simulate.highorder`) with
its own adaptive step, its own record, peaks, snapshots and stop; only the arithmetic is
shared. The members' states are stored interleaved, ``y[i, lane]``, so that every
loop of a step -- the polynomial sines and cosines, the stage sums, and above all the
tridiagonal elimination, whose recurrence is a chain of dependent multiply-adds that
a single chain cannot overlap -- runs over the lanes in SIMD registers, several
independent recurrences at once. Each iteration advances every active member by one
attempted step (of its own size); a member that stops (snap, t_end, failure) leaves
the lane set. After each attempt the member's own bookkeeping
(:func:`snapping.simulate.rk.after_attempt`) runs exactly as in a single run, so an
ensemble member's Dataset equals that of the single run to round-off.

Example
-------
>>> from snapping.simulate import run_ensemble
>>> dss = run_ensemble([0.3, 0.5], 30, chords="exact")
>>> [round(ds.attrs["t_snap_v"], 4) for ds in dss]
[1.1941, 1.1548]
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np
from numba import njit

from .. import _validate as V
from . import angles as AG
from . import highorder as HO
from . import kernels as K
from . import rk as R
from .chain import initial_state

__all__ = ["run_ensemble", "rhs_lanes"]

BLOCK = AG.BLOCK


@njit(cache=True, fastmath=False, boundscheck=False)
def rhs_lanes(N, L, y, f, c, s, S, cp, dp, sig, pm, pmm, qv, cpv, snx, snn):
    """:func:`angles.angle_rhs` for L interleaved chains: ``y, f`` (2N, >= L), work
    ``c, s, S, cp, dp, sig`` (N, >= L), lane vectors ``pm ... snn`` (>= L)."""
    fN = float(N)
    n2 = fN * fN
    inv_n2 = 1.0 / n2
    big = 0.0
    for j in range(N):
        for lane in range(L):
            big = max(big, abs(y[j, lane]))
    if big > AG.SINCOS_FAST_MAX:
        for j in range(N):
            for lane in range(L):
                c[j, lane] = math.cos(y[j, lane])
                s[j, lane] = math.sin(y[j, lane])
    else:
        for j in range(N):
            for lane in range(L):
                c[j, lane], s[j, lane] = AG.sincos1(y[j, lane])
    for j in range(N):
        for lane in range(L):
            f[j, lane] = y[N + j, lane]
    if N == 1:
        for lane in range(L):
            w = y[1, lane]
            sig[0, lane] = w * w - s[0, lane]
            f[1, lane] = -c[0, lane]
        return
    for lane in range(L):
        cpv[lane] = 0.0
        pm[lane] = 1.0
        pmm[lane] = 0.0
        qv[lane] = 0.0
    j0 = 0
    while j0 < N - 1:
        j1 = min(j0 + BLOCK, N - 1)
        for j in range(j0, j1):
            for lane in range(L):
                cj = c[j, lane]
                sj = s[j, lane]
                cn = c[j + 1, lane]
                sn = s[j + 1, lane]
                C = cn * cj + sn * sj
                S[j, lane] = sn * cj - cn * sj
                w = y[N + j, lane]
                r = -(w * w) * inv_n2
                cprev = cpv[lane]
                pml = pm[lane]
                p = -2.0 * pml - (cprev * cprev) * pmm[lane]
                q = r * pml - cprev * qv[lane]
                inv = 1.0 / p
                cp[j, lane] = C * pml * inv
                dp[j, lane] = q * inv
                pmm[lane] = pml
                pm[lane] = p
                qv[lane] = q
                cpv[lane] = C
        for lane in range(L):
            e = math.frexp(pm[lane])[1]
            sc = math.ldexp(1.0, -e)
            pm[lane] *= sc
            pmm[lane] *= sc
            qv[lane] *= sc
        j0 = j1
    jl = N - 1
    for lane in range(L):
        w = y[N + jl, lane]
        r = -(w * w) * inv_n2 + s[jl, lane] / fN
        cprev = cpv[lane]
        p = -pm[lane] - (cprev * cprev) * pmm[lane]
        q = r * pm[lane] - cprev * qv[lane]
        snx[lane] = q / p
        sig[jl, lane] = snx[lane]
        snn[lane] = 0.0
    for j in range(N - 2, -1, -1):
        if j + 1 == N - 1:
            for lane in range(L):
                sj = dp[j, lane] - cp[j, lane] * snx[lane]
                sig[j, lane] = sj
                f[N + j + 1, lane] = -n2 * sj * S[j, lane] - fN * c[j + 1, lane]
                snn[lane] = snx[lane]
                snx[lane] = sj
        else:
            for lane in range(L):
                sj = dp[j, lane] - cp[j, lane] * snx[lane]
                sig[j, lane] = sj
                f[N + j + 1, lane] = n2 * (snn[lane] * S[j + 1, lane] - sj * S[j, lane])
                snn[lane] = snx[lane]
                snx[lane] = sj
    for lane in range(L):
        f[N, lane] = n2 * snn[lane] * S[0, lane]


@njit(cache=True, fastmath=False, boundscheck=False)
def _rhs_tiles(N, y, f, c, s, S, cp, dp, sig):
    """:func:`angles.angle_rhs` (the same arithmetic) for the ``W = y.shape[1]`` (a
    multiple of 4) interleaved chains of ``y, f`` (2N, W); work ``c ... sig`` (N, W).
    The recurrences run on tiles of 4 lanes held in scalars (one SIMD register each)."""
    W = y.shape[1]
    fN = float(N)
    n2 = fN * fN
    inv_n2 = 1.0 / n2
    yf = y.reshape(-1)
    ff = f.reshape(-1)
    cf = c.reshape(-1)
    sf = s.reshape(-1)
    nW = N * W
    big = 0.0
    for i in range(nW):
        big = max(big, abs(yf[i]))
    if big > AG.SINCOS_FAST_MAX:
        for i in range(nW):
            cf[i] = math.cos(yf[i])
            sf[i] = math.sin(yf[i])
    else:
        for i in range(nW):
            cf[i], sf[i] = AG.sincos1(yf[i])
    for i in range(nW):
        ff[i] = yf[nW + i]
    if N == 1:
        for lane in range(W):
            w = y[1, lane]
            sig[0, lane] = w * w - s[0, lane]
            f[1, lane] = -c[0, lane]
        return
    for g in range(W // 4):
        l = 4 * g
        cprev0 = 0.0
        pm0 = 1.0
        pmm0 = 0.0
        q0 = 0.0
        cprev1 = 0.0
        pm1 = 1.0
        pmm1 = 0.0
        q1 = 0.0
        cprev2 = 0.0
        pm2 = 1.0
        pmm2 = 0.0
        q2 = 0.0
        cprev3 = 0.0
        pm3 = 1.0
        pmm3 = 0.0
        q3 = 0.0
        j0 = 0
        while j0 < N - 1:
            j1 = min(j0 + BLOCK, N - 1)
            for j in range(j0, j1):
                cj = c[j, l]
                sj = s[j, l]
                cn = c[j + 1, l]
                sn = s[j + 1, l]
                C = cn * cj + sn * sj
                S[j, l] = sn * cj - cn * sj
                w = y[N + j, l]
                r = -(w * w) * inv_n2
                p = -2.0 * pm0 - (cprev0 * cprev0) * pmm0
                q0 = r * pm0 - cprev0 * q0
                inv = 1.0 / p
                cp[j, l] = C * pm0 * inv
                dp[j, l] = q0 * inv
                pmm0 = pm0
                pm0 = p
                cprev0 = C
                cj = c[j, l + 1]
                sj = s[j, l + 1]
                cn = c[j + 1, l + 1]
                sn = s[j + 1, l + 1]
                C = cn * cj + sn * sj
                S[j, l + 1] = sn * cj - cn * sj
                w = y[N + j, l + 1]
                r = -(w * w) * inv_n2
                p = -2.0 * pm1 - (cprev1 * cprev1) * pmm1
                q1 = r * pm1 - cprev1 * q1
                inv = 1.0 / p
                cp[j, l + 1] = C * pm1 * inv
                dp[j, l + 1] = q1 * inv
                pmm1 = pm1
                pm1 = p
                cprev1 = C
                cj = c[j, l + 2]
                sj = s[j, l + 2]
                cn = c[j + 1, l + 2]
                sn = s[j + 1, l + 2]
                C = cn * cj + sn * sj
                S[j, l + 2] = sn * cj - cn * sj
                w = y[N + j, l + 2]
                r = -(w * w) * inv_n2
                p = -2.0 * pm2 - (cprev2 * cprev2) * pmm2
                q2 = r * pm2 - cprev2 * q2
                inv = 1.0 / p
                cp[j, l + 2] = C * pm2 * inv
                dp[j, l + 2] = q2 * inv
                pmm2 = pm2
                pm2 = p
                cprev2 = C
                cj = c[j, l + 3]
                sj = s[j, l + 3]
                cn = c[j + 1, l + 3]
                sn = s[j + 1, l + 3]
                C = cn * cj + sn * sj
                S[j, l + 3] = sn * cj - cn * sj
                w = y[N + j, l + 3]
                r = -(w * w) * inv_n2
                p = -2.0 * pm3 - (cprev3 * cprev3) * pmm3
                q3 = r * pm3 - cprev3 * q3
                inv = 1.0 / p
                cp[j, l + 3] = C * pm3 * inv
                dp[j, l + 3] = q3 * inv
                pmm3 = pm3
                pm3 = p
                cprev3 = C
            sc = math.ldexp(1.0, -math.frexp(pm0)[1])
            pm0 *= sc
            pmm0 *= sc
            q0 *= sc
            sc = math.ldexp(1.0, -math.frexp(pm1)[1])
            pm1 *= sc
            pmm1 *= sc
            q1 *= sc
            sc = math.ldexp(1.0, -math.frexp(pm2)[1])
            pm2 *= sc
            pmm2 *= sc
            q2 *= sc
            sc = math.ldexp(1.0, -math.frexp(pm3)[1])
            pm3 *= sc
            pmm3 *= sc
            q3 *= sc
            j0 = j1
        jl = N - 1
        w = y[N + jl, l]
        r = -(w * w) * inv_n2 + s[jl, l] / fN
        p = -pm0 - (cprev0 * cprev0) * pmm0
        q0 = r * pm0 - cprev0 * q0
        snx0 = q0 / p
        sig[jl, l] = snx0
        snn0 = 0.0
        w = y[N + jl, l + 1]
        r = -(w * w) * inv_n2 + s[jl, l + 1] / fN
        p = -pm1 - (cprev1 * cprev1) * pmm1
        q1 = r * pm1 - cprev1 * q1
        snx1 = q1 / p
        sig[jl, l + 1] = snx1
        snn1 = 0.0
        w = y[N + jl, l + 2]
        r = -(w * w) * inv_n2 + s[jl, l + 2] / fN
        p = -pm2 - (cprev2 * cprev2) * pmm2
        q2 = r * pm2 - cprev2 * q2
        snx2 = q2 / p
        sig[jl, l + 2] = snx2
        snn2 = 0.0
        w = y[N + jl, l + 3]
        r = -(w * w) * inv_n2 + s[jl, l + 3] / fN
        p = -pm3 - (cprev3 * cprev3) * pmm3
        q3 = r * pm3 - cprev3 * q3
        snx3 = q3 / p
        sig[jl, l + 3] = snx3
        snn3 = 0.0
        j = N - 2
        sj = dp[j, l] - cp[j, l] * snx0
        sig[j, l] = sj
        f[N + j + 1, l] = -n2 * sj * S[j, l] - fN * c[j + 1, l]
        snn0 = snx0
        snx0 = sj
        sj = dp[j, l + 1] - cp[j, l + 1] * snx1
        sig[j, l + 1] = sj
        f[N + j + 1, l + 1] = -n2 * sj * S[j, l + 1] - fN * c[j + 1, l + 1]
        snn1 = snx1
        snx1 = sj
        sj = dp[j, l + 2] - cp[j, l + 2] * snx2
        sig[j, l + 2] = sj
        f[N + j + 1, l + 2] = -n2 * sj * S[j, l + 2] - fN * c[j + 1, l + 2]
        snn2 = snx2
        snx2 = sj
        sj = dp[j, l + 3] - cp[j, l + 3] * snx3
        sig[j, l + 3] = sj
        f[N + j + 1, l + 3] = -n2 * sj * S[j, l + 3] - fN * c[j + 1, l + 3]
        snn3 = snx3
        snx3 = sj
        for j in range(N - 3, -1, -1):
            sj = dp[j, l] - cp[j, l] * snx0
            sig[j, l] = sj
            f[N + j + 1, l] = n2 * (snn0 * S[j + 1, l] - sj * S[j, l])
            snn0 = snx0
            snx0 = sj
            sj = dp[j, l + 1] - cp[j, l + 1] * snx1
            sig[j, l + 1] = sj
            f[N + j + 1, l + 1] = n2 * (snn1 * S[j + 1, l + 1] - sj * S[j, l + 1])
            snn1 = snx1
            snx1 = sj
            sj = dp[j, l + 2] - cp[j, l + 2] * snx2
            sig[j, l + 2] = sj
            f[N + j + 1, l + 2] = n2 * (snn2 * S[j + 1, l + 2] - sj * S[j, l + 2])
            snn2 = snx2
            snx2 = sj
            sj = dp[j, l + 3] - cp[j, l + 3] * snx3
            sig[j, l + 3] = sj
            f[N + j + 1, l + 3] = n2 * (snn3 * S[j + 1, l + 3] - sj * S[j, l + 3])
            snn3 = snx3
            snx3 = sj
        f[N, l] = n2 * snn0 * S[0, l]
        f[N, l + 1] = n2 * snn1 * S[0, l + 1]
        f[N, l + 2] = n2 * snn2 * S[0, l + 2]
        f[N, l + 3] = n2 * snn3 * S[0, l + 3]


@njit(cache=True, fastmath=False, boundscheck=False)
def _err_tiles(n, hL, y0, y1, KE, tolL, errL):
    """The scaled error of every lane (rk.rk_step's max norm and summation order)."""
    W = y0.shape[1]
    for lane in range(W):
        errL[lane] = 0.0
    for i in range(n):
        for g in range(W // 4):
            l = 4 * g
            e50 = 0.0
            e30 = 0.0
            e51 = 0.0
            e31 = 0.0
            e52 = 0.0
            e32 = 0.0
            e53 = 0.0
            e33 = 0.0
            for jj in range(R._E5NZ.size):
                j = R._E5NZ[jj]
                a = R.E5_RK[j]
                e50 += a * KE[j, i, l]
                e51 += a * KE[j, i, l + 1]
                e52 += a * KE[j, i, l + 2]
                e53 += a * KE[j, i, l + 3]
            for jj in range(R._E3NZ.size):
                j = R._E3NZ[jj]
                a = R.E3_RK[j]
                e30 += a * KE[j, i, l]
                e31 += a * KE[j, i, l + 1]
                e32 += a * KE[j, i, l + 2]
                e33 += a * KE[j, i, l + 3]
            sc = tolL[l] * (1.0 + max(abs(y0[i, l]), abs(y1[i, l])))
            e5 = e50 / sc
            e3 = e30 / sc
            d = e5 * e5 + 0.01 * e3 * e3
            if d > 0.0:
                e = abs(hL[l]) * e5 * e5 / math.sqrt(d)
                if e > errL[l]:
                    errL[l] = e
            elif not (d == 0.0):
                errL[l] = np.inf
            sc = tolL[l + 1] * (1.0 + max(abs(y0[i, l + 1]), abs(y1[i, l + 1])))
            e5 = e51 / sc
            e3 = e31 / sc
            d = e5 * e5 + 0.01 * e3 * e3
            if d > 0.0:
                e = abs(hL[l + 1]) * e5 * e5 / math.sqrt(d)
                if e > errL[l + 1]:
                    errL[l + 1] = e
            elif not (d == 0.0):
                errL[l + 1] = np.inf
            sc = tolL[l + 2] * (1.0 + max(abs(y0[i, l + 2]), abs(y1[i, l + 2])))
            e5 = e52 / sc
            e3 = e32 / sc
            d = e5 * e5 + 0.01 * e3 * e3
            if d > 0.0:
                e = abs(hL[l + 2]) * e5 * e5 / math.sqrt(d)
                if e > errL[l + 2]:
                    errL[l + 2] = e
            elif not (d == 0.0):
                errL[l + 2] = np.inf
            sc = tolL[l + 3] * (1.0 + max(abs(y0[i, l + 3]), abs(y1[i, l + 3])))
            e5 = e53 / sc
            e3 = e33 / sc
            d = e5 * e5 + 0.01 * e3 * e3
            if d > 0.0:
                e = abs(hL[l + 3]) * e5 * e5 / math.sqrt(d)
                if e > errL[l + 3]:
                    errL[l + 3] = e
            elif not (d == 0.0):
                errL[l + 3] = np.inf


#: elements per chunk of the flat stage sums (a chunk of the sum stays in L1)
CHUNK = 1024


@njit(cache=True, fastmath=False, boundscheck=False)
def _stage_flat(st, hx, y0, KE, out):
    """out = y0 + h_lane sum_j A[st, j] K_j for every lane, with the arithmetic of
    rk._stage_state; ``hx`` holds each element's lane step (h of its lane). Flat,
    vectorisable passes over chunks of CHUNK elements, each term read once."""
    nW = out.size
    o = out.reshape(-1)
    y = y0.reshape(-1)
    m = R._NZ[st]
    for c0 in range(0, nW, CHUNK):
        c1 = min(c0 + CHUNK, nW)
        oc = o[c0:c1]
        hc = hx[c0:c1]
        j = R._NZC[st, 0]
        a = R.A_RK[st, j]
        Kc = KE[j].reshape(-1)[c0:c1]
        yc = y[c0:c1]
        for i in range(c1 - c0):
            oc[i] = yc[i] + (hc[i] * a) * Kc[i]
        for jj in range(1, m):
            j = R._NZC[st, jj]
            a = R.A_RK[st, j]
            Kc = KE[j].reshape(-1)[c0:c1]
            for i in range(c1 - c0):
                oc[i] += (hc[i] * a) * Kc[i]


@njit(cache=True, fastmath=False, boundscheck=False)
def advance_lanes(N, L, act, Y0s, Y1s, KKs, TSs, HSs, DOKs, ctls, recs, pks, meass, Zs, cM, sM, sigM, rinv0,
                  yE0, KE, yEt, yE1, cE, sE, SE, cpE, dpE, sigE, hL, lastL, errL, tolL, hx, codes):
    """Advance the members ``act[:L]`` (one lane each) together until one of them needs
    Python; ``codes[m]`` then holds the return code of each member m that does (-1:
    none). The per-member arrays (first index m) are those of a single run's engine;
    the lane buffers have ``W = yE0.shape[1] >= L`` columns, a multiple of 4 (the
    lanes past L repeat lane 0 and are ignored)."""
    n = 2 * N
    W = yE0.shape[1]
    for lane in range(L):
        ctls[act[lane], R.Q_NCALL] = 0.0
        tolL[lane] = ctls[act[lane], R.Q_TOL]
    first = True
    slot = np.zeros(L, dtype=np.int64)  # per lane: the member's current slot, then the slot of its attempt
    acc = np.zeros(L, dtype=np.bool_)
    while True:
        for lane in range(L):
            m = act[lane]
            slot[lane] = int(ctls[m, R.Q_SLOT])
            h, last = R.step_size(ctls[m])
            hL[lane] = h
            lastL[lane] = 1.0 if last else 0.0
        # copies between the members' rows and the lane buffers run with the lane index
        # innermost, so that each cache line of a lane buffer is touched once per copy
        for i in range(n):
            for lane in range(L):
                m = act[lane]
                yE0[i, lane] = Y1s[m, slot[lane], i]
                KE[0, i, lane] = KKs[m, slot[lane], R.NS, i]
        if first:  # the padding lanes: a copy of lane 0 (finite; its results are not used)
            first = False
            for lane in range(L, W):
                hL[lane] = hL[0]
                tolL[lane] = tolL[0]
                for i in range(n):
                    yE0[i, lane] = yE0[i, 0]
                    KE[0, i, lane] = KE[0, i, 0]
        for i in range(n):  # each element's lane step, for the flat stage sums
            b = i * W
            for lane in range(W):
                hx[b + lane] = hL[lane]
        for st in range(1, R.NS):
            _stage_flat(st, hx, yE0, KE, yEt)
            _rhs_tiles(N, yEt, KE[st], cE, sE, SE, cpE, dpE, sigE)
        _stage_flat(R.NSX, hx, yE0, KE, yE1)  # (row NSX of _NZ: the weights B)
        _rhs_tiles(N, yE1, KE[R.NS], cE, sE, SE, cpE, dpE, sigE)
        # ---- error of each lane (as rk.rk_step)
        _err_tiles(n, hL, yE0, yE1, KE, tolL, errL)
        # ---- accepted steps go into the member's other slot
        n_acc = 0
        for lane in range(L):
            slot[lane] = 1 - slot[lane]
            acc[lane] = R.accepted(errL[lane])
            n_acc += acc[lane]
        if n_acc:
            for i in range(n):
                for lane in range(L):
                    if acc[lane]:
                        m = act[lane]
                        Y0s[m, slot[lane], i] = yE0[i, lane]
                        Y1s[m, slot[lane], i] = yE1[i, lane]
            for j in range(R.NS + 1):
                for i in range(n):
                    for lane in range(L):
                        if acc[lane]:
                            KKs[act[lane], slot[lane], j, i] = KE[j, i, lane]
            for j in range(N):
                for lane in range(L):
                    if acc[lane]:
                        m = act[lane]
                        cM[m, j] = cE[j, lane]
                        sM[m, j] = sE[j, lane]
                        sigM[m, j] = sigE[j, lane]
        # ---- each member's own bookkeeping
        stop = False
        for lane in range(L):
            m = act[lane]
            code = R.after_attempt(N, errL[lane], hL[lane], lastL[lane] != 0.0, slot[lane], Y1s[m], TSs[m], HSs[m],
                                   DOKs[m], cM[m], sM[m], sigM[m], Zs[m], rinv0, ctls[m], recs[m], pks[m], meass[m])
            if code >= 0:
                codes[m] = code
                stop = True
        if stop:
            return


class _Lanes:
    """Stacked per-member arrays (the members' engines hold views into them) and the
    interleaved lane buffers (as many lanes as active members, rounded up to 4)."""

    def __init__(self, engines):
        M = len(engines)
        N = engines[0].N
        self.M, self.N = M, N
        self.engines = engines
        names = ("Y0", "Y1", "KK", "F", "TS", "HS", "DOK", "ctl", "rec", "pk", "meas", "Z")
        for name in names:
            stack = np.stack([getattr(e, name) for e in engines])
            setattr(self, name, stack)
            for m, e in enumerate(engines):
                setattr(e, name, stack[m])  # the engine now works on its row
        self.c = np.zeros((M, N))
        self.s = np.zeros((M, N))
        self.sig = np.zeros((M, N))
        self.rinv0 = engines[0].rinv0
        self.codes = np.full(M, -1, dtype=np.int64)
        self.W = 0

    def _buffers(self, W: int) -> None:
        n, N = 2 * self.N, self.N
        self.W = W
        self.yE0 = np.zeros((n, W))
        self.KE = np.zeros((R.NS + 1, n, W))
        self.yEt = np.zeros((n, W))
        self.yE1 = np.zeros((n, W))
        self.cE, self.sE, self.SE, self.cpE, self.dpE, self.sigE = (np.zeros((N, W)) for _ in range(6))
        self.hL, self.lastL, self.errL, self.tolL = (np.zeros(W) for _ in range(4))
        self.hx = np.zeros(n * W)

    def advance(self, act: np.ndarray) -> None:
        W = 4 * ((act.size + 3) // 4)
        if W != self.W:
            self._buffers(W)
        self.codes[:] = -1
        advance_lanes(self.N, act.size, act, self.Y0, self.Y1, self.KK, self.TS, self.HS, self.DOK, self.ctl, self.rec,
                      self.pk, self.meas, self.Z, self.c, self.s, self.sig, self.rinv0, self.yE0, self.KE, self.yEt,
                      self.yE1, self.cE, self.sE, self.SE, self.cpE, self.dpE, self.sigE, self.hL, self.lastL,
                      self.errL, self.tolL, self.hx, self.codes)


def run_ensemble(chis, N: int, *, tol: float = 1e-8, method: str = "fast", t_end: float | None = None,
                 stop_fraction: float = 0.5, t_end_max: float = 10.0, snapshot_times=(), record_thin: float = 0.0,
                 max_link_error: float = 1e-2, chords: str = "arclength", outputs=None, progress: bool = False,
                 dt_min: float = 1e-14):
    """Run several chains of N links (one per ``chis`` value) together, one vectorised
    kernel advancing all of them, each with its own adaptive DOP853 step.

    Same physics, numerics, stop rules and Dataset as ``run(chi, N, method="dop853",
    ...)`` for each chi (the angle form of :mod:`snapping.simulate.angles`); the members
    share only the arithmetic. The interleaved tension recurrence is cheaper per member
    than one chain's (latency-bound), but the rest of a step is not, and members that
    need fewer steps idle in their lanes: measured, an ensemble costs 1.0-1.4x as much
    as separate single runs (``benchmarks/bench_methods.py``; the parts of a step in
    ``benchmarks/bench_step_costs.py``), so prefer single runs
    for speed; use an ensemble to keep several chi in one process and one call.

    Parameters
    ----------
    chis : sequence of float
        One member per value, each in (0, 1) (repeats allowed).
    N : int
        Number of links of every member.
    tol, t_end, stop_fraction, t_end_max, snapshot_times, record_thin, max_link_error, chords
        As in :func:`snapping.simulate.run`, for every member.
    method : {"fast", "dop853"}
        The angle-form method (the only one with an ensemble kernel).
    outputs : sequence of paths, optional
        Write member i's Dataset to ``outputs[i]``.
    progress : bool
        Show a progress bar of finished members.

    Returns
    -------
    list of xarray.Dataset
        One run Dataset per chi, in order. ``wall_time`` of each is the ensemble's wall
        time divided by the number of members; ``n_rhs`` counts the member's own
        evaluations. A member that fails numerically has ``status = 'failed'`` (the
        others go on; a warning names it) instead of raising.

    Examples
    --------
    >>> dss = run_ensemble([0.25, 0.5], 20, t_end=0.2)
    >>> [ds.attrs["status"] for ds in dss], [ds.attrs["method"] for ds in dss]
    (['completed', 'completed'], ['dop853', 'dop853'])
    """
    from .stepper import _validate

    if method not in HO.HIGH_ORDER_METHODS:
        raise V.SnappingInputError(f"method={method!r}: ensembles run the angle-form methods {HO.HIGH_ORDER_METHODS}")
    try:
        chis = [float(c) for c in np.atleast_1d(np.asarray(chis, dtype=float))]
    except (TypeError, ValueError):
        raise V.SnappingInputError(f"chis={chis!r} is not a sequence of numbers") from None
    if not chis:
        raise V.SnappingInputError("chis=[] is empty: give at least one chi")
    if outputs is not None and len(outputs) != len(chis):
        raise V.SnappingInputError(f"outputs has {len(outputs)} paths for {len(chis)} members")
    checked = []
    for i, chi in enumerate(chis):
        checked.append(_validate(chi, N, tol, method, None, t_end, stop_fraction, t_end_max, snapshot_times,
                                 record_thin, max_link_error, chords, None,
                                 None if outputs is None else outputs[i]))
    N = checked[0][1]
    tol, t_end, stop_fraction, t_end_max, snapshot_times, record_thin, max_link_error, chords = (
        checked[0][2], checked[0][5], checked[0][6], checked[0][7], checked[0][8], checked[0][9], checked[0][10],
        checked[0][11])
    method = HO.resolve_method(method)
    HO._warm_up()
    _warm_up()
    wall0 = time.perf_counter()
    engines, inputs = [], []
    for chi in chis:
        st = initial_state(chi, N, chords)
        eng = HO._Engine(AG.state_to_angles(st), 0.0, tol=tol, dt0=None,
                         t_end=(t_end if t_end is not None else t_end_max),
                         stop_fraction=(0.0 if t_end is not None else stop_fraction), thin=record_thin,
                         max_link_error=max_link_error, snapshot_times=snapshot_times, dt_min=dt_min)
        engines.append(eng)
        inputs.append({
            "chi": chi, "N": N, "method": method, "tol": tol, "dt0": eng.dt0,
            "t_end": 0.0 if t_end is None else t_end, "stop_fraction": stop_fraction,
            "snapshot_times": list(snapshot_times), "record_thin": record_thin, "chords": chords,
            "initial": "catenary", "t_end_max": t_end_max, "max_link_error": max_link_error,
        })
    lanes = _Lanes(engines)
    for e in engines:
        e.start()
    final_codes: dict[int, int] = {}
    act = np.arange(len(chis), dtype=np.int64)
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(chis), desc=f"ensemble N={N}", unit="run")
    try:
        while act.size:
            lanes.advance(act)
            for m in np.flatnonzero(lanes.codes >= 0):
                res = engines[m].handle(int(lanes.codes[m]))
                if res is not None:
                    final_codes[int(m)] = res
                    if bar is not None:
                        bar.update()
            act = np.array([m for m in act if int(m) not in final_codes], dtype=np.int64)
    finally:
        if bar is not None:
            bar.close()
    wall = (time.perf_counter() - wall0) / len(chis)
    out = []
    for m, eng in enumerate(engines):
        r = HO._finish(eng, inputs[m], final_codes.get(m), "completed", "", wall,
                       None if outputs is None else outputs[m], stop_fraction, t_end, raise_on_failure=False)
        if r.dataset.attrs["status"] == "failed":
            warnings.warn(f"ensemble member chi={chis[m]:g} failed: {r.dataset.attrs['stop_reason']}", stacklevel=2)
        out.append(r.dataset)
    return out


_compiled = False


def _warm_up() -> None:
    """Compile (or load from the numba cache) the ensemble kernel on a tiny problem."""
    global _compiled
    if _compiled:
        return
    engines = [HO._Engine(AG.state_to_angles(initial_state(c, 3, chords="exact")), 0.0, tol=1e-6, dt0=None,
                          t_end=0.01, stop_fraction=0.0, thin=0.0, max_link_error=0.5, snapshot_times=())
               for c in (0.4, 0.6)]
    lanes = _Lanes(engines)
    for e in engines:
        e.start()
    lanes.advance(np.arange(2, dtype=np.int64))
    _compiled = True
