"""Reproduce the paper with one call: the runs, every computed figure and REPORT.md.

``reproduce(out_dir, mode="quick"|"full")`` runs (through :mod:`snapping.sweep`,
so in parallel, atomically saved and resumable) every simulation the paper's
quantitative claims and figures need, redraws Fig. 1(b)-(e), Fig. 2(a)-(d),
Fig. 3 and Fig. 4 as PNG and PDF, and writes ``REPORT.md``: one row per claim
with the value measured here, the paper's statement and a verdict.

``quick`` does it all at small N in under two minutes on two cores (40 MB written);
``full`` is the paper's resolution (N = 2000 and 5000; about 30 minutes on two cores).

Example
-------
>>> from snapping.reproduce import PLANS
>>> PLANS["full"].scaling_N
5000
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import _validate as V
from . import figures, ideal, sweep
from .estimates import PAPER_CHAIN
from .reproduce_verdicts import (_boundary_layer_links, _fmt, _pm, _snap_duration, amplification_verdict,
                                 boundary_layer_verdict, changed_digit, delta_verdict, monotone_verdict,
                                 spread_verdict, tolerance_verdict, TOL_DIGITS)

__all__ = ["Plan", "PLANS", "reproduce", "expected_seconds"]


@dataclass(frozen=True)
class Plan:
    """Which runs a reproduction makes (everything else follows from them)."""

    name: str
    shapes_chi: tuple = (0.75, 0.5, 0.25)
    shapes_N: int = 2000
    speed_chi: tuple = (0.05, 0.1, 0.25)
    speed_N: tuple = (500, 1000, 2000, 5000)
    scaling_chi: tuple = (0.1, 0.15, 0.2, 0.25, 0.3, 0.4)
    scaling_N: int = 5000
    tol_chi: float = 0.25
    tol_N: int = 5000
    tols: tuple = (1e-7, 1e-8, 1e-9)
    tol: float = 1e-8
    #: the continuum limit (snapping.continuum.converge): chi, levels, index of the coarsest level
    continuum_chi: tuple = (0.05, 0.1, 0.15, 0.25, 0.4)
    continuum_levels: int = 5
    continuum_first: int = -1
    #: thinning of the per-step record (simulate.run's record_thin; 0: every step). The
    #: peaks, snapping times and snapshots are tracked densely regardless; 1e-3 moves the
    #: fitted exponents by ~1e-6 and writes ~8x less.
    record_thin: float = 0.0
    #: the paper's method and chain, given explicitly (the library's defaults are the fast
    #: exact method with exact chords): Euler-Richardson from nodes at equal arclength
    method: str = "euler-richardson"
    chords: str = "arclength"
    #: beyond the paper, the planar snap's stability (snapping.spatial.stability): chi, N
    #: (doubling), the amplitude eps, and (chi, N) and the eps of the linearity check
    stability_chi: tuple = (0.1, 0.25, 0.5)
    stability_N: tuple = (100, 200, 400, 800)
    stability_eps: float = 1e-6
    stability_lin: tuple = (0.25, 100)
    stability_lin_eps: tuple = (1e-6, 1e-5, 1e-4)
    stability_perturbations: tuple = ("velocity sin", "velocity sin 3", "velocity random", "shape sin")
    #: beyond the paper, what caps the snap (snapping.caps_report): the catalogue's links, the live study's size
    caps_N: int = 400
    caps_live: str = "full"

    def options(self, tol: float) -> dict:
        """The run options of every run of the plan at tolerance ``tol`` (the paper's method
        and chords, explicitly)."""
        return {"method": self.method, "chords": self.chords, "tol": tol,
                **({"record_thin": self.record_thin} if self.record_thin else {})}

    def describe(self) -> str:
        """The method, chain and units of the plan's runs, in words (the log and REPORT.md)."""
        return (f"method {self.method} (the paper's), chords {self.chords} (the paper's chain: nodes at equal "
                f"arclength), tol {self.tol:g} unless stated; units: nondimensional (length L, mass M, time "
                f"sqrt(L/g), force M g)")

    def grids(self) -> list[sweep.Grid]:
        """The sweeps, with the default tolerance first and one grid per other tolerance."""
        base = self.options(self.tol)
        grids = [
            sweep.Grid(chi=list(self.shapes_chi), N=[self.shapes_N], options=base),
            sweep.Grid(chi=list(self.speed_chi), N=list(self.speed_N), options=base),
            sweep.Grid(chi=list(self.scaling_chi), N=[self.scaling_N], options=base),
        ]
        grids += [sweep.Grid(chi=[self.tol_chi], N=[self.tol_N], options=self.options(t))
                  for t in self.tols if t != self.tol]
        return grids

    def points(self) -> list[tuple[float, int, float]]:
        """Unique (chi, N, tol) of all runs."""
        pts = []
        for g in self.grids():
            for p in g.points():
                key = (p["chi"], p["N"], p["tol"])
                if key not in pts:
                    pts.append(key)
        if (self.tol_chi, self.tol_N, self.tol) not in pts:
            pts.append((self.tol_chi, self.tol_N, self.tol))
        return pts


PLANS = {
    "quick": Plan(
        name="quick",
        shapes_N=400,
        speed_chi=(0.05, 0.1, 0.25),
        speed_N=(100, 200, 400),
        scaling_chi=(0.1, 0.15, 0.2, 0.25, 0.3, 0.4),
        scaling_N=400,
        tol_N=400,
        continuum_chi=(0.25,),
        continuum_levels=4,
        continuum_first=-1,
        record_thin=1e-3,
        stability_chi=(0.25,),
        stability_N=(50, 100, 200),
        stability_lin=(0.25, 50),
        # (the 8-mode random field is not resolved at N <= 200: its out-of-plane speed still
        # grows as N^0.44 there, faster than the in-plane peak speed; --full has it at N = 800)
        stability_perturbations=("velocity sin", "velocity sin 3", "shape sin"),
        caps_N=100,
        caps_live="quick",
    ),
    "full": Plan(name="full"),
}

#: Rough cost model: right-hand-side evaluations of a run to its snap at tol 1e-8, and ns per node-evaluation.
_NS_PER_NODE_EVAL = 18.0
#: seconds per run beyond its evaluations (starting workers, loading the compiled kernels, writing
#: the file), and for the fits and figures (calibrated on the quick plan: 17 runs in 70 s, fits and
#: figures 20 s, on a 2-core VM under load 2)
_SECONDS_PER_RUN = 4.5
_SECONDS_AFTER_RUNS = 20.0


def _continuum_seconds(plan: Plan) -> float:
    """The continuum studies: 16 s for 5 levels at chi = 0.25 (docs/benchmarks/bench_continuum.txt:
    117 s at chi = 0.1, 744 s at 0.05, i.e. ~chi^-2.4), 2.5x less per level fewer; the smallest
    chi's study is also run with the paper's lumping."""
    one = {c: 16.0 * (0.25 / c) ** 2.4 * 2.5 ** (plan.continuum_levels - 5) for c in plan.continuum_chi}
    chi0 = 0.25 if 0.25 in one else min(one)
    return sum(one.values()) + one[chi0]


def _stability_seconds(plan: Plan) -> float:
    """The stability study: 5 runs per chi and N at tol 1e-10, serial; 89 s for chi = 0.1, 0.25,
    0.5 and N = 100-800 (1.49e6 evaluations) on the 2-core VM under load 7."""
    runs = (1 + len(plan.stability_perturbations)) / 5.0
    return 30.0 * runs * len(plan.stability_chi) * sum(plan.stability_N) / 1500.0 + 2.0


def _rhs_evaluations(chi: float, N: int, tol: float) -> float:
    return 4.0e5 * (0.25 / chi) ** 0.9 * (N / 400.0) ** 0.35 * (1e-8 / tol) ** 0.5


def expected_seconds(plan: Plan, workers: int = 2) -> float:
    """A rough wall-time estimate of a plan's runs on ``workers`` cores (printed before a run starts)."""
    total = sum(_rhs_evaluations(c, n, t) * n * _NS_PER_NODE_EVAL * 1e-9 for c, n, t in plan.points())
    return ((total + _SECONDS_PER_RUN * len(plan.points())) / max(workers, 1) + _SECONDS_AFTER_RUNS
            + _continuum_seconds(plan) + _stability_seconds(plan))


def _path(out: Path, plan: Plan, chi: float, N: int, tol: float) -> Path:
    return sweep.Grid(chi=[chi], N=[N], options=plan.options(tol)).path(out / "runs", chi, N)


def _load(out: Path, plan: Plan, chi: float, N: int, tol: float):
    from .simulate import load_run

    return load_run(_path(out, plan, chi, N, tol))


def reproduce(out_dir, mode: str = "quick", *, workers: int | None = None, progress: bool = True, log=print) -> Path:
    """Run, draw and report everything; returns the path of REPORT.md.

    Parameters
    ----------
    out_dir : path
        Output directory: ``runs/`` (one netCDF file per run), ``figures/`` and ``REPORT.md``.
    mode : {"quick", "full"} or Plan
        Small N in minutes, or the paper's resolution (or a custom :class:`Plan`).
    workers : int, optional
        Local worker processes for the runs.
    progress : bool
        Progress bars.
    log : callable
        Where progress lines go.
    """
    from . import scaling

    if isinstance(mode, Plan):
        plan, mode = mode, mode.name
    elif mode in PLANS:
        plan = PLANS[mode]
    else:
        raise V.SnappingInputError(f"mode={mode!r} is not one of {sorted(PLANS)} (or a Plan)")
    if workers is not None:
        workers = V.integer("workers", workers, 1)
    out = Path(V.file_path("out_dir", out_dir))
    sweep._check_out_dir(out)
    runs = sweep._check_out_dir(out / "runs")
    sweep._check_room(runs, [(p, path) for g in plan.grids() for p in g.points()
                             if not sweep.is_complete_run(path := g.path(runs, p["chi"], p["N"]))])
    figdir = out / "figures"
    timings: dict[str, float] = {}
    import os

    n_workers = workers or os.cpu_count() or 1
    log(f"snapping reproduce --{mode}: {len(plan.points())} runs, expected about "
        f"{expected_seconds(plan, n_workers) / 60:.1f} min on {n_workers} cores (finished runs in {out / 'runs'} are reused); "
        f"{plan.describe()}")

    t0 = time.perf_counter()
    grids = plan.grids()
    for k, g in enumerate(grids):
        label = f"sweep {k + 1}/{len(grids)} (chi {', '.join(f'{c:g}' for c in g.chi)}; N {', '.join(map(str, g.N))})"
        sweep.run_sweep(g, out / "runs", workers=workers, progress=progress,
                        log=None if progress else (lambda m, label=label: log(f"{label}:{m}")))
    timings["runs"] = time.perf_counter() - t0

    rows: list[tuple[str, str, str, str]] = []  # claim, measured, paper, verdict

    # ---------------------------------------------------------------- ideal
    t_star = ideal.t_star()
    check = ideal.check_printed_equations()
    rows.append(("t* of the perfectly folded string = 2E(pi/4|2)", ideal.t_star_str(15), "≈ 1.19814",
                 "agrees" if abs(t_star - 1.19814) < 5e-6 else "differs"))
    ok_integral = check.get("first_integral_satisfies_derived_ode") and not check.get("first_integral_satisfies_printed_ode")
    rows.append(("kink ODE s0'' = ½(1 − s0'²/(1 − s0)) integrates to eq. (shockvelocity)",
                 "the printed first integral and t* follow from s0'' = ½(1 + s0'²/(1 − s0)); the printed "
                 "(minus) ODE conserves no energy and never snaps", "printed with a minus sign",
                 "typo in the paper (sign)" if ok_integral else "check"))

    # ---------------------------------------------------------------- Fig. 1
    shape_runs = [_load(out, plan, c, plan.shapes_N, plan.tol) for c in plan.shapes_chi]
    r025 = _load(out, plan, 0.25, plan.shapes_N, plan.tol)
    table = {c: [(n, float(_load(out, plan, c, n, plan.tol).attrs["v_peak"])) for n in plan.speed_N] for c in plan.speed_chi}
    for name, draw in (("fig1_shapes", lambda: figures.shapes(shape_runs)),
                       ("fig1e_pin_force", lambda: figures.pin_force(r025)),
                       # ---------------------------------------------------- Fig. 2
                       ("fig2_profiles", lambda: figures.profiles(r025)),
                       ("fig2d_peak_speed_vs_N", lambda: figures.peak_speed_vs_N(table))):
        t1 = time.perf_counter()
        figures.save(draw(), figdir / name)
        timings[name] = time.perf_counter() - t1
    a_peak = float(r025.attrs["a_peak"])
    dur = _snap_duration(r025)
    rows.append((f"chi = 0.25 (N = {plan.shapes_N}): peak acceleration", _fmt(a_peak), "order 10^4",
                 "agrees" if 3e3 <= a_peak <= 3e4 else "differs"))
    rows.append((f"chi = 0.25 (N = {plan.shapes_N}): snap duration (FWHM of the max-acceleration spike)",
                 _fmt(dur, 3), "about 10^-3", "agrees" if 3e-4 <= dur <= 3e-3 else "differs"))
    slopes = []
    for c, vals in table.items():
        (n1, v1), (n2, v2) = sorted(vals)[-2:]
        slopes.append((c, math.log(v2 / v1) / math.log(n2 / n1)))
    rows.append(("peak speed against N grows slower than N^(1/2) (regularisation is not by discreteness)",
                 ", ".join(f"chi={c:g}: d ln v/d ln N = {s:.3f}" for c, s in slopes)
                 + f" (N = {plan.speed_N[-2]}→{plan.speed_N[-1]})",
                 "slower than 1/2", "agrees" if all(s < 0.5 for _, s in slopes) else "differs"))

    # ---------------------------------------------------------------- Fig. 3 / 4
    t1 = time.perf_counter()
    sc_runs = [_load(out, plan, c, plan.scaling_N, plan.tol) for c in plan.scaling_chi]
    results = [scaling.fit_run(ds) for ds in sc_runs]
    timings["fits (Fig. 3/4 runs)"] = time.perf_counter() - t1
    for name, plot in (("fig3_maxima", scaling.plot_maxima), ("fig3_local_slopes", scaling.plot_local_slopes),
                       ("fig4_delta", scaling.plot_delta)):
        t1 = time.perf_counter()  # drawn once, saved as PNG and PDF
        plot(sc_runs, results, [figdir / f"{name}.png", figdir / f"{name}.pdf"])
        timings[name] = time.perf_counter() - t1

    def exponent_row(name, paper, ref, ref_value=None):
        cells, agree, inconclusive, agree_w, n_w = [], 0, 0, 0, 0
        for res in results:
            try:
                r = res.row(name)
            except KeyError:
                continue
            if r.fit is None:
                cells.append(f"chi={res.chi:g}: no fit")
                continue
            cell = f"chi={res.chi:g}: {_pm(r.fit.beta, r.fit.beta_err)}"
            if math.isfinite(r.ideal_window_beta) and ref_value is None:  # (the in-window reference is the row's ref)
                cell += f" (exact folded string on the same window: {r.ideal_window_beta:+.3f})"
                n_w += 1
                agree_w += "agrees with the exact" in r.verdict
            cells.append(cell)
            word = r.word(r.spec.ref if ref_value is None else ref_value)
            agree += word == "agrees"
            inconclusive += word == "inconclusive"
        verdict = f"agrees with {ref} in {agree} of {len(results)}"
        if inconclusive:
            verdict += f" (inconclusive in {inconclusive})"
        if n_w:
            verdict += f"; with the exact folded string on the fit window in {agree_w} of {n_w}"
        rows.append((f"exponent of {name} near t*_chi (N = {plan.scaling_N})", "; ".join(cells), paper, verdict))

    exponent_row("v_max", "-1/3", "-1/3")
    exponent_row("a_end", "-4/3", "-4/3")
    exponent_row("sigma_max", "-2/3", "-2/3")
    exponent_row("a_max", "about -5/6 at intermediate times", "-5/6", -5.0 / 6.0)
    exponent_row("kappa_max", "about -1/6 late (not the inferred -2/3)", "-1/6")
    rows.append(("t*_chi from max speed, acceleration and tension agree",
                 "; ".join(f"chi={r.chi:g}: t*_chi {r.snap.t_star:.6f}, spread {r.snap.spread:.1e} "
                           f"(digit {changed_digit(r.snap.t_star, r.snap.spread)})" for r in results),
                 "differ only at the 5th significant digit",
                 spread_verdict([r.snap.t_star for r in results], [r.snap.spread for r in results])))
    by_chi = sorted(results, key=lambda r: r.chi)
    rows.append(("t*_chi approaches the ideal t* as chi -> 0",
                 "; ".join(f"chi={r.chi:g}: {r.snap.t_star:.5f}" for r in by_chi),
                 f"ideal t* = {t_star:.5f}",
                 monotone_verdict([r.chi for r in by_chi], [r.snap.t_star for r in by_chi], t_star)))
    sig_amp = []  # over t < t*_chi, as the curvature's (scaling.fit_run)
    for ds, r in zip(sc_runs, results):
        sg = np.asarray(ds["sigma_max"].values, dtype=float)
        sig_amp.append(float(np.nanmax(sg[ds["t"].values < r.snap.t_star]) / sg[0]))
    rows.append(("amplification of the maximum curvature is weak",
                 "; ".join(f"chi={r.chi:g}: kappa ×{r.kappa_amplification:.2f} (tension ×{s:.0f})"
                           for r, s in zip(results, sig_amp)),
                 "weak (an approximate doubling early)",
                 amplification_verdict([r.kappa_amplification for r in results], sig_amp)))
    for scale, paper in (("delta_kappa0", "v, sigma barely within an order of magnitude; a under by ~2 orders"),
                         ("delta_kappa_m", "v and a in excellent agreement; sigma over by about ×2"),
                         ("delta_c", "less accurate, but within an order of magnitude")):
        cells, ratios = [], []
        for res in results:
            if res.delta is None:
                continue
            rr = res.delta.ratios()[scale]
            ratios.append(rr)
            cells.append(f"chi={res.chi:g}: v ×{rr['v']:.2f}, a ×{rr['a']:.2f}, σ ×{rr['sigma']:.2f}")
        rows.append((f"predicted/computed peaks with {scale} (eq. estimates)", "; ".join(cells), paper,
                     delta_verdict(scale, ratios) if ratios else "no curvature data"))

    chi_bl = min(plan.scaling_chi)
    res_bl = min(results, key=lambda r: r.chi)
    dkm = res_bl.delta.deltas["delta_kappa_m"] if res_bl.delta is not None else math.nan
    n90 = _boundary_layer_links(_load(out, plan, chi_bl, plan.scaling_N, plan.tol))
    links = dkm * plan.scaling_N
    verdict = boundary_layer_verdict(links, plan.scaling_N)
    rows.append((f"links in the boundary layer at chi = {chi_bl:g}, N = {plan.scaling_N}",
                 f"{links:.1f} links in delta_kappa_m (the whirling length; {n90} links from the free end to 90% "
                 "of the peak tension at the snap)", "10-15 at chi = 0.1, N = 5000", verdict))

    # ---------------------------------------------------------------- drift and tolerance
    # the paper's bounds are for the computations it reports: chi >= 0.1 at N = 5000
    worst = {k: max(float(ds.attrs[k]) for ds in sc_runs) for k in ("link_drift_initial", "length_drift", "energy_drift")}
    rows.append((f"local link length change (against the initial chords), worst of the Fig. 3 runs (N = {plan.scaling_N})",
                 _fmt(worst["link_drift_initial"], 3),
                 "< 5e-4", "agrees" if worst["link_drift_initial"] < 5e-4 else "differs"))
    rows.append(("global string length change, worst of the Fig. 3 runs", _fmt(worst["length_drift"], 3), "< 4e-6",
                 "agrees" if worst["length_drift"] < 4e-6 else "differs"))
    rows.append(("global energy change, worst of the Fig. 3 runs", _fmt(worst["energy_drift"], 3), "< 8e-7",
                 "agrees" if worst["energy_drift"] < 8e-7 else "differs"))
    tol_runs = {t: _load(out, plan, plan.tol_chi, plan.tol_N, t) for t in plan.tols}
    ref = tol_runs[min(plan.tols)]
    cells, digits_coarse = [], None
    for t in sorted(plan.tols, reverse=True)[:-1]:
        x = {q: (float(ref.attrs[q]), float(tol_runs[t].attrs[q]) - float(ref.attrs[q])) for q in TOL_DIGITS}
        digits = {q: changed_digit(v, dv) for q, (v, dv) in x.items()}
        if digits_coarse is None:
            digits_coarse = digits
        cells.append(f"tol {t:g} vs {min(plan.tols):g}: " + ", ".join(
            f"{q} {abs(dv / v):.1e} (digit {digits[q]})" for q, (v, dv) in x.items()))
    rows.append((f"maxima insensitive to tol {max(plan.tols):g} -> {min(plan.tols):g} (chi = {plan.tol_chi:g}, N = {plan.tol_N})",
                 "; ".join(cells), "N = 5000: v changes at the 9th digit, a and sigma at the 6th",
                 tolerance_verdict(digits_coarse, plan.tol_N) if digits_coarse else "needs two tolerances"))

    # ---------------------------------------------------------------- the continuum limit
    t1 = time.perf_counter()
    continuum_lines = _continuum(plan, out, figdir, log)
    timings["continuum limit"] = time.perf_counter() - t1
    t1 = time.perf_counter()
    stability_lines = _stability(plan, out, figdir, log)
    timings["stability (3D)"] = time.perf_counter() - t1
    t1 = time.perf_counter()
    from .caps_report import section as caps_section  # beyond the paper: what caps the snap (issue 24)

    caps_lines = caps_section(plan.caps_N, plan.caps_live, out, figdir, log)
    timings["what caps the snap"] = time.perf_counter() - t1

    # ---------------------------------------------------------------- REPORT.md
    timings["total"] = time.perf_counter() - t0
    report = out / "REPORT.md"
    lines = [f"# snapping: reproduction of the paper ({mode})", "",
             f"Runs: {len(plan.points())} (in `runs/`): {plan.describe()}. "
             f"Paper's chain for SI: {PAPER_CHAIN.length:g} m, {PAPER_CHAIN.mass:g} kg.", "",
             "| claim | measured here | paper | verdict |", "|---|---|---|---|"]
    lines += [f"| {a} | {b} | {c} | {d} |" for a, b, c, d in rows]
    lines += [""] + continuum_lines + [""]
    lines += stability_lines + [""] + caps_lines + [""]
    lines += ["", "## Fit report per run (Fig. 3 as numbers)", ""]
    for res in results:
        lines += [f"### chi = {res.chi:g}, N = {res.N}: t*_chi = {res.snap.t_star:.6f} ± {res.snap.t_star_err:.1e}", "", "```"]
        lines += ["  ".join(r) for r in scaling.report_rows(res)]
        if res.delta is not None:
            lines += [""] + ["  ".join(r) for r in scaling.delta_rows(res.delta)]
        lines += ["```", ""]
    lines += ["## Figures", ""]
    for name, cap in (("fig1_shapes", "Fig. 1(b)-(d): shapes up to the snap, chi = 0.75, 0.5, 0.25"),
                      ("fig1e_pin_force", "Fig. 1(e): force on the pin, chi = 0.25, paper's chain"),
                      ("fig2_profiles", "Fig. 2(a)-(c): speed, acceleration, tension along the chain, chi = 0.25"),
                      ("fig2d_peak_speed_vs_N", "Fig. 2(d): peak speed against N with the N^(1/2) line"),
                      ("fig3_maxima", "Fig. 3: maxima against t*_chi - t with the folded-string scalings"),
                      ("fig3_local_slopes", "local log-log slopes and fit windows"),
                      ("fig4_delta", "Fig. 4: the scales delta and the predicted against computed peaks"),
                      ("fig5_continuum", "the continuum limit: peaks against resolution, graded and uniform chains"),
                      ("fig6_planar_stability", "beyond the paper: out-of-plane amplitude at the snap against eps, "
                       "and its amplification against N with the in-plane focusing")):
        lines += [f"**{cap}**", "", f"![{name}](figures/{name}.png)", ""]
    lines += ["## Wall time", "", "| part | seconds |", "|---|---|"]
    lines += [f"| {k} | {v:.1f} |" for k, v in timings.items()]
    from ._files import write_atomic

    text = "\n".join(lines) + "\n"
    write_atomic(report, lambda tmp: Path(tmp).write_text(text), name="report")  # the directory's own file
    log(f"wrote {report} and {len(list(figdir.glob('*.png')))} figures in {figdir} ({timings['total']:.0f} s)")
    return report


def _continuum(plan: Plan, out: Path, figdir: Path, log) -> list[str]:
    """Run the continuum-limit studies of the plan (resumable, in ``out/continuum``), draw
    their figure for the smallest chi and return the report's section."""
    from . import continuum, figures
    from .simulate import load_run

    studies, uniform, finest = {}, {}, {}
    for chi in plan.continuum_chi:
        d = out / "continuum" / f"chi{chi:g}"
        studies[chi] = continuum.converge(chi, levels=plan.continuum_levels, first=plan.continuum_first, output=d)
        finest[chi] = load_run(studies[chi].paths[-1])
        Ns = [N for c, N, t in plan.points() if c == chi and t == plan.tol]
        if Ns:
            uniform[chi] = _load(out, plan, chi, max(Ns), plan.tol)
        log(f"continuum limit chi = {chi:g}: v = {studies[chi].dataset.attrs['v_peak_limit']:.6g} "
            f"± {studies[chi].dataset.attrs['v_peak_error']:.1g}")
    chi0 = 0.25 if 0.25 in plan.continuum_chi else min(plan.continuum_chi)
    runs_u = sorted((_load(out, plan, c, N, t) for c, N, t in plan.points() if c == chi0 and t == plan.tol),
                    key=lambda ds: int(ds.attrs["N"]))
    paper = continuum.converge(chi0, levels=plan.continuum_levels, first=plan.continuum_first, lumping="paper",
                               output=out / "continuum" / f"chi{chi0:g}_paper_lumping")
    fig = figures.convergence_figure(studies[chi0].dataset, uniform=runs_u or None, other=paper.dataset)
    figures.save(fig, figdir / "fig5_continuum")
    from . import scaling

    fits = {}
    for chi, ds in finest.items():
        try:
            fits[chi] = scaling.fit_run(ds)
        except V.SnappingInputError as exc:  # e.g. too coarse a study to fit
            log(f"continuum limit chi = {chi:g}: no exponent fit on the finest level ({exc})")
    return continuum.report_section(studies, uniform, finest, fits)


def _stability(plan: Plan, out: Path, figdir: Path, log) -> list[str]:
    """Beyond the paper: the planar snap's stability (:mod:`snapping.spatial.stability`), its
    figure and the report's section. The numbers are kept in ``out/stability/study.json``
    and reused while the plan's stability parameters are the same."""
    import json

    from ._files import write_atomic
    from .spatial import stability as S

    params = {"chi": list(plan.stability_chi), "N": list(plan.stability_N), "eps": plan.stability_eps,
              "perturbations": list(plan.stability_perturbations),
              "lin": list(plan.stability_lin), "lin_eps": list(plan.stability_lin_eps), "tol": S.TOL, "seed": S.SEED}
    path = out / "stability" / "study.json"
    saved = json.loads(path.read_text()) if path.is_file() else {}
    if saved.get("params") == params:
        st, lin = saved["study"], saved["linearity"]
    else:
        st = S.study(plan.stability_chi, plan.stability_N, plan.stability_perturbations, eps=plan.stability_eps,
                     tol=S.TOL, seed=S.SEED)
        chi, N = plan.stability_lin
        lin = S.linearity(chi, N, "velocity sin", plan.stability_lin_eps, tol=S.TOL, seed=S.SEED)
        path.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps({"params": params, "study": st, "linearity": lin})
        write_atomic(path, lambda tmp: Path(tmp).write_text(text), name="stability study")
    figures.save(S.figure(st, lin), figdir / "fig6_planar_stability")
    log(f"stability: {S.verdict(st)['text']}")
    return S.report_section(st, lin)
