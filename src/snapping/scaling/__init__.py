"""Scaling analysis of runs: snapping times, exponent fits with uncertainties,
local log-log slopes, fit reports and the paper's Fig. 3 and Fig. 4.

Pure functions on arrays (:mod:`snapping.scaling.fit`)
    :func:`peak_time`, :func:`local_slope`, :func:`find_window`, :func:`fit_power_law`
Run Datasets (:mod:`snapping.scaling.run`)
    :func:`load_run`, :func:`iter_runs`, :func:`snapping_times`, :func:`fit_run`,
    :func:`delta_comparison`, :func:`report_rows`, :func:`summary_rows`, :func:`local_slopes`
Figures (:mod:`snapping.scaling.plots`)
    :func:`plot_maxima` (Fig. 3), :func:`plot_local_slopes`, :func:`plot_delta` (Fig. 4);
    :func:`front_arclength` (the curvature maximum between nodes), :func:`thin_log`

Example
-------
>>> import numpy as np
>>> from snapping import scaling
>>> tau = np.logspace(-6, 0, 300)
>>> fit = scaling.fit_power_law(1.2 - tau, 0.8736 * tau ** (-1 / 3), t_star=1.2)
>>> round(fit.beta, 4)
-0.3333
"""

from .fit import (
    LocalSlope,
    PeakTime,
    PowerLawFit,
    Window,
    find_window,
    fit_power_law,
    local_slope,
    peak_time,
)
from .run import (
    DeltaComparison,
    ExponentRow,
    RowSpec,
    RunFit,
    SnapTimes,
    check_run,
    delta_comparison,
    delta_rows,
    fit_run,
    ideal_window_exponent,
    iter_runs,
    load_run,
    local_slopes,
    report_rows,
    report_specs,
    snapping_times,
    summary_rows,
)


def __getattr__(name):  # figures import matplotlib lazily
    if name in ("plot_maxima", "plot_local_slopes", "plot_delta", "front_arclength", "thin_log"):
        from . import plots

        return getattr(plots, name)
    raise AttributeError(name)


__all__ = [
    "ideal_window_exponent",
    "LocalSlope", "PeakTime", "PowerLawFit", "Window", "find_window", "fit_power_law", "local_slope", "peak_time",
    "DeltaComparison", "ExponentRow", "RowSpec", "RunFit", "SnapTimes", "check_run", "delta_comparison", "delta_rows", "fit_run",
    "iter_runs", "load_run", "local_slopes", "report_rows", "report_specs", "snapping_times", "summary_rows",
    "plot_maxima", "plot_local_slopes", "plot_delta",
]
