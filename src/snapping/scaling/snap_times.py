"""The snapping time of a run from the peaks of v_max, a_max and sigma_max (:func:`snapping_times`),
and the local log-log slopes of its maxima before that time (:func:`local_slopes`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .. import _validate as V
from .inputs import _PEAK_VARS, _t, check_run
from .peak import PeakTime, peak_time
from .slopes import local_slope


@dataclass(frozen=True)
class SnapTimes:
    """Snapping time of a run from the peaks of v_max, a_max and sigma_max.

    Attributes
    ----------
    t_star : float
        Mean of the three peak times (the paper's t*_chi).
    t_star_err : float
        Half their range and the largest interpolation uncertainty, in quadrature.
    spread : float
        Largest minus smallest of the three peak times.
    peaks : dict
        For each variable, its :class:`~snapping.scaling.fit.PeakTime`.
    """

    t_star: float
    t_star_err: float
    spread: float
    peaks: dict[str, PeakTime]

    def to_dict(self) -> dict:
        return {
            "t_star": self.t_star,
            "t_star_err": self.t_star_err,
            "spread": self.spread,
            "peaks": {k: asdict(p) for k, p in self.peaks.items()},
        }


def _stop_info(ds) -> str:
    st = ds.attrs.get("status")
    why = ds.attrs.get("stop_reason")
    out = []
    if st is not None:
        out.append(f"status={st!r}")
    if why:
        out.append(f"stop_reason={why!r}")
    return (" (" + ", ".join(out) + ")") if out else ""


def snapping_times(ds, *, min_drop: float = 1e-3) -> SnapTimes:
    """Snapping time t*_chi of a run from each of max speed, acceleration and tension.

    Each peak is located between recorded steps (:func:`~snapping.scaling.fit.peak_time`);
    the paper (section "Ideal and anomalous evolution") reports that the three
    agree to about five significant digits for chi >= 0.1.

    Parameters
    ----------
    ds : xarray.Dataset
        A run.
    min_drop : float
        Each quantity must have fallen by this fraction after its peak by the end
        of the record, else the run stopped before the snap.

    Returns
    -------
    SnapTimes

    Raises
    ------
    SnappingInputError
        Not a run, or a run that stopped before the snap.

    Examples
    --------
    >>> import xarray as xr
    >>> t = np.linspace(0.9, 1.1, 201); y = 1 / np.hypot(t - 1.0003, 1e-2)
    >>> run = xr.Dataset({k: ("step", y) for k in ("v_max", "a_max", "sigma_max")}, coords={"t": ("step", t)})
    >>> round(snapping_times(run).t_star, 5)
    1.0003
    """
    check_run(ds)
    t = _t(ds)
    peaks = {}
    for v in _PEAK_VARS:
        try:
            peaks[v] = peak_time(t, np.asarray(ds[v].values, dtype=float), name=v, min_drop=min_drop)
        except V.SnappingInputError as exc:
            raise V.SnappingInputError(f"{exc}{_stop_info(ds)}") from None
    ts = np.array([p.t for p in peaks.values()])
    spread = float(ts.max() - ts.min())
    err = math.hypot(0.5 * spread, max(p.err for p in peaks.values()))
    return SnapTimes(float(ts.mean()), float(err), spread, peaks)


def local_slopes(ds, t_star: float | None = None, variables=("v_max", "a_max", "a_end", "sigma_max", "kappa_max"), **kw):
    """Local log-log slope curves of a run's maxima (for plots and for judging windows).

    Returns a dict variable -> :class:`~snapping.scaling.fit.LocalSlope`.
    """
    check_run(ds)
    if t_star is None:
        t_star = snapping_times(ds).t_star
    t = _t(ds)
    return {
        v: local_slope(t, np.asarray(ds[v].values, dtype=float), t_star, **kw) for v in variables if v in ds.variables
    }
