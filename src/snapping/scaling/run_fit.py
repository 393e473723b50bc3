"""Every exponent of a run fitted and judged (:func:`fit_run`), with its rows (:class:`ExponentRow`)
and the whole result (:class:`RunFit`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from ..ideal import TAU_MIN
from .delta import DeltaComparison, delta_comparison
from .inputs import _t, check_run
from .power_law import PowerLawFit, fit_power_law
from .references import RowSpec, _judge, _verdict, ideal_window_exponent, report_specs
from .snap_times import SnapTimes, snapping_times


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
