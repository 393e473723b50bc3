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

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from .. import _validate as V

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


# ------------------------------------------------------------------------ peak time
@dataclass(frozen=True)
class PeakTime:
    """Time and value of the largest value of a sampled peak, located between samples.

    Attributes
    ----------
    t : float
        Interpolated time of the peak (vertex of the parabola through the largest
        sample and its two neighbours).
    value : float
        Interpolated peak value.
    err : float
        Largest difference in time between the 3-point parabola and two other
        estimators (a parabola through log y, a least-squares parabola through five
        samples): the interpolation uncertainty.
    index : int
        Index of the largest sample.
    t_sample : float
        Time of the largest sample.
    """

    t: float
    value: float
    err: float
    index: int
    t_sample: float


def _vertex(t3: np.ndarray, y3: np.ndarray) -> tuple[float, float] | None:
    """Vertex of the parabola through three points (non-uniform spacing)."""
    t0, t1, t2 = t3
    y0, y1, y2 = y3
    d01 = (y1 - y0) / (t1 - t0)
    d12 = (y2 - y1) / (t2 - t1)
    c = (d12 - d01) / (t2 - t0)  # second divided difference = half the curvature
    if not c < 0:
        return None
    # p(t) = y1 + b (t - t1) + c (t - t1)^2, with b the derivative at t1
    b = d01 + c * (t1 - t0)
    tv = t1 - b / (2.0 * c)
    return tv, y1 - b * b / (4.0 * c)


def peak_time(t, y, *, name: str = "y", min_drop: float = 0.0) -> PeakTime:
    """Locate the peak of a sampled quantity between recorded steps.

    The snapping time of a run is the time of the peak of its maximum speed,
    acceleration or tension (the paper's t*_chi, section "Ideal and anomalous
    evolution"). The peak is the vertex of the parabola through the largest sample
    and its neighbours; its uncertainty is the spread against a parabola through
    log y and a least-squares parabola through five samples.

    Parameters
    ----------
    t, y : array_like
        Sample times (increasing) and values.
    name : str
        Name used in error messages (e.g. ``"v_max"``).
    min_drop : float
        Required relative fall of ``y`` after the peak (last sample <= (1 - min_drop)
        times the peak). A quantity still rising at the end of the record has not
        peaked: the run stopped before the snap.

    Returns
    -------
    PeakTime

    Raises
    ------
    SnappingInputError
        The largest sample is the first or last one, or ``y`` has not fallen by
        ``min_drop`` after it.

    Examples
    --------
    >>> t = np.linspace(0, 1, 11)
    >>> p = peak_time(t, 1 - (t - 0.537) ** 2)
    >>> round(p.t, 12)
    0.537
    """
    min_drop = V.real("min_drop", min_drop)
    if not 0.0 <= min_drop < 1.0:
        raise V.SnappingInputError(f"min_drop={min_drop!r} is out of range: must lie in [0, 1) (a relative fall)")
    t, y = _arrays(t, y, name)
    n = t.size
    i = int(np.argmax(y))
    if i == 0:
        raise V.SnappingInputError(
            f"{name} is largest at the first sample (t={t[0]:.6g}): no peak to locate"
        )
    if i >= n - 1 or y[-1] > (1.0 - min_drop) * y[i]:
        raise V.SnappingInputError(
            f"{name} is still rising or has not fallen after its largest sample (t={t[i]:.6g}, "
            f"last t={t[-1]:.6g}): the record stopped before the peak (before the snap)"
        )
    v = _vertex(t[i - 1 : i + 2], y[i - 1 : i + 2])
    if v is None:  # flat top: equal neighbours
        tv, yv = float(t[i]), float(y[i])
    else:
        tv, yv = v
    lo, hi = float(t[i - 1]), float(t[i + 1])
    tv = min(max(tv, lo), hi)
    others = []
    if np.all(y[i - 1 : i + 2] > 0):
        vl = _vertex(t[i - 1 : i + 2], np.log(y[i - 1 : i + 2]))
        if vl is not None:
            others.append(min(max(vl[0], lo), hi))
    j0, j1 = max(i - 2, 0), min(i + 3, n)
    if j1 - j0 >= 4:
        ts, ys = t[j0:j1], y[j0:j1]
        scale = max(float(ts[-1] - ts[0]), 1e-300)
        c2, c1, _ = np.polyfit((ts - t[i]) / scale, ys, 2)
        if c2 < 0:
            others.append(min(max(float(t[i] - 0.5 * c1 / c2 * scale), lo), hi))
    err = max((abs(o - tv) for o in others), default=0.5 * (hi - lo))
    return PeakTime(float(tv), float(max(yv, y[i])), float(err), i, float(t[i]))


# ---------------------------------------------------------------------- local slope
@dataclass(frozen=True)
class LocalSlope:
    """The local log-log slope d ln y / d ln (t* - t) as a curve.

    Attributes
    ----------
    tau : ndarray
        Centres of the local fits (t* - t), increasing.
    slope : ndarray
        Local slope at each centre (NaN where fewer than ``min_points`` samples).
    stderr : ndarray
        Standard error of each local slope (from the scatter about the local line).
    n : ndarray
        Samples in each local fit.
    span : float
        Full width of each local fit in decades.
    """

    tau: np.ndarray
    slope: np.ndarray
    stderr: np.ndarray
    n: np.ndarray
    span: float

    def to_dict(self) -> dict:
        return {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in asdict(self).items()}


def _local_slope_arrays(X, Y, w, centers, half, min_points):
    m = centers.size
    slope = np.full(m, np.nan)
    se = np.full(m, np.nan)
    nn = np.zeros(m, dtype=int)
    lo = np.searchsorted(X, centers - half, side="left")
    hi = np.searchsorted(X, centers + half, side="right")
    for k in range(m):
        i0, i1 = lo[k], hi[k]
        nn[k] = i1 - i0
        if i1 - i0 < min_points:
            continue
        xs = X[i0:i1]
        if xs[-1] - xs[0] < 0.5 * half:  # samples bunched on one side: not a slope over the span
            continue
        f = _wls(xs, Y[i0:i1], w[i0:i1])
        slope[k], se[k] = f.b, f.se_b
    return slope, se, nn


def local_slope(
    t,
    y,
    t_star: float,
    *,
    span: float = 0.5,
    spacing: float = 0.05,
    min_points: int = 4,
) -> LocalSlope:
    """Local log-log slope d ln y / d ln (t* - t) of a sampled quantity.

    At each centre (every ``spacing`` decades of tau = t* - t) a straight line is
    fitted, weighted as in :func:`fit_power_law`, to the samples within
    ``span/2`` decades. For a pure power law y = A tau^beta (the paper's
    eq. asymptoticscalings) the curve is flat at beta; a plateau of the curve is
    the window where the exponent can be read.

    Parameters
    ----------
    t, y : array_like
        Sample times and values (only samples with t < t* and y > 0 are used).
    t_star : float
        The snapping time.
    span : float
        Full width of each local fit in decades (> 0).
    spacing : float
        Distance between centres in decades (> 0).
    min_points : int
        Fewest samples for a local fit (>= 3).

    Returns
    -------
    LocalSlope

    Examples
    --------
    >>> tau = np.logspace(-6, 0, 200)
    >>> ls = local_slope(1.0 - tau, 3.0 * tau ** (-1 / 3), 1.0)
    >>> bool(np.allclose(ls.slope[np.isfinite(ls.slope)], -1 / 3))
    True
    """
    t_star = V.real("t_star", t_star)
    span = V.positive("span", span)
    spacing = V.positive("spacing", spacing)
    min_points = V.integer("min_points", min_points, 3)
    t, y = _arrays(t, y)
    if min_points > t.size:
        raise V.SnappingInputError(f"min_points={min_points} is out of range: the data hold {t.size} finite samples")
    X, Y, w, _ = _before(t, y, t_star, min_points)
    centers = _grid(X, span, spacing)
    slope, se, nn = _local_slope_arrays(X, Y, w, centers, 0.5 * span, min_points)
    if not np.isfinite(slope).any():
        raise V.SnappingInputError(f"span={span!r}, spacing={spacing!r} (decades): no local fit has {min_points} "
                                   f"samples spread over its span; the data span {X[-1] - X[0]:.3g} decades of "
                                   f"t* - t")
    return LocalSlope(10.0**centers, slope, se, nn, span)


def _center_grid(X: np.ndarray, spacing: float) -> np.ndarray:
    k0 = math.floor(X[0] / spacing)
    k1 = math.ceil(X[-1] / spacing)
    return spacing * np.arange(k0, k1 + 1)


# -------------------------------------------------------------------------- windows
@dataclass(frozen=True)
class Window:
    """A window of tau = t* - t chosen where the local slope is flat.

    Attributes
    ----------
    tau_lo, tau_hi : float
        The window.
    flatness : float
        Largest deviation of the local slopes inside the window from their mean,
        less three standard errors each (<= 0: flat within the noise).
    tol : float
        The flatness tolerance the window was accepted with (the requested one, or
        larger when no window of ``min_width`` met it).
    flat : bool
        True when ``flatness`` <= the requested tolerance.
    slope : float
        Mean local slope inside the window.
    """

    tau_lo: float
    tau_hi: float
    flatness: float
    tol: float
    flat: bool
    slope: float


_PREFER = ("widest", "latest", "earliest")


def _choose_window(centers, slope, se, *, min_width, tol, prefer, slope_range, half, spacing):
    m = centers.size
    nh = int(round(half / spacing))
    nmin = max(int(math.ceil(min_width / spacing - 1e-9)), 2 * nh + 1)
    if m <= nmin:
        return None
    good = np.isfinite(slope) & np.isfinite(se)
    s = np.where(good, slope, 0.0)
    e = np.where(good, se, 0.0)
    up = np.where(good, s - 3.0 * e, -np.inf)  # max over k of (s_k - 3 se_k) - mean
    dn = np.where(good, s + 3.0 * e, np.inf)  # mean - min over k of (s_k + 3 se_k)
    cs = np.concatenate([[0.0], np.cumsum(s)])
    cbad = np.concatenate([[0], np.cumsum(~good)])
    # inner centres k in [i + nh, j - nh] for a window with edges at centres i and j
    for i in range(m - nmin):
        k0 = i + nh
        runmax = np.maximum.accumulate(up[k0:])
        runmin = np.minimum.accumulate(dn[k0:])
        j = np.arange(i + nmin, m)
        k1 = j - nh  # inclusive
        idx = k1 - k0
        cnt = k1 - k0 + 1
        bad = cbad[k1 + 1] - cbad[k0]
        mean = (cs[k1 + 1] - cs[k0]) / cnt
        D = np.maximum(runmax[idx] - mean, mean - runmin[idx])
        D = np.where(bad > 0, np.inf, D)
        if slope_range is not None:
            D = np.where((mean < slope_range[0]) | (mean > slope_range[1]), np.inf, D)
        else:
            D = np.where(np.abs(mean) < 0.05, np.inf, D)  # a plateau of y is not a power law
        yield i, j, D, mean


def find_window(
    t,
    y,
    t_star: float,
    *,
    min_width: float = 1.0,
    tol: float = 1e-3,
    prefer: str = "widest",
    slope_range: tuple[float, float] | None = None,
    span: float = 0.5,
    spacing: float = 0.05,
    t_star_name: str = "t_star",
) -> Window:
    """Choose the window of tau = t* - t where the local log-log slope is flat.

    A window (edges on a grid of ``spacing`` decades, at least ``min_width``
    decades wide) is *flat* when every local slope (:func:`local_slope`, fitted
    entirely inside the window) lies within ``tol`` plus three of its standard
    errors of the mean local slope in the window. Among flat windows the one
    preferred is the widest (``prefer="widest"``), the one reaching closest to t*
    (``"latest"``) or farthest from it (``"earliest"``). When no window of
    ``min_width`` is flat within ``tol``, the tolerance is raised to the flattest
    such window's deviation (times 1.5) and ``flat`` is False.

    Windows whose mean slope has magnitude below 0.05 (the regularised top of a
    peak) are skipped unless ``slope_range`` is given, which restricts the
    windows to mean local slopes in ``[lo, hi]`` (to pick one regime out of
    several, e.g. the paper's -5/6 intermediate regime of the maximum
    acceleration).

    Parameters
    ----------
    t, y : array_like
        Samples.
    t_star : float
        The snapping time.
    min_width : float
        Smallest window width in decades (> span).
    tol : float
        Flatness tolerance on the local slope (> 0).
    prefer : {"widest", "latest", "earliest"}
        Which flat window to return.
    slope_range : (float, float), optional
        Allowed range of the mean local slope.
    span, spacing : float
        Local slope fits (see :func:`local_slope`).
    t_star_name : str
        Name of ``t_star`` in error messages.

    Returns
    -------
    Window

    Examples
    --------
    >>> tau = np.logspace(-7, 0, 300)
    >>> y = 2.0 * (tau**2 + 1e-10) ** (-1 / 6)      # regularised below tau ~ 1e-5
    >>> w = find_window(1.0 - tau, y, 1.0)
    >>> w.tau_lo > 3e-5 and bool(abs(w.slope + 1 / 3) < 2e-3)
    True
    """
    t_star = V.real("t_star", t_star)
    span = V.positive("span", span)
    spacing = V.positive("spacing", spacing)
    tol = V.positive("tol", tol)
    min_width = V.positive("min_width", min_width)
    if min_width <= span:
        raise V.SnappingInputError(f"min_width={min_width!r} is out of range: must be > span={span!r} (decades)")
    if prefer not in _PREFER:
        raise V.SnappingInputError(f"prefer={prefer!r} is not one of {_PREFER}")
    if slope_range is not None:
        slope_range = (float(slope_range[0]), float(slope_range[1]))
        if not slope_range[0] < slope_range[1]:
            raise V.SnappingInputError(f"slope_range={slope_range!r} must be an increasing pair (lo, hi)")
    t, y = _arrays(t, y)
    X, Y, w, _ = _before(t, y, t_star, _MIN_POINTS, t_star_name)
    half = 0.5 * span
    centers = _grid(X, span, spacing, min_width)
    slope, se, _ = _local_slope_arrays(X, Y, w, centers, half, 4)
    cands = list(
        _choose_window(
            centers, slope, se, min_width=min_width, tol=tol, prefer=prefer,
            slope_range=slope_range, half=half, spacing=spacing,
        )
    )
    if not cands:
        raise V.SnappingInputError(
            f"the data span only {X[-1] - X[0]:.3g} decades of t* - t; min_width={min_width!r} decades is needed"
        )
    Dmin = min(float(np.min(D)) for _, _, D, _ in cands)
    if not math.isfinite(Dmin):
        raise V.SnappingInputError(
            "no window of t* - t with enough samples"
            + (f" and a mean local slope in slope_range={slope_range!r}" if slope_range else " and a non-zero slope")
            + f" (span={span!r}, spacing={spacing!r}, min_width={min_width!r} decades)"
        )
    tol_eff = tol if Dmin <= tol else 1.5 * Dmin
    best = None
    for i, j, D, mean in cands:
        ok = np.nonzero(D <= tol_eff)[0]
        for jj in ok:
            jw = int(j[jj])
            width = jw - i
            if prefer == "widest":
                key = (width, -D[jj])
            elif prefer == "latest":
                key = (-i, width, -D[jj])
            else:
                key = (jw, -i, -D[jj])
            if best is None or key > best[0]:
                best = (key, i, jw, float(D[jj]), float(mean[jj]))
    _, i, j, D, mean = best
    return Window(
        float(10.0 ** centers[i]), float(10.0 ** centers[j]), D, float(tol_eff), bool(D <= tol), mean
    )


# ----------------------------------------------------------------------- power laws
@dataclass(frozen=True)
class PowerLawFit:
    """A fit y = A (t* - t)^beta on a window of t* - t, with its uncertainty.

    Attributes
    ----------
    beta, beta_err : float
        Exponent and its total uncertainty (the three parts below in quadrature).
    beta_err_stat, beta_err_window, beta_err_t_star, beta_err_drift : float
        Parts of the uncertainty: least-squares standard error, window choice,
        t* (given: its +-t_star_err; fitted: its 1-sigma profile interval), and
        drift (half the change of the local slope across the window, from a
        quadratic fit on log-log axes: the exponent is not constant by that much).
    A, A_err : float
        Prefactor (y at t* - t = 1 on the fitted line) and its uncertainty, combined
        like beta's (from the intercept on log axes).
    t_star, t_star_err : float
        The snapping time used (given or fitted) and its uncertainty.
    t_star_fitted : bool
        Whether t* was fitted jointly.
    tau_lo, tau_hi : float
        The window of t* - t used.
    window_auto : bool
        Whether the window was chosen by :func:`find_window`.
    flat : bool
        Whether the automatic window met the flatness tolerance (always True for a
        given window).
    n_points : int
        Samples in the window.
    rms : float
        Weighted rms residual of log10 y about the line.
    """

    beta: float
    beta_err: float
    A: float
    A_err: float
    t_star: float
    t_star_err: float
    t_star_fitted: bool
    tau_lo: float
    tau_hi: float
    n_points: int
    beta_err_stat: float
    beta_err_window: float
    beta_err_t_star: float
    beta_err_drift: float
    window_auto: bool
    flat: bool
    rms: float
    notes: tuple[str, ...] = field(default_factory=tuple)

    def predict(self, tau) -> np.ndarray:
        """The fitted power law A tau^beta at ``tau``."""
        return self.A * np.asarray(tau, dtype=float) ** self.beta

    def to_dict(self) -> dict:
        d = asdict(self)
        d["notes"] = list(self.notes)
        return d


def _select(t, y, t_star, tau_lo, tau_hi):
    X, Y, w, ts = _loglog(t, y, t_star)
    lo, hi = math.log10(tau_lo), math.log10(tau_hi)
    i0 = np.searchsorted(X, lo - 1e-12, side="left")
    i1 = np.searchsorted(X, hi + 1e-12, side="right")
    return X[i0:i1], Y[i0:i1], w[i0:i1], ts[i0:i1]


def _drift(t, y, t_star, tau_lo, tau_hi) -> tuple[float, float]:
    """Half the change of the local slope across the window, from a weighted quadratic
    fit log10 y = a + b X + c X^2 (local slope b + 2 c X): |c| (X_hi - X_lo)."""
    X, Y, w, _ = _select(t, y, t_star, tau_lo, tau_hi)
    if X.size < _MIN_POINTS:
        return 0.0, 0.0
    xm = float(w @ X) / float(w.sum())
    Xc = X - xm
    sw = np.sqrt(w)
    M = np.stack([np.ones_like(Xc), Xc, Xc * Xc], axis=1) * sw[:, None]
    coef, *_ = np.linalg.lstsq(M, Y * sw, rcond=None)
    # the slope uncertainty pivots the line about the window centre xm: the intercept
    # (log10 A at tau = 1) moves by drift * |xm|
    return float(abs(coef[2]) * (X[-1] - X[0])), xm


def _fit_fixed(t, y, t_star, tau_lo, tau_hi) -> _WLS | None:
    X, Y, w, _ = _select(t, y, t_star, tau_lo, tau_hi)
    if X.size < _MIN_POINTS or X[-1] - X[0] <= 0:
        return None
    return _wls(X, Y, w)


class _Profile:
    """Weighted least squares on a fixed set of samples as a function of t*."""

    def __init__(self, ts: np.ndarray, ys: np.ndarray):
        self.ts = ts
        self.Y = np.log10(ys)
        self.t_b = float(ts.max())

    def fit(self, t_star: float) -> _WLS:
        X = np.log10(t_star - self.ts)
        order = np.argsort(X, kind="stable")
        X, Y = X[order], self.Y[order]
        return _wls(X, Y, _weights(X))

    def wrss(self, u: float) -> float:
        t_star = self.t_b + 10.0**u
        if not t_star > self.t_b:
            return math.inf
        return self.fit(t_star).wrss


def _joint(t, y, t_guess, tau_lo, tau_hi, notes: list[str]):
    """Fit t* by profiling on the samples of the window (chosen with ``t_guess``).

    Returns (t_star, t_star_err, fit, beta range over the 1-sigma t* interval)."""
    _, Y, _, ts = _select(t, y, t_guess, tau_lo, tau_hi)
    if ts.size < _MIN_POINTS + 1:
        return None
    prof = _Profile(ts, 10.0**Y)
    gap = t_guess - prof.t_b  # >= tau_lo
    u_lo = math.log10(max(gap, tau_lo)) - 3.0
    u_lo = max(u_lo, math.log10(64 * np.finfo(float).eps * max(abs(prof.t_b), 1e-300)))
    u_hi = math.log10(tau_hi) + 0.5
    us = np.linspace(u_lo, u_hi, 121)
    rs = np.array([prof.wrss(u) for u in us])
    k = int(np.nanargmin(rs))
    if k == 0 or k == us.size - 1:
        notes.append(
            "t* fit: the best t* lies at the edge of the search range "
            f"(t* - last sample = {10**us[k]:.3g}); t* is not determined by this window"
        )
    a, b = us[max(k - 1, 0)], us[min(k + 1, us.size - 1)]
    res = minimize_scalar(prof.wrss, bounds=(a, b), method="bounded", options={"xatol": 1e-10})
    u_best = float(res.x) if res.fun <= rs[k] else float(us[k])
    best = prof.fit(prof.t_b + 10.0**u_best)
    t_best = prof.t_b + 10.0**u_best
    # 1-sigma profile interval: wrss rises by one residual variance
    target = best.wrss + best.s2

    def g(u):
        return prof.wrss(u) - target

    ends = []
    for direction in (-1.0, 1.0):
        u1 = u_best
        step = 0.01
        found = None
        for _ in range(60):
            u2 = u1 + direction * step
            if g(u2) > 0:
                found = brentq(g, min(u1, u2), max(u1, u2), xtol=1e-12)
                break
            u1, step = u2, step * 1.5
            if u1 < u_lo - 6 or u1 > u_hi + 2:
                break
        ends.append(found)
    t_ends = [prof.t_b + 10.0**u for u in ends if u is not None]
    if len(t_ends) < 2:
        notes.append("t* fit: the 1-sigma profile interval of t* is open on one side")
    t_err = max((abs(te - t_best) for te in t_ends), default=float("inf"))
    betas = [prof.fit(te) for te in t_ends]
    return t_best, t_err, best, betas


#: largest edge displacement of the window uncertainty (decades)
_MAX_PERTURB = 3.0


def fit_power_law(
    t,
    y,
    t_star: float | None = None,
    *,
    t_star_err: float = 0.0,
    t_star_guess: float | None = None,
    window: tuple[float, float] | None = None,
    min_width: float = 1.0,
    tol: float = 1e-3,
    prefer: str = "widest",
    slope_range: tuple[float, float] | None = None,
    perturb: float = 0.25,
    span: float = 0.5,
    spacing: float = 0.05,
    name: str = "y",
) -> PowerLawFit:
    """Fit y(t) = A (t* - t)^beta on a window of t* - t, with an honest uncertainty.

    The paper's asymptotic scalings (eq. asymptoticscalings) are power laws of
    tau = t* - t: v ~ tau^-1/3, a ~ tau^-4/3, sigma ~ tau^-2/3, and the maximum
    curvature's anomalous kappa_m ~ tau^-1/6. This fits such a law by weighted
    least squares on log-log axes (weights: the log10 tau interval of each
    sample).

    * ``t_star`` given: beta and A by least squares; its uncertainty
      ``t_star_err`` (e.g. the spread of the snapping times from v, a, sigma) is
      propagated by refitting at t* +- t_star_err.
    * ``t_star`` None: t* is fitted jointly, by profiling the residual over t*
      (beta and A by least squares for each candidate t*) on the samples of the
      window; the 1-sigma interval of t* is where the residual sum of squares has
      risen by one residual variance. Window and t* are iterated to consistency.
    * ``window`` None: chosen by :func:`find_window` where the local slope is
      flat; otherwise ``(tau_lo, tau_hi)``.

    The uncertainty combines (in quadrature) the least-squares standard error,
    the window choice (largest change of beta when either edge moves by a
    factor 10^(+-perturb)) and the t* choice; see the module docstring.

    Parameters
    ----------
    t, y : array_like
        Samples (e.g. ``run.t`` and ``run.v_max``).
    t_star : float, optional
        Snapping time; fitted when None.
    t_star_err : float
        Uncertainty of a given t* (>= 0).
    t_star_guess : float, optional
        Starting t* of a joint fit (default: the time of the peak of y, or just
        past the last sample if y is still rising there).
    window : (float, float), optional
        ``(tau_lo, tau_hi)`` with 0 < tau_lo < tau_hi, overriding the automatic one.
    min_width, tol, prefer, slope_range, span, spacing
        Automatic window, see :func:`find_window`.
    perturb : float
        Edge displacement in decades for the window uncertainty (>= 0).
    name : str
        Name of the quantity in error messages.

    Returns
    -------
    PowerLawFit

    Raises
    ------
    SnappingInputError
        Bad parameters, or a window holding fewer than 5 samples (outside the data).

    Examples
    --------
    >>> tau = np.logspace(-6, 0, 400)
    >>> f = fit_power_law(1.2 - tau, 0.437 * tau ** (-2 / 3), t_star=1.2)
    >>> round(f.beta, 6), round(f.A, 6)
    (-0.666667, 0.437)
    >>> g = fit_power_law(1.2 - tau, 0.437 * tau ** (-2 / 3))   # t* fitted too
    >>> round(g.t_star, 6)
    1.2
    """
    t_star_err = V.real("t_star_err", t_star_err)
    if not t_star_err >= 0:
        raise V.SnappingInputError(f"t_star_err={t_star_err!r} is out of range: must be a finite number >= 0")
    perturb = V.real("perturb", perturb)
    if not 0 <= perturb <= _MAX_PERTURB:
        raise V.SnappingInputError(f"perturb={perturb!r} is out of range: must lie in [0, {_MAX_PERTURB:g}] (decades)")
    t, y = _arrays(t, y, name)
    if window is not None:
        try:
            tau_lo, tau_hi = (float(window[0]), float(window[1]))
        except (TypeError, ValueError, IndexError, OverflowError):
            raise V.SnappingInputError(f"window={window!r} must be a pair (tau_lo, tau_hi)") from None
        if not (0 < tau_lo < tau_hi < math.inf):
            raise V.SnappingInputError(
                f"window={window!r} is out of range: needs 0 < tau_lo < tau_hi (values of t* - t)"
            )
    notes: list[str] = []
    fitted = t_star is None
    if fitted:
        if t_star_guess is None:
            i = int(np.argmax(y))
            if i < t.size - 1:
                t_guess = peak_time(t, y, name=name).t
            else:
                t_guess = float(t[-1] + (t[-1] - t[-2]))
        else:
            t_guess = V.real("t_star_guess", t_star_guess)
            if not (np.count_nonzero(t < t_guess) >= _MIN_POINTS and t_guess <= t[-1] + (t[-1] - t[0])):
                raise V.SnappingInputError(
                    f"t_star_guess={t_guess!r} is out of range: must lie after {_MIN_POINTS} samples and not past "
                    f"t[-1] + (t[-1] - t[0]) = {2 * t[-1] - t[0]:.6g}")
    else:
        t_star = V.real("t_star", t_star)
        t_guess = t_star
        if t_star > t[0] and not t_star_err < t_star - t[0]:
            raise V.SnappingInputError(f"t_star_err={t_star_err!r} is out of range: must be < t* - t[0] = "
                                       f"{t_star - t[0]:.6g} (the time the data span before t*)")

    kw = dict(min_width=min_width, tol=tol, prefer=prefer, slope_range=slope_range, span=span, spacing=spacing)

    def choose(ts_):
        if window is not None:
            _check_window(t, y, ts_, tau_lo, tau_hi, name)
            return tau_lo, tau_hi, True
        w = find_window(t, y, ts_, **kw, t_star_name="t_star" if not fitted else "t_star_guess")
        if not w.flat:
            notes.append(
                f"no window of {min_width:g} decades is flat within tol={tol:g}; "
                f"accepted local-slope deviation {w.tol:.3g}"
            )
        return w.tau_lo, w.tau_hi, w.flat

    if not fitted:
        lo, hi, flat = choose(t_star)
        f0 = _fit_fixed(t, y, t_star, lo, hi)
        if f0 is None:
            raise V.SnappingInputError(f"window=({lo:.3g}, {hi:.3g}) of t* - t holds fewer than {_MIN_POINTS} samples of {name}")
        t_fit, t_err = t_star, t_star_err
        err_t_b, err_t_a = 0.0, 0.0
        for dt in (-t_star_err, t_star_err):
            if dt == 0:
                continue
            fs = _fit_fixed(t, y, t_star + dt, lo, hi)
            if fs is None:
                notes.append("t* +- t_star_err leaves too few samples in the window")
                continue
            err_t_b = max(err_t_b, abs(fs.b - f0.b))
            err_t_a = max(err_t_a, abs(fs.a - f0.a))
    else:
        t_cur = t_guess
        res = None
        for _ in range(6):
            lo, hi, flat = choose(t_cur)
            res = _joint(t, y, t_cur, lo, hi, notes)
            if res is None:
                raise V.SnappingInputError(
                    f"window=({lo:.3g}, {hi:.3g}) of t* - t holds too few samples of {name} to fit t*"
                )
            t_new = res[0]
            if abs(t_new - t_cur) <= 1e-3 * lo:
                t_cur = t_new
                break
            t_cur = t_new
        t_fit, t_err, f0, fends = res
        # the window in tau relative to the fitted t*
        f0 = _fit_fixed(t, y, t_fit, lo, hi) or f0
        err_t_b = max((abs(fe.b - f0.b) for fe in fends), default=float("inf"))
        err_t_a = max((abs(fe.a - f0.a) for fe in fends), default=float("inf"))

    # window choice
    err_w_b, err_w_a = 0.0, 0.0
    if perturb > 0:
        for dlo in (-perturb, 0.0, perturb):
            for dhi in (-perturb, 0.0, perturb):
                if dlo == 0.0 and dhi == 0.0:
                    continue
                plo, phi = lo * 10.0**dlo, hi * 10.0**dhi
                if math.log10(phi / plo) < 0.5 * math.log10(hi / lo):
                    continue
                if fitted:
                    r = _joint(t, y, t_fit, plo, phi, [])
                    fp = None if r is None else r[2]
                else:
                    fp = _fit_fixed(t, y, t_fit, plo, phi)
                if fp is None:
                    continue
                err_w_b = max(err_w_b, abs(fp.b - f0.b))
                err_w_a = max(err_w_a, abs(fp.a - f0.a))
    drift, xm = _drift(t, y, t_fit, lo, hi)
    beta_err = math.sqrt(f0.se_b**2 + err_w_b**2 + err_t_b**2 + drift**2)
    la_err = math.sqrt(f0.se_a**2 + err_w_a**2 + err_t_a**2 + (drift * xm) ** 2)
    A = 10.0**f0.a
    A_err = A * (10.0**la_err - 1.0)
    return PowerLawFit(
        beta=float(f0.b),
        beta_err=float(beta_err),
        A=float(A),
        A_err=float(A_err),
        t_star=float(t_fit),
        t_star_err=float(t_err),
        t_star_fitted=fitted,
        tau_lo=float(lo),
        tau_hi=float(hi),
        n_points=int(f0.n),
        beta_err_stat=float(f0.se_b),
        beta_err_window=float(err_w_b),
        beta_err_t_star=float(err_t_b),
        beta_err_drift=float(drift),
        window_auto=window is None,
        flat=bool(flat),
        rms=float(math.sqrt(f0.wrss / f0.n_eff)),
        notes=tuple(notes),
    )


def _check_window(t, y, t_star, tau_lo, tau_hi, name):
    tau = t_star - t
    ok = (tau > 0) & (y > 0)
    if not np.any(ok):
        raise V.SnappingInputError(f"t_star={t_star!r}: no samples of {name} before t*")
    dmin, dmax = float(tau[ok].min()), float(tau[ok].max())
    n_in = int(np.count_nonzero(ok & (tau >= tau_lo * (1 - 1e-12)) & (tau <= tau_hi * (1 + 1e-12))))
    if n_in < _MIN_POINTS:
        raise V.SnappingInputError(
            f"window=({tau_lo:.6g}, {tau_hi:.6g}) lies outside the data of {name}: holds {n_in} samples "
            f"(at least {_MIN_POINTS} needed); t* - t spans [{dmin:.6g}, {dmax:.6g}]"
        )
