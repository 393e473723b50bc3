"""Scaling analysis of run Datasets: snapping times, the fit report, delta scales.

Thin functions that take a run :class:`xarray.Dataset` (names from
:mod:`snapping.schema`), pull out arrays and call the pure functions of
:mod:`snapping.scaling.fit` and :mod:`snapping.estimates`.

Reference exponents and prefactors come from :mod:`snapping.ideal` (the folded
string, derived) and the paper's observations (-5/6, -1/6).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .. import _validate as V
from .. import estimates, schema
from ..ideal import TAU_MIN
from .fit import PeakTime, PowerLawFit, fit_power_law, local_slope, peak_time

if TYPE_CHECKING:  # annotations only
    import xarray as xr

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

T = "t"
_PEAK_VARS = ("v_max", "a_max", "sigma_max")
assert all(v in schema.STEP_VARS for v in _PEAK_VARS + ("a_end", "kappa_max", "s_kappa_max"))


# ----------------------------------------------------------------------- reference
@dataclass(frozen=True)
class RowSpec:
    """One line of the fit report: which variable, against which exponent.

    Attributes
    ----------
    name : str
        Row label.
    var : str
        Run variable (a key of :data:`snapping.schema.STEP_VARS`).
    ref : float
        Exponent the paper states for it.
    ref_label : str
        Where ``ref`` comes from.
    prefactor : float or None
        Ideal prefactor (folded string), None where unknown.
    alt : float or None
        A second exponent to compare with (the inferred -2/3 for curvature, the
        late-time -4/3 for the maximum acceleration).
    fit_kw : dict
        Extra arguments of :func:`~snapping.scaling.fit.fit_power_law`.
    ideal : str or None
        Attribute of :class:`snapping.ideal.KinkState` with the exact folded-string
        counterpart of ``var`` (e.g. ``"tether_tension"``); its exponent fitted on
        the same window is the fair reference at finite t* - t (the asymptotic
        exponent holds only as t* - t -> 0).
    """

    name: str
    var: str
    ref: float
    ref_label: str
    prefactor: float | None = None
    alt: float | None = None
    alt_label: str = ""
    fit_kw: dict = field(default_factory=dict)
    ideal: str | None = None


def _ideal_refs() -> dict[str, tuple[float, float | None]]:
    """(exponent, prefactor) of the folded string from snapping.ideal (derived with sympy)."""
    from .. import ideal

    sc = ideal.asymptotic_scalings()
    ob = ideal.observed_scalings()
    return {
        "v": (sc["free_end_speed"].exponent_float, sc["free_end_speed"].prefactor_float),
        "a_end": (sc["free_end_acceleration"].exponent_float, sc["free_end_acceleration"].prefactor_float),
        "sigma": (sc["tether_tension"].exponent_float, sc["tether_tension"].prefactor_float),
        "kappa_inferred": (sc["curvature_inferred"].exponent_float, None),
        "kappa_observed": (ob["curvature_max"].exponent_float, None),
        "a_intermediate": (ob["acceleration_max_intermediate"].exponent_float, None),
    }


def report_specs() -> list[RowSpec]:
    """The rows of the fit report (paper, eq. asymptoticscalings and Fig. 3).

    ====================  ==========  =============================================
    row                   exponent    source
    ====================  ==========  =============================================
    v_max                 -1/3        free-end speed 2 s0' of the folded string
    a_end                 -4/3        free-end acceleration 2 s0''
    a_max                 -4/3, -5/6  one fit, judged against both: -4/3 once the
                                      maximum is at the free end (late), -5/6 the
                                      paper's observation (maximum near the fold)
    sigma_max             -2/3        tether tension s0 + s0'^2
    kappa_max             -1/6        paper's anomalous late-time observation
                                      (-2/3 inferred from kappa' ~ v kappa^2)
    ====================  ==========  =============================================

    >>> [q.name for q in report_specs()][:2]
    ['v_max', 'a_end']
    """
    r = _ideal_refs()
    return [
        RowSpec("v_max", "v_max", r["v"][0], "folded string 2 s0'", r["v"][1], ideal="free_end_speed"),
        RowSpec("a_end", "a_end", r["a_end"][0], "folded string 2 s0''", r["a_end"][1], ideal="free_end_acceleration"),
        RowSpec(
            "a_max", "a_max", r["a_end"][0], "free end, late", r["a_end"][1],
            alt=r["a_intermediate"][0], alt_label="paper, near the fold", fit_kw={"prefer": "latest"},
            ideal="free_end_acceleration",
        ),
        RowSpec("sigma_max", "sigma_max", r["sigma"][0], "tether tension s0 + s0'^2", r["sigma"][1],
                ideal="tether_tension"),
        RowSpec(
            "kappa_max", "kappa_max", r["kappa_observed"][0], "paper, anomalous", None,
            alt=r["kappa_inferred"][0], alt_label="inferred kappa' ~ v kappa^2",
            fit_kw={"prefer": "latest", "slope_range": (-1.0, -0.02)},
        ),
    ]


# --------------------------------------------------------------------------- input
def _t(ds) -> np.ndarray:
    return np.asarray(ds[T].values, dtype=float)


def check_run(ds, *, require: tuple[str, ...] = _PEAK_VARS, name: str = "run") -> None:
    """Check that ``ds`` is a run Dataset with the variables the analysis needs.

    Parameters
    ----------
    ds : xarray.Dataset
        A run (:mod:`snapping.schema`).
    require : tuple of str
        Step variables that must be present.
    name : str
        How to call the run in error messages (e.g. its file name).

    Raises
    ------
    SnappingInputError
        Not a Dataset, no time coordinate ``t`` on dimension ``step``, or missing
        variables.

    Examples
    --------
    >>> import xarray as xr
    >>> check_run(xr.Dataset())
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: run is not a run Dataset: no time coordinate 't' along dimension 'step'
    """
    import xarray as xr

    if not isinstance(ds, xr.Dataset):
        raise V.SnappingInputError(f"{name}={type(ds).__name__} is not a run Dataset (expected an xarray.Dataset)")
    if T not in ds.variables or schema.STEP_DIM not in ds[T].dims:
        raise V.SnappingInputError(
            f"{name} is not a run Dataset: no time coordinate {T!r} along dimension {schema.STEP_DIM!r}"
        )
    missing = [v for v in require if v not in ds.variables]
    if missing:
        raise V.SnappingInputError(f"{name} is not a run Dataset: missing variables {missing}")


def load_run(path) -> "xr.Dataset":
    """Open a run file (netCDF4) into memory and check it is a run Dataset.

    Parameters
    ----------
    path : str or Path
        The file written by :mod:`snapping.simulate` (or a sweep file combining runs).

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    SnappingInputError
        Missing or unreadable file, or not a run Dataset.

    Examples
    --------
    >>> load_run("no/such/run.nc")
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: path='no/such/run.nc' does not exist
    """
    import xarray as xr

    p = Path(V.file_path("path", path))
    if not p.exists():
        raise V.SnappingInputError(f"path={str(path)!r} does not exist")
    if not p.is_file():
        raise V.SnappingInputError(f"path={str(path)!r} is not a file")
    try:
        with xr.open_dataset(p) as ds:
            ds = ds.load()
    except Exception as exc:  # netCDF4/h5 raise OSError, ValueError, KeyError ...
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        raise V.SnappingInputError(
            f"path={str(path)!r} is not a readable netCDF run file ({type(exc).__name__}: {msg[:160]})"
        ) from None
    check_run(ds, name=repr(str(path)))
    return ds


def iter_runs(ds):
    """Split a sweep Dataset (extra dimensions such as ``chi``, ``N``) into runs.

    A plain run is yielded as is. For a sweep (:func:`snapping.sweep.combine`),
    each combination of the extra dimensions gives one run: its steps where ``t``
    is defined, ``t`` as the coordinate, and the sweep coordinates and 0-d summary
    variables (``v_peak``, ...) as attributes.

    Parameters
    ----------
    ds : xarray.Dataset

    Yields
    ------
    xarray.Dataset

    Examples
    --------
    >>> import xarray as xr
    >>> t = np.linspace(0, 1, 6)
    >>> sweep = xr.Dataset({"t": (("chi", "step"), [t, t]), "v_max": (("chi", "step"), [t, 2 * t])},
    ...                    coords={"chi": [0.1, 0.2]})
    >>> [float(r.attrs["chi"]) for r in iter_runs(sweep)]
    [0.1, 0.2]
    """
    check_run(ds, require=("v_max",))
    extra = [d for d in ds["v_max"].dims if d != schema.STEP_DIM]
    if not extra:
        yield ds
        return
    for idx in itertools.product(*(range(ds.sizes[d]) for d in extra)):
        sub = ds.isel(dict(zip(extra, idx)))
        t = np.asarray(sub[T].values, dtype=float)
        keep = np.isfinite(t)
        if keep.sum() < 5:
            continue
        sub = sub.isel({schema.STEP_DIM: np.nonzero(keep)[0]})
        if T not in sub.coords:
            sub = sub.set_coords(T)
        attrs = dict(ds.attrs)
        for d in extra:
            if d in sub.coords:
                val = sub[d].values.item()
                attrs[d] = val
        for k in list(sub.data_vars):
            if sub[k].ndim == 0 and (k in schema.RESULT_ATTRS or k in schema.INPUT_ATTRS):
                val = sub[k].values.item()
                if not (isinstance(val, float) and math.isnan(val)):
                    attrs[k] = val
                sub = sub.drop_vars(k)
        sub = sub.drop_vars([d for d in extra if d in sub.coords])
        sub.attrs = attrs
        yield sub


# --------------------------------------------------------------------- snap times
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


# ----------------------------------------------------------------- delta / Fig. 4
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


# ----------------------------------------------------------------------- the report
@dataclass(frozen=True)
class ExponentRow:
    """One fitted exponent of a run against its reference.

    Attributes
    ----------
    spec : RowSpec
    fit : PowerLawFit or None
        Fit with t* = t*_chi (the paper's procedure), None if it failed.
    fit_joint : PowerLawFit or None
        Fit with t* fitted jointly (same window rules).
    z : float
        (beta - ref) / beta_err of ``fit``.
    verdict : str
        In plain words, against each reference: "agrees with -1/3", "differs from
        -1/3 (z = -3.0)", "inconclusive: ..." (first clause: ``spec.ref``; then
        ``spec.alt``; then the exact folded string on the fit's window).
    error : str
        Why a fit failed.
    ideal_window_beta : float
        Exponent of the exact folded-string counterpart (``spec.ideal``) fitted on
        the same window of t* - t (NaN if there is none).
    """

    spec: RowSpec
    fit: PowerLawFit | None
    fit_joint: PowerLawFit | None
    z: float
    verdict: str
    error: str = ""
    ideal_window_beta: float = math.nan
    z_alt: float = math.nan
    notes: str = ""

    def word(self, ref: float) -> str:
        """``agrees``, ``differs`` or ``inconclusive`` against ``ref`` (the row's reference
        or its alternative), or ``no fit``."""
        if self.fit is None:
            return "no fit"
        return _judge(self.fit, ref, self.spec)[1]

    def to_dict(self) -> dict:
        return {
            "name": self.spec.name,
            "var": self.spec.var,
            "ref": self.spec.ref,
            "ref_label": self.spec.ref_label,
            "ref_prefactor": self.spec.prefactor,
            "alt": self.spec.alt,
            "fit": None if self.fit is None else self.fit.to_dict(),
            "fit_joint": None if self.fit_joint is None else self.fit_joint.to_dict(),
            "z": self.z,
            "z_alt": self.z_alt,
            "verdict": self.verdict,
            "notes": self.notes,
            "error": self.error,
            "ideal_window_beta": self.ideal_window_beta,
        }


@dataclass(frozen=True)
class RunFit:
    """Everything the fit report says about one run.

    Attributes
    ----------
    chi, N : float, int
    snap : SnapTimes
    rows : list of ExponentRow
    delta : DeltaComparison or None
    kappa_max_0 : float
        Maximum curvature at t = 0 (for the amplification kappa_max(t)/kappa_max(0)).
    kappa_amplification : float
        Peak of kappa_max over kappa_max(0) before t*.
    """

    chi: float
    N: int | None
    snap: SnapTimes
    rows: list[ExponentRow]
    delta: DeltaComparison | None
    kappa_max_0: float
    kappa_amplification: float
    notes: tuple[str, ...] = ()

    def row(self, name: str) -> ExponentRow:
        for r in self.rows:
            if r.spec.name == name:
                return r
        raise KeyError(name)

    def to_dict(self) -> dict:
        return {
            "chi": self.chi,
            "N": self.N,
            "snap": self.snap.to_dict(),
            "rows": [r.to_dict() for r in self.rows],
            "delta": None if self.delta is None else self.delta.to_dict(),
            "kappa_max_0": self.kappa_max_0,
            "kappa_amplification": self.kappa_amplification,
            "notes": list(self.notes),
        }


def ideal_window_exponent(quantity: str, tau_lo: float, tau_hi: float) -> float:
    """Exponent of the exact folded-string ``quantity`` (an attribute of
    :class:`snapping.ideal.KinkState`, e.g. ``"tether_tension"``) fitted by least
    squares on log-log over ``tau_lo <= t* - t <= tau_hi``.

    The asymptotic exponents (-1/3, -4/3, -2/3) hold only as t* - t -> 0; on a
    finite window the exact solution has its own effective exponent (the tether
    tension s0 + s0'^2 carries the static weight s0 ~ 1), which is the fair
    reference for a run fitted on that window.

    >>> round(ideal_window_exponent("free_end_speed", 1e-9, 1e-8), 3)
    -0.333
    >>> round(ideal_window_exponent("tether_tension", 1e-3, 1e-2), 1)   # not -2/3 on this window
    -0.6
    """
    from .. import ideal

    names = [f.name for f in fields(ideal.KinkState) if f.name not in ("t", "tau")]
    if quantity not in names:
        raise V.SnappingInputError(f"quantity={quantity!r} is not one of {names}")
    tau_lo = V.real("tau_lo", tau_lo)
    tau_hi = V.real("tau_hi", tau_hi)
    if not ideal.TAU_MIN <= tau_lo < min(tau_hi, ideal.t_star()):
        raise V.SnappingInputError(f"tau_lo={tau_lo!r}, tau_hi={tau_hi!r}: the window of t* - t must satisfy "
                                   f"{ideal.TAU_MIN:g} <= tau_lo < tau_hi and tau_lo < t* = {ideal.t_star():.6g}")
    tau = np.logspace(math.log10(tau_lo), math.log10(min(tau_hi, ideal.t_star())), 200)
    y = np.abs(getattr(ideal.kink_state(tau=tau), quantity))
    ok = y > 0  # the free end starts at rest (tau = t*)
    if ok.sum() < 2:
        return math.nan
    return float(np.polyfit(np.log(tau[ok]), np.log(y[ok]), 1)[0])


#: Spacing of the paper's exponent ladder (-1/3, -2/3, -4/3): the separation from the
#: nearest other candidate for rows that name no alternative exponent.
EXPONENT_SPACING = 1.0 / 3.0


def inconclusive_err(spec: RowSpec) -> float:
    """Largest exponent uncertainty that still tells the row's reference from its nearest
    other candidate (the alternative exponent, else EXPONENT_SPACING) at 4 uncertainties,
    so that an "agrees" (within 2) excludes the other candidate. kappa_max: |-1/6 + 2/3| / 4
    = 0.125; v_max: 1/12."""
    sep = abs(spec.ref - spec.alt) if spec.alt is not None else EXPONENT_SPACING
    return sep / 4.0


def _judge(fit: PowerLawFit, ref: float, spec: RowSpec) -> tuple[float, str]:
    """z-score of the fitted exponent against ``ref`` and the word for it: ``agrees``
    (|z| <= 2), ``differs``, or ``inconclusive`` (uncertainty above :func:`inconclusive_err`)."""
    z = (fit.beta - ref) / fit.beta_err if fit.beta_err > 0 else math.inf
    if not fit.beta_err <= inconclusive_err(spec):
        return z, "inconclusive"
    return z, "agrees" if abs(z) <= 2.0 else "differs"


def exponent_text(x: float) -> str:
    """An exponent as the fraction it is (denominator <= 12): -1/3, -4/3, -5/6; else a decimal."""
    from fractions import Fraction

    f = Fraction(x).limit_denominator(12)
    if abs(float(f) - x) >= 1e-9:
        return f"{x:+.4g}"
    return f"{f.numerator}/{f.denominator}" if f.denominator > 1 else str(f.numerator)


def _clause(word: str, ref: float, z: float, label: str = "") -> str:
    name = exponent_text(ref) + (f" ({label})" if label else "")
    return f"agrees with {name}" if word == "agrees" else f"differs from {name} (z = {z:+.1f})"


def _verdict(fit: PowerLawFit, spec: RowSpec, ideal_beta: float = math.nan) -> tuple[float, str, str, float]:
    """``(z, verdict, notes, z_alt)``: the verdict in plain words against the row's
    reference (``agrees with -1/3`` within 2 uncertainties, ``differs from -1/3 (z = ...)``),
    then against its alternative and the exact folded string on this window, or
    ``inconclusive: ...`` when the uncertainty is above :func:`inconclusive_err`; notes: a
    window that is not flat, a window chosen inside a slope range (which leans the fit)."""
    z, v = _judge(fit, spec.ref, spec)
    z_alt = math.nan
    if spec.alt is not None:
        z_alt = (fit.beta - spec.alt) / fit.beta_err if fit.beta_err > 0 else math.inf
    if v == "inconclusive":
        other = (exponent_text(spec.alt) if spec.alt is not None
                 else f"{exponent_text(spec.ref - EXPONENT_SPACING)} or {exponent_text(spec.ref + EXPONENT_SPACING)}")
        verdict = (f"inconclusive: uncertainty {fit.beta_err:.2g} > {inconclusive_err(spec):.2g}, too large to tell "
                   f"{exponent_text(spec.ref)} from {other} (a wider or flatter window is needed)")
    else:
        clauses = [_clause(v, spec.ref, z)]
        if spec.alt is not None:
            clauses.append(_clause(_judge(fit, spec.alt, spec)[1], spec.alt, z_alt, spec.alt_label))
        if math.isfinite(ideal_beta):
            zi, vi = _judge(fit, ideal_beta, spec)
            clauses.append(("agrees with" if vi == "agrees" else f"differs (z = {zi:+.1f}) from")
                           + f" the exact folded string on this window ({ideal_beta:+.3f})")
        verdict = "; ".join(clauses)
    notes = []
    if not fit.flat:
        notes.append("window not flat")
    sr = spec.fit_kw.get("slope_range")
    if sr is not None:
        notes.append(f"window constrained to local slopes in [{sr[0]:g}, {sr[1]:g}]")
    return float(z), verdict, "; ".join(notes), float(z_alt)


def fit_run(
    ds,
    *,
    specs: list[RowSpec] | None = None,
    joint: bool = True,
    delta: bool = True,
    windows: dict[str, tuple[float, float]] | None = None,
    **fit_kw,
) -> RunFit:
    """Fit every exponent of a run: the paper's Fig. 3 as numbers.

    For each row of :func:`report_specs` (v_max, a_end, a_max, sigma_max, kappa_max) the law y ~ A (t*_chi - t)^beta is fitted
    (:func:`~snapping.scaling.fit.fit_power_law`) with t*_chi the mean snapping
    time from the three peaks and its uncertainty propagated, and again with
    t* fitted jointly; each gets a verdict in plain words against the paper's exponent
    (eq. asymptoticscalings, -5/6, -1/6), its alternative and the exact folded string on
    the same window: "agrees with -1/3" when within two of its uncertainties, "differs
    from -1/3 (z = ...)", "inconclusive: ..." when that uncertainty is too large to
    exclude the nearest other candidate exponent (:func:`inconclusive_err`).

    Parameters
    ----------
    ds : xarray.Dataset
        A run that went through the snap.
    specs : list of RowSpec, optional
        Rows to fit (default :func:`report_specs`).
    joint : bool
        Also fit t* jointly.
    delta : bool
        Also measure delta_kappa_m and the Fig. 4 predictions.
    windows : dict, optional
        Windows ``(tau_lo, tau_hi)`` overriding the automatic choice, keyed by row
        name or variable (``"v_max"``).
    **fit_kw
        Passed to every fit (e.g. ``tol``, ``min_width``).

    Returns
    -------
    RunFit
    """
    check_run(ds)
    for k in ("tol", "min_width"):  # chosen by the user: refuse rather than fail every row quietly
        if k in fit_kw:
            fit_kw[k] = V.positive(k, fit_kw[k])
    span = V.positive("span", fit_kw.get("span", 0.5))
    if "min_width" in fit_kw and not fit_kw["min_width"] > span:
        raise V.SnappingInputError(f"min_width={fit_kw['min_width']!r} is out of range: must be > span={span!r} "
                                   f"(decades)")
    specs = report_specs() if specs is None else specs
    if windows:
        known = {s.name for s in specs} | {s.var for s in specs}
        unknown = sorted(set(windows) - known)
        if unknown:
            raise V.SnappingInputError(f"windows has unknown rows or variables {unknown} (known: {sorted(known)})")
    snap = snapping_times(ds)
    t = _t(ds)
    rows = []
    for spec in specs:
        if spec.var not in ds.variables:
            rows.append(ExponentRow(spec, None, None, math.nan, "missing", f"no variable {spec.var!r}"))
            continue
        y = np.asarray(ds[spec.var].values, dtype=float)
        kw = {**spec.fit_kw, **fit_kw}
        if windows:
            w = windows.get(spec.name, windows.get(spec.var))
            if w is not None:
                kw["window"] = w
        try:
            f = fit_power_law(t, y, snap.t_star, t_star_err=snap.t_star_err, name=spec.var, **kw)
        except V.SnappingInputError as exc:
            if "window" in kw:  # a window the user chose: say so, do not hide it in a row
                raise V.SnappingInputError(f"{spec.name}: {exc}") from None
            rows.append(ExponentRow(spec, None, None, math.nan, "inconclusive: no fit", str(exc)))
            continue
        fj = None
        if joint:
            try:
                fj = fit_power_law(t, y, None, t_star_guess=snap.t_star, name=spec.var, **kw)
            except V.SnappingInputError:
                fj = None
        bw = math.nan
        if spec.ideal is not None:
            bw = ideal_window_exponent(spec.ideal, max(f.tau_lo, TAU_MIN), f.tau_hi)
        z, verdict, notes, z_alt = _verdict(f, spec, bw)
        rows.append(ExponentRow(spec, f, fj, z, verdict, ideal_window_beta=bw, z_alt=z_alt, notes=notes))
    if "min_width" in fit_kw and rows and all(r.fit is None for r in rows):  # the user's window width fits nothing
        raise V.SnappingInputError(f"min_width={fit_kw['min_width']!r}: no row could be fitted ({rows[0].error})")
    dc = None
    notes = []
    if delta and "kappa_max" in ds.variables and "s_kappa_max" in ds.variables and "chi" in ds.attrs:
        dc = delta_comparison(ds, snap)
        if dc.note:
            notes.append(dc.note)
    k0, amp = math.nan, math.nan
    if "kappa_max" in ds.variables:
        kap = np.asarray(ds["kappa_max"].values, dtype=float)
        k0 = float(ds.attrs.get("kappa_max_0", kap[0]))
        amp = float(np.nanmax(kap[t < snap.t_star]) / k0)
    chi = float(ds.attrs["chi"]) if "chi" in ds.attrs else math.nan
    N = int(ds.attrs["N"]) if "N" in ds.attrs else None
    return RunFit(chi, N, snap, rows, dc, k0, amp, tuple(notes))


def _pad(rows: list[tuple], left: tuple = (0, -1)) -> list[tuple]:
    """Pad every column to its width (the columns ``left``, by default the first and the
    last, left-aligned; the rest right-aligned)."""
    rows = [tuple(str(c) for c in r) for r in rows]
    n = max(len(r) for r in rows)
    rows = [r + ("",) * (n - len(r)) for r in rows]
    w = [max(len(r[i]) for r in rows) for i in range(n)]
    lefts = {i % n for i in left}
    return [tuple(c.ljust(w[i]) if i in lefts else c.rjust(w[i]) for i, c in enumerate(r)) for r in rows]


def _pm(x: float, e: float) -> str:
    if not math.isfinite(x):
        return "-"
    return f"{x:+.4f} ± {e:.4f}" if math.isfinite(e) else f"{x:+.4f} ± inf"


def report_rows(res: RunFit) -> list[tuple]:
    """Rows (name, value, ...) of the exponent table of one run, for ``print_table``.

    Columns: quantity, beta with uncertainty (t* = t*_chi), reference exponent,
    window of t* - t, beta with t* fitted jointly, prefactor A against the ideal
    one, verdict.
    """
    out = [("quantity", "beta (t*=t*_chi)", "ref", "ideal in window", "window t*-t", "beta (t* fitted)",
            "A / A_ideal", "verdict", "notes")]
    for r in res.rows:
        s = r.spec
        refs = exponent_text(s.ref) + ("" if s.alt is None else f", {exponent_text(s.alt)}")
        if r.fit is None:
            out.append((s.name, "-", refs, "-", "-", "-", "-", f"{r.verdict}: {r.error}", ""))
            continue
        f = r.fit
        win = f"[{f.tau_lo:.2e}, {f.tau_hi:.2e}]"
        bj = "-" if r.fit_joint is None else _pm(r.fit_joint.beta, r.fit_joint.beta_err)
        ratio = "-" if s.prefactor is None else f"{f.A / s.prefactor:.3f}"
        bw = "-" if not math.isfinite(r.ideal_window_beta) else f"{r.ideal_window_beta:+.4f}"
        out.append((s.name, _pm(f.beta, f.beta_err), refs, bw, win, bj, ratio, r.verdict, r.notes))
    return _pad(out, left=(0, -2, -1))


def delta_rows(dc: DeltaComparison) -> list[tuple]:
    """Rows of the Fig. 4 table: each scale delta, its predicted v, a, sigma and the
    ratios predicted / computed; first the run's computed peaks."""
    rows = [("scale", "delta", "v", "a", "sigma", "predicted/computed v, a, sigma")]
    c = dc.computed
    rows.append(("computed peaks", "", f"{c['v']:.4g}", f"{c['a']:.4g}", f"{c['sigma']:.4g}", ""))
    ratios = dc.ratios()
    for k, dv in dc.deltas.items():
        p, rr = dc.predicted[k], ratios[k]
        rows.append((k, f"{dv:.4g}", f"{p['v']:.4g}", f"{p['a']:.4g}", f"{p['sigma']:.4g}",
                     f"{rr['v']:.3g}, {rr['a']:.3g}, {rr['sigma']:.3g}"))
    return _pad(rows)


def summary_rows(results: list[RunFit]) -> list[tuple]:
    """One row per run (several files or a sweep): chi, N, t*_chi and every exponent."""
    if not results:
        return []
    names = [r.spec.name for r in results[0].rows]
    head = ("chi", "N", "t*_chi", *names, "delta_kappa_m")
    out = [head]
    for res in results:
        cells = []
        for n in names:
            try:
                r = res.row(n)
            except KeyError:
                cells.append("-")
                continue
            cells.append("-" if r.fit is None else _pm(r.fit.beta, r.fit.beta_err))
        dkm = "-" if res.delta is None else f"{res.delta.deltas['delta_kappa_m']:.4g}"
        out.append((f"{res.chi:.4g}", str(res.N), f"{res.snap.t_star:.8f}", *cells, dkm))
    return _pad(out)


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


__all__ += ["local_slopes"]
