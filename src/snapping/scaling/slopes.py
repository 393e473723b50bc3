"""Local log-log slopes d ln y / d ln (t* - t) as a curve (:func:`local_slope`), and the window of
t* - t where that slope is flat, the power law's range (:func:`find_window`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .. import _validate as V
from ._loglog import _MIN_POINTS, _arrays, _before, _grid, _wls


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
