"""The time and height of a peak of sampled data (:func:`peak_time`): the parabola through the
largest sample and its two neighbours, with an error from two other estimators.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from ._loglog import _arrays


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
