"""Whether a regime study's cell is converged: beyond its extrapolation's own verdict (issue 24).

A cell's levels can agree with each other and still sit before the asymptotic regime: the
extrapolation (:func:`snapping.continuum.extrapolate`) then reports an order and a small
error bar for a limit the finer levels would leave. For bending this happens when the rod's
bending length at the fold,

    l_B = sqrt(beta / T),    T = the ideal chain's peak tension (``sigma_peak_ideal``, the
                             fold's tension scale, units lambda g L),

is shorter than the links there: the node moments ``(B/l)(theta_i - theta_{i-1})`` then act
as hinge springs at the link scale (each link a stiff segment), not as a rod whose fold has a
radius of its own, and refining the links changes the physics of the run, not only its
accuracy. The fold's links are measured where the ideal fold is at the snap: ``h_fold``, the
link at arclength ``1/kappa_ideal`` (the ideal fold's radius) from the free end.

Measured (``python benchmarks/bench_bendconv.py``, fold-graded levels frac = 0.08 ... 0.01):
at chi = 0.1, beta = 7.2e-8 the levels give 47.20, 57.59, 58.25, 57.19 with ``l_B / h_fold``
= 0.30, 0.33, 0.46, 0.92: the first three extrapolate to 58.29 +- 0.04 (order 4), a limit the
fourth level leaves by 25 error bars; at beta = 1e-8 they climb 31.9, 35.5, 39.3, 41.5
(``l_B / h_fold`` <= 0.34). Where the finest level reaches ``l_B / h_fold`` >= 1 (chi = 0.2,
beta = 5.2e-7: 16.25, 17.23, 17.55, 17.65 at 0.41-1.47; chi = 0.3: 1.03) the levels are
monotone with differences shrinking at order 1.7-1.8. Resolution is necessary, not sufficient:
chi = 0.1, beta = 5.2e-7 reaches 2.47 and its differences still grow (+1.37, +2.12); the order
test flags it. Two finer levels (frac 0.005, 0.0025; RODAS4 at tol 1e-5, the study's 1e-7 being
unaffordable there) settle the chi = 0.1 cells once ``l_B / h_fold`` passes ~1: beta = 7.2e-8 goes
57.19, 56.95, 57.02 (0.92, 1.85, 3.69; x1.729 of the ideal), beta = 5.2e-7 55.09, 55.41 and
beta = 1e-8 42.18, 42.37 (docs/guide/regimes.md, "Does a small stiffness raise the peak?").

:func:`converged` is the per-cell flag the study stores (``converged``, with
``bending_resolution``, by :func:`snapping.regimes.regimes`) and that
:func:`snapping.regimes_analysis.analyze` requires of the cells it fits.

>>> import numpy as np
>>> fold_link(np.array([1.0, 2.0, 3.0]), 1 / 2.5)   # arclength 2.5 lies in the second link
2.0
"""

from __future__ import annotations

import math

import numpy as np

from . import _validate as V

__all__ = ["BEND_RESOLVED", "AGREE", "fold_link", "bending_resolution", "converged"]

#: bending: a cell is converged only when its finest level has l_B / h_fold >= this (see the module)
BEND_RESOLVED = 1.0


def fold_link(h, kappa: float) -> float:
    """The link at arclength ``1/kappa`` from the free end (``h[0]`` the free end's link; beyond
    the chain's length: the last link)."""
    h = np.asarray(V.float_array("h", h), dtype=float).ravel()
    if h.size == 0 or not np.all(h > 0):
        raise V.SnappingInputError("h must hold one or more positive link lengths")
    kappa = V.real("kappa", kappa)
    if not (math.isfinite(kappa) and kappa > 0):
        raise V.SnappingInputError(f"kappa={kappa!r} is out of range: must be finite and > 0")
    edges = np.cumsum(h)  # the far end of each link
    i = int(np.searchsorted(edges, 1.0 / kappa, side="left"))
    return float(h[min(i, h.size - 1)])


def bending_resolution(h, beta: float, sigma_ideal: float, kappa_ideal: float) -> float:
    """``l_B / h_fold``: the bending length ``sqrt(beta / sigma_ideal)`` over the link at the ideal
    fold (:func:`fold_link` at ``kappa_ideal``). NaN where the ideal's peaks are not finite."""
    beta = V.real("beta", beta)
    if not (math.isfinite(beta) and beta >= 0):
        raise V.SnappingInputError(f"beta={beta!r} is out of range: must be finite and >= 0")
    if not (math.isfinite(sigma_ideal) and sigma_ideal > 0 and math.isfinite(kappa_ideal) and kappa_ideal > 0):
        return float("nan")
    return math.sqrt(beta / sigma_ideal) / fold_link(h, kappa_ideal)


#: levels whose spread is at most this fraction of the value agree (converged for a study aiming at 1%) even where
#: the extrapolation finds no order (differences of the tolerance's size change sign)
AGREE = 1e-3


def converged(order, resolution=None, threshold: float = BEND_RESOLVED, value=None, error=None) -> np.ndarray:
    """The per-cell flag: the levels converge (a finite observed ``order``, or, given ``value`` and
    its ``error`` bar, levels that agree to :data:`AGREE` of the value) and, where a
    ``resolution`` (:func:`bending_resolution` of the finest level) is given, it is at least
    ``threshold`` (NaN resolution: not converged)."""
    o = np.asarray(order, dtype=float)
    ok = np.isfinite(o)
    if value is not None and error is not None:
        v, e = np.asarray(value, dtype=float), np.asarray(error, dtype=float)
        with np.errstate(invalid="ignore"):
            ok = ok | (np.isfinite(v) & np.isfinite(e) & (np.abs(e) <= AGREE * np.abs(v)))
    if resolution is not None:
        r = np.asarray(resolution, dtype=float)
        with np.errstate(invalid="ignore"):
            ok = ok & np.isfinite(r) & (r >= threshold)
    return ok
