"""delta_kappa_m of a run and the whirling-rod predictions of the three delta scales against the
run's peaks (paper Fig. 4, :func:`delta_comparison`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from .. import _validate as V
from .. import estimates
from .inputs import _PEAK_VARS, _t, check_run
from .snap_times import SnapTimes, snapping_times


@dataclass(frozen=True)
class DeltaComparison:
    """Predicted peaks from the three scales against the run's peaks (paper Fig. 4).

    Attributes
    ----------
    chi : float
    deltas : dict
        ``delta_kappa0``, ``delta_c``, ``delta_kappa_m`` (NaN if it could not be
        measured).
    t_cross : float
        Time where 1 - s(kappa_m) meets (pi/2)/kappa_m.
    computed : dict
        The run's interpolated peaks ``v``, ``a``, ``sigma``.
    predicted : dict
        For each scale, the whirling-rod predictions ``v``, ``a``, ``sigma``
        (eq. estimates) with P = P(chi).
    note : str
        Why delta_kappa_m is missing, if it is.
    """

    chi: float
    P: float
    deltas: dict[str, float]
    t_cross: float
    computed: dict[str, float]
    predicted: dict[str, dict[str, float]]
    note: str = ""

    def ratios(self) -> dict[str, dict[str, float]]:
        """predicted / computed for each scale and quantity."""
        return {k: {q: p[q] / self.computed[q] for q in p} for k, p in self.predicted.items()}

    def to_dict(self) -> dict:
        d = asdict(self)
        d["ratios"] = self.ratios()
        return d


def _chi(ds) -> float:
    if "chi" not in ds.attrs:
        raise V.SnappingInputError("the run has no attribute 'chi' (initial end-to-end separation)")
    return V.open_interval("chi", ds.attrs["chi"], 0.0, 1.0)


def delta_comparison(ds, snap: SnapTimes | None = None) -> DeltaComparison:
    """delta_kappa_m of a run and the whirling-rod predictions of all three scales.

    delta_kappa_m is where 1 - s(kappa_m) = (pi/2)/kappa_m
    (:func:`snapping.estimates.delta_kappa_m`, on the steps before t*);
    delta_kappa0 = (pi/2)/kappa_m(0) and delta_c = (1/2)(pi/kappa_m(0))^(4/3)
    (eq. deltacrude) come from chi alone. Each gives v = (6 P/delta)^(1/2),
    a = v^2/delta, sigma = v^2/2 (eq. estimates), compared with the run's peaks
    (paper Fig. 4(b)-(d)).

    Parameters
    ----------
    ds : xarray.Dataset
        A run with ``kappa_max`` and ``s_kappa_max`` and attribute ``chi``.
    snap : SnapTimes, optional
        Precomputed snapping times.

    Returns
    -------
    DeltaComparison
    """
    check_run(ds, require=_PEAK_VARS + ("kappa_max", "s_kappa_max"))
    chi = _chi(ds)
    snap = snap or snapping_times(ds)
    t = _t(ds)
    before = t < snap.t_star
    note = ""
    try:
        dkm, t_c = estimates.delta_kappa_m(
            t[before], ds["kappa_max"].values[before], ds["s_kappa_max"].values[before], return_time=True
        )
    except V.SnappingInputError as exc:
        dkm, t_c, note = float("nan"), float("nan"), str(exc)
    deltas = {
        "delta_kappa0": estimates.delta_kappa0(chi),
        "delta_kappa_m": dkm,
        "delta_c": estimates.delta_crude(chi),
    }
    P = estimates.available_energy(chi)
    predicted = {
        k: (estimates.whirling_rod(P, d) if math.isfinite(d) else {"v": math.nan, "a": math.nan, "sigma": math.nan})
        for k, d in deltas.items()
    }
    pk = snap.peaks
    computed = {"v": pk["v_max"].value, "a": pk["a_max"].value, "sigma": pk["sigma_max"].value}
    return DeltaComparison(chi, P, deltas, t_c, computed, predicted, note)
