"""SI design rules: a real chain (:class:`Chain`), and :func:`design_estimate`, the snap
predicted from the initial geometry (and, with the number of links, computed by the table of
fast exact runs, :mod:`snapping.table`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as V
from .catenary import (CHI_MIN, _A_MAX, _A_MIN, available_energy, catenary_parameter, check_chi,
                       chi_from_parameter, delta_crude, delta_kappa0, delta_N, whirling_rod)

__all__ = ["Chain", "PAPER_CHAIN", "CHAIN_RANGE", "DesignEstimate", "design_estimate", "print_estimate", "attach_computed",
           "estimator_factors", "check_tip_mass", "COMPUTED"]

# ------------------------------------------------------------------ SI design rules
def _t_star() -> float:
    """Ideal snapping time of the folded string, t* = 2 sqrt(pi) Gamma(3/4) / Gamma(1/4) in
    doubles (the same float as ``float(snapping.ideal.t_star())``, without importing mpmath for
    every estimate; the tests check that they agree)."""
    return 2.0 * math.sqrt(math.pi) * math.gamma(0.75) / math.gamma(0.25)


#: range of a chain's length, mass and gravity in SI
CHAIN_RANGE = V.SI_SCALE_RANGE


@dataclass(frozen=True)
class Chain:
    """A real chain or tether: length [m], mass [kg] and gravity [m/s^2].

    Converts the nondimensional quantities of the library (length l, velocity
    sqrt(g l), acceleration g, force M g, time sqrt(l/g)) to SI. The defaults
    are the paper's chain (Tomaszewski et al.; Geminard & Vanel): 1.022 m,
    0.0208 kg, 229 links.

    Examples
    --------
    >>> c = Chain()
    >>> round(c.velocity(1.0), 4)   # sqrt(g l) in m/s
    3.1664
    >>> round(c.force(1.0), 6)      # M g in N
    0.204048
    """

    length: float = 1.022
    mass: float = 0.0208
    g: float = 9.81

    def __post_init__(self):
        V.si_scales(self.length, self.mass, self.g)

    def velocity(self, v):
        """Nondimensional speed -> m/s."""
        return v * math.sqrt(self.g * self.length)

    def acceleration(self, a):
        """Nondimensional acceleration -> m/s^2."""
        return a * self.g

    def force(self, sigma):
        """Nondimensional tension -> N (rho g l = M g)."""
        return sigma * self.mass * self.g

    def time(self, t):
        """Nondimensional time -> s."""
        return t * math.sqrt(self.length / self.g)

    def distance(self, x):
        """Nondimensional length -> m."""
        return x * self.length

    def energy(self, e):
        """Nondimensional energy -> J (rho g l^2 = M g l)."""
        return e * self.mass * self.g * self.length


PAPER_CHAIN = Chain()

_SCALE_LABELS = {
    "delta_kappa0": "delta_kappa0 = (pi/2)/kappa_m(0)",
    "delta_c": "delta_c = (1/2)(pi/kappa_m(0))^(4/3)",
    "delta_N": "delta_N = 1/N",
    "delta_kappa_m": "delta_kappa_m (measured on the runs)",
}


#: the computed quantities of a design estimate: key -> (table quantity, SI key, converter name, label)
COMPUTED = {
    "v": ("v_peak", "v_m_per_s", "velocity", "peak speed", "m/s"),
    "a": ("a_peak", "a_m_per_s2", "acceleration", "peak acceleration", "m/s^2"),
    "sigma": ("sigma_peak", "sigma_N", "force", "peak tension", "N"),
    "t_snap": ("t_snap_v", "t_snap_s", "time", "snapping time", "s"),
}


@dataclass
class DesignEstimate:
    """Everything :func:`design_estimate` predicts, nondimensional and SI.

    ``nondim`` holds the geometry (chi, a, kappa_m0, P, t_star); ``scales`` the
    lengths delta; ``predictions[scale]`` the whirling-rod peaks {v, a, sigma};
    ``si`` the same in SI units for ``chain``; ``warnings`` what makes a prediction
    doubtful (a scale delta longer than the chain).

    With the number of links (``links``): ``computed`` the peaks {v, a, sigma, t_snap}
    of the fast exact method for that chain (``computed_source``: "table", interpolated
    in :mod:`snapping.table`, with relative error bounds ``computed_errors``; or
    "simulation", one run), and ``factors[scale][q]`` = prediction / computed peak at
    this point, ``factor_ranges[scale][q]`` = (geometric mean, min, max) of the same
    ratio over the table (tip mass 0): how far each of the paper's estimators is off.
    """

    chain: Chain
    nondim: dict[str, float]
    scales: dict[str, float]
    predictions: dict[str, dict[str, float]]
    si: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    links: int | None = None
    tip_mass: float = 0.0
    computed: dict | None = None
    computed_errors: dict = field(default_factory=dict)
    computed_source: str = ""
    computed_note: str = ""
    factor_span: str = ""
    factors: dict = field(default_factory=dict)
    factor_ranges: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """One JSON-serialisable dict whose keys name the quantities (with units in SI keys)."""
        out = {
            "chain": {"length_m": self.chain.length, "mass_kg": self.chain.mass, "g_m_per_s2": self.chain.g},
            **self.nondim,
            "scales": dict(self.scales),
            "predictions": {k: dict(v) for k, v in self.predictions.items()},
            "si": self.si,
            "warnings": list(self.warnings),
        }
        if self.computed is not None:
            out.update(links=self.links, tip_mass=self.tip_mass, computed=dict(self.computed),
                       computed_errors=dict(self.computed_errors), computed_source=self.computed_source,
                       computed_note=self.computed_note,
                       factors={k: dict(v) for k, v in self.factors.items()},
                       factor_ranges={k: {q: list(r) for q, r in v.items()} for k, v in self.factor_ranges.items()})
        return out


def _chi_of(chain: Chain, chi, separation, curvature) -> float:
    """chi from exactly one of chi, separation [m], curvature [1/m]."""
    given = [name for name, v in (("chi", chi), ("separation", separation), ("curvature", curvature)) if v is not None]
    if len(given) != 1:
        raise V.SnappingInputError(
            f"give exactly one of chi, separation, curvature (got {', '.join(given) or 'none'})"
        )
    if separation is not None:
        sep = V.open_interval("separation", separation, 0.0, chain.length)
        chi = sep / chain.length
        if chi < CHI_MIN:
            raise V.SnappingInputError(f"separation={sep!r} m is out of range: must lie in "
                                       f"[{CHI_MIN * chain.length:.3g}, {chain.length:g}) m for length "
                                       f"{chain.length:g} m (chi >= {CHI_MIN:g})")
    elif curvature is not None:
        kappa = V.positive("curvature", curvature)
        lo, hi = 1.0 / (_A_MAX * chain.length), 1.0 / (_A_MIN * chain.length)
        if not lo <= kappa <= hi:  # curvature so small or large that chi rounds to 1 or leaves [CHI_MIN, 1)
            raise V.SnappingInputError(f"curvature={kappa!r} 1/m is out of range: must lie in [{lo:.3g}, {hi:.3g}] "
                                       f"1/m for length {chain.length:g} m (chi in [{CHI_MIN:g}, 1); a catenary "
                                       f"of unit length has no smaller or larger curvature at its bottom)")
        chi = chi_from_parameter(1.0 / (kappa * chain.length))
    return check_chi(chi)


def check_tip_mass(tip_mass) -> float:
    """A tip-mass ratio (point mass at the free end / chain mass) in [0, 1e6]."""
    r = V.real("tip_mass", tip_mass)
    if not 0.0 <= r <= 1e6:
        raise V.SnappingInputError(f"tip_mass={r!r} is out of range: the ratio of the tip mass to the chain's "
                                   f"mass must lie in [0, 1e6]")
    return r


def design_estimate(
    chain: Chain = PAPER_CHAIN,
    *,
    chi: float | None = None,
    separation: float | None = None,
    curvature: float | None = None,
    N: int | None = None,
    links: int | None = None,
    tip_mass: float = 0.0,
    table=None,
) -> DesignEstimate:
    """Predict the snap of ``chain`` from its initial catenary.

    Give exactly one of ``chi`` (end separation / length), ``separation`` (end
    separation in m) or ``curvature`` (initial maximum curvature in 1/m).

    With ``links`` (the chain's number of links, and optionally ``tip_mass``, a point
    mass at the free end as a ratio to the chain's mass) the estimate leads with the
    computed peaks: those of the fast exact method interpolated from the shipped table
    of simulations (:mod:`snapping.table`), with their error bounds (raises
    :class:`snapping.table.OutsideTable`, naming the input and the range, outside it;
    ``snapping.design.simulate_estimate`` runs such a case instead). ``table``: another
    table file. This is always the table's answer, whatever its bound: ``snapping estimate
    --links`` answers instead with ``snapping.design.computed_estimate``, which runs the
    chain where the bound is above 1% (speed, tension) or 3% (acceleration) and a run is
    cheap, so the two can differ (the command's ``--table`` gives this function's answer).

    The paper's estimators follow in any case: the scales delta_kappa0 and delta_c
    (and delta_N = 1/N if ``N`` or ``links`` is given, and delta_kappa_m as measured on
    the table's runs with ``links``) each give the whirling-rod peaks of the paper's
    eq. (estimates), v = (6P/delta)^(1/2), a = v^2/delta, sigma = v^2/2, which are
    also converted to SI together with the ideal snapping time t* sqrt(l/g). With
    ``links`` each comes with its error factor (prediction / computed peak) here and
    over the table. The estimators take no tip mass into account.

    Examples
    --------
    >>> est = design_estimate(Chain(length=1.022, mass=0.0208), chi=0.25)
    >>> round(est.si["t_star_s"], 4)   # 2E(pi/4|2) sqrt(l/g) in s
    0.3867
    >>> est = design_estimate(Chain(), chi=0.25, links=229)      # the paper's chain
    >>> round(est.si["computed"]["v_m_per_s"], 1), est.computed_errors["v"] < 0.02
    (26.2, True)
    """
    if not isinstance(chain, Chain):
        raise V.SnappingInputError(f"chain={chain!r} is not a snapping.estimates.Chain")
    chi = _chi_of(chain, chi, separation, curvature)
    if N is not None:
        N = V.integer("N", N, 1)
        delta_N(N)
    tip_mass = check_tip_mass(tip_mass)
    if links is not None:
        links = V.integer("links", links, 1)
        delta_N(links)
        if N is not None and N != links:
            raise V.SnappingInputError(f"N={N} and links={links} disagree: give the number of links once")
        N = links
    elif tip_mass:
        raise V.SnappingInputError(f"tip_mass={tip_mass:g} needs links (the number of links): the estimate with "
                                   f"a tip mass is the computed one")
    peaks = None
    if links is not None:
        from .. import table as T

        tab = T.load_table(table)
        try:
            tab.check(chi, links, tip_mass)
        except T.OutsideTable as exc:
            lo, hi = tab.ranges["chi"]
            if separation is not None and str(exc).startswith("chi="):
                raise T.OutsideTable(f"separation={separation:g} m (chi = {chi:.3g}) is outside the table of computed "
                                     f"snaps: it covers separations in [{lo * chain.length:.3g}, "
                                     f"{hi * chain.length:.3g}] m for length {chain.length:g} m (chi in [{lo:g}, "
                                     f"{hi:g}])") from None
            if curvature is not None and str(exc).startswith("chi="):
                k_hi, k_lo = (1.0 / (catenary_parameter(c) * chain.length) for c in (lo, hi))
                raise T.OutsideTable(f"curvature={curvature:g} 1/m (chi = {chi:.3g}) is outside the table of "
                                     f"computed snaps: it covers curvatures in [{k_lo:.3g}, {k_hi:.3g}] 1/m for "
                                     f"length {chain.length:g} m (chi in [{lo:g}, {hi:g}])") from None
            raise
        peaks = tab.lookup(chi, links, tip_mass)
    est = _estimate(chain, chi, N)
    if peaks is not None:
        v = peaks.values
        attach_computed(est, {"v": v["v_peak"], "a": v["a_peak"], "sigma": v["sigma_peak"], "t_snap": v["t_snap_v"],
                              "delta_kappa_m": v["delta_kappa_m"]},
                        {"v": peaks.errors["v_peak"], "a": peaks.errors["a_peak"],
                         "sigma": peaks.errors["sigma_peak"], "t_snap": peaks.errors["t_snap_v"]},
                        source="table", links=links, tip_mass=tip_mass, table=table)
    return est


def _estimate(chain: Chain, chi: float, N: int | None) -> DesignEstimate:
    """The paper's estimators for the catenary chi (and delta_N with N)."""
    a = catenary_parameter(chi)
    P = available_energy(chi)
    t_star = _t_star()
    nondim = {"chi": chi, "a": a, "kappa_m0": 1.0 / a, "P": P, "t_star": t_star}
    scales = {"delta_kappa0": delta_kappa0(chi), "delta_c": delta_crude(chi)}
    if N is not None:
        scales["delta_N"] = delta_N(N)
    est = DesignEstimate(chain=chain, nondim=nondim, scales=scales, predictions={})
    _predict(est)
    return est


def _predict(est: DesignEstimate) -> None:
    """The whirling-rod predictions of every scale, their SI values and the warnings."""
    chain, P = est.chain, est.nondim["P"]
    est.predictions = {name: whirling_rod(P, d) for name, d in est.scales.items()}
    est.warnings = [f"{name} = {d:.3g} is longer than the chain (length 1): the whirling-rod estimate needs a "
                    f"regularising length much shorter than the chain, so its predicted peaks are not meaningful"
                    for name, d in est.scales.items() if d > 1.0]
    est.si.update({
        "separation_m": chain.distance(est.nondim["chi"]),
        "kappa_m0_per_m": 1.0 / chain.distance(est.nondim["a"]),
        "P_J": chain.energy(P),
        "t_star_s": chain.time(est.nondim["t_star"]),
        "scales_m": {name: chain.distance(d) for name, d in est.scales.items()},
        "predictions": {
            name: {
                "v_m_per_s": chain.velocity(p["v"]),
                "a_m_per_s2": chain.acceleration(p["a"]),
                "sigma_N": chain.force(p["sigma"]),
            }
            for name, p in est.predictions.items()
        },
    })


def attach_computed(est: DesignEstimate, computed: dict, errors: dict, *, source: str, links: int,
                    tip_mass: float = 0.0, table=None) -> DesignEstimate:
    """Lead ``est`` with computed peaks (nondimensional ``computed``: v, a, sigma, t_snap,
    and optionally delta_kappa_m; relative ``errors``): their SI values, the
    delta_kappa_m prediction, and every estimator's error factor here and over the table."""
    est.links, est.tip_mass = int(links), float(tip_mass)
    est.computed = {k: float(v) for k, v in computed.items()}
    est.computed_errors = {k: float(v) for k, v in errors.items()}
    est.computed_source = source
    est.scales.setdefault("delta_N", delta_N(links))
    dkm = est.computed.get("delta_kappa_m", float("nan"))
    if math.isfinite(dkm) and dkm > 0:
        est.scales["delta_kappa_m"] = dkm
    _predict(est)
    chain = est.chain
    est.si["computed"] = {si: getattr(chain, conv)(est.computed[k]) for k, (_, si, conv, _l, _u) in COMPUTED.items()}
    est.factors = {name: {q: p[q] / est.computed[q] for q in ("v", "a", "sigma")}
                   for name, p in est.predictions.items()}
    from .. import table as T

    try:
        est.factor_ranges = estimator_factors(links, tip_mass, table)
        lo, hi = T.load_table(table).ranges["chi"]
        est.factor_span = f"{lo:g} to {hi:g}"
    except (T.OutsideTable, OSError):  # a simulated chain outside the table: no ranges
        est.factor_ranges = {}
    if tip_mass:
        est.warnings.append(f"the paper's estimators take no tip mass into account (tip mass {tip_mass:g} of the "
                            f"chain's mass): their error factors below say how far off that makes them")
    wide = {k: e for k, e in est.computed_errors.items() if e > T.BOUND_TRUST}
    if source == "table" and links <= T.FEW_LINKS:
        est.computed_note = (f"a chain of {links} links snaps erratically from one separation to the next: the "
                             f"table's peaks and bounds are not reliable for it; run it (snapping.design."
                             f"computed_estimate or simulate_estimate, snapping estimate without --table)")
    elif wide and source == "table":
        est.computed_note = (f"the table's bound here ({', '.join(f'{k} +-{100 * e:.2g}%' for k, e in wide.items())})"
                             f" is above {100 * T.BOUND_TRUST:g}%: the snap changes character near this point and "
                             f"the bound itself may fail; run it (snapping.design.simulate_estimate, snapping "
                             f"estimate --simulate)")
    return est


def estimator_factors(links: int, tip_mass: float = 0.0, table=None) -> dict:
    """(geometric mean, min, max), over the table's separations chi for a chain of ``links``
    links and ``tip_mass``, of the ratio of each of the paper's estimators' whirling-rod
    peak to the computed one, for v, a and sigma: ``{scale: {q: (mean, lo, hi)}}`` (scales
    delta_kappa0, delta_c, delta_N and delta_kappa_m, the last as measured on the runs).
    How far off each estimator is for this chain, whatever its separation."""
    from .. import table as T

    tab = T.load_table(table)
    chis = [float(c) for c in tab.chi]
    values, _ = tab.evaluate(np.array(chis), links, tip_mass)
    P = np.array([available_energy(c) for c in chis])
    scales = {"delta_kappa0": np.array([delta_kappa0(c) for c in chis]),
              "delta_c": np.array([delta_crude(c) for c in chis]),
              "delta_N": np.full(len(chis), 1.0 / links),
              "delta_kappa_m": values["delta_kappa_m"]}
    out = {}
    with np.errstate(invalid="ignore", divide="ignore"):
        for s, d in scales.items():
            v = np.sqrt(6.0 * P / d)  # the whirling rod (whirling_rod), at every chi at once
            pred = {"v": v, "a": v * v / d, "sigma": 0.5 * v * v}
            out[s] = {}
            for q, var in (("v", "v_peak"), ("a", "a_peak"), ("sigma", "sigma_peak")):
                r = pred[q] / values[var]
                r = r[np.isfinite(r) & (r > 0)]
                if r.size:
                    out[s][q] = (float(np.exp(np.mean(np.log(r)))), float(r.min()), float(r.max()))
    return out


def _pct(e: float) -> str:
    return "-" if not math.isfinite(e) else f"+-{100 * e:.2g}%"


def print_estimate(est: DesignEstimate, file=None) -> None:
    """Print a :class:`DesignEstimate` as a readable table (what ``snapping estimate`` shows)."""
    import sys

    out = file or sys.stdout
    c, nd, si = est.chain, est.nondim, est.si

    def line(s=""):
        print(s, file=out)

    line(f"Snap estimate for a catenary with chi = {nd['chi']:.6g}")
    chain = f"chain: length {c.length:g} m, mass {c.mass:g} kg, g {c.g:g} m/s^2"
    if est.computed is not None:
        chain += f", {est.links} links" + (f", tip mass {est.tip_mass:g} x the chain's" if est.tip_mass else "")
    line(chain)
    line()
    if est.computed is not None:
        how = ("interpolated from the table of fast exact runs (snapping.table), error bound from held-out grid "
               "points" if est.computed_source == "table" else "one run of the fast exact method, tol 1e-6")
        line(f"Computed peaks: {how}")
        line(f"  {'quantity':<20} {'SI':>12} {'':<6} {'error':>9} {'nondimensional':>15}")
        for k, (_, sik, _conv, label, unit) in COMPUTED.items():
            line(f"  {label:<20} {si['computed'][sik]:>12.4g} {unit:<6} {_pct(est.computed_errors.get(k, math.nan)):>9} "
                 f"{est.computed[k]:>15.5g}")
        if est.computed_note:
            line(f"  note: {est.computed_note}")
        line()
    line(f"  {'quantity':<34} {'nondimensional':>15} {'SI':>15}")
    rows = [
        ("end separation chi", nd["chi"], si["separation_m"], "m"),
        ("catenary parameter a", nd["a"], c.distance(nd["a"]), "m"),
        ("initial max curvature kappa_m(0)", nd["kappa_m0"], si["kappa_m0_per_m"], "1/m"),
        ("available energy P", nd["P"], si["P_J"], "J"),
        ("ideal snapping time t*", nd["t_star"], si["t_star_s"], "s"),
    ]
    for name, d in est.scales.items():
        rows.append((_SCALE_LABELS[name], d, si["scales_m"][name], "m"))
    for name, nd_v, si_v, unit in rows:
        line(f"  {name:<34} {nd_v:>15.6g} {si_v:>15.6g} {unit}")
    line()
    line("The paper's estimators (whirling rod, eq. estimates: v = (6P/delta)^1/2, a = v^2/delta, sigma = v^2/2)")
    line(f"  {'scale':<14} {'v':>10} {'a':>12} {'sigma':>10} | {'v [m/s]':>10} {'a [m/s^2]':>12} {'sigma [N]':>10}")
    for name, p in est.predictions.items():
        q = si["predictions"][name]
        line(
            f"  {name:<14} {p['v']:>10.4g} {p['a']:>12.4g} {p['sigma']:>10.4g} | "
            f"{q['v_m_per_s']:>10.4g} {q['a_m_per_s2']:>12.4g} {q['sigma_N']:>10.4g}"
        )
    for w in est.warnings:
        line(f"  warning: {w}")
    line()
    if est.computed is None:
        line("Against simulations (paper Fig. 4; snapping reproduce): delta_kappa0 underestimates the peak")
        line("acceleration by one to two orders of magnitude; delta_c, from the initial geometry alone, is")
        line("within an order of magnitude; delta_kappa_m (needs a run: snapping fit) is the most accurate.")
        line("Give --links N (the chain's number of links) for the computed peaks.")
        return
    line(f"Error factors: estimate / computed peak, here and (geometric mean [min, max]) over the table's "
         f"separations chi {est.factor_span} for this chain")
    line(f"  {'scale':<14} {'v here':>8} {'a here':>9} {'sigma here':>10} | {'v over chi':>24} "
         f"{'a over chi':>24} {'sigma over chi':>24}")
    for name, f in est.factors.items():
        rng = est.factor_ranges.get(name, {})
        cells = [f"{r[0]:.2g} [{r[1]:.2g}, {r[2]:.2g}]" if r else "-" for r in (rng.get(q) for q in ("v", "a", "sigma"))]
        line(f"  {name:<14} {f['v']:>8.3g} {f['a']:>9.3g} {f['sigma']:>10.3g} | {cells[0]:>24} {cells[1]:>24} "
             f"{cells[2]:>24}")
