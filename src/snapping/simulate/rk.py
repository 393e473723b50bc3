"""A compiled Dormand-Prince 8(5,3) integrator for the chain in link angles.

The explicit embedded Runge-Kutta pair DOP853 (Hairer, Norsett & Wanner, *Solving
ODE I*, sec. II.10; coefficients from :mod:`scipy.integrate._ivp.dop853_coefficients`
at import time) with its 7th-order dense output, applied to the angle formulation of
:mod:`snapping.simulate.angles` (link lengths exact to round-off). The whole step loop
-- 12 stages, error estimate, step-size control, the per-step diagnostics and record
of :mod:`snapping.simulate.kernels`, peak detection, stop rules -- is one numba
function (:func:`advance_rk`); Python only sees it every few thousand steps or when
something must happen (a snapshot, a peak to refine, a full record buffer).

Error control: per component ``e_i = h |e5_i|^2 / sqrt(e5_i^2 + 0.01 e3_i^2)`` with
``e5, e3`` the 5th- and 3rd-order embedded estimates scaled by
``tol (1 + max(|y_i(t)|, |y_i(t + h)|))`` (rtol = atol = tol), and the *maximum* over
the 2N components (not the RMS: the snap is local to a few links at the free end and
an RMS over N links would dilute it). A step is accepted when the error is <= 1; the
next step is ``h min(10, 0.9 err^(-1/8))`` (at most ``h`` after a rejection), a
rejected one is retried with ``h max(0.2, 0.9 err^(-1/8))``.

Peaks. The maxima over the chain of speed, acceleration, tension and curvature are
sampled at every accepted step like the Euler-Richardson runs; when a sample that is
a new record is followed by a smaller one, the peak lies between the neighbouring
steps, and it is located with the dense output (bounded Brent search on the
interpolated state; accelerations and tensions there from a tension solve). The run's
``*_peak`` values and ``t_snap_*`` times are those located maxima.

Cost: 12 right-hand-side evaluations per attempted step (first same as last), 3 more
for the dense output of a step where it is needed, 1 per point of a peak search; all
are counted in ``n_rhs``.

Example: one step of this module's tableau (:func:`_stage_state`, :func:`end_state`)
on dy/dt = y, y(0) = 1, against exp(h). An 8th-order method has a local error
~ C h^9, so halving the step divides the error by about 2^9:

>>> import math
>>> def step(h):
...     y0, K, tmp, y1 = np.ones(1), np.zeros((NSX, 1)), np.zeros(1), np.zeros(1)
...     K[0] = y0                               # f(y) = y
...     for st in range(1, NS):
...         _stage_state(1, st, h, y0, K, tmp)
...         K[st] = tmp
...     end_state(1, h, y0, K, y1)
...     return y1[0]
>>> err = [abs(float(step(h)) - math.exp(h)) for h in (0.8, 0.4)]
>>> round(math.log2(err[0] / err[1]))
9
>>> err[1] < 1e-10
True
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.integrate._ivp import dop853_coefficients as _dc

from . import general as G
from . import models as MD
from . import kernels as K

NS = _dc.N_STAGES  # 12
NSX = _dc.N_STAGES_EXTENDED  # 16
NI = _dc.INTERPOLATOR_POWER  # 7
A_RK = np.ascontiguousarray(_dc.A, dtype=np.float64)  # (16, 16), rows 13..15: dense-output stages
B_RK = np.ascontiguousarray(_dc.B, dtype=np.float64)  # (12,)
E3_RK = np.ascontiguousarray(_dc.E3, dtype=np.float64)  # (13,)
E5_RK = np.ascontiguousarray(_dc.E5, dtype=np.float64)  # (13,)
D_RK = np.ascontiguousarray(_dc.D, dtype=np.float64)  # (4, 16)
C_RK = np.ascontiguousarray(_dc.C, dtype=np.float64)  # (16,) stage times (fractions of the step)
#: number of nonzero A entries of each stage row, and their columns (skip the zeros)
#: (row NSX: the nonzero weights B of the solution, as a 17th row of A_RK)
A_RK = np.vstack([np.hstack([A_RK, np.zeros((NSX, 1))]), np.zeros((1, NSX + 1))])
A_RK[NSX, :NS] = B_RK
_NZ = np.zeros(NSX + 1, dtype=np.int64)
_NZC = np.zeros((NSX + 1, NSX + 1), dtype=np.int64)
for _s in range(NSX + 1):
    _cols = [j for j in range(_s) if A_RK[_s, j] != 0.0]
    _NZ[_s] = len(_cols)
    _NZC[_s, : len(_cols)] = _cols
_E5NZ = np.array([j for j in range(NS + 1) if E5_RK[j] != 0.0], dtype=np.int64)
_E3NZ = np.array([j for j in range(NS + 1) if E3_RK[j] != 0.0], dtype=np.int64)

SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
ERR_EXPONENT = -1.0 / 8.0

# ---------------------------------------------------------------- control array
(Q_T, Q_H, Q_SLOT, Q_NSTEPS, Q_NREJ, Q_NRHS, Q_NREC, Q_TOL, Q_THIN, Q_MAXLINK, Q_DTMIN,
 Q_STEPS_PER_CALL, Q_TEND, Q_TRET, Q_VUP, Q_VDOWN, Q_STOPFRAC, Q_E0, Q_L0, Q_LAST_V, Q_LAST_A,
 Q_LAST_S, Q_LAST_K, Q_DRIFT_LINK, Q_DRIFT_LEN, Q_DRIFT_E, Q_DT_MIN_ACC, Q_DT_MAX_ACC,
 Q_ERR_MAX_ACC, Q_REFINE, Q_ERROLD, Q_BETA, Q_REJECTED, Q_NCALL, Q_MAXENERGY, Q_MAXREJ, Q_CONSREJ,
 Q_TBRK, Q_LASTBRK, Q_TSETTLE, Q_ARMED, Q_VRBASE, Q_VRPEAK, Q_VFLOOR) = range(44)
NQ = 44

#: ``Q_VFLOOR``: the stop rule's floor, max(v_max at the start, layout.STOP_FLOOR sqrt(g L))

# peak tracking: rows v, a, sigma, kappa
(PK_SBEST, PK_TPREV, PK_TBEFORE, PK_NEED, PK_TA, PK_TB, PK_BEST, PK_TBEST) = range(8)
NPKR = 8

RET_REFINE = 7  # (the other return codes are those of kernels.advance)
#: internal codes of :func:`after_attempt`: step rejected / accepted, go on
GO_REJECTED, GO_ON = -2, -1


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _stage_state(n, s, h, y0, Kst, out):
    """out = y0 + h sum_j A[s, j] K_j over the nonzero A[s, j]."""
    m = _NZ[s]
    j = _NZC[s, 0]
    a = h * A_RK[s, j]
    Kj = Kst[j]
    for i in range(n):
        out[i] = y0[i] + a * Kj[i]
    for jj in range(1, m):
        j = _NZC[s, jj]
        a = h * A_RK[s, j]
        Kj = Kst[j]
        for i in range(n):
            out[i] += a * Kj[i]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def rk_step(N, t, h, y0, y1, Kst, ytmp, c, s, S, cp, dp, sig, tol, mdl):
    """One DOP853 step of size h from y0 at time t (with Kst[0] = f(t, y0)) into y1;
    Kst[1..12] are filled (Kst[12] = f(t + h, y1), and c, s, sig then belong to y1).
    ``mdl`` is the chain's model (:func:`snapping.simulate.models.model_rhs`); the state
    has ``y0.shape[0]`` components. Returns the scaled error (accept if <= 1)."""
    n = y0.shape[0]
    for st in range(1, NS):
        _stage_state(n, st, h, y0, Kst, ytmp)
        MD.model_rhs(N, t + C_RK[st] * h, ytmp, Kst[st], c, s, S, cp, dp, sig, mdl)
    end_state(n, h, y0, Kst, y1)
    MD.model_rhs(N, t + h, y1, Kst[NS], c, s, S, cp, dp, sig, mdl)
    return step_error(n, h, tol, y0, y1, Kst, ytmp)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def end_state(n, h, y0, Kst, y1):
    """y1 = y0 + h sum_j B_j K_j, the end state of a step."""
    for i in range(n):
        y1[i] = y0[i] + h * end_sum(Kst, i)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def step_error(n, h, tol, y0, y1, Kst, ytmp):
    """The scaled error of a step (accept if <= 1): the maximum over i of
    :func:`scaled_error`, computed elementwise into ``ytmp`` first so that the loop
    vectorises."""
    for i in range(n):
        ytmp[i] = scaled_error(Kst, i, y0[i], y1[i], h, tol)
    err = 0.0
    for i in range(n):
        if ytmp[i] > err:
            err = ytmp[i]
    return err


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy", inline="always")
def end_sum(Kst, i):
    """sum_j B_j K_j[i], the stage combination of the end state (in stage order, from 0.0)."""
    acc = 0.0
    for j in range(NS):
        acc += B_RK[j] * Kst[j, i]
    return acc


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy", inline="always")
def scaled_error(Kst, i, y0i, y1i, h, tol):
    """Component i's term of the scaled error of a step (Hairer's DOP853 norm; the error
    is the maximum over i): 0 where both estimates vanish, inf where they are NaN.
    Branch-free, so that a loop over i vectorises."""
    e5 = 0.0
    for jj in range(_E5NZ.size):
        j = _E5NZ[jj]
        e5 += E5_RK[j] * Kst[j, i]
    e3 = 0.0
    for jj in range(_E3NZ.size):
        j = _E3NZ[jj]
        e3 += E3_RK[j] * Kst[j, i]
    sc = tol * (1.0 + max(abs(y0i), abs(y1i)))
    e5 /= sc
    e3 /= sc
    d = e5 * e5 + 0.01 * e3 * e3
    v = abs(h) * e5 * e5 / math.sqrt(d)
    return v if d > 0.0 else (0.0 if d == 0.0 else np.inf)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def dense_build(N, t, h, y0, y1, Kst, F, ytmp, c, s, S, cp, dp, sig, mdl):
    """The 7 dense-output coefficient vectors F of a step from time t (3 more evaluations)."""
    n = y0.shape[0]
    for st in range(NS + 1, NSX):
        _stage_state(n, st, h, y0, Kst, ytmp)
        MD.model_rhs(N, t + C_RK[st] * h, ytmp, Kst[st], c, s, S, cp, dp, sig, mdl)
    for i in range(n):
        dy = y1[i] - y0[i]
        f0 = Kst[0, i]
        f1 = Kst[NS, i]
        F[0, i] = dy
        F[1, i] = h * f0 - dy
        F[2, i] = 2.0 * dy - h * (f1 + f0)
        for r in range(4):
            acc = 0.0
            for j in range(NSX):
                acc += D_RK[r, j] * Kst[j, i]
            F[3 + r, i] = h * acc


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def dense_eval(N, x, y0, F, out):
    """The dense output at the fraction x in [0, 1] of the step (scipy's Horner form)."""
    n = y0.shape[0]
    for i in range(n):
        v = 0.0
        for k in range(NI):
            v += F[NI - 1 - k, i]
            if k % 2 == 0:
                v *= x
            else:
                v *= 1.0 - x
        out[i] = v + y0[i]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def _changed(q, last, thin):
    return abs(q - last) > thin * abs(last)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def step_size(ctl):
    """(h, last): the next step size, clipped to land on ``ctl[Q_TEND]``, or on the next
    breakpoint of the held end's motion ``ctl[Q_TBRK]`` (where its acceleration jumps; a
    step never straddles one)."""
    h = ctl[Q_H]
    rem = ctl[Q_TEND] - ctl[Q_T]
    if h >= rem * (1.0 - 1e-8):
        return rem, True
    rb = ctl[Q_TBRK] - ctl[Q_T]
    if h >= rb * (1.0 - 1e-8):
        return rb, False
    return h, False


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy", inline="always")
def accepted(err) -> bool:
    """The acceptance rule of :func:`after_attempt`: a finite scaled error <= 1."""
    return err - err == 0.0 and err <= 1.0


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def after_attempt(N, err, h, last, ns, y1, TS, HS, DOK, c, s, sig, Z, rinv0, ctl, rec, pk, meas, mdl):
    """:func:`after_attempt_with` for DOP853 (its error exponent -1/8, growth at most 10x,
    12 evaluations per attempted step)."""
    return after_attempt_with(N, err, h, last, ns, y1, TS, HS, DOK, c, s, sig, Z, rinv0, ctl, rec, pk, meas, mdl,
                              ERR_EXPONENT, MAX_FACTOR, float(NS))


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def after_attempt_with(N, err, h, last, ns, y1, TS, HS, DOK, c, s, sig, Z, rinv0, ctl, rec, pk, meas, mdl,
                       expo, max_factor, nrhs):
    """Everything after the stages of an attempted step of size h into slot ``ns``
    (``y1`` the new state, c, s, sig its trigonometry and tension; any strides):
    rejection and step-size control, or acceptance with the diagnostics, the record,
    peak detection, invariants and the stop rules. Returns :data:`GO_REJECTED`,
    :data:`GO_ON` or a return code for Python. Shared by the single-run loop
    :func:`advance_rk` and the ensemble loop (:mod:`snapping.simulate.ensemble`).
    For a general chain (``meas`` of length ``general.NMEAS_G``) the energy bound applies
    to the balance ``E - W`` (W: the work done by the held end) and the record carries the
    held end's position, velocity and work (``rec`` of width ``general.NREC_G``).
    The method's step-size rule: ``h_new = h max(MIN_FACTOR, SAFETY err^expo)`` after a
    rejection, ``h min(max_factor, SAFETY err^expo)`` after an acceptance (``expo = -1/(q +
    1)``, q the order of the error estimate); ``nrhs`` evaluations are counted per attempt."""
    ctl[Q_NRHS] += nrhs
    dtmin = ctl[Q_DTMIN]
    if not (err - err == 0.0):  # NaN/inf in the stages: reject, shrink hard
        ctl[Q_H] = MIN_FACTOR * h
        ctl[Q_NREJ] += 1.0
        ctl[Q_REJECTED] = 1.0
        ctl[Q_CONSREJ] += 1.0
        if ctl[Q_H] < dtmin:
            return K.RET_FAIL_NAN
        if ctl[Q_CONSREJ] > ctl[Q_MAXREJ]:
            return K.RET_FAIL_REJECT
        return GO_REJECTED
    if err > 1.0:
        ctl[Q_H] = h * max(MIN_FACTOR, SAFETY * err ** expo)
        ctl[Q_NREJ] += 1.0
        ctl[Q_REJECTED] = 1.0
        ctl[Q_CONSREJ] += 1.0
        if ctl[Q_H] < dtmin:
            return K.RET_FAIL_DT
        if ctl[Q_CONSREJ] > ctl[Q_MAXREJ]:
            return K.RET_FAIL_REJECT
        return GO_REJECTED
    # ---- accept
    # (PI control, Gustafsson / Hairer's DOP853: beta = ctl[Q_BETA]; 0 is the I controller)
    beta = ctl[Q_BETA]
    if err == 0.0:
        fac = max_factor
    else:
        fac = min(max_factor, SAFETY * err ** (expo + 0.2 * beta) * ctl[Q_ERROLD] ** beta)
    ctl[Q_ERROLD] = max(err, 1e-4)
    if ctl[Q_REJECTED] != 0.0:
        fac = min(1.0, fac)
    ctl[Q_REJECTED] = 0.0
    ctl[Q_CONSREJ] = 0.0
    t = ctl[Q_T]
    TS[ns] = t
    HS[ns] = h
    DOK[ns] = 0.0
    t = ctl[Q_TEND] if last else t + h
    brk = ctl[Q_TBRK]
    at_brk = not last and brk < np.inf and abs(t - brk) <= 1e-13 * max(1.0, abs(brk))
    if at_brk:  # (the step was clipped to land on it; the next starts with the right limit there)
        t = brk
        ctl[Q_LASTBRK] = brk
    ctl[Q_T] = t
    ctl[Q_SLOT] = float(ns)
    dt = h * fac
    ctl[Q_H] = dt
    ctl[Q_NSTEPS] += 1.0
    ctl[Q_NCALL] += 1.0
    if h < ctl[Q_DT_MIN_ACC]:
        ctl[Q_DT_MIN_ACC] = h
    if h > ctl[Q_DT_MAX_ACC] and not last:
        ctl[Q_DT_MAX_ACC] = h
    if err > ctl[Q_ERR_MAX_ACC]:
        ctl[Q_ERR_MAX_ACC] = err
    MD.model_measure(N, t, y1, c, s, sig, Z, rinv0, meas, mdl)
    # ---- running peaks (every accepted step)
    for qi in range(pk.shape[0]):
        if qi == 0:
            q = meas[K.M_VMAX]
        elif qi == 1:
            q = meas[K.M_AMAX]
        elif qi == 2:
            q = meas[K.M_SIGMAX]
        elif qi == 3:
            q = meas[K.M_KMAX]
        else:  # (a general chain's fifth row) kappa_max_interior on the approach: while v_max is at its running peak
            q = meas[G.M_KIN] if meas[K.M_VMAX] >= pk[0, PK_SBEST] else -np.inf
        if q > pk[qi, PK_SBEST]:
            pk[qi, PK_SBEST] = q
            pk[qi, PK_TBEFORE] = pk[qi, PK_TPREV]
            pk[qi, PK_NEED] = 1.0
            if q > pk[qi, PK_BEST]:
                pk[qi, PK_BEST] = q
                pk[qi, PK_TBEST] = t
        elif pk[qi, PK_NEED] != 0.0:
            pk[qi, PK_NEED] = 0.0
            pk[qi, PK_TA] = pk[qi, PK_TBEFORE]
            pk[qi, PK_TB] = t
            ctl[Q_REFINE] = float(int(ctl[Q_REFINE]) | (1 << qi))
        pk[qi, PK_TPREV] = t
    # ---- invariants
    if meas[K.M_LINKERR] > ctl[Q_DRIFT_LINK]:
        ctl[Q_DRIFT_LINK] = meas[K.M_LINKERR]
    l0 = ctl[Q_L0]
    dl = abs(meas[K.M_LENGTH] - l0) / l0
    if dl > ctl[Q_DRIFT_LEN]:
        ctl[Q_DRIFT_LEN] = dl
    ebal = meas[K.M_ENERGY]
    if meas.shape[0] > K.NMEAS:
        ebal -= meas[G.M_WORK]
    if meas.shape[0] > G.NMEAS_G:  # a chain with node forces: + the energy dissipated (forced.M_DISS)
        ebal += meas[G.NMEAS_G + 1]
    de = abs(ebal - ctl[Q_E0])
    if de > ctl[Q_DRIFT_E]:
        ctl[Q_DRIFT_E] = de
    # ---- why stop here?
    vmax = meas[K.M_VMAX]
    vbest = pk[0, PK_BEST]
    stopfrac = ctl[Q_STOPFRAC]
    vdown = ctl[Q_VDOWN]
    if ctl[Q_TSETTLE] >= 0.0:
        # a moving held end (general.settle_time): the chain's speed relative to the held
        # end, from the time the held end's acceleration stops changing; the rule falls
        # only after a rise above the speed it was armed with
        vrel = meas[G.M_VREL]
        if ctl[Q_ARMED] == 0.0:
            if t >= ctl[Q_TSETTLE]:
                ctl[Q_ARMED] = 1.0
                ctl[Q_VRBASE] = vrel
                ctl[Q_VRPEAK] = vrel
        elif vrel > ctl[Q_VRPEAK]:
            ctl[Q_VRPEAK] = vrel
        fell = ctl[Q_ARMED] != 0.0 and ctl[Q_VRPEAK] > ctl[Q_VRBASE] and vrel < stopfrac * ctl[Q_VRPEAK]
    else:
        fell = vbest > ctl[Q_VFLOOR] and vmax < stopfrac * vbest
    code = GO_ON
    if meas[K.M_FINITE] == 0.0:
        code = K.RET_FAIL_NAN
    elif meas[K.M_LINKERR] > ctl[Q_MAXLINK]:
        code = K.RET_FAIL_DRIFT
    elif de > ctl[Q_MAXENERGY]:
        code = K.RET_FAIL_ENERGY
    elif dt < dtmin:
        code = K.RET_FAIL_DT
    elif stopfrac > 0.0 and fell:
        code = K.RET_STOP
    elif last:
        code = K.RET_END
    elif t >= ctl[Q_TRET] or at_brk:
        code = K.RET_T_RETURN
    elif vmax >= ctl[Q_VUP]:
        code = K.RET_V_UP
    elif vdown > 0.0 and vmax < vdown * vbest:
        code = K.RET_V_DOWN
    elif ctl[Q_REFINE] != 0.0:
        code = RET_REFINE
    # ---- record (thinned by relative change; always the last step)
    thin = ctl[Q_THIN]
    nrec = int(ctl[Q_NREC])
    if (thin == 0.0 or code == K.RET_STOP or code == K.RET_END or code >= K.RET_FAIL_NAN
            or _changed(vmax, ctl[Q_LAST_V], thin) or _changed(meas[K.M_AMAX], ctl[Q_LAST_A], thin)
            or _changed(meas[K.M_SIGMAX], ctl[Q_LAST_S], thin) or _changed(meas[K.M_KMAX], ctl[Q_LAST_K], thin)):
        K._write_record(rec, nrec, t, h, err * ctl[Q_TOL], meas)
        for q in range(rec.shape[1] - K.NREC):
            rec[nrec, K.NREC + q] = meas[K.NMEAS + q]
        nrec += 1
        ctl[Q_NREC] = float(nrec)
        ctl[Q_LAST_V] = vmax
        ctl[Q_LAST_A] = meas[K.M_AMAX]
        ctl[Q_LAST_S] = meas[K.M_SIGMAX]
        ctl[Q_LAST_K] = meas[K.M_KMAX]
    if code >= 0:
        return code
    if nrec >= rec.shape[0]:
        return K.RET_RECORD_FULL
    if ctl[Q_NCALL] >= ctl[Q_STEPS_PER_CALL]:
        return K.RET_CALL_LIMIT
    return GO_ON


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def advance_rk(N, Y0, Y1, KK, TS, HS, DOK, ytmp, c, s, S, cp, dp, sig, Z, rinv0, ctl, rec, pk, meas, mdl):
    """Advance the angle-form chain with DOP853 until something needs Python.

    Two step slots (arrays indexed [slot]): ``Y0``/``Y1`` start and end states, ``KK``
    (2, 16, 2N) the stages, ``TS``/``HS`` start time and size, ``DOK`` whether the
    slot's dense output has been built (cleared when the slot is reused).
    ``ctl[Q_SLOT]`` is the slot of the last accepted step: its ``Y1`` is the current
    state, ``KK[slot, 12]`` its derivative, and ``Z``/``meas`` its diagnostics.
    Returns a ``kernels.RET_*`` code or :data:`RET_REFINE` (``ctl[Q_REFINE]`` is a
    bit mask of the quantities v, a, sigma, kappa whose peak is to be located on
    ``[pk[q, PK_TA], pk[q, PK_TB]]``, which the two slots cover).
    """
    n = Y0.shape[1]
    tol = ctl[Q_TOL]
    ctl[Q_NCALL] = 0.0
    while True:
        sl = int(ctl[Q_SLOT])
        ns = 1 - sl
        h, last = step_size(ctl)
        y0 = Y0[ns]
        ycur = Y1[sl]
        for i in range(n):
            y0[i] = ycur[i]
        if ctl[Q_T] == ctl[Q_LASTBRK]:
            # a step from a breakpoint of the held end's motion (its acceleration jumps):
            # the first stage is the derivative just after it, not the last step's end (FSAL)
            MD.model_rhs(N, np.nextafter(ctl[Q_T], np.inf), y0, KK[ns, 0], c, s, S, cp, dp, sig, mdl)
            ctl[Q_NRHS] += 1.0
        else:
            for i in range(n):
                KK[ns, 0, i] = KK[sl, NS, i]
        err = rk_step(N, ctl[Q_T], h, y0, Y1[ns], KK[ns], ytmp, c, s, S, cp, dp, sig, tol, mdl)
        code = after_attempt(N, err, h, last, ns, Y1[ns], TS, HS, DOK, c, s, sig, Z, rinv0, ctl, rec, pk, meas,
                             mdl)
        if code >= 0:
            return code
