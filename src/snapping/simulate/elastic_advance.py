"""The elastic line's RODAS4 run loop, compiled: many steps and their bookkeeping between two
returns to Python (``elastic.solve(..., method="rodas4")``; :func:`advance_links` and
:class:`LinksRun` for ``"rodas4-links"``: the link-coordinate step, the node state's measures,
the same bookkeeping, :func:`_book`).

:func:`advance` takes accepted steps (:func:`snapping.simulate.elastic_rodas.rodas_accept`)
and after each does what :func:`snapping.simulate.elastic_solve.solve`'s step loop does for
the other methods, in the same order and with the same arithmetic: the per-state measures
(:func:`elastic_kernels.measure_given`, from the step's last evaluation: the next step's
first stage is ``f`` at the new state, so its tensions and accelerations are already there),
one row of the step record, the running maxima of v, a and sigma with the continuous
extensions of the steps around each (kept in a pool of step slots, without copies), the
first slack link, the running peak of v_max and its state, then the checks: a non-finite
state, ``max_rhs``, the energy balance, the stop rule (v_max below ``stop_fraction`` of its
running peak once that peak is above the floor), the energy-error failure. It returns to
Python at the end, at a stop or failure, after the step that passes the next snapshot time,
and when the record buffer is full (:class:`RodasRun` then drains it). The peaks are then
refined on the kept steps by :func:`elastic_refine.refine` (compiled, on the step slots), or by
``elastic_solve._Peaks.refine`` (:meth:`RodasRun.segments`; ``COMPILED_REFINE = False``): the
dense output guides it, the states are integrated from the step's start.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import elastic_kernels as EK
from . import elastic_links_rodas as ELR
from . import elastic_refine as ERF
from . import elastic_rodas as ER

__all__ = ["advance", "advance_links", "RodasRun", "LinksRun", "NREC", "NSLOT"]

#: columns of a record row: t, then elastic_solve.STEP_NAMES
NREC = 22
#: rows of the record buffer (a full buffer returns to Python, which drains it)
ROWS = 4096
#: step slots of the pool (three kept steps per peak kind, the last step, one being taken; four kinds since
#: branch stretchapp: v, a, sigma and kappa_max_interior on the approach)
NSLOT = 15
#: the approach kind's row in the pool's peaks (``best``, ``keep``): kappa_max_interior while v_max is at its
#: running peak (``kappa_peak_approach``), refined after the other three (:func:`elastic_refine.refine_approach`)
APPROACH = 3
#: the peak kinds' columns of the measures (v_max, a_max, sigma_max)
KCOL = ERF.KCOL
#: the approach kind's column (kappa_max_interior)
KIN = ERF.KIN
#: the run's controls (``sctl``): t_end given, stop_fraction, the stop floor, the running peak
#: of v_max, when the stop rule was armed, the largest energy error, E(0), U(0), max_rhs, the
#: next snapshot time, the first slack time, rows in the buffer, the running peak's time, the
#: last step's slot, the energy error's failure fraction
(S_TEND, S_FRAC, S_FLOOR, S_RUN, S_ARMED, S_ERR, S_E0, S_U0, S_MAXRHS, S_TSNAP, S_SLACK, S_NREC, S_PEAKT,
 S_PREV, S_EFAIL) = range(15)
NSCTL = 15
#: what :func:`advance` returns
(R_FINISHED, R_SNAP, R_STEP_FAILED, R_NONFINITE, R_MAXRHS, R_ENERGY, R_SNAPSHOT, R_BUFFER) = range(8)


@njit(cache=True, error_model="numpy")
def _hold(ref, keep, nkeep, k, s):
    keep[k, nkeep[k]] = s
    nkeep[k] += 1
    ref[s] += 1


@njit(cache=True, error_model="numpy")
def _peaks_update(t, mm, s, prev, ref, keep, nkeep, after, best):
    """``_Peaks.update`` of elastic_solve on slots: a new maximum keeps the step before it and
    its own, and the step after it once taken. The fourth kind (:data:`APPROACH`): kappa_max_interior
    where v_max is at its running peak (the v kind's best, this step's included), else nothing."""
    for k in range(4):
        if k < 3:
            q = mm[KCOL[k]]
        else:
            q = mm[KIN] if mm[0] >= best[0, 0] else -np.inf
        if after[k]:
            _hold(ref, keep, nkeep, k, s)
            after[k] = False
        if q > best[k, 0]:
            best[k, 0] = q
            best[k, 1] = t
            for q in range(nkeep[k]):
                ref[keep[k, q]] -= 1
            nkeep[k] = 0
            if prev >= 0:
                _hold(ref, keep, nkeep, k, prev)
            _hold(ref, keep, nkeep, k, s)
            after[k] = True
    if prev >= 0:
        ref[prev] -= 1
    ref[s] += 1


@njit(cache=True, error_model="numpy")
def _free(ref):
    """The first step slot no one uses."""
    s = 0
    while ref[s] > 0:
        s += 1
    return s


@njit(cache=True, error_model="numpy")
def _book(N, t, t_old, y, mm, s, s_node, s_link, nfev, finished, ref, keep, nkeep, after, best, sctl, rec, peak_z):
    """The bookkeeping of the accepted step ``t_old -> t`` in slot ``s`` ending at the node state
    ``y`` with the measures ``mm``: its record row, the peaks, the first slack time, the running
    peak and its state, then the checks. Returns an ``R_*`` code, or -1 to go on."""
    n = y.shape[0]
    r = int(sctl[S_NREC])
    row = rec[r]
    W = y[4 * N]
    D = y[4 * N + 1]
    row[0] = t
    row[1] = t - t_old
    row[2] = mm[0]
    row[3] = mm[2]
    row[4] = mm[4]
    row[5] = s_node[int(mm[1])]
    row[6] = s_node[int(mm[3])]
    row[7] = s_link[int(mm[5])]
    row[8] = mm[6]
    row[9] = mm[8]
    row[10] = mm[9]
    row[11] = mm[10]
    row[12] = mm[11]
    row[13] = mm[12] + mm[13] + mm[14]
    row[14] = mm[14]
    row[15] = W
    row[16] = D
    row[17] = mm[15]
    row[18] = mm[16]
    row[19] = mm[17]
    row[20] = s_node[int(mm[18])]
    row[21] = mm[19]
    sctl[S_NREC] = r + 1
    prev = int(sctl[S_PREV])
    _peaks_update(t, mm, s, prev, ref, keep, nkeep, after, best)
    sctl[S_PREV] = s
    if mm[16] > 0 and np.isnan(sctl[S_SLACK]):
        sctl[S_SLACK] = t
    if mm[0] > sctl[S_RUN]:
        sctl[S_RUN] = mm[0]
        sctl[S_PEAKT] = t
        for i in range(n):
            peak_z[i] = y[i]
    for i in range(n):
        if not (y[i] - y[i] == 0.0):
            return R_NONFINITE
    if nfev > sctl[S_MAXRHS]:
        return R_MAXRHS
    tend = sctl[S_TEND] != 0.0
    sctl[S_ERR] = max(sctl[S_ERR], abs(row[13] - W + D - sctl[S_E0]))
    if np.isnan(sctl[S_ARMED]) and sctl[S_RUN] >= sctl[S_FLOOR]:
        sctl[S_ARMED] = t
    if not tend and not np.isnan(sctl[S_ARMED]) and mm[0] < sctl[S_FRAC] * sctl[S_RUN]:
        return R_SNAP
    if not tend and sctl[S_ERR] > sctl[S_EFAIL] * (abs(sctl[S_E0]) + abs(W) + sctl[S_U0]):
        return R_ENERGY
    if finished:
        return R_FINISHED
    if t >= sctl[S_TSNAP]:
        return R_SNAPSHOT
    if r + 1 == rec.shape[0]:
        return R_BUFFER
    return -1


@njit(cache=True, error_model="numpy")
def advance(N, y, St, B, gW, gD, dsp, F, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g, ytmp,
            btmp, w, ft, ctl, T, E, ED, FV, m, tabw, snode, s_node, s_link, mm, PY0, PY1, PC, PT, ref, keep, nkeep,
            after, best, sctl, rec, peak_z):
    """Accepted steps from ``(ctl[C_T], y)`` and their bookkeeping until one of the ``R_*``
    codes (see the module). Slot ``s`` of the pool holds a step's start ``PY0[s]``, end
    ``PY1[s]``, dense output ``PC[s]`` and ``PT[s] = (t_old, t)``; ``ref[s]`` counts its users
    (the kept steps of the peaks, the last step)."""
    pin = pins[6]
    while True:
        s = _free(ref)
        if ER.rodas_accept(N, y, St, B, gW, gD, dsp, F, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe,
                           tabt, g, ytmp, btmp, w, ft, PY1[s], PY0[s], PC[s], ctl, T, E, ED, FV) != 0:
            return R_STEP_FAILED
        t = ctl[ER.C_T]
        PT[s, 0] = ctl[ER.C_TOLD]
        PT[s, 1] = t
        # St[0] = f(t, y) and T, E its tensions and strains, with the held end at t (pins[6])
        EK.measure_given(N, y, pin, h, m, ea, tabe, tabt, tabw, g, snode, St[0], T, E, mm)
        code = _book(N, t, ctl[ER.C_TOLD], y, mm, s, s_node, s_link, ctl[ER.C_NFEV], ctl[ER.C_STATUS] == ER.FINISHED,
                     ref, keep, nkeep, after, best, sctl, rec, peak_z)
        if code >= 0:
            return code


@njit(cache=True, error_model="numpy")
def advance_links(N, y, yn, St, B, gW, gD, dsp, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g,
                  ytmp, btmp, w, ft, zn1, ctl, T, E, ED, FV, gx, gy, cw, m, tabw, snode, s_node, s_link, mm, PY0, PY1,
                  PC, PT, PN0, ref, keep, nkeep, after, best, sctl, rec, peak_z):
    """:func:`advance` for ``"rodas4-links"`` (:func:`elastic_links_rodas.links_accept` on the
    link state ``y``, node state ``yn``): slot ``s`` holds the step's link states ``PY0[s]``,
    ``PY1[s]``, dense output ``PC[s]`` and node start ``PN0[s]``; the measures are the node
    state's (``ElasticLine.measure``), as the Python loop takes them."""
    while True:
        s = _free(ref)
        if ELR.links_accept(N, y, yn, St, B, gW, gD, dsp, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe,
                            tabt, g, ytmp, btmp, w, ft, PY1[s], zn1, PY0[s], PN0[s], PC[s], ctl, T, E, ED, FV, gx, gy,
                            cw) != 0:
            return R_STEP_FAILED
        t = ctl[ER.C_T]
        PT[s, 0] = ctl[ER.C_TOLD]
        PT[s, 1] = t
        ERF.measure(N, t, yn, pinpar, pintab, h, m, ea, damp, tabe, tabt, tabw, g, snode, mm)
        code = _book(N, t, ctl[ER.C_TOLD], yn, mm, s, s_node, s_link, ctl[ER.C_NFEV], ctl[ER.C_STATUS] == ER.FINISHED,
                     ref, keep, nkeep, after, best, sctl, rec, peak_z)
        if code >= 0:
            return code


class RodasRun:
    """A RODAS4 run of :func:`elastic_solve.solve`: the stepper's state (a
    :class:`~snapping.simulate.elastic_rodas.RodasStepper`), the pool of step slots, the
    peaks and the run's controls; :meth:`advance` runs the compiled loop to its next return."""

    def __init__(self, stepper, mm0, *, t_end_given, stop_fraction, floor, E0, U0, max_rhs, energy_fail, rows=None):
        st = self.st = stepper
        n = st.y.size
        self.PY0, self.PY1 = np.zeros((NSLOT, n)), np.zeros((NSLOT, n))
        self.PC = np.zeros((NSLOT, 2, n))
        self.PT = np.zeros((NSLOT, 2))
        self.ref = np.zeros(NSLOT, dtype=np.int64)
        self.keep = np.full((4, 3), -1, dtype=np.int64)
        self.nkeep = np.zeros(4, dtype=np.int64)
        self.after = np.ones(4, dtype=np.bool_)  # (as _Peaks.update(0, mm0, None) leaves them)
        self.best = np.array([[mm0[c], 0.0] for c in KCOL] + [[-np.inf, 0.0]])
        if mm0[KIN] > -np.inf:  # (NaN: fewer than KAPPA_TIP_JOINTS + 1 links, no approach peak)
            self.best[APPROACH, 0] = mm0[KIN]
        else:
            self.after[APPROACH] = False
        self.sctl = np.zeros(NSCTL)
        c = self.sctl
        c[S_TEND], c[S_FRAC], c[S_FLOOR], c[S_RUN] = float(t_end_given), stop_fraction, floor, 0.0
        c[S_ARMED], c[S_ERR], c[S_E0], c[S_U0], c[S_MAXRHS] = np.nan, 0.0, E0, U0, max_rhs
        c[S_TSNAP], c[S_SLACK], c[S_NREC], c[S_PEAKT], c[S_PREV], c[S_EFAIL] = np.inf, np.nan, 0, 0.0, -1, energy_fail
        self.rec = np.zeros((ROWS if rows is None else rows, NREC))
        self.peak_z = st.y.copy()
        self.mm = np.zeros(EK.NMEAS)
        ln = st.line
        self.model = (ln.m, ln.tabw, ln.snode, np.concatenate([ln.snode, [0.0]]), ln.snode - 0.5 * ln.h)

    def advance(self, t_snapshot=np.inf, rows=None) -> int:
        """Steps until the next return code (``R_*``), the next snapshot time ``t_snapshot``;
        ``rows``: the record buffer's rows this call may fill (default all: R_BUFFER once full;
        fewer return sooner, the same steps: :class:`snapping.simulate.elastic_progress.Chunks`)."""
        st = self.st
        self.sctl[S_TSNAP] = t_snapshot
        rec = self.rec if rows is None else self.rec[:rows]
        return advance(st.N, st.y, st.St, st.B, st.gW, st.gD, st.dsp, st.F, st.ab, st.piv, st.pins, st.pinpar,
                       st.pintab, *st.args(), st.ytmp, st.btmp, st.w, st.ft, st.ctl, *st.work, *self.model, self.mm,
                       self.PY0, self.PY1, self.PC, self.PT, self.ref, self.keep, self.nkeep, self.after, self.best,
                       self.sctl, rec, self.peak_z)

    def drain(self) -> np.ndarray:
        """The record rows since the last drain (t first, then STEP_NAMES)."""
        k = int(self.sctl[S_NREC])
        out = self.rec[:k].copy()
        self.sctl[S_NREC] = 0
        return out

    def dense(self, s):
        """The continuous extension of the step in slot ``s``."""
        return ER.RodasDense(self.PT[s, 0], self.PT[s, 1], self.PY0[s].copy(), self.PY1[s].copy(), self.PC[s])

    def last_dense(self):
        return self.dense(int(self.sctl[S_PREV]))

    def start(self, s):
        """The node state at the start of the step in slot ``s``."""
        return self.PY0[s].copy()

    def last_start(self):
        return self.start(int(self.sctl[S_PREV]))

    #: the stepper's arrays that carry a run from one step to the next (the rest is scratch that
    #: every attempt sets anew): the state, the controls and counts (the step-size controller's
    #: step and last error among them), f (``St[0]``) and the Jacobian at the state
    STEPPER_STATE = ("y", "ctl", "St0", "B", "gW", "gD", "dsp")
    #: the run's: the step slots (the peaks' kept steps, the last step), the peaks, the run's
    #: controls and the running peak's state (the record is drained at every return)
    RUN_STATE = ("PY0", "PY1", "PC", "PT", "ref", "keep", "nkeep", "after", "best", "sctl", "peak_z")

    def state(self) -> dict:
        """{name: copy} of the arrays from which :meth:`restore` continues the run, bit for bit:
        taken at a return of the compiled loop, after :meth:`drain` (what a checkpoint of the
        run must hold besides its record, snapshots and inputs;
        ``benchmarks/probe_elastic_restore.py``)."""
        st = self.st
        out = {f"stepper_{k}": (st.St[0] if k == "St0" else getattr(st, k)).copy() for k in self.STEPPER_STATE}
        out.update({k: getattr(self, k).copy() for k in self.RUN_STATE})
        return out

    def restore(self, state: dict) -> None:
        """Put :meth:`state`'s arrays back, in place, into this run and its stepper (built for the
        same line); a missing name or a shape that differs is a ValueError."""
        st = self.st
        want = {f"stepper_{k}" for k in self.STEPPER_STATE} | set(self.RUN_STATE)
        if set(state) != want:
            raise ValueError(f"run state: expected the arrays {sorted(want)}, got {sorted(state)}")
        for k, v in state.items():
            dst = (st.St[0] if k == "stepper_St0" else getattr(st, k[8:])) if k.startswith("stepper_") \
                else getattr(self, k)
            if np.shape(v) != dst.shape:
                raise ValueError(f"run state: {k} has shape {np.shape(v)}, the run's is {dst.shape}")
            dst[...] = v

    def segments(self):
        """{kind index: (best value, its time, [(t_old, y_old, t, dense) of the kept steps])}
        (kinds v, a, sigma, and the approach's kappa_max_interior): the peaks before refinement, with the
        kept steps' starts."""
        return {k: (float(self.best[k, 0]), float(self.best[k, 1]),
                    [(float(self.PT[s, 0]), self.start(int(s)), float(self.PT[s, 1]), self.dense(int(s)))
                     for s in self.keep[k, :self.nkeep[k]]]) for k in range(4)}


class LinksRun(RodasRun):
    """:class:`RodasRun` for a :class:`~snapping.simulate.elastic_links_rodas.LinksStepper`
    (:func:`advance_links`): the slots hold link states, and ``PN0`` the steps' node starts."""

    STEPPER_STATE = ("zl", "yn", "ctl", "St0", "B", "gW", "gD", "dsp")
    RUN_STATE = RodasRun.RUN_STATE + ("PN0",)

    def __init__(self, stepper, mm0, **kw):
        super().__init__(stepper, mm0, **kw)
        self.PN0 = np.zeros_like(self.PY0)

    def advance(self, t_snapshot=np.inf, rows=None) -> int:
        st = self.st
        self.sctl[S_TSNAP] = t_snapshot
        rec = self.rec if rows is None else self.rec[:rows]
        return advance_links(st.N, st.zl, st.yn, st.St, st.B, st.gW, st.gD, st.dsp, st.ab, st.piv, st.pins,
                             st.pinpar, st.pintab, *st.args(), st.ytmp, st.btmp, st.w, st.ft, st.zn1, st.ctl,
                             *st.work, st.cw, *self.model, self.mm, self.PY0, self.PY1, self.PC, self.PT, self.PN0,
                             self.ref, self.keep, self.nkeep, self.after, self.best, self.sctl, rec, self.peak_z)

    def dense(self, s):
        return ELR.LinksDense(self.st.links, self.PT[s, 0], self.PT[s, 1], self.PY0[s].copy(), self.PY1[s].copy(),
                              self.PC[s])

    def start(self, s):
        return self.PN0[s].copy()
