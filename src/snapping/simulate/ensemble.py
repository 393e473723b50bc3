"""Ensembles: several chains of the same N (e.g. a sweep over chi) in one vectorised kernel.

Every member is a full DOP853 angle-form run (:mod:`snapping.simulate.methods.dop853`) with
its own adaptive step, its own record, peaks, snapshots and stop; only the arithmetic is
shared. The members' states are stored interleaved, ``y[i, lane]``: the elementwise
passes of a step (stage sums, sines and cosines, coupling coefficients, accelerations,
error norm) run over the flattened (component, lane) index, and the two recurrences of
the tension solve -- chains of dependent operations that one chain cannot overlap --
update all lanes at once at each node, so that the compiler vectorises them across
the lanes. Each iteration advances every active member by one attempted step (of its
own size); a member that stops (snap, t_end, failure) leaves the lanes, and the last
last two finish on the single-run kernel. The lanes keep their members' last two steps
themselves (for the dense output); after each attempt the member's own bookkeeping
(:func:`snapping.simulate.rk.after_attempt`) runs on its lane exactly as in a single
run. Every operation is the single run's, in the same order, so an ensemble member's
Dataset equals that of its single run bit for bit (all but ``wall_time``).

Cost: at 8 lanes the coupling coefficients, the tension recurrence and the
accelerations cost 1.3x less per member (4.1 against 5.3 ns per node; at 2 lanes they
cost more), but the rest of a step (sines and cosines, stage sums, error norm,
diagnostics) is already vectorised along the chain in a single run, and the lanes
multiply the working set by their number (out of the core's L2 cache from N ~ 1000 at
8 lanes). Measured on a 2-core Xeon (``benchmarks/bench_methods.py``,
``benchmarks/bench_step_costs.py``), an ensemble costs 1.1-1.2x as much as its members
run one after another: use it to keep several chi in one process and one call, not
for speed.

Example
-------
>>> from snapping.simulate import run_ensemble
>>> dss = run_ensemble([0.3, 0.5], 30, chords="exact")
>>> [round(ds.attrs["t_snap_v"], 4) for ds in dss]
[1.1941, 1.1548]
"""

from __future__ import annotations

import contextlib
import math
import time
import warnings

import numpy as np
from numba import njit

from .. import _files
from .. import _validate as V
from . import angles as AG
from . import kernels as K
from . import rk as R
from .chain import initial_state
from .methods import dop853 as DOP
from .options import RunOptions

__all__ = ["run_ensemble", "rhs_lanes", "LaneWork"]

BLOCK = AG.BLOCK
#: elements per chunk of the flat stage sums (a chunk of the sum stays in L1)
CHUNK = 1024
#: with this many active members or fewer, each runs on the single-run kernel (2 lanes cost
#: ~1.2x per member what one chain does: ``benchmarks/bench_step_costs.py``)
SINGLE_BELOW = 2


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def rhs_lanes(N, y, f, c, s, S, C, P, Q, cp, dp, sig):
    """:func:`angles.angle_rhs` for the ``W = y.shape[1]`` interleaved chains of ``y, f``
    (2N, W), with the same arithmetic (and so the same results, bit for bit).

    Work: ``c, s, S, cp, dp, sig`` (N, W); ``C, P, Q`` (N + 2, W), where row j + 2
    holds the coupling coefficient C_j, the leading minor p_j and the eliminated right
    side q_j of row j (rows 0 and 1: the start of the recurrence). Every pass that is
    elementwise runs over the flattened (node, lane) index; only the two recurrences
    (forward elimination, back substitution) step through the nodes, each step
    updating all W lanes at once, so that the compiler vectorises them across lanes.
    """
    W = y.shape[1]
    fN = float(N)
    n2 = fN * fN
    inv_n2 = 1.0 / n2
    nW = N * W
    yf = y.reshape(-1)
    ff = f.reshape(-1)
    cf = c.reshape(-1)
    sf = s.reshape(-1)
    AG.sincos(nW, yf, cf, sf)
    yw = yf[nW:]
    for i in range(nW):
        ff[i] = yw[i]
    if N == 1:
        for lane in range(W):
            w = y[1, lane]
            sig[0, lane] = w * w - s[0, lane]
            f[1, lane] = -c[0, lane]
        return
    # coefficients C_j = cos(theta_{j+1} - theta_j), S_j = sin(...), right sides -theta_j'^2 / N^2
    # (slices keep every index of the flat loops provably non-negative: they vectorise)
    Sf = S.reshape(-1)
    Cf2 = C.reshape(-1)[2 * W:]
    Qf2 = Q.reshape(-1)[2 * W:]
    cf1 = cf[W:]
    sf1 = sf[W:]
    for i in range((N - 1) * W):
        cj = cf[i]
        sj = sf[i]
        cn = cf1[i]
        sn = sf1[i]
        Cf2[i] = cn * cj + sn * sj
        Sf[i] = sn * cj - cn * sj
    for i in range(nW):
        w = yw[i]
        Qf2[i] = -(w * w) * inv_n2
    for lane in range(W):
        Q[N + 1, lane] = Q[N + 1, lane] + s[N - 1, lane] / fN  # the pin row
        C[1, lane] = 0.0
        P[0, lane] = 0.0
        P[1, lane] = 1.0
        Q[1, lane] = 0.0
    # forward elimination, rows j = 0 .. N-2 (rescaled by a power of two every BLOCK rows)
    j0 = 0
    while j0 < N - 1:
        j1 = min(j0 + BLOCK, N - 1)
        for j in range(j0, j1):
            for lane in range(W):
                cprev = C[j + 1, lane]
                pm = P[j + 1, lane]
                p = -2.0 * pm - (cprev * cprev) * P[j, lane]
                q = Q[j + 2, lane] * pm - cprev * Q[j + 1, lane]
                P[j + 2, lane] = p
                Q[j + 2, lane] = q
                inv = 1.0 / p
                cp[j, lane] = C[j + 2, lane] * pm * inv
                dp[j, lane] = q * inv
        for lane in range(W):
            sc = math.ldexp(1.0, -math.frexp(P[j1 + 1, lane])[1])
            P[j1 + 1, lane] *= sc
            P[j1, lane] *= sc
            Q[j1 + 1, lane] *= sc
        j0 = j1
    jl = N - 1  # the last row (link N, at the pin): b = -1
    for lane in range(W):
        cprev = C[jl + 1, lane]
        pm = P[jl + 1, lane]
        p = -pm - (cprev * cprev) * P[jl, lane]
        q = Q[jl + 2, lane] * pm - cprev * Q[jl + 1, lane]
        sig[jl, lane] = q / p
    for j in range(N - 2, -1, -1):
        for lane in range(W):
            sig[j, lane] = dp[j, lane] - cp[j, lane] * sig[j + 1, lane]
    # angular accelerations: links 2 .. N-1 elementwise, then the free end and the pin
    gf = sig.reshape(-1)
    fa = ff[nW + W:]
    g2 = gf[2 * W:]
    S1 = Sf[W:]
    for i in range((N - 2) * W):
        fa[i] = n2 * (g2[i] * S1[i] - gf[i] * Sf[i])
    for lane in range(W):
        f[N, lane] = n2 * sig[1, lane] * S[0, lane]
        f[2 * N - 1, lane] = -n2 * sig[N - 2, lane] * S[N - 2, lane] - fN * c[N - 1, lane]


class LaneWork:
    """Work arrays of :func:`rhs_lanes` for W chains of N links."""

    def __init__(self, N: int, W: int):
        self.c, self.s, self.S, self.cp, self.dp, self.sig = (np.zeros((N, W)) for _ in range(6))
        self.C, self.P, self.Q = (np.zeros((N + 2, W)) for _ in range(3))

    def args(self):
        return self.c, self.s, self.S, self.C, self.P, self.Q, self.cp, self.dp, self.sig


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _err_lanes(n, hx, tolx, y0, y1, KE, ev, errL):
    """The scaled error of every lane: rk.rk_step's norm with its operations in its order
    (:func:`rk.scaled_error`), elementwise over the flattened (component, lane) index
    (``hx``, ``tolx``: each element's lane step and tolerance; ``ev``: (n, W) scratch),
    then the maximum of each lane."""
    W = y0.shape[1]
    m = n * W
    evf = ev.reshape(-1)
    y0f = y0.reshape(-1)
    y1f = y1.reshape(-1)
    Kf = KE.reshape(KE.shape[0], m)
    for i in range(m):
        evf[i] = R.scaled_error(Kf, i, y0f[i], y1f[i], hx[i], tolx[i])
    for lane in range(W):
        errL[lane] = 0.0
    for i in range(n):
        for lane in range(W):
            v = ev[i, lane]
            if v > errL[lane]:
                errL[lane] = v


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
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


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _y1_flat(hx, y0, KE, out):
    """out = y0 + h_lane sum_j B_j K_j (rk.rk_step's end state, :func:`rk.end_sum`)."""
    m = out.size
    o = out.reshape(-1)
    y = y0.reshape(-1)
    Kf = KE.reshape(KE.shape[0], m)
    for i in range(m):
        o[i] = y[i] + hx[i] * R.end_sum(Kf, i)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _lane_columns(A, B, mask):
    """B[..., lane] = A[..., lane] for the lanes with ``mask[lane]`` (A, B of one shape)."""
    W = mask.size
    Af = A.reshape(-1)
    Bf = B.reshape(-1)
    for r in range(Af.size // W):
        b = r * W
        for lane in range(W):
            if mask[lane]:
                Bf[b + lane] = Af[b + lane]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _lanes_copy(act, sel, gl, into_lanes, Y0s, Y1s, KKs, ctls, YA, YB, KL):
    """Copy the two step slots of each selected member (``sel[lane]``) between its rows
    and its lane: into the lanes if ``into_lanes``, else back to the rows. Slot
    ``ctl[Q_SLOT]`` (the last accepted step) is at parity 1 - gl[lane], the other slot
    at gl[lane]."""
    for lane in range(act.size):
        if not sel[lane]:
            continue
        m = act[lane]
        sl = int(ctls[m, R.Q_SLOT])
        g = gl[lane]
        for par in range(2):
            k = sl if par == 1 - g else 1 - sl
            if into_lanes:
                YA[par, :, lane] = Y0s[m, k]
                YB[par, :, lane] = Y1s[m, k]
                KL[par, :, :, lane] = KKs[m, k, :R.NS + 1]
            else:
                Y0s[m, k] = YA[par, :, lane]
                Y1s[m, k] = YB[par, :, lane]
                KKs[m, k, :R.NS + 1] = KL[par, :, :, lane]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def advance_lanes(N, act, fresh, par, Y0s, Y1s, KKs, TSs, HSs, DOKs, ctls, recs, pks, meass, Zs, rinv0, YA, YB, KL,
                  yEt, ev, c, s, S, C, P, Q, cp, dp, sig, hL, lastL, errL, hx, tolx, codes, mdl):
    """Advance the members ``act`` (one lane each, ``W = act.size`` lanes) together
    until one of them needs Python; ``codes[m]`` then holds the return code of each
    member m that does (-1: none), and those members' rows their two step slots as a
    single run has them (the last accepted step, and the step before it or the
    rejected attempt).

    The per-member arrays (first index m) are those of a single run's engine. The
    lanes keep their step slots themselves, between calls too, in two parities:
    ``YA, YB`` (2, 2N, W) the start and end states, ``KL`` (2, 13, 2N, W) the stages.
    Every attempt writes parity ``g = par[0]`` and starts from parity 1 - g, where each
    lane's last accepted step is; after an iteration in which some lane accepted, g
    flips, and the lanes that rejected copy their last step across (so that it is again
    at 1 - g). Lanes marked ``fresh`` are first loaded from their members' rows. Each
    member's diagnostics and bookkeeping (:func:`rk.after_attempt`) run exactly as in a
    single run, on its lane's columns. ``mdl``: the (uniform) model of every member,
    :func:`snapping.simulate.general.uniform_model`.
    """
    n = 2 * N
    W = act.size
    g = par[0]
    for lane in range(W):
        ctls[act[lane], R.Q_NCALL] = 0.0
    for i in range(n):
        b = i * W
        for lane in range(W):
            tolx[b + lane] = ctls[act[lane], R.Q_TOL]
    gl = np.full(W, g)
    _lanes_copy(act, fresh, gl, True, Y0s, Y1s, KKs, ctls, YA, YB, KL)
    rej = np.zeros(W, dtype=np.bool_)
    out = np.zeros(W, dtype=np.bool_)
    while True:
        for lane in range(W):
            h, last = R.step_size(ctls[act[lane]])
            hL[lane] = h
            lastL[lane] = 1.0 if last else 0.0
        for i in range(n):  # each element's lane step, for the flat sums
            b = i * W
            for lane in range(W):
                hx[b + lane] = hL[lane]
        ya = YA[g]
        yb = YB[g]
        Kg = KL[g]
        ypf = YB[1 - g].reshape(-1)  # start: the last accepted state, and its derivative (FSAL)
        yaf = ya.reshape(-1)
        k0 = Kg[0].reshape(-1)
        kp = KL[1 - g, R.NS].reshape(-1)
        for i in range(n * W):
            yaf[i] = ypf[i]
            k0[i] = kp[i]
        for st in range(1, R.NS):
            _stage_flat(st, hx, ya, Kg, yEt)
            rhs_lanes(N, yEt, Kg[st], c, s, S, C, P, Q, cp, dp, sig)
        _y1_flat(hx, ya, Kg, yb)
        rhs_lanes(N, yb, Kg[R.NS], c, s, S, C, P, Q, cp, dp, sig)
        _err_lanes(n, hx, tolx, ya, yb, Kg, ev, errL)
        # ---- each member's own bookkeeping, on its lane's new state, trigonometry and tension
        n_acc = 0
        stop = False
        for lane in range(W):
            m = act[lane]
            ok = R.accepted(errL[lane])
            rej[lane] = not ok
            n_acc += ok
            code = R.after_attempt(N, errL[lane], hL[lane], lastL[lane] != 0.0, 1 - int(ctls[m, R.Q_SLOT]),
                                   yb[:, lane], TSs[m], HSs[m], DOKs[m], c[:, lane], s[:, lane], sig[:, lane],
                                   Zs[m], rinv0, ctls[m], recs[m], pks[m], meass[m], mdl)
            if code >= 0:
                codes[m] = code
                stop = True
        if stop:  # the members that need Python get their slots back as a single run has them:
            for lane in range(W):  # the last accepted step, and the step before it or a rejected attempt
                out[lane] = codes[act[lane]] >= 0
                gl[lane] = g if rej[lane] else 1 - g
            _lanes_copy(act, out, gl, False, Y0s, Y1s, KKs, ctls, YA, YB, KL)
        if n_acc:
            g = 1 - g
            if n_acc < W:  # the lanes that rejected: their last step to parity 1 - g
                _lane_columns(YA[g], YA[1 - g], rej)
                _lane_columns(YB[g], YB[1 - g], rej)
                _lane_columns(KL[g], KL[1 - g], rej)
        if stop:
            par[0] = g
            return


class _Lanes:
    """Stacked per-member arrays (the members' engines hold views into them) and the
    lane buffers of :func:`advance_lanes` (one lane per active member), kept between
    calls while the set of active members stays the same."""

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
        self.rinv0 = engines[0].rinv0
        self.codes = np.full(M, -1, dtype=np.int64)
        self.act = np.zeros(0, dtype=np.int64)
        self.par = np.zeros(1, dtype=np.int64)

    def _buffers(self, W: int) -> None:
        n, N = 2 * self.N, self.N
        self.YA = np.zeros((2, n, W))
        self.YB = np.zeros((2, n, W))
        self.KL = np.zeros((2, R.NS + 1, n, W))
        self.yEt = np.zeros((n, W))
        self.ev = np.zeros((n, W))
        self.work = LaneWork(N, W)
        self.hL, self.lastL, self.errL = (np.zeros(W) for _ in range(3))
        self.hx = np.zeros(n * W)
        self.tolx = np.zeros(n * W)

    def advance(self, act: np.ndarray) -> None:
        """Advance the members ``act`` until some need Python (their codes in ``codes``)."""
        self.codes[:] = -1
        same = np.array_equal(act, self.act)
        if not same and self.act.size:  # the lanes change: the staying members' slots back to their rows
            # first (those that left got theirs when they returned their codes)
            _lanes_copy(self.act, np.isin(self.act, act), np.full(self.act.size, int(self.par[0])), False,
                        self.Y0, self.Y1, self.KK, self.ctl, self.YA, self.YB, self.KL)
            self.act = np.zeros(0, dtype=np.int64)
        if act.size <= SINGLE_BELOW:  # few members left: the single-run loop is the faster kernel
            for m in act:
                e = self.engines[int(m)]
                w = e.w
                self.codes[m] = R.advance_rk(e.N, e.Y0, e.Y1, e.KK, e.TS, e.HS, e.DOK, e.ytmp, w.c, w.s, w.S, w.cp,
                                             w.dp, w.sig, e.Z, e.rinv0, e.ctl, e.rec, e.pk, e.meas, e.mdl)
            return
        if not same:
            self._buffers(act.size)
        fresh = np.full(act.size, not same)
        self.act = act.copy()
        advance_lanes(self.N, act, fresh, self.par, self.Y0, self.Y1, self.KK, self.TS, self.HS, self.DOK, self.ctl,
                      self.rec, self.pk, self.meas, self.Z, self.rinv0, self.YA, self.YB,
                      self.KL, self.yEt, self.ev, *self.work.args(), self.hL, self.lastL, self.errL,
                      self.hx, self.tolx, self.codes, self.engines[0].mdl)


def run_ensemble(chis, N: int, *, tol: float | None = None, method: str = "fast", t_end: float | None = None,
                 stop_fraction: float = 0.5, t_end_max: float = 10.0, snapshot_times=(), record_thin: float = 0.0,
                 max_link_error: float = 1e-2, chords: str = "exact", outputs=None, progress: bool = False,
                 dt_min: float = 1e-14, overwrite: bool = False):
    """Run several chains of N links (one per ``chis`` value) together, one vectorised
    kernel advancing all of them, each with its own adaptive DOP853 step.

    Same physics, numerics, stop rules and Dataset as ``run(chi, N, method="dop853",
    ...)`` for each chi (the angle form of :mod:`snapping.simulate.angles`), bit for
    bit; the members share only the arithmetic. Measured, an ensemble costs 1.1-1.2x as
    much as separate single runs (see the module docstring), so prefer single runs for
    speed; use an ensemble to keep several chi in one process and one call.

    Parameters
    ----------
    chis : sequence of float
        One member per value, each in (0, 1) (repeats allowed).
    N : int
        Number of links of every member.
    tol, t_end, stop_fraction, t_end_max, snapshot_times, record_thin, max_link_error, chords
        As in :func:`snapping.simulate.run`, for every member (defaults too: tol the
        fast method's, chords ``exact``).
    method : {"fast", "dop853"}
        The angle-form method (the only one with an ensemble kernel).
    outputs : sequence of paths, optional
        Write member i's Dataset to ``outputs[i]`` (distinct new paths, checked before the
        run and locked while it lasts; rules: :mod:`snapping._files`).
    overwrite : bool
        Replace outputs that exist (default: refuse them).
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
    from .dataset import check_writable

    if method not in DOP.NAMES:
        raise V.SnappingInputError(f"method={method!r}: ensembles run the angle-form methods {DOP.NAMES}")
    try:
        chis = [float(c) for c in np.atleast_1d(np.asarray(chis, dtype=float))]
    except (TypeError, ValueError, OverflowError):
        raise V.SnappingInputError(f"chis={chis!r} is not a sequence of numbers") from None
    if not chis:
        raise V.SnappingInputError("chis=[] is empty: give at least one chi")
    if outputs is not None and len(outputs) != len(chis):
        raise V.SnappingInputError(f"outputs has {len(outputs)} paths for {len(chis)} members")
    from ..estimates import check_chi

    chis = [check_chi(chi) for chi in chis]
    N = V.integer("N", N, 1)
    if not isinstance(chords, str) or chords not in ("arclength", "exact"):
        raise V.SnappingInputError(f"chords={chords!r} is not one of ('arclength', 'exact')")
    opts = RunOptions(tol=DOP.DEFAULT_TOL if tol is None else tol, t_end=t_end, stop_fraction=stop_fraction, t_end_max=t_end_max,
                      snapshot_times=snapshot_times, record_thin=record_thin, max_link_error=max_link_error,
                      dt_min=dt_min)
    if outputs is not None:
        outputs = [check_writable(o, name=f"outputs[{i}]", overwrite=overwrite) for i, o in enumerate(outputs)]
        same = [o for o in set(outputs) if outputs.count(o) > 1]
        if same:
            raise V.SnappingInputError(f"outputs names {same[0]!r} more than once: give each member its own file")
    with contextlib.ExitStack() as held:  # every output locked against other writers while the ensemble runs
        for o in outputs or ():
            held.enter_context(_files.locked(o))
        return _run_members(chis, N, method, opts, chords, outputs, progress)


def _run_members(chis, N, method, opts, chords, outputs, progress):
    """:func:`run_ensemble` once its inputs are checked and its outputs locked."""
    method = DOP.resolve_method(method)
    DOP._warm_up()
    _warm_up()
    wall0 = time.perf_counter()
    engines, inputs = [], []
    for chi in chis:
        eng = DOP.Engine(AG.state_to_angles(initial_state(chi, N, chords)), 0.0, **opts.engine_kwargs())
        engines.append(eng)
        inputs.append({"chi": chi, "N": N, "method": method, **opts.input_attrs(), "chords": chords,
                       "initial": "catenary"})
        inputs[-1]["dt0"] = eng.dt0
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
        r = _finish(eng, inputs[m], final_codes.get(m), wall, None if outputs is None else outputs[m], opts)
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
    engines = [DOP.Engine(AG.state_to_angles(initial_state(c, 3, chords="exact")), 0.0, tol=1e-6, dt0=None,
                          t_end=0.01, stop_fraction=0.0, thin=0.0, max_link_error=0.5, snapshot_times=())
               for c in (0.4, 0.5, 0.6)]  # (more than SINGLE_BELOW: the lanes' kernel)
    lanes = _Lanes(engines)
    for e in engines:
        e.start()
    lanes.advance(np.arange(3, dtype=np.int64))
    _compiled = True


def _finish(eng, inputs: dict, code, wall: float, output, opts):
    """The run Dataset of a finished member (saved to ``output`` if given), as a Run; a
    numerical failure gives status 'failed' (no exception: the ensemble goes on)."""
    from .dataset import Run, build_dataset, save, seal
    from .errors import FAILURES, SimulationError

    status, reason, failure, node = "completed", "", "", -1
    if code is not None:
        if code == K.RET_STOP:
            reason = f"snap detected: v_max fell below {opts.stop_fraction:g} of its peak"
        elif code == K.RET_END:
            reason = "t_end reached" if opts.t_end is not None else \
                "t_end_max reached before the speed fell after a peak"
        else:
            status = "failed"
            node = eng.worst_node(code)
            reason = eng.failure_message(code, node)
            failure = FAILURES.get(code, SimulationError).kind
    ds = build_dataset(eng.records(), eng.snapshots_now(), eng.N, inputs,
                       eng.results(status, reason, wall, failure, node))
    path = save(seal(ds), output, overwrite=True) if output is not None else None
    return Run(ds, eng.final_state(), path)
