"""The weighted log-log least squares every fit of :mod:`snapping.scaling.fit` shares: input checks,
the log-log samples before t*, their thinning and weights (each sample weighs the log10(tau)
interval it represents), the grids of window centres, and the weighted straight-line fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V


_MIN_POINTS = 5


# --------------------------------------------------------------------------- inputs
def _arrays(t, y, name: str = "y") -> tuple[np.ndarray, np.ndarray]:
    t = V.float_array("t", t)
    y = V.float_array(name, y)
    if t.ndim != 1 or y.ndim != 1:
        raise V.SnappingInputError(f"t and {name} must be 1-D arrays; got shapes {t.shape} and {y.shape}")
    if t.shape != y.shape:
        raise V.SnappingInputError(f"t and {name} must have the same length; got {t.size} and {y.size}")
    ok = np.isfinite(t) & np.isfinite(y)
    t, y = t[ok], y[ok]
    if t.size < _MIN_POINTS:
        raise V.SnappingInputError(f"{name} has {t.size} finite samples; at least {_MIN_POINTS} are needed")
    if np.any(np.diff(t) < 0):
        order = np.argsort(t, kind="stable")
        t, y = t[order], y[order]
    return t, y


def _loglog(t: np.ndarray, y: np.ndarray, t_star: float):
    """log10 tau (ascending), log10 y and the log10-tau interval weights of the samples
    before t* with y > 0."""
    tau = t_star - t
    ok = (tau > 0) & (y > 0)
    if not ok.any():  # every sample after t* (or y <= 0): nothing to fit
        e = np.zeros(0)
        return e, e, e, e
    X = np.log10(tau[ok])
    Y = np.log10(y[ok])
    order = np.argsort(X, kind="stable")
    X, Y, ts = X[order], Y[order], t[ok][order]
    X, Y, ts = _thin(X, Y, ts)
    return X, Y, _weights(X), ts


def _before(t, y, t_star, min_points, name="t_star"):
    """_loglog, refusing a t* (named ``name``) with fewer than ``min_points`` samples before it
    or so far past the data that t* - t spans no range."""
    X, Y, w, ts = _loglog(t, y, t_star)
    if X.size < min_points:
        raise V.SnappingInputError(
            f"{name}={t_star!r}: only {X.size} samples with t < t_star and y > 0; at least {min_points} are needed"
        )
    if not X[-1] - X[0] > 1e-9:
        raise V.SnappingInputError(f"{name}={t_star!r} is out of range: so far past the data that t* - t spans "
                                   f"no range (the samples lie in [{t.min():.6g}, {t.max():.6g}])")
    return X, Y, w, ts


#: most local fits of a local-slope curve (data span / spacing)
_MAX_CENTERS = 100_000


def _grid(X, span, spacing, min_width=None):
    """The centres of the local fits, refusing a spacing (or min_width) that the data cannot hold."""
    width = float(X[-1] - X[0])
    if not spacing <= width:
        raise V.SnappingInputError(f"spacing={spacing!r} is out of range: must be <= the {width:.3g} decades of "
                                   f"t* - t the data span")
    if not width / spacing <= _MAX_CENTERS:
        raise V.SnappingInputError(f"spacing={spacing!r} is out of range: the data span {width:.3g} decades of "
                                   f"t* - t, which would make more than {_MAX_CENTERS} local fits (spacing >= "
                                   f"{width / _MAX_CENTERS:.3g})")
    if min_width is not None and not min_width <= width + spacing:
        raise V.SnappingInputError(
            f"the data span only {width:.3g} decades of t* - t; min_width={min_width!r} decades is needed"
        )
    return _center_grid(X, spacing)


_PER_DECADE = 200  # resolution of the log10(tau) bins when records are long


def _thin(X: np.ndarray, *arrays: np.ndarray):
    """Average samples within bins of 1/_PER_DECADE decade of tau when there are many more
    samples than bins (an adaptive stepper records ~1e5 steps near the snap). ``X`` is sorted.
    The least-squares weights are per log10(tau) interval, so this changes the fits only
    by averaging out sample-to-sample jitter; it makes them O(bins) instead of O(steps)."""
    if X.size < 4 * _PER_DECADE * max(float(X[-1] - X[0]), 1.0):
        return (X, *arrays)
    b = np.floor(X * _PER_DECADE).astype(np.int64)
    starts = np.concatenate([[0], np.nonzero(np.diff(b))[0] + 1])
    counts = np.diff(np.concatenate([starts, [X.size]]))
    out = [np.add.reduceat(a, starts) / counts for a in (X, *arrays)]
    return tuple(out)


def _weights(X: np.ndarray) -> np.ndarray:
    """Trapezoidal interval weights of sorted abscissae (half intervals at the ends)."""
    if X.size < 2:
        return np.ones_like(X)
    d = np.diff(X)
    w = np.empty_like(X)
    w[0] = 0.5 * d[0]
    w[-1] = 0.5 * d[-1]
    w[1:-1] = 0.5 * (d[:-1] + d[1:])
    # duplicated abscissae get zero weight; keep every sample counted a little
    tiny = 1e-12 * max(float(X[-1] - X[0]), 1e-300)
    return np.maximum(w, tiny)


@dataclass(frozen=True)
class _WLS:
    a: float  # intercept (log10 y at log10 tau = 0)
    b: float  # slope
    se_a: float
    se_b: float
    s2: float  # residual variance per unit weight-normalised sample
    wrss: float  # weighted residual sum of squares, weights normalised to sum n_eff
    n_eff: float
    n: int


def _wls(X: np.ndarray, Y: np.ndarray, w: np.ndarray) -> _WLS:
    W = float(w.sum())
    n_eff = W * W / float(w @ w)
    wn = w * (n_eff / W)  # weights summing to n_eff
    xm = float(wn @ X) / n_eff
    ym = float(wn @ Y) / n_eff
    dx = X - xm
    Sxx = float(wn @ (dx * dx))
    b = float(wn @ (dx * (Y - ym))) / Sxx
    a = ym - b * xm
    r = Y - a - b * X
    wrss = float(wn @ (r * r))
    dof = max(n_eff - 2.0, 1.0)
    s2 = wrss / dof
    w2 = wn * wn
    var_b = s2 * float(w2 @ (dx * dx)) / Sxx**2
    var_ym = s2 * float(w2.sum()) / n_eff**2
    cov = s2 * float(w2 @ dx) / (n_eff * Sxx)
    var_a = var_ym + xm * xm * var_b - 2.0 * xm * cov
    return _WLS(a, b, math.sqrt(max(var_a, 0.0)), math.sqrt(max(var_b, 0.0)), s2, wrss, n_eff, int(X.size))


def _center_grid(X: np.ndarray, spacing: float) -> np.ndarray:
    k0 = math.floor(X[0] / spacing)
    k1 = math.ceil(X[-1] / spacing)
    return spacing * np.arange(k0, k1 + 1)
