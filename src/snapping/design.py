"""Inverse design: the end separations (and tip masses) that keep the snap's peaks under limits.

An engineer has a chain or tether (length, mass, number of links) and limits: the
tension its attachment takes, the speed or acceleration its payload may see. The
peaks of the snap against the end separation chi come from the shipped table of
fast exact runs (:mod:`snapping.table`, interpolated with an error bound);
:func:`design` finds the separations whose peaks stay under every limit, for the
given tip mass or for every tip mass of the table. A separation is *admissible*
when the computed peak plus its error bound is under the limit (``nominal``: the
computed peak alone); where the bound is above :data:`BOUND_TRUST` (the snap changes
character near there) a separation is neither. Chains of at most :data:`FEW_LINKS`
links, whose peaks jump from one separation to the next, are run instead
(:data:`N_SCAN_RUNS` runs of the fast method per tip mass; a separation between two runs
is admissible only if both are). :func:`simulate_estimate` computes one case with the
fast method (a point outside the table, or a check); :func:`computed_estimate` chooses
between the table and a run (:func:`run_instead`).

>>> from snapping.estimates import Chain
>>> res = design(Chain(length=2.0, mass=0.05), links=100, max_tension=20.0, tip_mass=0.0)
>>> lo, hi = res.rows[0].admissible[0]
>>> round(lo * 2.0, 2), hi                  # from 0.36 m apart (chi 0.18) to the table's widest
(0.36, 0.9)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import _validate as V
from . import table as T
from .estimates import Chain, DesignEstimate, attach_computed, check_tip_mass, design_estimate

__all__ = ["LIMITS", "DesignRow", "DesignResult", "NoAdmissibleSeparation", "design", "print_design",
           "plot_design", "simulate_estimate", "computed_estimate", "run_instead", "TARGETS", "MAX_SECONDS",
           "FEW_LINKS"]

#: the accuracy a computed estimate should have (relative): above it, a cheap run replaces the table
TARGETS = {"v": 0.01, "a": 0.03, "sigma": 0.01}
#: the longest run (CPU seconds, as the table measured its neighbours) that replaces the table by itself
MAX_SECONDS = 10.0
#: chains of at most this many links are always run (their peaks jump with chi between the table's
#: points, where the leave-one-out bound cannot see it; a run costs milliseconds)
FEW_LINKS = T.FEW_LINKS

#: the limits: keyword -> (table quantity, Chain converter, unit, what)
LIMITS = {
    "max_tension": ("sigma_peak", "force", "N", "tension"),
    "max_speed": ("v_peak", "velocity", "m/s", "speed"),
    "max_acceleration": ("a_peak", "acceleration", "m/s^2", "acceleration"),
}

#: points of the chi scan (log-spaced over the table's range; boundaries interpolated between them)
N_SCAN = 2000


class NoAdmissibleSeparation(V.SnappingInputError):
    """No separation (and tip mass) of the table keeps the peaks under the limits."""


@dataclass
class DesignRow:
    """The admissible separations for one tip mass: lists of (chi_lo, chi_hi) intervals,
    with the error bound (``admissible``) and without (``nominal``), and per limit the
    smallest peak over the table's chi range (SI) and where it is."""

    tip_mass: float
    admissible: list = field(default_factory=list)
    nominal: list = field(default_factory=list)
    minimum: dict = field(default_factory=dict)


@dataclass
class DesignResult:
    """What :func:`design` found: the chain, links, limits (SI, by keyword), one
    :class:`DesignRow` per tip mass, and the scanned curves for :func:`plot_design`
    (``curves[tip][keyword] = (chi, peak in SI, relative error bound)``)."""

    chain: Chain
    links: int
    limits: dict
    rows: list
    curves: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    source: str = "table"

    def to_dict(self) -> dict:
        L = self.chain.length
        return {
            "chain": {"length_m": L, "mass_kg": self.chain.mass, "g_m_per_s2": self.chain.g},
            "links": self.links, "limits": dict(self.limits), "source": self.source, "notes": list(self.notes),
            "rows": [{"tip_mass": r.tip_mass,
                      "admissible_chi": [list(i) for i in r.admissible],
                      "admissible_separation_m": [[a * L, b * L] for a, b in r.admissible],
                      "nominal_chi": [list(i) for i in r.nominal],
                      "nominal_separation_m": [[a * L, b * L] for a, b in r.nominal],
                      "minimum": {k: {**{a: b for a, b in m.items() if a != "upper"}, "separation_m": m["chi"] * L}
                                  for k, m in r.minimum.items()}}
                     for r in self.rows],
        }


def _intervals(chi: np.ndarray, g: np.ndarray) -> list:
    """The chi intervals where g <= 0 (g sampled on ``chi``), their ends interpolated linearly
    in log chi between the samples around each sign change."""
    ok = g <= 0.0
    out = []
    n = chi.size

    def edge(i, j):  # g(chi[i]) <= 0 < g(chi[j]) (neighbours)
        f = g[i] / (g[i] - g[j])
        return float(math.exp(math.log(chi[i]) + f * (math.log(chi[j]) - math.log(chi[i]))))

    i = 0
    while i < n:
        if not ok[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and ok[j + 1]:
            j += 1
        lo = float(chi[i]) if i == 0 else edge(i, i - 1)
        hi = float(chi[j]) if j == n - 1 else edge(j, j + 1)
        out.append((lo, hi))
        i = j + 1
    return out


#: points of the chi scan of a few-link chain (one run each)
N_SCAN_RUNS = 200
#: above this relative bound a table point is unknown (not admissible, not nominal)
BOUND_TRUST = T.BOUND_TRUST


def _scan_runs(chi: np.ndarray, links: int, tip: float):
    """The peaks of one fast run at every chi (values, errors 0: the method's tolerance)."""
    from tqdm.auto import tqdm

    from .table.build import run_point

    keys = ("v_peak", "a_peak", "sigma_peak", "t_snap_v")
    out = {q: np.full(chi.size, np.nan) for q in keys}
    for i, c in enumerate(tqdm(chi, desc=f"runs ({links} links, tip mass {tip:g})", unit="run", leave=False,
                               disable=None)):
        d = run_point(float(c), links, tip)
        if d["status"] == "completed" and d.get("snap_reached"):
            for q in keys:
                out[q][i] = d[q]
    errors = {q: np.where(np.isfinite(out[q]), 0.0, np.inf) for q in keys}
    return out, errors


def _both_neighbours(g: np.ndarray) -> np.ndarray:
    """g on the midpoints' terms: a sample counts as meeting the limit (g <= 0) only if it and
    both its neighbours do, so an interval never reaches past the last sampled run that met it."""
    out = g.copy()
    out[1:] = np.maximum(out[1:], g[:-1])
    out[:-1] = np.maximum(out[:-1], g[1:])
    return out


def design(chain: Chain, links: int, *, max_tension: float | None = None, max_speed: float | None = None,
           max_acceleration: float | None = None, tip_mass: float | None = None, table=None) -> DesignResult:
    """The end separations (as chi = separation / length) that keep every given peak
    under its limit (SI: N, m/s, m/s^2) for ``chain`` with ``links`` links, for the given
    ``tip_mass`` (ratio to the chain's mass) or, when None, for every tip mass of the
    table (only 0 when ``links`` is above its ``n_tip_max``).

    Raises :class:`NoAdmissibleSeparation` (naming the smallest peak reachable, and
    where) when no separation of the table's range meets the limits, and
    :class:`snapping.table.OutsideTable` for links or a tip mass outside the table.
    """
    if not isinstance(chain, Chain):
        raise V.SnappingInputError(f"chain={chain!r} is not a snapping.estimates.Chain")
    limits = {k: V.positive(k, v) for k, v in (("max_tension", max_tension), ("max_speed", max_speed),
                                               ("max_acceleration", max_acceleration)) if v is not None}
    if not limits:
        raise V.SnappingInputError("give at least one limit: max_tension= [N], max_speed= [m/s] or "
                                   "max_acceleration= [m/s^2]")
    links = V.integer("links", links, 1)
    tab = T.load_table(table)
    r = tab.ranges
    notes = []
    if tip_mass is None:
        tips = [float(t) for t in tab.tip] if links <= tab.n_tip_max else [0.0]
        if links > tab.n_tip_max:
            notes.append(f"the table has tip masses only up to {tab.n_tip_max} links: tip mass 0 alone")
    else:
        tips = [check_tip_mass(tip_mass)]
    tab.check(r["chi"][0], links, tips[-1])
    few = links <= FEW_LINKS
    chi = np.geomspace(r["chi"][0], r["chi"][1], N_SCAN_RUNS if few else N_SCAN)
    if few:
        notes.append(f"a chain of {links} links snaps erratically from one separation to the next: the peaks are "
                     f"those of {chi.size} runs of the fast method per tip mass (not the table), and a separation "
                     f"between two runs is admissible only if both are")
    rows, curves = [], {}
    for tip in tips:
        values, errors = _scan_runs(chi, links, tip) if few else tab.evaluate(chi, links, tip)
        # a bound above BOUND_TRUST is no bound (the snap changes character near there): never admissible
        errors = {q: np.where(e <= BOUND_TRUST, e, np.inf) for q, e in errors.items()}
        curves[tip] = {}
        ratio = {True: [], False: []}
        row = DesignRow(tip_mass=tip)
        for key, lim in limits.items():
            q, conv, _, _ = LIMITS[key]
            si, e = getattr(chain, conv)(values[q]), errors[q]
            curves[tip][key] = (chi, si, e)
            with np.errstate(over="ignore"):  # (a limit of 5e-324 N: every peak is infinitely over it)
                ratio[True].append(si * (1.0 + e) / lim - 1.0)
                ratio[False].append(si / lim - 1.0)
            upper = np.where(np.isfinite(si), si * (1.0 + e), np.inf)  # (inf: no run, or no bound)
            i = int(np.argmin(upper)) if np.isfinite(upper).any() else int(np.nanargmin(si))
            row.minimum[key] = {"peak": float(si[i]), "error": float(e[i]), "chi": float(chi[i]),
                                "upper": float(upper[i])}
        g_bound = np.max(ratio[True], axis=0)
        g_nominal = np.where(np.isfinite(g_bound), np.max(ratio[False], axis=0), np.inf)
        if few:  # between two runs, only if both meet the limits (no interpolation of an erratic peak)
            g_bound = _both_neighbours(g_bound)
            g_nominal = _both_neighbours(g_nominal)
        row.admissible = _intervals(chi, g_bound)
        row.nominal = _intervals(chi, g_nominal)
        rows.append(row)
    if not any(row.admissible for row in rows):
        span = f"{links} links, separations {r['chi'][0] * chain.length:.3g} to {r['chi'][1] * chain.length:.3g} m"

        def smallest(key):  # the smallest bounded peak of one quantity over chi and the tip masses, and where
            best = min(rows, key=lambda row: (row.minimum[key]["upper"], row.minimum[key]["peak"]))
            m = best.minimum[key]
            tip_txt = f", tip mass {best.tip_mass:g}" if best.tip_mass or len(tips) > 1 else ""
            return m, (f"the minimum is {m['peak']:.4g} {LIMITS[key][2]} ({_pct(m['error'])}) at separation "
                       f"{m['chi'] * chain.length:.3g} m (chi = {m['chi']:.3g}{tip_txt})")

        alone = [k for k in limits if smallest(k)[0]["upper"] > limits[k]]
        if alone:  # a limit that no separation meets by itself
            key = alone[0]
            raise NoAdmissibleSeparation(
                f"{key}={limits[key]:g} {LIMITS[key][2]}: no separation keeps the {LIMITS[key][3]} under it for this "
                f"chain ({span}): {smallest(key)[1]}")
        given = " and ".join(f"{k}={v:g} {LIMITS[k][2]}" for k, v in limits.items())
        raise NoAdmissibleSeparation(f"{given}: each is met at some separation, but no separation meets them all "
                                     f"for this chain ({span}); " + "; ".join(
                                         f"{LIMITS[k][3]}: {smallest(k)[1]}" for k in limits))
    return DesignResult(chain=chain, links=links, limits=limits, rows=rows, curves=curves, notes=notes,
                        source="runs" if few else "table")


def _pct(e: float) -> str:
    return "no bound" if not math.isfinite(e) else ("exact" if e == 0 else f"+-{100 * e:.2g}%")


def _fmt_intervals(iv: list, L: float, span=None, what: str = "the table's range") -> str:
    """The intervals in m and chi; an end that is an end of the scanned ``span`` (chi_lo, chi_hi)
    is said to be one: the separations beyond it were not computed (it is no limit of the chain)."""
    if not iv:
        return "none"
    text = ", ".join(f"{a * L:.3g}-{b * L:.3g} m (chi {a:.3g}-{b:.3g})" for a, b in iv)
    if span is not None:
        ends = [f"{x * L:.3g} m" for x, e in ((iv[0][0], span[0]), (iv[-1][1], span[1]))
                if math.isclose(x, e, rel_tol=1e-9)]
        if ends:
            text += (f" [{' and '.join(ends)}: {'the end' if len(ends) == 1 else 'the ends'} of {what}, "
                     f"not {'a limit' if len(ends) == 1 else 'limits'} of the chain]")
    return text


def _span(res, tip) -> tuple | None:
    """The (smallest, largest) chi scanned for tip mass ``tip`` (None if unknown)."""
    for chi, *_ in res.curves.get(tip, {}).values():
        chi = np.asarray(chi, float)
        if chi.size:
            return float(chi.min()), float(chi.max())
    return None


def print_design(res: DesignResult, file=None) -> None:
    """Print a :class:`DesignResult` (what ``snapping design`` shows)."""
    import sys

    out = file or sys.stdout
    c = res.chain
    lim = ", ".join(f"{LIMITS[k][3]} <= {v:g} {LIMITS[k][2]}" for k, v in res.limits.items())
    print(f"Separations that keep the snap's peaks under the limits ({lim})", file=out)
    where = "runs of the fast method" if res.source == "runs" else "the table of fast exact runs (snapping.table)"
    print(f"chain: length {c.length:g} m, mass {c.mass:g} kg, g {c.g:g} m/s^2, {res.links} links; peaks from "
          f"{where}", file=out)
    print("admissible: computed peak + its error bound under every limit; nominal: the computed peak alone "
          f"(neither where the bound is above {100 * BOUND_TRUST:g}%: the snap changes character there)", file=out)
    for n in res.notes:
        print(f"note: {n}", file=out)
    print(file=out)
    for row in res.rows:
        print(f"  tip mass {row.tip_mass:g} x the chain's mass:", file=out)
        span, what = _span(res, row.tip_mass), "the runs' range" if res.source == "runs" else "the table's range"
        print(f"    admissible: {_fmt_intervals(row.admissible, c.length, span, what)}", file=out)
        print(f"    nominal:    {_fmt_intervals(row.nominal, c.length, span, what)}", file=out)
        for k, m in row.minimum.items():
            print(f"    smallest {LIMITS[k][3]}: {m['peak']:.4g} {LIMITS[k][2]} ({_pct(m['error'])}) at "
                  f"{m['chi'] * c.length:.3g} m", file=out)


def plot_design(res: DesignResult, path=None, *, overwrite: bool = False):
    """The peaks against the separation (one panel per limit, one curve per tip mass,
    the error band shaded), the limit, and the admissible separations; saved to
    ``path`` if given. Returns the figure."""
    import matplotlib

    if path is not None:
        from ._files import check_output

        check_output(path, name="plot", overwrite=overwrite)
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    keys = list(res.limits)
    fig, axes = plt.subplots(1, len(keys), figsize=(5.2 * len(keys), 4.2), squeeze=False)
    L = res.chain.length
    cmap = plt.get_cmap("viridis")
    tips = list(res.curves)
    for ax, key in zip(axes[0], keys):
        for n, tip in enumerate(tips):
            chi, si, e = res.curves[tip][key]
            color = cmap(n / max(len(tips) - 1, 1))
            ax.plot(chi * L, si, color=color, label=f"tip mass {tip:g}" if len(tips) > 1 else "computed peak")
            band = np.isfinite(e)
            ax.fill_between(chi * L, si / (1 + e), si * (1 + e), where=band, color=color, alpha=0.2, lw=0)
        ax.axhline(res.limits[key], color="C3", ls="--", label=f"limit {res.limits[key]:g} {LIMITS[key][2]}")
        if len(tips) == 1:
            for a, b in res.rows[0].admissible:
                ax.axvspan(a * L, b * L, color="C2", alpha=0.12, label="admissible")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("end separation [m]")
        ax.set_ylabel(f"peak {LIMITS[key][3]} [{LIMITS[key][2]}]")
        ax.legend(fontsize=6, ncol=2 if len(tips) > 4 else 1)
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"{res.links}-link chain, {L:g} m, {res.chain.mass:g} kg: peaks of the snap (table of fast runs)",
                 fontsize=10)
    fig.tight_layout()
    if path is not None:
        from ._files import save_figure

        save_figure(fig, path, overwrite=overwrite)
    return fig


def simulate_estimate(chain: Chain, *, chi: float | None = None, separation: float | None = None,
                      curvature: float | None = None, links: int, tip_mass: float = 0.0,
                      progress: bool | None = None) -> DesignEstimate:
    """The design estimate of :func:`snapping.estimates.design_estimate`, led by one run of
    the fast exact method for this chain (links, tip mass) instead of the table: for a
    point outside the table, or to check it."""
    from .table.build import peaks_of_run, run_case

    est = design_estimate(chain, chi=chi, separation=separation, curvature=curvature, N=links)
    links = V.integer("links", links, 1)
    tip_mass = check_tip_mass(tip_mass)
    chi = est.nondim["chi"]
    ds = run_case(chi, links, tip_mass, progress=progress).dataset
    if not int(ds.attrs["snap_reached"]):
        raise V.SnappingInputError(f"the run for chi={chi:g}, links={links} did not reach the snap: "
                                   f"{ds.attrs['snap_note']}")
    p = peaks_of_run(ds)
    computed = {"v": p["v_peak"], "a": p["a_peak"], "sigma": p["sigma_peak"], "t_snap": p["t_snap_v"],
                "delta_kappa_m": p["delta_kappa_m"]}
    return attach_computed(est, computed, {k: float("nan") for k in ("v", "a", "sigma", "t_snap")},
                           source="simulation", links=links, tip_mass=tip_mass)


def run_instead(chi: float, links: int, tip_mass: float, errors: dict, *,
                max_seconds: float = MAX_SECONDS) -> tuple[bool, str]:
    """Whether a run of the fast method should replace the table's peaks at this point
    (``errors``: the table's relative bounds by v, a, sigma): ``(run, why)``. A run replaces
    them for chains of at most :data:`FEW_LINKS` links, and where a bound is above
    :data:`TARGETS` and the table says such a run costs at most ``max_seconds``; ``why`` is
    empty when the table's peaks meet the targets."""
    max_seconds = V.nonnegative("max_seconds", max_seconds)
    over = {q: e for q, e in errors.items() if q in TARGETS and not e <= TARGETS[q]}
    few = links <= FEW_LINKS
    if not over and not few:
        return False, ""
    cost = float(T.load_table().values("cpu_s", chi, links, tip_mass))
    bound = ", ".join(f"{q} +-{100 * e:.2g}%" for q, e in over.items())
    target = "the target (1% speed and tension, 3% acceleration)"
    if cost <= max_seconds:
        reason = (f"a chain of {links} links snaps erratically between the table's separations" if few else
                  f"the table's error bound here ({bound}) is above {target}")
        return True, f"{reason}: the peaks are those of one run of the fast method (about {cost:.2g} CPU s)"
    if not over:
        return False, ""
    return False, (f"the table's error bound here ({bound}) is above {target}; one run of the fast method "
                   f"(simulate_estimate, snapping estimate --simulate) would take about {cost:.3g} CPU s")


def computed_estimate(chain: Chain, *, chi: float | None = None, separation: float | None = None,
                      curvature: float | None = None, links: int, tip_mass: float = 0.0,
                      max_seconds: float = MAX_SECONDS, progress: bool | None = None) -> DesignEstimate:
    """The most accurate design estimate within ``max_seconds``: the table's interpolated peaks
    (:func:`snapping.estimates.design_estimate` with ``links``) when their error bounds meet
    :data:`TARGETS` (1% speed and tension, 3% acceleration), else one run of the fast method
    (:func:`simulate_estimate`) when the table says such a run costs at most ``max_seconds``
    (heavy tip masses, whose peaks jump between the table's points, cost a second or so), and
    always for chains of at most :data:`FEW_LINKS` links (milliseconds); else the table's
    answer, with ``computed_note`` naming its bound (:func:`run_instead` decides). Outside
    the table: :class:`snapping.table.OutsideTable` (``simulate_estimate`` runs it).

    This is what ``snapping estimate --links`` prints; ``design_estimate(..., links=...)``
    is the table's answer alone (``snapping estimate --table``), so where the table's bound
    misses the targets the two differ: one run's peaks here, the interpolated ones there."""
    max_seconds = V.nonnegative("max_seconds", max_seconds)
    est = design_estimate(chain, chi=chi, separation=separation, curvature=curvature, links=links,
                          tip_mass=tip_mass)
    run, why = run_instead(est.nondim["chi"], est.links, est.tip_mass, est.computed_errors, max_seconds=max_seconds)
    if run:
        est = simulate_estimate(chain, chi=est.nondim["chi"], links=est.links, tip_mass=est.tip_mass,
                                progress=progress)
    if why:
        est.computed_note = why
    return est
