"""The real answer of a line that stretches and carries a body (bending, drag), where the stretching
factor on uniform links does not settle: the combined model (the extensible line with the line's
body, :mod:`snapping.simulate.elastic_body`, by the compiled RODAS4) on graded links, level after
level, extrapolated (issue 24). Opt-in: ``caps.cap(..., combined=True)``, ``snapping estimate
--combined``: minutes of CPU where the default answer takes seconds.

Why. :func:`snapping.caps_runs.stretch_factor_body` (the combined model over the inextensible one on
50 and 100 uniform links) settles only where those links resolve the fold. The climbing rope's
(bending length 1.9e-4 L, c = 22.45 sqrt(gL)) never does: at chi 0.1 both models' peaks grow with
uniform links (``benchmarks/rope_combined.py``). On the stretching study's fold grading the combined
model settles (docs/guide/caps.md, "The climbing rope at chi 0.1 on graded links"; ``benchmarks/
rope_study_grid.py``): v 27.0, 37.73, 37.93, 37.46 sqrt(gL) and T 82.6, 141, 150, 146 M g on 947,
1857, 3680, 7328 links, where the inextensible model's do not (v 41.1, 65.1, 58.6).

The levels (:func:`combined_links`): ``grading.fold_following`` with the parameters of
:func:`snapping.continuum.level_parameters` from :data:`COMBINED_FIRST` (the stretching study's; every
length halving per level, no tip floor). The runs (:func:`combined_level`): the stretching study's
settings (``Elastic(ea=EA/(M g), grid_damping=4)``, start ``"matched"``, ``stop_floor=1``, the snap's a
and T peaks, :data:`snapping.regimes_spec.STRETCH_PEAK_ATTRS`), the line's body and masses
(:func:`snapping.caps_runs.problem` on the graded links), its fast bending waves grid-damped as the
inextensible answer's (:func:`snapping.caps_runs.method_for`), RODAS4 at :data:`COMBINED_TOL`. The
answer (:func:`combined_answer`): :func:`snapping.caps_runs.graded_levels` (levels 0-2, :data:`COMBINED_MIN_LEVELS`,
then more while a peak's Richardson estimate at order 2 is over 1% or its last three levels converge at no order
>= 1, up to :data:`COMBINED_MAX_LINKS` links).

**The ideal beside it, and the verdict** (:func:`same_links`, :func:`combined_verdict`). The answer's factor is
taken against the ideal chain's continuum limit (shipped: :mod:`snapping.caps_ideal`). For the verdict, the ideal
chain and the inextensible line with the same body are run on the combined levels too (the ideal's there: T 177.2,
196.3, 203.3, 205.3 M g on the rope's 947-7328 links at chi 0.1; its limit 205.98), and real/ideal on the finest
level splits into the body's step b (inextensible with the body / ideal) and stretching's s (combined /
inextensible with the body). A step that raises the peak takes nothing down: the mechanism is the one whose
step takes the peak further down (``"stretching"``, or the body's, named by :func:`snapping.caps.decide`'s rule
among the runs alone); the words say when neither step is below 0.9
(:data:`snapping.regimes_analysis.LEVEL`) on the finest level though the factor is.
"""

from __future__ import annotations

import math
import time

from .caps_runs import GRID_DAMPING, GRADED_ORDER, GRADED_WITHIN, QUANTITIES, graded_levels, method_for, problem

__all__ = ["combined_links", "combined_level", "combined_answer", "combined_route", "COMBINED_METHOD",
           "COMBINED_TOL", "COMBINED_MAX_LINKS", "COMBINED_FIRST", "COMBINED_DAMPING", "COMBINED_MIN_LEVELS", "same_links", "combined_verdict"]

#: the combined runs' method and tolerance
COMBINED_METHOD = "rodas4"
COMBINED_TOL = 1e-6
#: the coarsest level's index in :func:`snapping.continuum.level_parameters` (the stretching study's: at chi 0.1
#: 947 and 1857 links for the first two levels)
COMBINED_FIRST = -1
#: the most links of an escalated level (the climbing rope at chi 0.1: 7328 on level 3, 351 s of CPU)
COMBINED_MAX_LINKS = 8000
#: the fewest levels of a combined answer, and from three on a peak converging at no order >= 1 is not resolved
#: (:func:`snapping.caps_runs.graded_levels`' ``min_levels``): two levels' estimate assumes the asymptotic range,
#: which the rope's acceleration at chi 0.4-0.5 is not in (a 38.7, 39.3, 57.0, 187.8 g-units on 189-1141 links at
#: chi 0.5, where levels 0-1 said +-0.5%; its tension 2.0805, 2.0901, 2.0932, 2.0943 converges)
COMBINED_MIN_LEVELS = 3
#: the elastic waves' grid damping ratio (the stretching study's, ``regimes_spec.STRETCH_DAMPING``: with 1 the
#: rope's coarse graded levels ring, the peak guard refusing them)
COMBINED_DAMPING = 4.0


def combined_links(chi: float, level: int, first: int = COMBINED_FIRST):
    """The links (nondimensional, free end first) of level ``level`` of the combined answer: the fold-following
    grading with the parameters of :func:`snapping.continuum.level_parameters` from level ``first``."""
    from .continuum import level_parameters
    from .simulate import grading

    p = level_parameters(int(level) + 1, 0.5, first=first)[-1]
    return grading.fold_following(chi, frac=p["frac"], h_min=p["h_min"], h_max=p["h_max"])


def combined_level(sp, chi: float, on, level: int, *, tol: float = COMBINED_TOL, method: str = COMBINED_METHOD,
                   stiff_tol: float = None, damping: float = GRID_DAMPING, first: int = COMBINED_FIRST) -> dict:
    """One level's peaks (nondimensional) of the combined model of line ``sp`` at ``chi`` with the mechanisms
    ``on`` on :func:`combined_links`; with ``links``, ``n_rhs``, ``cpu``, ``wall``, ``strain_peak``, ``method``."""
    from .regimes_spec import STRETCH_PEAK_ATTRS, STRETCH_STOP_FLOOR
    from .simulate.elastic import Elastic, solve

    t0, c0 = time.perf_counter(), time.process_time()
    h = combined_links(chi, level, first)
    on = tuple(on)
    p = problem(sp, chi, h.size, on, h=h)
    stiff, _, omega_min = method_for(p, tol, stiff_tol)
    if stiff == "rodas4" and damping > 0.0:
        p = problem(sp, chi, h.size, on, h=h, damping=damping, omega_min=omega_min)
    a = solve(p, Elastic(ea=sp.ea / (sp.mass * sp.g), grid_damping=COMBINED_DAMPING), tol=tol, method=method,
              start="matched", stop_floor=STRETCH_STOP_FLOOR).dataset.attrs
    if a.get("status") != "completed":
        raise RuntimeError(f"the combined run on {h.size} graded links did not complete ({a.get('stop_reason', '')}"
                           f"{'; ' + a['peak_note'] if a.get('peak_note') else ''})")
    return {**{q: float(a[STRETCH_PEAK_ATTRS.get(q, q)]) for q in QUANTITIES}, "links": int(h.size),
            "n_rhs": int(a["n_rhs"]), "strain_peak": float(a["strain_peak"]), "method": f"combined {method} {tol:g}",
            "wall": time.perf_counter() - t0, "cpu": time.process_time() - c0}


def combined_answer(sp, chi: float, on, *, within: float = GRADED_WITHIN, max_links: int = COMBINED_MAX_LINKS,
                    logged=None, **kw) -> dict:
    """The combined model's answer (nondimensional): :func:`snapping.caps_runs.graded_levels` over
    :func:`combined_level` (``logged(level)`` after each, if given), extrapolated at order
    :data:`snapping.caps_runs.GRADED_ORDER`; its dict (``levels``, ``pair``, ``extrapolated``, ``error``,
    ``relative_error``, ``observed_order``, ``stopped``, ``why``) with ``resolved`` per peak (its estimate
    within ``within``)."""
    kw.setdefault("first", COMBINED_FIRST)

    def run_level(k):
        x = combined_level(sp, chi, on, k, **kw)
        if logged is not None:
            logged(x)
        return x

    g = graded_levels(run_level, lambda k: combined_links(chi, k, kw["first"]).size, within, max_links, GRADED_ORDER,
                      min_levels=COMBINED_MIN_LEVELS)
    g["resolved"] = {q: bool(math.isfinite(g["relative_error"][q]) and g["relative_error"][q] <= within
                             and g["asymptotic"][q]) for q in QUANTITIES}
    return g


def combined_route(runs, present, full_nd: dict, uniform: list, resolved: dict) -> dict:
    """The combined answer of :func:`snapping.caps.cap` (``combined=True``) where the uniform stretching factor
    did not settle (``uniform``: :func:`snapping.caps_runs.stretch_factor_body`'s two levels, ``resolved`` per
    peak): :func:`combined_answer` for ``runs``' line and chi with the mechanisms ``present``, each level logged
    in ``runs``; with ``factor`` (its extrapolated peaks over the inextensible full run's ``full_nd``: the
    answer's real peaks, the full run's times it, are the combined model's) and ``why`` (in words)."""
    def logged(x):
        runs._logged({"run": "combined", "N": x["links"], "method": x["method"], "tol": COMBINED_TOL,
                      "n_rhs": x["n_rhs"], "cpu": x["cpu"]})

    cg = combined_answer(runs.sp, runs.chi, present, logged=logged, damping=runs.damping)  # (same_links': the same)
    ext, rel = cg["extrapolated"], cg["relative_error"]
    links = "/".join(str(x["links"]) for x in cg["levels"])
    off = [q for q in QUANTITIES if not resolved[q]]
    cg["factor"] = {q: ext[q] / full_nd[q] for q in QUANTITIES}
    cg.update(same_links(runs, present, cg))
    cg["why"] = (f"the factor on {uniform[0]['N']} and {uniform[1]['N']} uniform links did not settle ("
                 + ", ".join(f"{q} {uniform[0][q]:.4g} -> {uniform[1][q]:.4g}" for q in off)
                 + f"): the real answer is the combined model's (the elastic line with the line's body, "
                 f"{cg['levels'][-1]['method']}) on graded links ({links}), extrapolated at order {GRADED_ORDER:g}: "
                 + ", ".join(f"{q} +-{rel[q]:.2%}" for q in QUANTITIES) + f" ({cg['why']}); strain peak "
                 f"{cg['levels'][-1]['strain_peak']:.3g}")
    return cg


def same_links(runs, present, cg: dict) -> dict:
    """The ideal chain and the inextensible line with the body ``present`` on each level of the combined answer
    ``cg`` (:func:`combined_links`; ``runs.get``: the fast method, RODAS4 where bending waves are stiff), the
    ideal's extrapolated on ``cg``'s pair at :data:`GRADED_ORDER`: ``ideal`` (``levels``, ``extrapolated``,
    ``error``, ``relative_error``) and ``inextensible`` (its levels' peaks), nondimensional."""
    hs = [(combined_links(runs.chi, k), f"combined level {k}") for k in range(len(cg["levels"]))]
    ideal = [runs.get((), h.size, h=h, where=where) for h, where in hs]  # (made once: ideal_on takes the pair's)
    inext = [runs.get(tuple(present), h.size, h=h, where=where) for h, where in hs]
    return {"ideal": {**runs.ideal_on([hs[k] for k in cg["pair"]]), "levels": ideal}, "inextensible": inext}


def combined_verdict(cg: dict, quantity: str, factor: float, alone: dict, decide) -> tuple[str, str]:
    """The capping mechanism of a combined answer ``cg`` (:func:`combined_route` with :func:`same_links`) and
    why, in words: ``"none"`` where ``factor`` (real / the ideal's continuum limit, of ``quantity``) is at
    least :data:`snapping.regimes_analysis.LEVEL`; else, on the finest level, the body's step b (the
    inextensible line with the body over the ideal chain) and stretching's s (the combined model over the
    inextensible line with the body), each step down min(log step, 0): ``"stretching"`` where stretching's
    step down is the larger, else ``decide(alone)`` (the body's mechanism nearest the real answer,
    :func:`snapping.caps.decide`'s rule; ``alone``: {mechanism: peak})."""
    from .regimes_analysis import LEVEL

    k = len(cg["levels"]) - 1
    real, inext, ideal = cg["levels"][k][quantity], cg["inextensible"][k][quantity], cg["ideal"]["levels"][k][quantity]
    s, b = real / inext, inext / ideal
    steps = (f"on the finest level ({cg['levels'][k]['links']} links) the body's step (inextensible with it / ideal) "
             f"x{b:.3g}, stretching's (combined / inextensible with the body) x{s:.3g}")
    if factor >= LEVEL:
        return "none", f"real/ideal {factor:.3g} >= {LEVEL:g} (the ideal chain's continuum limit); {steps}"
    head = f"real/ideal {factor:.3g} < {LEVEL:g} (the ideal chain's continuum limit); {steps}"
    if min(s, b) >= LEVEL:
        head += f" (neither below {LEVEL:g} on the finest level)"
    down_s, down_b = min(math.log(s), 0.0), min(math.log(b), 0.0)
    if down_s < down_b or (down_s == down_b and s <= b):
        return "stretching", head + ": stretching takes it down"
    return decide(alone), head + ": the body takes it down"
