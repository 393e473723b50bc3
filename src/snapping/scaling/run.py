"""Scaling analysis of run Datasets: snapping times, the fit report, delta scales.

Thin functions that take a run :class:`xarray.Dataset` (names from
:mod:`snapping.schema`), pull out arrays and call the pure functions of
:mod:`snapping.scaling.fit` and :mod:`snapping.estimates`.

Reference exponents and prefactors come from :mod:`snapping.ideal` (the folded
string, derived) and the paper's observations (-5/6, -1/6).
"""

from __future__ import annotations

# One idea a module (a pure split of the former run.py; every name is importable from here as before):
#   inputs      the run Datasets read (check_run, load_run, iter_runs)
#   snap_times  snapping_times, local_slopes
#   delta       delta_comparison (Fig. 4)
#   references  report_specs, ideal_window_exponent, the verdicts
#   run_fit     fit_run, ExponentRow, RunFit
#   tables      report_rows, delta_rows, summary_rows
from .delta import DeltaComparison, _chi, delta_comparison  # noqa: F401
from .inputs import _PEAK_VARS, T, _t, check_run, iter_runs, load_run  # noqa: F401
from .references import (EXPONENT_SPACING, RowSpec, _clause, _ideal_refs, _judge, _verdict,  # noqa: F401
                         exponent_text, ideal_window_exponent, inconclusive_err, report_specs)
from .run_fit import ExponentRow, RunFit, fit_run
from .snap_times import SnapTimes, _stop_info, local_slopes, snapping_times  # noqa: F401
from .tables import _pad, _pm, delta_rows, report_rows, summary_rows  # noqa: F401

__all__ = [
    "report_specs",
    "RowSpec",
    "SnapTimes",
    "ExponentRow",
    "DeltaComparison",
    "RunFit",
    "load_run",
    "check_run",
    "iter_runs",
    "snapping_times",
    "delta_comparison",
    "fit_run",
    "report_rows",
    "summary_rows",
    "delta_rows",
    "ideal_window_exponent",
]

__all__ += ["local_slopes"]
