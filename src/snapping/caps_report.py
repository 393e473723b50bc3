"""The report's section "Beyond the paper: what caps the snap" (issue 24, item 4).

Two parts, each claim a computed verdict:

* the catalogue's design answers (:func:`catalogue`: :func:`snapping.caps.cap` for every line
  of :mod:`snapping.lines`; the ball chain on its own 229 links, the others on ``N``): the
  peak tension of each in newtons, ideal beside real, the factor, the capping mechanism, and
  whether the answer is resolved (the full run's tension moves by at most 1% from N/2 to N);
* the regime studies: the files ``src/snapping/data/regimes/<mechanism>.nc`` where they exist
  (:func:`snapping.regimes.load_study`), else a small live study (:data:`LIVE`), reported by
  :func:`snapping.regimes_analysis.report` (laws and crossovers) with the regime map.

:func:`section` is what :func:`snapping.reproduce.reproduce` calls with the plan's ``caps_N`` and
``caps_live`` (``quick``: N = 100 and the smallest live study, about 10 s of CPU; ``full``:
N = 400 and two live studies of 3 chi x 4-5 numbers at 4 levels).
"""

from __future__ import annotations

import time
from pathlib import Path

__all__ = ["catalogue", "catalogue_table", "studies", "report_section", "section", "convergence_words", "LIVE",
           "CATALOGUE_N", "RESOLVED", "stretching_speeds", "ideal_speeds"]

#: the catalogue's links per mode (the ball chain always on its 229)
CATALOGUE_N = {"quick": 100, "full": 400}
#: an answer is resolved when its tension moves by at most this much from N/2 to N
RESOLVED = 0.01
#: the live studies when no study file is shipped: mode -> (mechanism, chis, numbers, levels, first level)
LIVE = {"tiny": [("end-mass", (0.5,), (1.0,), 2, -4)],
        "quick": [("end-mass", (0.5,), (0.001, 0.01), 3, -3)],
        "full": [("end-mass", (0.15, 0.25, 0.4), (0.01, 0.1, 0.3, 1.0, 3.0), 4, -1),
                 ("drag", (0.15, 0.25, 0.4), (0.01, 0.1, 1.0, 10.0), 4, -1)]}


def catalogue(chi: float = 0.25, N: int = 200, *, tol: float = 1e-6, check: bool = True, names=None) -> list[dict]:
    """:func:`snapping.caps.cap` for each catalogue line (``names``: all) at ``chi``, on ``N``
    links (``"auto"``: :func:`snapping.caps.cap`'s; a line of discrete links, the ball chain:
    on its own, :attr:`snapping.lines.Line.pitch`)."""
    from . import caps, lines

    out = []
    for name in names or lines.names():
        n = None if lines.get(name).pitch is not None else N
        out.append(caps.cap(name, chi, N=n, tol=tol, check=check and n != "auto"))
    return out


def resolved_words(r: dict) -> str:
    """The resolution verdict of one answer (its tension from N/2 to N; on graded links, the
    extrapolation's error estimate)."""
    g = r.get("graded") or {}
    if (r.get("own_links") or {}).get("used"):
        return f"its own {r['own_links']['links']} links (a chain of discrete links: no limit in N)"
    if g.get("used"):
        e = g["relative_error"]["sigma_peak"]
        return (f"{'resolved' if e <= RESOLVED else f'not resolved to {RESOLVED:.0%}'} on graded links "
                f"({'/'.join(str(g['levels'][k]) for k in g.get('pair', (0, 1)))}, extrapolated: +-{e:.1%})")
    res = r.get("resolution")
    if not res:
        return "not checked"
    d = res["sigma_peak"]
    return (f"resolved ({d:+.1%} from N/2)" if abs(d) <= RESOLVED else
            f"not resolved to {RESOLVED:.0%} ({d:+.1%} from N/2)")


def catalogue_table(answers: list[dict], seconds: bool = True) -> list[str]:
    """Markdown rows: line, chi, N, ideal and real peak tension (N), factor, capping
    mechanism, resolution, evaluations and (``seconds``) CPU seconds."""
    out = ["| line | chi | N | ideal peak tension (N) | real peak tension (N) | factor | capped by | resolution "
           "(tension) | evaluations |" + (" CPU s |" if seconds else ""),
           "|---|---|---|---|---|---|---|---|---|" + ("---|" if seconds else "")]
    for r in answers:
        out.append(f"| {r['line']} | {r['chi']:g} | {r['N']} | {r['ideal']['sigma_peak']:.4g} | "
                   f"{r['real']['sigma_peak']:.4g} | {r['factor']['sigma_peak']:.3f} | {r['cap']} | "
                   f"{resolved_words(r)} | {r['n_rhs']} |" + (f" {r.get('cpu', r['wall']):.1f} |" if seconds else ""))
    return out


def studies(mode: str = "quick", data_dir=None, out_dir=None, log=print) -> list:
    """The regime studies: every ``<mechanism>.nc`` in ``data_dir`` (default the package's
    ``data/regimes``) that loads as a study; none there: the live studies of :data:`LIVE`
    (saved in ``out_dir`` when given, and reused from there)."""
    from . import regimes

    d = Path(data_dir) if data_dir is not None else Path(__file__).parent / "data" / "regimes"
    found = []
    for p in sorted(d.glob("*.nc")) if d.is_dir() else []:
        if p.name.startswith("."):
            continue
        try:
            found.append(regimes.load_study(p))
        except Exception as exc:  # noqa: BLE001 - a study being written, or another file: named and skipped
            log(f"what caps the snap: {p.name} skipped ({str(exc).splitlines()[0]})")
    if found:
        for ds in found:
            ds.attrs["source"] = "shipped study file"
        return found
    out = []
    for mech, chis, nums, levels, first in LIVE[mode]:
        path = None if out_dir is None else Path(out_dir) / f"{mech}.nc"
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
        ds = regimes.regimes(mech, list(chis), list(nums), levels=levels, first=first, out=path,
                             progress=False)
        ds.attrs["source"] = "live study (no shipped study file)"
        out.append(ds)
    return out


def convergence_words(ds, quantity: str = "v_peak") -> str:
    """A study's own convergence verdict: its cells flagged not converged
    (:mod:`snapping.regimes_resolution`), named, and where the mechanism *raises* the peak
    (converged, resolved cells whose ratio exceeds 1 by more than three error bars: the
    largest per chi). Empty for a study without the flag."""
    import numpy as np

    from .regimes_analysis import resolved

    if "converged" not in ds:
        return ""
    name = ds.attrs["number_name"]
    ok = ds["converged"].values.astype(bool)
    bad = [f"chi={c:g} {name}={n:.3g}" for i, c in enumerate(ds.chi.values) for j, n in enumerate(ds.number.values)
           if not ok[i, j]]
    words = ("every cell converged" if not bad else
             f"{len(bad)} of {ok.size} cells not converged (their finest links do not resolve the mechanism's "
             f"length, or the levels do not converge; left out of the laws): {', '.join(bad)}")
    r, e = ds[f"{quantity}_ratio"].values, ds[f"{quantity}_ratio_error"].values
    good = ok & resolved(ds[quantity].values, ds[f"{quantity}_error"].values, ds[f"{quantity}_order"].values)
    rises = []
    for i, c in enumerate(ds.chi.values):
        up = np.flatnonzero(good[i] & (r[i] - 1.0 > 3.0 * e[i]))
        if up.size:
            j = up[np.argmax(r[i, up])]
            rises.append(f"x{r[i, j]:.3f} +- {e[i, j]:.2g} at chi={c:g}, {name}={ds.number.values[j]:.3g}")
    words += ("; a small " + name + " raises the peak (converged cells, ratio > 1 by 3 error bars): "
              + "; ".join(rises) if rises else "; no converged cell has its peak raised above the ideal's")
    return words


def report_section(answers: list[dict], study_list: list, figure_names=()) -> list[str]:
    """Markdown lines of the section "Beyond the paper: what caps the snap"."""
    from . import caps
    from .regimes_analysis import LEVEL, analyze, level_ratios, report, with_level_ratios

    lines = ["## Beyond the paper: what caps the snap", "",
             "The paper's snap is capped by geometry (the fold's curvature scale); a real line has bending, "
             "stretching, drag and an end mass besides. Each line of the catalogue (`snapping.lines`) released from "
             f"its catenary, from runs of the real model (`snapping.caps.cap`): the ideal chain on the same links, "
             "the full inextensible model (bending + drag + end mass + taper), stretching as an elastic/rigid factor "
             f"where the full run's peak speed reaches {caps.STRETCH_MATTERS:g} of the wave speed (each peak's factor "
             f"applied only where it agrees within {caps.RESOLVED:.0%} on {caps.STRETCH_LEVELS[0]} and "
             f"{caps.STRETCH_LEVELS[1]} links, else left out), and each mechanism "
             f"alone. Rule: {answers[0]['rule'] if answers else ''}.", ""]
    lines += catalogue_table(answers, seconds=False) + [""]
    for r in answers:
        q = r["quantity"]
        who = ("nothing but the ideal chain's own cap" if r["cap"] == "none" else f"**{r['cap']}**")
        lines.append(f"- {r['line']}: capped by {who} at {r['real'][q]:.4g} N (ideal {r['ideal'][q]:.4g} N, "
                     f"factor {r['factor'][q]:.3f}); {resolved_words(r)}; stretching: {r['stretching']['why']}.")
    n_res = sum(1 for r in answers if resolved_words(r).startswith("resolved"))
    capped = sorted({r["cap"] for r in answers if r["cap"] != "none"})
    lines += ["", f"**Verdict (computed): {len(answers) - sum(r['cap'] == 'none' for r in answers)} of "
                  f"{len(answers)} lines are capped below {LEVEL:g} of the ideal chain's peak tension (by "
                  f"{', '.join(capped) or 'nothing'}); {n_res} of {len(answers)} answers are resolved to "
                  f"{RESOLVED:.0%} at these links.**", ""]
    for k, ds in enumerate(study_list):
        a = analyze(ds, "v_peak")
        crossed = [f"chi={chi:g}: {row['crossover']['statement']}" for chi, row in a["chi"].items()]
        lines += [f"### Regime study: {ds.attrs['mechanism']} ({ds.attrs.get('source', '')})", "", "```"]
        loose = [chi for chi, row in a["chi"].items() if row["crossover"]["statement"].startswith("no crossover: the "
                                                                                                 "ideal's limit")]
        if ds.attrs["mechanism"] == "stretching" and loose:  # limits not resolved apart: the same-links ratio judges
            ideal = ", ".join(f"chi={chi:g}: {row['ideal']:.4g} +- {row['ideal_error']:.2g}"
                              for chi, row in a["chi"].items())
            verdict = ("each cell's own continuum limit is not resolved at this study's levels (the ideal's: "
                       f"{ideal}), so its crossovers are the same-links ratio's (below); "
                       f"{convergence_words(with_level_ratios(ds))}")
        else:
            verdict = ("; ".join(crossed) + f"; {a['crossover_law']['statement']}"
                       + (f"; {convergence_words(ds)}" if "converged" in ds else ""))
        lines += report(ds) + ["```", "", f"**Verdict (computed, v_peak): {verdict}.**", ""]
        if ds.attrs["mechanism"] == "stretching":
            lr = level_ratios(ds, "v_peak")
            lines += [("The stretching study's levels are too coarse for each limit apart (above); the ratio to "
                       if loose else "A second estimate of the crossovers (its discretisation errors shared): the ratio to ")
                      + "the ideal on the same links, extrapolated across the levels "
                      "(`regimes_analysis.level_ratios`):", "", "```"]
            for chi, r in lr["chi"].items():
                lines.append(f"chi={chi:g}: " + " ".join(f"{n:g}: {v:.3f} +- {e:.2g}" for n, v, e in
                                                         zip(ds.number.values, r["ratio"], r["error"]))
                             + f"; {r['crossover']['statement']}")
            lines += [f"{lr['crossover_law']['statement']}", "```", "",
                      f"**Verdict (computed, stretching against the issue's guess, c ~ v): "
                      f"{'; '.join(stretching_speeds(lr, ideal_speeds(study_list)))}.**", ""]
        if k < len(figure_names):
            lines += [f"![{figure_names[k]}](figures/{figure_names[k]}.png)", ""]
    return lines


def stretching_speeds(ratios: dict, v_ideal: dict) -> list[str]:
    """Per chi of a stretching study's level ratios (:func:`snapping.regimes_analysis.level_ratios`):
    the crossover wave speed c_c = 1/number_c (units sqrt(g L); interval from the number's) against
    the ideal's peak speed ``v_ideal[chi] = (value, source)``, c_c / v_ideal -- the issue's guess
    was that stretching matters once the speed approaches c (c_c / v_ideal ~ 1)."""
    out = []
    for chi, r in ratios["chi"].items():
        x = r["crossover"]
        if not x["bracketed"]:
            out.append(f"chi={chi:g}: no c_c ({x['statement']})")
            continue
        cc = 1.0 / x["number"]
        span = (f" ({1.0 / x['hi']:.3g}..{1.0 / x['lo']:.3g})" if x["hi"] > 0 and x["lo"] > 0 else "")
        if chi not in v_ideal:
            out.append(f"chi={chi:g}: c_c = {cc:.3g}{span} (no resolved ideal speed)")
            continue
        v, src = v_ideal[chi]
        out.append(f"chi={chi:g}: c_c = {cc:.3g}{span}, v_ideal = {v:.4g} ({src}), c_c/v_ideal = {cc / v:.3g}")
    return out


def ideal_speeds(study_list) -> dict:
    """chi -> (the ideal's continuum peak speed, its source) from the studies whose ideal limit is
    resolved (error bar <= MAX_REL_ERROR), the smallest error bar first."""
    from .regimes_analysis import MAX_REL_ERROR

    best = {}
    for ds in study_list:
        for chi in ds.chi.values:
            v, e = float(ds.v_peak_ideal.sel(chi=chi)), float(ds.v_peak_ideal_error.sel(chi=chi))
            if abs(e) <= MAX_REL_ERROR * abs(v) and (float(chi) not in best or e < best[float(chi)][2]):
                best[float(chi)] = (v, f"{ds.attrs['mechanism']} study, +- {e:.2g}", e)
    return {c: (v, s) for c, (v, s, _) in best.items()}


def section(N: int, live: str, out: Path, figdir: Path, log=print) -> list[str]:
    """Compute and write the section for :func:`snapping.reproduce.reproduce`: the catalogue at
    chi = 0.25 on ``N`` links (kept in ``out/caps/answers.json`` and reused while ``N`` is the
    same), the studies (shipped, else the live studies ``LIVE[live]``, kept in
    ``out/regimes``), a regime map per study."""
    import json

    from . import figures
    from ._files import write_atomic
    from .regimes_analysis import regime_map, with_level_ratios

    t0 = time.perf_counter()
    if live not in LIVE:
        from ._validate import SnappingInputError

        raise SnappingInputError(f"live={live!r} is not one of {sorted(LIVE)}")
    path = Path(out) / "caps" / "answers.json"
    params = {"chi": 0.25, "N": int(N), "tol": 1e-6}
    saved = json.loads(path.read_text()) if path.is_file() else {}
    if saved.get("params") == params:
        answers = saved["answers"]
    else:
        answers = catalogue(params["chi"], params["N"], tol=params["tol"])
        path.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps({"params": params, "answers": answers}, default=float)
        write_atomic(path, lambda tmp: Path(tmp).write_text(text), name="caps answers")
    found = studies(live, out_dir=Path(out) / "regimes", log=log)
    names = []
    for ds in found:
        name = f"fig7_regime_map_{ds.attrs['mechanism']}"
        figures.save(regime_map(with_level_ratios(ds) if ds.attrs["mechanism"] == "stretching" else ds),
                     Path(figdir) / name)
        names.append(name)
    log(f"what caps the snap: {len(answers)} lines, {len(found)} regime studies ({time.perf_counter() - t0:.0f} s)")
    return report_section(answers, found, names)
