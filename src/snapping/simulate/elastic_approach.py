"""The extensible line's curvature peak on the approach (branch stretchapp, issue 24): the run attributes
``kappa_peak_approach`` and ``t_kappa_peak_approach``, the chain's (``general.py``, ``dense_peaks.py``), from
the per-step ``kappa_max_interior`` (:func:`snapping.simulate.elastic_kernels.curvature_max_both`: the
joints at least ``KAPPA_TIP_JOINTS`` links from the free end, turning angle over the mean rest length).

The chain locates its fifth peak between steps on its dense output; the elastic line takes it on the
accepted steps, as it does its ``kappa_peak`` (no evaluation added: every run's ``n_rhs`` is what it was).
How far that lies below the peak between the steps was measured on the stretching study's cells
(docs/guide/regimes.md, "The extensible line's approach curvature").
"""

from __future__ import annotations

import numpy as np

__all__ = ["approach_peak"]


def approach_peak(times, v_max, kappa_interior) -> dict:
    """``kappa_peak_approach`` and ``t_kappa_peak_approach`` of the records (t = 0 and every accepted
    step): the largest ``kappa_max_interior`` over the rows at which v_max is at its running maximum
    (a new or equal one: the chain's rule, ``rk.after_attempt_with``'s fifth row), on the accepted steps
    (not located between them: docs/guide/regimes.md "The extensible line's approach curvature"); the
    first such row on a tie. NaN (and NaN time) with fewer than ``KAPPA_TIP_JOINTS + 1`` links."""
    v = np.asarray(v_max, dtype=float)
    k = np.where(v >= np.maximum.accumulate(v), np.asarray(kappa_interior, dtype=float), -np.inf)
    k = np.where(np.isnan(k), -np.inf, k)
    i = int(np.argmax(k)) if k.size else 0
    if not k.size or not np.isfinite(k[i]):
        return {"kappa_peak_approach": np.nan, "t_kappa_peak_approach": np.nan}
    return {"kappa_peak_approach": float(k[i]), "t_kappa_peak_approach": float(times[i])}
