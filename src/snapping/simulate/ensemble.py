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
def _stage_lanes(n, L, st, hL, y0, KE, out, hv):
    """out = y0 + h_lane sum_j A[st, j] K_j for every lane (flat passes over i * L + lane)."""
    m = R._NZ[st]
    W = out.shape[1]
    o = out.reshape(-1)
    y = y0.reshape(-1)
    for jj in range(m):
        j = R._NZC[st, jj]
        a = R.A_RK[st, j]
        for lane in range(L):
            hv[lane] = hL[lane] * a
        Kj = KE[j].reshape(-1)
        if jj == 0:
            for i in range(n):
                b = i * W
                for lane in range(L):
                    o[b + lane] = y[b + lane] + hv[lane] * Kj[b + lane]
        else:
            for i in range(n):
                b = i * W
                for lane in range(L):
                    o[b + lane] += hv[lane] * Kj[b + lane]


@njit(cache=True, fastmath=False, boundscheck=False)
def _err_lanes(n, L, hL, y0, y1, KE, e5w, e3w, tolL, errL):
    """The scaled error of every lane (rk.rk_step's max norm), e5 and e3 in flat passes."""
    W = e5w.shape[1]
    o5 = e5w.reshape(-1)
    o3 = e3w.reshape(-1)
    for jj in range(R._E5NZ.size):
        j = R._E5NZ[jj]
        a = R.E5_RK[j]
        Kj = KE[j].reshape(-1)
        for i in range(n):
            b = i * W
            for lane in range(L):
                if jj == 0:
                    o5[b + lane] = a * Kj[b + lane]
                else:
                    o5[b + lane] += a * Kj[b + lane]
    for jj in range(R._E3NZ.size):
        j = R._E3NZ[jj]
        a = R.E3_RK[j]
        Kj = KE[j].reshape(-1)
        for i in range(n):
            b = i * W
            for lane in range(L):
                if jj == 0:
                    o3[b + lane] = a * Kj[b + lane]
                else:
                    o3[b + lane] += a * Kj[b + lane]
    for lane in range(L):
        errL[lane] = 0.0
    for i in range(n):
        for lane in range(L):
            sc = tolL[lane] * (1.0 + max(abs(y0[i, lane]), abs(y1[i, lane])))
            e5 = e5w[i, lane] / sc
            e3 = e3w[i, lane] / sc
            d = e5 * e5 + 0.01 * e3 * e3
            if d > 0.0:
                e = abs(hL[lane]) * e5 * e5 / math.sqrt(d)
                if e > errL[lane]:
                    errL[lane] = e
            elif not (d == 0.0):
                errL[lane] = np.inf


@njit(cache=True, fastmath=False, boundscheck=False)
def advance_lanes(N, L, act, Y0s, Y1s, KKs, TSs, HSs, DOKs, ctls, recs, pks, meass, Zs, cM, sM, sigM, rinv0,
                  yE0, KE, yEt, yE1, e3w, cE, sE, SE, cpE, dpE, sigE, hL, lastL, errL, v1, v2, v3, v4, v5, v6,
                  codes):
    """Advance the members ``act[:L]`` (one lane each) together until one of them needs
    Python; ``codes[m]`` then holds the return code of each member m that does (-1:
    none). The per-member arrays (first index m) are those of a single run's engine."""
    n = 2 * N
    for lane in range(L):
        ctls[act[lane], R.Q_NCALL] = 0.0
    while True:
        for lane in range(L):
            m = act[lane]
            sl = int(ctls[m, R.Q_SLOT])
            h, last = R.step_size(ctls[m])
            hL[lane] = h
            lastL[lane] = 1.0 if last else 0.0
            for i in range(n):
                yE0[i, lane] = Y1s[m, sl, i]
                KE[0, i, lane] = KKs[m, sl, R.NS, i]
        for st in range(1, R.NS):
            _stage_lanes(n, L, st, hL, yE0, KE, yEt, errL)
            rhs_lanes(N, L, yEt, KE[st], cE, sE, SE, cpE, dpE, sigE, v1, v2, v3, v4, v5, v6)
        _stage_lanes(n, L, R.NSX, hL, yE0, KE, yE1, errL)  # (row NSX of _NZ: the weights B)
        rhs_lanes(N, L, yE1, KE[R.NS], cE, sE, SE, cpE, dpE, sigE, v1, v2, v3, v4, v5, v6)
        # ---- error of each lane (as rk.rk_step), in flat passes
        for lane in range(L):
            v1[lane] = ctls[act[lane], R.Q_TOL]
        _err_lanes(n, L, hL, yE0, yE1, KE, yEt, e3w, v1, errL)
        # ---- each member's own bookkeeping
        stop = False
        for lane in range(L):
            m = act[lane]
            err = errL[lane]
            ns = 1 - int(ctls[m, R.Q_SLOT])
            if err - err == 0.0 and err <= 1.0:  # accepted: the step goes into the member's slot
                for i in range(n):
                    Y0s[m, ns, i] = yE0[i, lane]
                    Y1s[m, ns, i] = yE1[i, lane]
                for j in range(R.NS + 1):
                    for i in range(n):
                        KKs[m, ns, j, i] = KE[j, i, lane]
                for j in range(N):
                    cM[m, j] = cE[j, lane]
                    sM[m, j] = sE[j, lane]
                    sigM[m, j] = sigE[j, lane]
            code = R.after_attempt(N, err, hL[lane], lastL[lane] != 0.0, ns, Y1s[m], TSs[m], HSs[m], DOKs[m],
                                   cM[m], sM[m], sigM[m], Zs[m], rinv0, ctls[m], recs[m], pks[m], meass[m])
            if code >= 0:
                codes[m] = code
                stop = True
        if stop:
            return


class _Lanes:
    """Stacked per-member arrays (the members' engines hold views into them) and the
    interleaved lane buffers."""

    def __init__(self, engines):
        M = len(engines)
        N = engines[0].N
        n = 2 * N
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
        self.yE0 = np.zeros((n, M))
        self.KE = np.zeros((R.NS + 1, n, M))
        self.yEt = np.zeros((n, M))
        self.yE1 = np.zeros((n, M))
        self.e3w = np.zeros((n, M))
        self.cE, self.sE, self.SE, self.cpE, self.dpE, self.sigE = (np.zeros((N, M)) for _ in range(6))
        self.hL, self.lastL, self.errL = np.zeros(M), np.zeros(M), np.zeros(M)
        self.v = [np.zeros(M) for _ in range(6)]
        self.codes = np.full(M, -1, dtype=np.int64)

    def advance(self, act: np.ndarray) -> None:
        self.codes[:] = -1
        advance_lanes(self.N, act.size, act, self.Y0, self.Y1, self.KK, self.TS, self.HS, self.DOK, self.ctl, self.rec,
                      self.pk, self.meas, self.Z, self.c, self.s, self.sig, self.rinv0, self.yE0, self.KE, self.yEt,
                      self.yE1, self.e3w, self.cE, self.sE, self.SE, self.cpE, self.dpE, self.sigE, self.hL, self.lastL,
                      self.errL, *self.v, self.codes)


def run_ensemble(chis, N: int, *, tol: float = 1e-8, method: str = "fast", t_end: float | None = None,
                 stop_fraction: float = 0.5, t_end_max: float = 10.0, snapshot_times=(), record_thin: float = 0.0,
                 max_link_error: float = 1e-2, chords: str = "arclength", outputs=None, progress: bool = False,
                 dt_min: float = 1e-14):
    """Run several chains of N links (one per ``chis`` value) together, one vectorised
    kernel advancing all of them, each with its own adaptive DOP853 step.

    Same physics, numerics, stop rules and Dataset as ``run(chi, N, method="dop853",
    ...)`` for each chi (the angle form of :mod:`snapping.simulate.angles`); the members
    share only the arithmetic, so the cost per member is less than that of separate
    runs (the tridiagonal recurrence of one chain is latency-bound; several interleave).

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
