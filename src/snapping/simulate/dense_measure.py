"""The diagnostics on DOP853's dense output at one time, in one compiled call.

:meth:`snapping.simulate.dense_peaks.DenseOutputPeaks.refine` locates each flagged peak with a bounded
scalar minimization whose every evaluation was four Python-level steps (the dense output, the right
side for the tensions, fresh ``Z`` and ``meas`` arrays, the measures: ~100 us each, 10,050 of them in
the fly line's answer at chi 0.1, ~1 s of its CPU under the profiler). :func:`measure_at` makes the
same calls of the same compiled functions on the same inputs, so the same floats, in one call.
"""

from __future__ import annotations

from numba import njit

from . import models as MD
from . import rk as R

__all__ = ["measure_at"]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def measure_at(N, t, x, y0, F, y, f, c, s, S, cp, dp, sig, Z, rinv0, meas, mdl):
    """The state ``y`` at the fraction ``x`` of a step (:func:`snapping.simulate.rk.dense_eval`), its
    right side ``f`` (which sets the tensions ``sig``) and its diagnostics ``meas`` (``Z`` and
    ``meas`` zeroed first, as fresh arrays were)."""
    R.dense_eval(N, x, y0, F, y)
    MD.model_rhs(N, t, y, f, c, s, S, cp, dp, sig, mdl)
    for i in range(Z.shape[0]):
        for j in range(Z.shape[1]):
            Z[i, j] = 0.0
    for i in range(meas.shape[0]):
        meas[i] = 0.0
    MD.model_measure(N, t, y, c, s, sig, Z, rinv0, meas, mdl)
