"""The peaks' refinement of a compiled RODAS4 run (``elastic.solve(..., method="rodas4")``),
compiled: the arithmetic of :meth:`snapping.simulate.elastic_solve._Peaks.refine`, the same
numbers bit for bit (``elastic_solve.COMPILED_REFINE = False``: the Python one).

For each peak kind (v_max, a_max, sigma_max) the continuous extension of each kept step
(:class:`~snapping.simulate.elastic_rodas.RodasDense`'s formula, on the step slots of
:class:`~snapping.simulate.elastic_advance.RodasRun`) is sampled at the ``samples - 1``
interior points of ``np.linspace(t_old, t, samples + 1)``; the best sample and the ``window``
samples on either side of it are integrated again from the step's start, each as a fresh
:class:`~snapping.simulate.elastic_rodas.RodasStepper` (``h0`` the whole interval, the run's
tolerance) would (:func:`restep`), and measured; a state integrated for one kind is reused by
the others (the Python refinement's cache, keyed by the step's start and the sample). In
Python that was ~2.5-3 ms a run at N = 100 (200 calls of the compiled ``measure`` and up to
nine steppers built); here one compiled call.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import elastic_kernels as EK
from . import elastic_links as EL
from . import elastic_links_rodas as ELR
from . import elastic_rodas as ER
from . import elastic_stage as ES

#: the peak kinds' columns of the measures (v_max, a_max, sigma_max; ``elastic_advance`` keeps its
#: peaks in this order)
KCOL = np.array([0, 2, 4])
#: the measures' column of kappa_max_interior (the approach kind's, ``elastic_advance.APPROACH``)
KIN = 19

__all__ = ["refine", "refine_approach", "refine_slots", "refine_segments", "restep", "restep_links", "restep_call", "grid", "measure"]


@njit(cache=True, error_model="numpy")
def grid(t0, t1, samples, out):
    """``np.linspace(t0, t1, samples + 1)`` into ``out``, the same numbers (numpy's
    ``arange * step + start``, the last point ``t1``; ``(i / div) * delta`` when the step is 0)."""
    div = samples
    delta = t1 - t0
    step = delta / div
    for i in range(samples + 1):
        if step == 0.0:
            out[i] = (i / div) * delta + t0
        else:
            out[i] = i * step + t0
    out[samples] = t1


@njit(cache=True, error_model="numpy")
def _fresh_ctl(t0, t1, tol, auto):
    """A fresh stepper's controls from ``t0`` to ``t1`` (``RodasStepper.__init__``'s)."""
    ctl = np.zeros(ER.NCTL)
    ctl[ER.C_T] = t0
    ctl[ER.C_TOLD] = np.nan
    ctl[ER.C_TB] = t1
    ctl[ER.C_TOL] = tol
    ctl[ER.C_HACC] = -1.0
    ctl[ER.C_AUTO] = auto
    return ctl


@njit(cache=True, error_model="numpy")
def _first_step(ctl, h0):
    """The first evaluation and Jacobian counted, the first step ``h0``."""
    ctl[ER.C_NFEV] += 1.0
    ctl[ER.C_NJEV] += 1.0
    ctl[ER.C_H] = h0


@njit(cache=True, error_model="numpy")
def _jacobian_work(N, n):
    """Fresh stage rows ``St`` and Jacobian blocks ``B, gW, gD, dsp`` of a stepper."""
    return np.zeros((7, n)), np.zeros((N, 3, 8)), np.zeros(4), np.zeros(4 * N), np.zeros(2)


@njit(cache=True, error_model="numpy")
def restep(N, t0, y0, t1, tol, auto, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g, y):
    """The state at ``t1`` integrated from ``(t0, y0)`` into ``y``, as ``RodasStepper(line, t0,
    y0, t1, tol, h0=t1 - t0)`` stepped until it stops would give it (fresh arrays, the same
    calls). Returns (finished, evaluations)."""
    n = y0.shape[0]
    ctl = _fresh_ctl(t0, t1, tol, auto)
    for i in range(n):
        y[i] = y0[i]
    St, B, gW, gD, dsp = _jacobian_work(N, n)
    F = np.zeros((N, ES.NF))
    ab = np.zeros((2 * N, ES.WIDTH))
    piv = np.zeros(2 * N, dtype=np.int64)
    ytmp, btmp, z1, ft, y0d = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    w = np.zeros(2 * N)
    c23 = np.zeros((2, n))
    T, E, ED, FV = np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N)
    pins = np.zeros((7, 4))
    ER.f_and_jacobian(N, t0, y, pinpar, pintab, pins[6], h, invm, ea, damp, tabe, tabt, g, St[0], B, gW, gD, dsp,
                      T, E, ED, FV)
    _first_step(ctl, t1 - t0)
    while ctl[ER.C_STATUS] == ER.RUNNING:
        if ER.rodas_accept(N, y, St, B, gW, gD, dsp, F, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt,
                           g, ytmp, btmp, w, ft, z1, y0d, c23, ctl, T, E, ED, FV) != 0:
            break
    return ctl[ER.C_STATUS] == ER.FINISHED, ctl[ER.C_NFEV]


@njit(cache=True, error_model="numpy")
def restep_links(N, t0, y0, t1, tol, auto, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g, y):
    """:func:`restep` for ``"rodas4-links"``: from the node state ``y0``, as ``LinksStepper(line,
    t0, y0, t1, tol, h0=t1 - t0)`` stepped until it stops would give it; the node state into
    ``y``. Returns (finished, evaluations)."""
    n = y0.shape[0]
    ctl = _fresh_ctl(t0, t1, tol, auto)
    pins = np.zeros((7, 6))
    EL.pin6_at(t0, pinpar, pintab, pins[6])
    z = np.empty(n)
    EL.from_nodes(N, y0, pins[6], z)
    for i in range(n):
        y[i] = y0[i]
    St, B, gW, gD, dsp = _jacobian_work(N, n)
    ab = np.zeros((2 * N, ES.WIDTH))
    piv = np.zeros(2 * N, dtype=np.int64)
    ytmp, btmp, z1, zn1, ft, y0d, yn0d = (np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                                          np.zeros(n), np.zeros(n))
    w = np.zeros(2 * N)
    c23 = np.zeros((2, n))
    T, E, ED, FV, gx, gy = np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N)
    cw = np.zeros((4, N))
    ELR.f_and_jacobian(N, t0, z, pinpar, pintab, pins[6], h, invm, ea, damp, tabe, tabt, g, St[0], B, gW, gD, dsp,
                       T, E, ED, FV, gx, gy, cw)
    _first_step(ctl, t1 - t0)
    while ctl[ER.C_STATUS] == ER.RUNNING:
        if ELR.links_accept(N, z, y, St, B, gW, gD, dsp, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt,
                            g, ytmp, btmp, w, ft, z1, zn1, y0d, yn0d, c23, ctl, T, E, ED, FV, gx, gy, cw) != 0:
            break
    return ctl[ER.C_STATUS] == ER.FINISHED, ctl[ER.C_NFEV]


@njit(cache=True, error_model="numpy")
def measure(N, t, z, pinpar, pintab, h, m, ea, damp, tabe, tabt, tabw, g, snode, out):
    """``ElasticLine.measure(t, z)`` into ``out``."""
    pin = np.zeros(4)
    ER.pin_at(t, pinpar, pintab, pin)
    for i in range(out.shape[0]):
        out[i] = 0.0
    EK.measure(N, z, pin, h, m, ea, damp, tabe, tabt, tabw, g, snode, np.empty_like(z), np.zeros(N), np.zeros(N),
               np.zeros(N), np.zeros(N), out)


@njit(cache=True, error_model="numpy")
def refine_slots(N, kcol, best, keep, nkeep, PT, PY0, PY1, PC, samples, window, tol, auto, pinpar, pintab, h, invm,
                 m, ea, damp, tabe, tabt, tabw, g, snode, out, links, PR0):
    """``_Peaks.refine`` on the kept step slots (``keep[k, :nkeep[k]]`` of ``RodasRun``) of the
    kinds ``kcol`` (measure columns) with the running peaks ``best``: the refined (value, time)
    of each kind into ``out``; returns the evaluations of the integrations. ``links``: the
    slots' ``PY0, PY1, PC`` are link states (their dense output is mapped to the nodes), the
    integrations :func:`restep_links`'; ``PR0`` the node states the integrations start from
    (``PY0`` itself for ``"rodas4"``)."""
    n = PY0.shape[1]
    p6 = np.zeros(6)
    yn = np.empty(n)
    nk = kcol.shape[0]
    ts = np.empty(samples + 1)
    y = np.empty(n)
    yd = np.empty(n)
    nslot = PT.shape[0]
    gm = np.zeros((nslot, samples, EK.NMEAS))
    done = np.zeros(nslot, dtype=np.bool_)
    # the cache of integrated states: (step start, sample) -> measures (or failed)
    cap = nk * (2 * window + 1)
    ck_t = np.empty(cap)
    ck_j = np.empty(cap, dtype=np.int64)
    ck_ok = np.zeros(cap, dtype=np.bool_)
    ck_mm = np.zeros((cap, EK.NMEAS))
    nc = 0
    nfev = 0.0
    for k in range(nk):
        c = kcol[k]
        val = best[k, 0]
        tp = best[k, 1]
        gs = -1
        gi = 0
        gval = -np.inf
        for q in range(nkeep[k]):
            s = keep[k, q]
            if not done[s]:  # (the measures of a step's samples, for every kind that keeps it)
                done[s] = True
                t_old = PT[s, 0]
                t_new = PT[s, 1]
                grid(t_old, t_new, samples, ts)
                for i in range(1, samples):
                    x = (ts[i] - t_old) / (t_new - t_old)
                    for r in range(n):
                        yd[r] = PY0[s, r] * (1.0 - x) + x * (PY1[s, r] + (1.0 - x) * (PC[s, 0, r] + x * PC[s, 1, r]))
                    if links:
                        EL.pin6_at(ts[i], pinpar, pintab, p6)
                        EL.to_nodes(N, yd, p6, yn)
                        measure(N, ts[i], yn, pinpar, pintab, h, m, ea, damp, tabe, tabt, tabw, g, snode, gm[s, i])
                    else:
                        measure(N, ts[i], yd, pinpar, pintab, h, m, ea, damp, tabe, tabt, tabw, g, snode, gm[s, i])
            for i in range(1, samples):
                if gm[s, i, c] > gval:
                    gs = s
                    gi = i
                    gval = gm[s, i, c]
        if gs < 0:
            out[k, 0] = val
            out[k, 1] = tp
            continue
        t_old = PT[gs, 0]
        grid(t_old, PT[gs, 1], samples, ts)
        for j in range(max(1, gi - window), min(samples - 1, gi + window) + 1):
            e = -1
            for q in range(nc):
                if ck_t[q] == t_old and ck_j[q] == j:
                    e = q
                    break
            if e < 0:
                e = nc
                nc += 1
                ck_t[e] = t_old
                ck_j[e] = j
                if links:
                    ok, nf = restep_links(N, t_old, PR0[gs], ts[j], tol, auto, pinpar, pintab, h, invm, ea, damp,
                                          tabe, tabt, g, y)
                else:
                    ok, nf = restep(N, t_old, PR0[gs], ts[j], tol, auto, pinpar, pintab, h, invm, ea, damp, tabe,
                                    tabt, g, y)
                nfev += nf
                ck_ok[e] = ok
                if ok:
                    measure(N, ts[j], y, pinpar, pintab, h, m, ea, damp, tabe, tabt, tabw, g, snode, ck_mm[e])
            if ck_ok[e] and ck_mm[e, c] > val:
                val = ck_mm[e, c]
                tp = ts[j]
        out[k, 0] = val
        out[k, 1] = tp
    return nfev


def refine(run, samples: int, window: int):
    """The refined peaks ``{"v": (value, time), "a": ..., "sigma": ...}`` of the finished
    :class:`~snapping.simulate.elastic_advance.RodasRun` ``run`` (``samples``, ``window``:
    ``elastic_solve.PEAK_SAMPLES``, ``PEAK_RESTEP``), and the evaluations its integrations took."""
    st = run.st
    ln = st.line
    links = hasattr(run, "PN0")
    out = np.zeros((3, 2))
    nfev = refine_slots(st.N, KCOL, run.best, run.keep, run.nkeep, run.PT, run.PY0, run.PY1, run.PC, int(samples),
                        int(window), st.tol, st.ctl[ER.C_AUTO], st.pinpar, st.pintab, ln.h, ln._invm, ln.m, ln.ea,
                        ln.damp, ln.tabe, ln.tabt, ln.tabw, ln.g, ln.snode, out, links, run.PN0 if links else run.PY0)
    return {k: (float(out[i, 0]), float(out[i, 1])) for i, k in enumerate(("v", "a", "sigma"))}, int(nfev)


def refine_approach(run, samples: int, window: int):
    """:func:`refine` of the run's fourth kind (``elastic_advance.APPROACH``: kappa_max_interior on the
    approach, column :data:`KIN`), on its own (no integration shared with the other three, whose numbers
    and evaluations are as before it existed): ``((value, time), evaluations)``; ``((NaN, NaN), 0)`` with
    no such peak (fewer than KAPPA_TIP_JOINTS + 1 links)."""
    st = run.st
    ln = st.line
    links = hasattr(run, "PN0")
    if not run.best[3, 0] > -np.inf:
        return (np.nan, np.nan), 0
    out = np.zeros((1, 2))
    nfev = refine_slots(st.N, np.array([KIN]), run.best[3:], run.keep[3:], run.nkeep[3:], run.PT, run.PY0, run.PY1,
                        run.PC, int(samples), int(window), st.tol, st.ctl[ER.C_AUTO], st.pinpar, st.pintab, ln.h,
                        ln._invm, ln.m, ln.ea, ln.damp, ln.tabe, ln.tabt, ln.tabw, ln.g, ln.snode, out, links,
                        run.PN0 if links else run.PY0)
    return (float(out[0, 0]), float(out[0, 1])), int(nfev)


def refine_segments(stepper, best, keep, samples: int, window: int, kcol=KCOL):
    """:func:`refine` for a ``"rodas4-links"`` run of the Python loop: ``best`` and ``keep`` of
    ``elastic_solve._Peaks`` (kinds v, a, sigma; kept steps ``(t_old, y_old, t, LinksDense)``)
    put on step slots, refined by :func:`refine_slots` (``links``); ``kcol``: the kinds' measure columns
    (``[KIN]`` with ``_Peaks``' approach kind alone: :func:`refine_approach`'s)."""
    segs, idx = [], {}
    nkind = len(kcol)
    kk = np.full((nkind, 3), -1, dtype=np.int64)
    nk = np.zeros(nkind, dtype=np.int64)
    for k, lst in enumerate(keep.values()):
        for q, seg in enumerate(lst):
            if id(seg) not in idx:
                idx[id(seg)] = len(segs)
                segs.append(seg)
            kk[k, q] = idx[id(seg)]
        nk[k] = len(lst)
    ns, n = max(1, len(segs)), stepper.yn.size
    PT, PY0, PY1, PR0, PC = np.zeros((ns, 2)), np.zeros((ns, n)), np.zeros((ns, n)), np.zeros((ns, n)), np.zeros((ns, 2, n))
    for s, (t0, y0, t1, dn) in enumerate(segs):
        d = dn.dense
        PT[s] = t0, t1
        PY0[s], PY1[s], PR0[s], PC[s, 0], PC[s, 1] = d.y0, d.y1, y0, d.c2, d.c3
    ln = stepper.line
    bb = np.array([best[k] for k in keep], dtype=float)
    out = np.zeros((nkind, 2))
    nfev = refine_slots(stepper.N, np.asarray(kcol), bb, kk, nk, PT, PY0, PY1, PC, int(samples), int(window), stepper.tol,
                        stepper.ctl[ER.C_AUTO], stepper.pinpar, stepper.pintab, ln.h, ln._invm, ln.m, ln.ea, ln.damp,
                        ln.tabe, ln.tabt, ln.tabw, ln.g, ln.snode, out, True, PR0)
    return {k: (float(out[i, 0]), float(out[i, 1])) for i, k in enumerate(keep)}, int(nfev)


def restep_call(stepper, method: str, n_restep: list):
    """``restep(t0, y0, t1)`` (the node state at ``t1`` integrated from ``(t0, y0)``, None if that fails) of a
    RODAS4 run's ``stepper`` as one compiled call (:func:`restep`, :func:`restep_links`: the same numbers as a
    fresh stepper's), its evaluations added to ``n_restep[0]``; None for other methods (branch window: the
    snap window's edge, :mod:`snapping.simulate.snap_edge`)."""
    if method not in ("rodas4", "rodas4-links") or getattr(stepper.line, "body", None) is not None:
        return None  # (a body's rodas4: elastic_rodas_body's stepper, the Python restep)
    fn = restep_links if method == "rodas4-links" else restep
    args = (stepper.tol, stepper.ctl[ER.C_AUTO], stepper.pinpar, stepper.pintab, *stepper.args())

    def call(t0, y0, t1):
        y = np.empty(np.shape(y0))
        ok, nf = fn(stepper.N, float(t0), np.ascontiguousarray(y0, dtype=float), float(t1), *args, y)
        n_restep[0] += int(nf)
        return y if ok else None
    return call
