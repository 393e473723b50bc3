"""What each fitted exponent of the report is compared with: the rows and their reference exponents
(:func:`report_specs`), the exact folded string's exponent on a finite window
(:func:`ideal_window_exponent`), and the verdict of a fit against its references (``_verdict``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

from .. import _validate as V
from .power_law import PowerLawFit


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
