"""Pure fitting functions on arrays (t, y): snapping times, local slopes, windows and
power-law fits ``y ~ A (t* - t)^beta`` with uncertainties.

Nothing here knows about run Datasets; :mod:`snapping.scaling.run` applies these
functions to the variables of a run.

Conventions
-----------
``tau = t* - t`` is the time left before the snap. Fits are straight lines on
log10-log10 axes, ``log10 y = log10 A + beta log10 tau``, each sample weighted by
the log10(tau) interval it represents, so that an adaptive stepper that crowds
samples near t* does not dominate the fit: the fit approximates the integral
``int (log10 y - log10 A - beta log10 tau)^2 d log10 tau`` over the window.
Windows are given as ``(tau_lo, tau_hi)``; widths are in decades.

Uncertainty of an exponent (all three reported separately, total in quadrature):

``stat``
    standard error of the weighted least-squares slope, with the residual
    variance estimated from the residuals and the effective number of samples
    ``(sum w)^2 / sum w^2``.
``window``
    the largest change of beta when each edge of the window is moved by
    ``10^(+-perturb)`` (8 perturbed windows): how much the answer depends on
    where one decides the power law starts and ends.
``t_star``
    t* given: the largest change of beta when t* is moved by +-``t_star_err``.
    t* fitted: the largest change of beta over the 1-sigma profile interval of
    t*, where the weighted residual sum of squares has risen by one residual
    variance above its minimum.
"""

from __future__ import annotations

# One idea a module (a pure split of the former fit.py; every name is importable from here as before):
#   _loglog    the weighted log-log least squares all fits share
#   peak       peak_time
#   slopes     local_slope, find_window
#   power_law  fit_power_law
from .peak import PeakTime, peak_time
from .power_law import PowerLawFit, fit_power_law
from .slopes import LocalSlope, Window, find_window, local_slope

__all__ = [
    "PeakTime",
    "LocalSlope",
    "Window",
    "PowerLawFit",
    "peak_time",
    "local_slope",
    "find_window",
    "fit_power_law",
]

