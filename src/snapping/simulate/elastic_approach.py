"""The extensible line's curvature peak on the approach (branch stretchapp, issue 24): the run attributes
``kappa_peak_approach`` and ``t_kappa_peak_approach``, the chain's (``general.py``, ``dense_peaks.py``), from
the per-step ``kappa_max_interior`` (:func:`snapping.simulate.elastic_kernels.curvature_max_both`: the
joints at least ``KAPPA_TIP_JOINTS`` links from the free end, turning angle over the mean rest length).

The chain locates its fifth peak between steps on its dense output; the elastic line locates it as it does
its v/a/sigma peaks (``elastic_solve._Peaks``, :mod:`snapping.simulate.elastic_refine`): the kept steps around
the steps' best sampled on the dense output, the best sample and its neighbours integrated again from the
step's start. It is a fourth kind of the step pool (``elastic_advance.APPROACH``), refined after the other three
and on its own, so their values and evaluations are what they were; its evaluations are the run's
``n_rhs_approach`` (counted in ``n_rhs``: ``n_rhs - n_rhs_approach`` is the count before it existed). Why not on
the accepted steps alone (:func:`approach_peak`, the steps' value): on the stretching study's cells the steps'
value lies 1e-5 to 1.75e-3 below the peak between them, unevenly from level to level, which widened the
Richardson bars past 1% in two cells (docs/guide/regimes.md, "The extensible line's approach curvature").
"""

from __future__ import annotations

import numpy as np

from . import elastic_refine as ERF

__all__ = ["approach_peak", "refine_peaks"]


def approach_peak(times, v_max, kappa_interior) -> dict:
    """``kappa_peak_approach`` and ``t_kappa_peak_approach`` of the records (t = 0 and every accepted
    step): the largest ``kappa_max_interior`` over the rows at which v_max is at its running maximum
    (a new or equal one: the chain's rule, ``rk.after_attempt_with``'s fifth row), on the accepted steps
    alone: the step pool's best before refinement (:func:`refine_peaks` refines it); the first such row on
    a tie. NaN (and NaN time) with fewer than ``KAPPA_TIP_JOINTS + 1`` links."""
    v = np.asarray(v_max, dtype=float)
    k = np.where(v >= np.maximum.accumulate(v), np.asarray(kappa_interior, dtype=float), -np.inf)
    k = np.where(np.isnan(k), -np.inf, k)
    i = int(np.argmax(k)) if k.size else 0
    if not k.size or not np.isfinite(k[i]):
        return {"kappa_peak_approach": np.nan, "t_kappa_peak_approach": np.nan}
    return {"kappa_peak_approach": float(k[i]), "t_kappa_peak_approach": float(times[i])}


def refine_peaks(peaks, solver, method, line, restep, n_restep, *, samples, window, compiled):
    """The run's refined peaks (``elastic_solve._Peaks`` ``peaks``, its compiled run or Python kept steps):
    ``(ref, (kappa_peak_approach, its time), n_rhs_approach)``, ``ref`` v/a/sigma's {name: (value, time)} as
    before the approach peak existed; every integration's evaluations added to ``n_restep[0]``."""
    # (the approach peak refined after the others, on its own: their numbers and counts as before it existed;
    # its evaluations, n_rhs_approach, are counted in n_rhs)
    if peaks.run is not None:
        ref, nf = ERF.refine(peaks.run, samples, window)
        n_restep[0] += nf
        app, n_app = ERF.refine_approach(peaks.run, samples, window)
        n_restep[0] += n_app
    elif method == "rodas4-links" and compiled:
        ref, nf = ERF.refine_segments(solver, *({k: d[k] for k in peaks.COLS} for d in (peaks.best, peaks.keep)),
                                      samples, window)
        n_restep[0] += nf
        app, n_app = (np.nan, np.nan), 0
        if peaks.best["kappa_approach"][0] > -np.inf:
            app, n_app = ERF.refine_segments(solver, *({k: d[k] for k in peaks.APPROACH} for d in (peaks.best, peaks.keep)),
                                             samples, window, kcol=np.array([ERF.KIN]))
            app = app["kappa_approach"]
        n_restep[0] += n_app
    else:
        ref = peaks.refine(line, restep)
        n0 = n_restep[0]
        app = peaks.refine_approach(line, restep)
        n_app = n_restep[0] - n0
    return ref, app, n_app
