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
from . import elastic_rodas as ER
from . import elastic_stage as ES

__all__ = ["refine", "refine_slots", "restep", "grid"]


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
def restep(N, t0, y0, t1, tol, auto, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g, y):
    """The state at ``t1`` integrated from ``(t0, y0)`` into ``y``, as ``RodasStepper(line, t0,
    y0, t1, tol, h0=t1 - t0)`` stepped until it stops would give it (fresh arrays, the same
    calls). Returns (finished, evaluations)."""
    n = y0.shape[0]
    ctl = np.zeros(ER.NCTL)
    ctl[ER.C_T] = t0
    ctl[ER.C_TOLD] = np.nan
    ctl[ER.C_TB] = t1
    ctl[ER.C_TOL] = tol
    ctl[ER.C_HACC] = -1.0
    ctl[ER.C_AUTO] = auto
    for i in range(n):
        y[i] = y0[i]
    St = np.zeros((7, n))
    B = np.zeros((N, 3, 8))
    gW, gD = np.zeros(4), np.zeros(4 * N)
    dsp = np.zeros(2)
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
    ctl[ER.C_NFEV] += 1.0
    ctl[ER.C_NJEV] += 1.0
    ctl[ER.C_H] = t1 - t0
    while ctl[ER.C_STATUS] == ER.RUNNING:
        if ER.rodas_accept(N, y, St, B, gW, gD, dsp, F, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt,
                           g, ytmp, btmp, w, ft, z1, y0d, c23, ctl, T, E, ED, FV) != 0:
            break
    return ctl[ER.C_STATUS] == ER.FINISHED, ctl[ER.C_NFEV]


@njit(cache=True, error_model="numpy")
def _measure(N, t, z, pinpar, pintab, h, m, ea, damp, tabe, tabt, tabw, g, snode, out):
    """``ElasticLine.measure(t, z)`` into ``out``."""
    pin = np.zeros(4)
    ER.pin_at(t, pinpar, pintab, pin)
    for i in range(out.shape[0]):
        out[i] = 0.0
    EK.measure(N, z, pin, h, m, ea, damp, tabe, tabt, tabw, g, snode, np.empty_like(z), np.zeros(N), np.zeros(N),
               np.zeros(N), np.zeros(N), out)


@njit(cache=True, error_model="numpy")
def refine_slots(N, kcol, best, keep, nkeep, PT, PY0, PY1, PC, samples, window, tol, auto, pinpar, pintab, h, invm,
                 m, ea, damp, tabe, tabt, tabw, g, snode, out):
    """``_Peaks.refine`` on the kept step slots (``keep[k, :nkeep[k]]`` of ``RodasRun``) of the
    kinds ``kcol`` (measure columns) with the running peaks ``best``: the refined (value, time)
    of each kind into ``out``; returns the evaluations of the integrations."""
    n = PY0.shape[1]
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
                    _measure(N, ts[i], yd, pinpar, pintab, h, m, ea, damp, tabe, tabt, tabw, g, snode, gm[s, i])
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
                ok, nf = restep(N, t_old, PY0[gs], ts[j], tol, auto, pinpar, pintab, h, invm, ea, damp, tabe, tabt,
                                g, y)
                nfev += nf
                ck_ok[e] = ok
                if ok:
                    _measure(N, ts[j], y, pinpar, pintab, h, m, ea, damp, tabe, tabt, tabw, g, snode, ck_mm[e])
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
    from .elastic_advance import KCOL

    st = run.st
    ln = st.line
    out = np.zeros((3, 2))
    nfev = refine_slots(st.N, KCOL, run.best, run.keep, run.nkeep, run.PT, run.PY0, run.PY1, run.PC, int(samples),
                        int(window), st.tol, st.ctl[ER.C_AUTO], st.pinpar, st.pintab, ln.h, ln._invm, ln.m, ln.ea,
                        ln.damp, ln.tabe, ln.tabt, ln.tabw, ln.g, ln.snode, out)
    return {k: (float(out[i, 0]), float(out[i, 1])) for i, k in enumerate(("v", "a", "sigma"))}, int(nfev)
