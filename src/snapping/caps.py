"""What caps the snap of a real line: design answers from runs of the real model (issue 24).

:func:`cap` answers, for a line in SI (a catalogue line of :mod:`snapping.lines` by name, a
:class:`snapping.lines.Line`, or the physical parameters alone) released from its catenary at
end separation chi: the peak speed, acceleration and tension of its snap **from runs of the
real model**, the ideal chain's answer beside them, the factor between them, and the
mechanism that capped the snap, decided by computation.

The runs (all on N links, each made once: :mod:`snapping.caps_runs`; the fast method of
:func:`snapping.simulate.run` at tolerance ``tol``, except the stiff runs, whose bending waves
would hold the explicit method to tiny steps: those are RODAS4's at ``stiff_tol`` with those
waves grid-damped, :func:`snapping.caps_runs.method_for`):

* **ideal**: the paper's chain, N equal links of the line's length and mass, no body;
* **full**: the real model with every mechanism at once, the inextensible line of
  :class:`snapping.simulate.Body` (bending EI, normal and tangential drag, the tip body's
  drag) with the line's masses (its taper, if any, and the end mass);
* **each mechanism alone** (``bending``, ``drag``, ``end-mass``, ``taper``: those the line
  has), the others switched off.

**Graded links** (``graded="auto"``): when bending holds a fold the N links cannot resolve
(:func:`snapping.caps_runs.grading_rule`: the bending length under 20 links, a run on them folded
onto one link), the full run is made on two levels of links graded to the free end in bending
lengths and extrapolated at order 2, with an error estimate per peak (the nylon line: 545 and 1072
links, its tension within 0.11% of the converged value, estimate 0.55%); while any peak's estimate
is over 1% a finer level is run and the last two extrapolated, up to
:data:`snapping.caps_runs.MAX_ESCALATED_LINKS` links (:func:`snapping.caps_runs.graded_levels`).

**Stretching** is the elastic model (:func:`snapping.simulate.elastic.solve`), which has no
bending or drag; it is run when EA is given and matters: when the line's peak speed (the full
inextensible run's, with every other mechanism: the speed the line reaches, not the ideal
chain's, ``stretching["v_over_c_ideal"]``) reaches ``STRETCH_MATTERS`` = 5% of the longitudinal
wave speed c = sqrt(EA/lambda) (the
elastic guide's measurements put the peaks' change at 0.1-0.3% for v/c of 1-3% and 4-11% for
v/c of about 20%). Then it runs the elastic line (from the rigid chain's release, ``"matched"``:
no release wave; grid damping 1; RODAS4) and the rigid chain on the same uniform links, on two
levels, ``STRETCH_LEVELS`` = 30 and 60 links, and takes their ratio as the stretching factor of
each peak **only where the two levels agree within** :data:`RESOLVED` = 1%
(:func:`snapping.caps_runs.accept_factors`: the finer level's factor); a peak whose two levels
disagree keeps the full run's value (factor 1), and the answer says so (``stretching["resolved"]``
per peak, ``stretching["why"]``, the printed answer). The ratio is not a converged quantity: the
ideal chain's snap, and with it v/c, grows with the links; the elastic line's tension peak is often
not the snap's but the snap's tension wave reaching the held end (L/c later, at the held end's
link) or, on a coarse chain at small chi, a slack link jerked taut after the snap where the rigid
chain carries compression (the nylon line at chi 0.1 on 30 links: x11.4 in the tension, 1.06 on 60;
the elastic guide, "The tension peak of the elastic chain"). The stretching-alone answer is the
ideal's times the applied factor; the **real answer** is the full run's times it (the two models
cannot run together: the factors are taken as independent, and the answer says so). Below the
threshold the answer says stretching was left out, and why.

**The ideal beside it** (:mod:`snapping.caps_ideal`): where the answer is a limit (``N="auto"``, graded links, the
combined model) the ideal chain's continuum limit at chi (shipped: :func:`snapping.table.limits.ideal_limit`), not
the ideal on the answer's links, whose peaks grow with them; on given links or a chain's own, the same links.

**The capping mechanism** (rule): if the real peak (of ``quantity``, default the tension) is
within 10% of the ideal's (ratio >= :data:`snapping.regimes_analysis.LEVEL` = 0.9, the
crossover of the regime studies) nothing caps it but the ideal chain's own cap (geometry, and
the links); otherwise it is the mechanism whose run *alone* comes closest to the real answer,
closeness measured as |log(alone / real)|.

The inputs (the line, its overrides ``**params``, a design's separations) are checked before any
run by :mod:`snapping.caps_inputs`, whose :class:`LineSpec` and :func:`spec` are importable from here.

:func:`design` answers at each chi of a list the same way (no N/2 check): the real and ideal
peaks, their factor and the capping mechanism per chi, and which chi keep the peaks under limits.

With ``check=True`` the full run is repeated on N/2 links: the relative change of each peak is
the answer's resolution check (the peaks of a continuous line converge as the links shrink
below the capping scale; the ideal chain's do not: its peaks grow with N).

>>> sp = spec("bungee-cord")                      # 1 m of 10 mm shock cord (snapping.lines)
>>> [m for m in MECHANISMS if sp.has(m)], round(sp.ea, 1)
(['bending', 'drag', 'stretching'], 200.0)
>>> r = cap(None, 0.3, N=16, check=False, length=2.0, mass=0.1)   # every mechanism off: the ideal chain
>>> r["cap"], r["factor"]["sigma_peak"]
('none', 1.0)
>>> spec(None, length=2.0, mass=0.1, ei=-1.0)
Traceback (most recent call last):
...
snapping._validate.SnappingInputError: ei=-1.0 is out of range: must be finite and >= 0 (N m2)
"""

from __future__ import annotations

import math
import time

from . import _validate as V
from .caps_inputs import END_MASS_MAX, SPEC_KEYS, SPEC_UNITS, LineSpec, spec  # noqa: F401 (caps' public names)
from .caps_combined import combined_links, combined_route, combined_verdict
from .caps_ideal import beside
from .caps_format import format_answer, format_design  # noqa: F401 (caps' public names)
from .caps_inputs import _pos
from .caps_inputs import as_spec as _as_spec
from .caps_inputs import check_chis as _check_chis
from .caps_runs import (GRADED_ORDER, GRID_DAMPING, MECHANISMS, QUANTITIES, STIFF_RATIO,  # noqa: F401
                        STIFF_TOL, STRETCH_LEVELS, STRETCH_METHOD, STRETCH_N, STRETCH_START, Runs, accept_factors,
                        bending_length, graded_h, graded_levels, grading_rule, method_for, problem, richardson,
                        stretch_factor, body_stretch_words)
from .caps_runs import grading_for as _grading

__all__ = ["LineSpec", "spec", "cap", "design", "decide", "unsure", "auto_hopeless", "auto_graded", "AUTO_GRADED_LINKS", "STRETCH_MATTERS", "STRETCH_N", "QUANTITIES", "MECHANISMS", "AUTO_N",
           "format_answer", "format_design"]

#: the full run's peak speed (the speed the line reaches) over the wave speed above which the stretching is run
STRETCH_MATTERS = 0.05
#: the links tried by ``N="auto"``, doubling, and the change of a peak from one to the next that stops it
AUTO_N = (100, 200, 400, 800, 1600)
RESOLVED = 0.01


def _si(sp: LineSpec, nd: dict) -> dict:
    """Nondimensional peaks in SI: speed sqrt(g L), acceleration g, tension M g."""
    u = {"v_peak": math.sqrt(sp.g * sp.length), "a_peak": sp.g, "sigma_peak": sp.mass * sp.g}
    return {q: float(nd[q]) * u[q] for q in QUANTITIES}


def cap(line=None, chi: float = 0.25, *, N: int | str | None = None, tol: float = 1e-6, quantity: str = "sigma_peak",
        check: bool = True, alone: bool = True, damping: float = GRID_DAMPING, stiff_tol: float = STIFF_TOL,
        graded="auto", stretch_method: str = STRETCH_METHOD, combined: bool = False, **params) -> dict:
    """The snap of a real line from runs of the real model, the ideal chain's beside it, and
    what caps it (the module's text says how).

    Parameters
    ----------
    line : str, snapping.lines.Line, LineSpec or None
        A catalogue line, a Line, a :class:`LineSpec`, or None (the ``params`` alone).
    chi : float
        End separation over the length, in (0, 1).
    N : int, "auto" or None
        Links of the runs (2 to 20000); ``"auto"``: doubled from 100 (:data:`AUTO_N`) until the
        full run's ``quantity`` moves by at most 1% (:data:`RESOLVED`; then ``resolved`` True
        and ``auto_N`` the links tried; not resolved at 1600: ``resolved`` False), or graded
        from the first (:func:`snapping.caps_runs.grading_rule`), or not doubled where no uniform
        links up to 1600 can resolve the fold (:func:`auto_hopeless`: ``auto_why``). None (the
        default): ``"auto"`` (since ``designres``; 200 before). A line of discrete links (a ball chain: :attr:`snapping.lines.Line.pitch`)
        is answered on its own links for None and ``"auto"`` (``own_links``; no N/2 check, no
        graded links: a chain is its links, 1% in N has no meaning), on ``N`` links if given.
    tol : float
        The fast method's (DOP853's) tolerance.
    quantity : str
        The peak that decides the capping mechanism: ``v_peak``, ``a_peak`` or ``sigma_peak``.
    check : bool
        Repeat the full run on N/2 links (the resolution check).
    alone : bool
        Run each mechanism alone (False: only the ideal and full runs, no capping mechanism).
    damping : float
        The grid damping ratio of a bending line's shortest waves (:data:`GRID_DAMPING`; 0: none,
        every run by the fast method as before).
    stretch_method : {"rodas4", "rodas4-links"}
        The elastic line's method in the stretching factor's runs (:func:`stretch_factor`; default
        :data:`STRETCH_METHOD`, node coordinates; ``"rodas4-links"``: link coordinates).
    stiff_tol : float
        RODAS4's tolerance, in the runs it takes (:func:`method_for`).
    graded : "auto", bool
        ``"auto"``: the full run on graded links, two levels extrapolated, when the line's bending
        holds a fold that N links cannot resolve (:func:`snapping.caps_runs.grading_rule`); True:
        always (a line with bending); False: never (N uniform links, as before).
    combined : bool
        Where a line with a body's stretching factor does not settle on uniform links, answer from the combined
        model on graded links (:mod:`snapping.caps_combined`; minutes of CPU); False: leave stretching out (said).
    **params
        :func:`spec`'s keywords (SI), overriding the line's.

    Returns
    -------
    dict
        ``line``, ``chi``, ``N``, ``numbers`` (nondimensional), ``ideal``, ``real``, ``full``
        (the inextensible run with every mechanism), ``alone`` ({mechanism: peaks}), each
        peaks in SI; ``factor`` (real / ideal per peak), ``cap`` (the capping mechanism or
        ``"none"``), ``rule``, ``stretching`` (what was done and why: ``run``, ``why``, and when run
        ``factor`` (the factor applied per peak, 1.0 where left out), ``resolved`` (per peak: whether
        the two levels agreed within :data:`RESOLVED`, i.e. whether the factor was applied) and
        ``levels`` (each level's links and factors, where and when its tension peaked)), ``resolution``
        (relative change N/2 -> N per peak; graded: coarse -> fine level), ``graded`` (``used``,
        ``why``, and when used ``levels`` (links of each level run), ``pair`` (the two levels
        extrapolated), ``observed_order`` (per peak, from the last three levels; None with two),
        ``stopped`` (``"within"`` or ``"max_links"``: why no finer level was run) and ``stop_why``,
        ``bending_length``, ``error`` (SI) and ``relative_error`` per peak, ``within`` (every peak's
        error <= 1%)), ``ideal_on`` (None, or where ``ideal`` is the ideal chain's continuum limit -- the
        answer a limit: ``N="auto"``, graded links, the combined model -- what it is per peak:
        :func:`snapping.caps_ideal.beside`), ``cap_why`` (a combined answer's verdict in words), ``runs`` (each run:
        what, links, method, evaluations, CPU s), ``n_rhs``, ``wall`` and ``cpu`` (s).
    """
    from .estimates import check_chi

    t0, c0 = time.perf_counter(), time.process_time()
    sp = _as_spec(line, params)
    chi = check_chi(chi)
    if quantity not in QUANTITIES:
        raise V.SnappingInputError(f"quantity={quantity!r} is not one of {tuple(QUANTITIES)}")
    tol = V.open_interval("tol", tol, 0.0, 1e-2)
    stiff_tol = V.open_interval("stiff_tol", stiff_tol, 0.0, 1e-2)
    if not isinstance(stretch_method, str) or stretch_method not in ("rodas4", "rodas4-links"):
        raise V.SnappingInputError(f"stretch_method={stretch_method!r} is not one of ('rodas4', 'rodas4-links') "
                                   f"(the elastic line's methods of the stretching factor)")
    damping = V.real("damping", damping)
    if not (math.isfinite(damping) and 0.0 <= damping <= 100.0):
        raise V.SnappingInputError(f"damping={damping!r} is out of range: the grid damping ratio must lie in [0, 100]")
    if not (graded == "auto" or graded is True or graded is False):
        raise V.SnappingInputError(f"graded={graded!r} is not one of 'auto', True, False")
    own = sp.own_links()
    if N is None or (own is not None and isinstance(N, str) and N == "auto"):
        N = "auto" if own is None else own  # (since designres; 200 links before)
    if not (isinstance(N, str) and N == "auto"):
        N = V.integer("N", N, 2, 20000)
    on_own = own is not None and N == own
    if on_own:
        check, graded = False, False
    from tqdm.auto import tqdm

    bar = tqdm(desc=f"{sp.name or 'line'}, chi={chi:g}", unit="run", leave=False, disable=None)  # (off without a terminal)
    try:
        runs = Runs(sp, chi, tol, stiff_tol, damping, stretch_method, bar=bar, combined=combined)
        runs.limit = N == "auto"  # (links chosen until the answer settles: the ideal's limit beside it)
        if N == "auto":
            r = _auto(runs, quantity, alone, graded)
        else:
            r = _answer(runs, N, quantity, check and N >= 4, alone, graded)
    finally:
        bar.close()
    if own is not None:
        r["own_links"] = {"links": own, "pitch": sp.pitch, "used": on_own,
                          "why": (f"a chain of {own} discrete links (pitch {sp.pitch * 1e3:.4g} mm): answered on them, "
                                  f"no limit in N sought" if on_own else
                                  f"a chain of {own} discrete links answered on N = {N} as asked")}
        if on_own:
            r["resolved"] = True  # (its links are the line's: exact in N)
    if r["stretching"].get("combined") and "resolved" in r:  # (the real answer is the combined model's)
        r["resolved"] = r["stretching"]["resolved"][quantity]
    r.update({"runs": runs.log, "n_rhs": sum(x["n_rhs"] for x in runs.log), "wall": time.perf_counter() - t0,
              "cpu": time.process_time() - c0})
    return r


def _answer(runs: Runs, N: int, quantity: str, check: bool, alone: bool, graded="auto") -> dict:
    """One answer on ``N`` links (the runs of ``runs``, each made once)."""
    sp, chi = runs.sp, runs.chi
    present = [m for m in MECHANISMS[:-1] if sp.has(m)]
    ideal_nd = runs.get((), N)
    limit_links = None  # (a limit answer's graded links: the stand-in for a peak without a shipped ideal limit)
    grade = _grading(runs, N, present, graded)
    if grade["used"]:
        on, lb = tuple(present), bending_length(sp)
        gl = graded_levels(lambda k: runs.graded(on, k), lambda k: graded_h(chi, lb, k).size, RESOLVED)
        lv = [gl["levels"][k] for k in gl["pair"]]  # the two extrapolated: the last two levels run
        full_nd = {**gl["extrapolated"], "method": lv[1]["method"]}
        grade.update(levels=[x["links"] for x in gl["levels"]], pair=gl["pair"], order=GRADED_ORDER,
                     relative_error=gl["relative_error"], observed_order=gl["observed_order"],
                     stopped=gl["stopped"], stop_why=gl["why"], levels_peaks=[_si(sp, x) for x in gl["levels"]])
        grade["error"] = _si(sp, gl["error"])
        grade["within"] = gl["stopped"] == "within"
        check = False
        limit_links = [(graded_h(chi, lb, k), f"graded {k}") for k in gl["pair"]]
    else:
        full_nd = runs.get(tuple(present), N)
    alone_nd = {}
    if alone:
        for m in present:
            alone_nd[m] = runs.get((m,), N)
    stretching = {"run": False}
    factor_s = {q: 1.0 for q in QUANTITIES}
    if sp.has("stretching"):
        c = math.sqrt(sp.ea / (sp.mass / sp.length)) / math.sqrt(sp.g * sp.length)
        ratio = full_nd["v_peak"] / c  # the speed the line reaches: the full run's, not the ideal chain's
        stretching.update({"wave_speed": c * math.sqrt(sp.g * sp.length), "v_over_c": ratio,
                           "v_over_c_ideal": ideal_nd["v_peak"] / c})
        if ratio >= STRETCH_MATTERS:
            body = "bending" in present or "drag" in present  # the combined model's factor (stretchbody)
            sl = runs.stretching_body(present) if body else [stretch_factor(sp, chi, runs.tol, n, method=runs.stretch_method)
                                                             for n in STRETCH_LEVELS]
            for f in sl:
                runs.log.append({"run": "stretching", "N": f["N"], "method": f.get("method", "elastic " + runs.stretch_method),
                                 "tol": runs.tol, "n_rhs": f["n_rhs"], "cpu": f["cpu"]})
            factor_s, ok = accept_factors(*({q: f[q] for q in QUANTITIES} for f in sl), RESOLVED)
            cg = None
            if body and runs.combined and not all(ok.values()):  # unsettled: the combined model on graded links answers
                cg = combined_route(runs, present, full_nd, sl, ok)
                factor_s, ok = cg["factor"], cg["resolved"]
            stretching.update({"run": True, "factor": factor_s, "resolved": ok, "N": sl[1]["N"], "body": body,
                               "model": "combined (elastic + body) over inextensible" if body else "elastic over rigid",
                               "levels": [{"N": f["N"], **{q: f[q] for q in QUANTITIES}, "s_sigma": f["s_sigma"],
                                           "t_sigma": f["t_sigma"], "t_snap": f["t_snap"]} for f in sl],
                               "strain_peak": sl[1]["strain_peak"],
                               "why": f"v_peak/c = {ratio:.3g} >= {STRETCH_MATTERS:g} (the full run's; the ideal chain's "
                                      f"{stretching['v_over_c_ideal']:.3g}): run ("
                                      + (body_stretch_words(sp, sl, ok) if body else
                                         f"elastic over rigid on {sl[0]['N']} and {sl[1]['N']} links")
                                      + "); " + stretch_words(sl, ok)
                                      + ("" if all(ok.values()) else unresolved_stretching_words(ratio, body))})
            if cg is not None:  # (its links: the ideal's stand-in where no shipped limit exists, caps_ideal)
                stretching.update(model="combined (elastic + body) on graded links", combined=cg, why=cg["why"])
                limit_links = [(combined_links(chi, k), f"combined level {k}") for k in cg["pair"]]
            if alone and not body:  # (with a body the factor is stretching's with it, not alone: no such run)
                alone_nd["stretching"] = {q: ideal_nd[q] * factor_s[q] for q in QUANTITIES}
        else:
            stretching["why"] = (f"v_peak/c = {ratio:.3g} < {STRETCH_MATTERS:g} (the full run's; the ideal chain's "
                                 f"{stretching['v_over_c_ideal']:.3g}): left out (the line is inextensible at the speed it "
                                 "reaches)")
    else:
        stretching["why"] = "no EA given: inextensible"
    real_nd = {q: full_nd[q] * factor_s[q] for q in QUANTITIES}
    resolution = None
    if grade["used"]:
        resolution = {q: (lv[1][q] - lv[0][q]) / lv[1][q] for q in QUANTITIES}
        grade["error"] = {q: grade["error"][q] * factor_s[q] for q in QUANTITIES}
    if check:
        half = runs.get(tuple(present), N // 2)
        resolution = {q: (full_nd[q] - half[q]) / full_nd[q] for q in QUANTITIES}
    ideal_on = None
    if runs.limit or limit_links is not None:  # a limit answer: the ideal's continuum limit beside it (caps_ideal)
        ideal_nd, ideal_on = beside(runs, ideal_nd, limit_links)
        ideal_on.update(uniform=_si(sp, ideal_on["uniform"]), N=N)
    factor = {q: real_nd[q] / ideal_nd[q] for q in QUANTITIES}
    judged = {m: v[quantity] for m, v in alone_nd.items() if m != "stretching" or stretching["resolved"][quantity]}
    capped = decide(factor[quantity], real_nd[quantity], judged,
                    bool(present or (stretching["run"] and stretching["resolved"][quantity])), alone)
    extra, rule_c = {}, ""
    if stretching.get("combined"):  # (the verdict splits the ratio on the same links: :func:`combined_verdict`)
        capped, why = combined_verdict(stretching["combined"], quantity, factor[quantity], judged,
                                       lambda a: decide(0.0, real_nd[quantity], a, True, alone))
        extra = {"cap_why": why}
        rule_c = ("; combined: against the ideal's continuum limit, the mechanism of the larger step "
                  "down on the finest level (stretching's, or the body's by the runs alone)")
    from .regimes_analysis import LEVEL

    rule = (f"{quantity}: real/ideal >= {LEVEL:g} -> none (the ideal chain's own cap: geometry and links); else the "
            f"mechanism whose run alone is closest to the real answer in |log(alone/real)|") + rule_c
    return {"line": sp.name, "chi": chi, "N": N, "tol": runs.tol, "quantity": quantity, "numbers": sp.numbers(N),
            "mechanisms": present + (["stretching"] if stretching["run"] else []),
            "ideal": _si(sp, ideal_nd), "full": _si(sp, full_nd), "real": _si(sp, real_nd),
            "alone": {m: _si(sp, v) for m, v in alone_nd.items()}, "factor": factor, "cap": capped, "rule": rule,
            "stretching": stretching, "resolution": resolution, "damping": runs.damping, "graded": grade,
            "methods": {"ideal": ideal_nd["method"], "full": full_nd["method"]}, "ideal_on": ideal_on, **extra}


def stretch_words(levels: list, resolved: dict) -> str:
    """What the stretching factor did, peak by peak (``levels``: :func:`stretch_factor`'s two,
    ``resolved``: :func:`accept_factors`'): applied where the two levels agree within
    :data:`RESOLVED`, left out (and said so) where they do not."""
    a, b = levels
    arrow = {q: f"{a[q]:.4g} -> {b[q]:.4g}" for q in QUANTITIES}
    on = [f"{q} x{b[q]:.4f} ({arrow[q]})" for q in QUANTITIES if resolved[q]]
    off = [f"{q} ({arrow[q]})" for q in QUANTITIES if not resolved[q]]
    words = []
    if on:
        words.append(f"applied where the two agree within {RESOLVED:.0%}: " + ", ".join(on)
                     + " (the real answer is the full run times it: the factors taken as independent)")
    if off:
        words.append(f"NOT applied, not resolved in the links (they differ by more than {RESOLVED:.0%}): "
                     + ", ".join(off) + ": the real answer leaves stretching out of "
                     + ("it" if len(off) == 1 else "them"))
    return "; ".join(words)


def unresolved_stretching_words(v_over_c: float, body: bool = False) -> str:
    """What leaving an unresolved stretching factor out means, said beside it: the answer's error bars
    are the inextensible runs' and do not hold stretching, whose effect at the speed the line reaches
    (``v_over_c``) the elastic guide measured (peaks changed by 0.1-0.3% at v/c 1-3%, 4-11% near 0.2).
    Why the factor does not settle: it is the ideal chain's (the elastic model has no bending or drag),
    whose snap and v/c grow with the links (the bungee cord at chi 0.25, tension ratio 0.913, 0.715,
    0.654, 0.638 on 30-240 links)."""
    return (f" (so the error bars above do not hold stretching: at v/c = {v_over_c:.2g} it is not negligible -- the "
            f"elastic guide measured peaks changed by 0.1-0.3% at v/c 1-3%, 4-11% near 0.2; "
            + ("the combined model's fold is not resolved on uniform links; combined=True answers on graded links)" if body else
               "the factor is the ideal chain's, whose v/c grows with its links, not this line's)"))


def decide(factor: float, real: float, alone: dict, acts: bool = True, tried: bool = True) -> str:
    """The capping mechanism (the module's rule): ``"none"`` when the real/ideal ``factor`` is
    at least :data:`snapping.regimes_analysis.LEVEL` (or nothing acts), else the mechanism of
    ``alone`` ({mechanism: its peak alone}) nearest ``real`` in |log(alone/real)|."""
    from .regimes_analysis import LEVEL

    if factor >= LEVEL or not acts:
        return "none"
    if not (tried and alone):
        return "not decided (alone=False)"
    return min(alone, key=lambda m: abs(math.log(alone[m] / real)))


def _auto(runs: Runs, quantity: str, alone: bool, graded="auto") -> dict:
    """``N="auto"``: the full run on :data:`AUTO_N` links, doubling, until ``quantity`` moves by at
    most :data:`RESOLVED` from one to the next (or the last); then the answer on those links, its
    resolution the last two full runs' (each run made once). An answer that takes graded links on
    the first of them (:func:`_grading`) is that answer, resolved when its error is within 1%."""
    on = tuple(m for m in MECHANISMS[:-1] if runs.sp.has(m))
    first = _grading(runs, AUTO_N[0], list(on), graded)
    if first["used"]:
        r = _answer(runs, AUTO_N[0], quantity, False, alone, graded)
        r["auto_N"] = [AUTO_N[0]]
        r["resolved"] = r["graded"]["relative_error"][quantity] <= RESOLVED
        return r
    why = auto_hopeless(first)
    if why:  # no uniform links up to AUTO_N[-1] resolve it, graded ones are too fine: not doubled (said)
        r = _answer(runs, AUTO_N[0], quantity, True, alone, graded)
        r.update(auto_N=[AUTO_N[0]], resolved=False, auto_why=why)
        return r
    why = auto_graded(runs, first, graded)
    if why:  # uniform links up to AUTO_N[-1] cannot reach the bending length: graded, though the rule kept them
        r = _answer(runs, AUTO_N[0], quantity, False, alone, True)
        r["graded"]["why"] = why
        r["auto_N"] = [AUTO_N[0]]
        r["resolved"] = r["graded"]["relative_error"][quantity] <= RESOLVED
        return r
    tried = []
    for n in AUTO_N:
        tried.append(n)
        if len(tried) > 1:
            cur, prev = runs.get(on, n), runs.get(on, tried[-2])
            if abs(cur[quantity] - prev[quantity]) <= RESOLVED * abs(cur[quantity]):
                break
        else:
            runs.get(on, n)
    n = tried[-1]
    r = _answer(runs, n, quantity, False, alone, graded)
    cur, prev = runs.get(on, n), runs.get(on, tried[-2])
    r["resolution"] = {q: (cur[q] - prev[q]) / cur[q] for q in QUANTITIES}
    r["resolved"] = abs(r["resolution"][quantity]) <= RESOLVED
    r["auto_N"] = tried
    return r


def auto_hopeless(grading: dict) -> str:
    """Why ``N="auto"`` does not double the links (``""``: it does): the grading on the first
    links (:func:`snapping.caps_runs.grading_for`'s answer) found a fold that collapses onto them
    which graded links would resolve but for their cost (``too_fine``: the finer level over
    :data:`snapping.caps_runs.MAX_GRADED_LINKS`), and the bending length is under
    :data:`snapping.caps_runs.GRADE_LINKS` links even on the last of :data:`AUTO_N`: no uniform
    links it would try reach the scale that holds the fold (the climbing rope at chi 0.05 and 0.1:
    0.31 links on 1600, where its tension still moved 35% from 800; 10.8 s of CPU for nothing).

    >>> auto_hopeless({"used": False, "too_fine": 5552, "bending_length": 1.91e-4})[:45]
    'the fold collapses onto the links and graded '
    >>> auto_hopeless({"used": False, "too_fine": 5552, "bending_length": 0.02}), auto_hopeless({"used": False})
    ('', '')
    """
    from .caps_runs import GRADE_LINKS, MAX_GRADED_LINKS

    n, lb = grading.get("too_fine"), grading.get("bending_length", 0.0)
    if grading.get("used") or not n or not lb or lb * AUTO_N[-1] >= GRADE_LINKS:
        return ""
    return (f"the fold collapses onto the links and graded links would need {n} (> {MAX_GRADED_LINKS}); the "
            f"bending length ({lb:.3g} L) is {lb * AUTO_N[-1]:.2g} links even on {AUTO_N[-1]} (< {GRADE_LINKS:g}): "
            f"no uniform links up to {AUTO_N[-1]} resolve it, so they were not doubled: NOT resolved, on "
            f"{AUTO_N[0]} links")


#: the most links of the finer graded level that ``N="auto"`` runs when uniform links cannot reach the bending
#: length (:func:`auto_graded`): the climbing rope's 5552 at chi 0.2 (levels 2785 and 5552: 5.6 s of CPU for its
#: whole answer, load 1.7; at chi 0.25-0.5, since ``heldarm``'s floor on the fold's links, 4220 down to 1552: 5.0-2.4 s)
AUTO_GRADED_LINKS = 6000


def auto_graded(runs, grading: dict, graded="auto") -> str:
    """Why ``N="auto"`` takes graded links where the grading rule on its first links did not
    (``""``: it does not): the line has bending, ``graded`` is ``"auto"``, the bending length is
    under :data:`snapping.caps_runs.GRADE_LINKS` links even on the last of :data:`AUTO_N` (uniform
    links it would try never resolve the bending length at the free end, where the peaks then converge
    at first order: the climbing rope at chi 0.25, v 124.7, 134.1, 139.1, 141.6 m/s on 400-3200 links,
    its graded levels 143.96 and 143.98), and the finer graded level is at most
    :data:`AUTO_GRADED_LINKS` links."""
    from .caps_runs import GRADE_LINKS, bending_length

    if graded != "auto" or grading.get("used") or grading.get("why") == "no bending":
        return ""
    lb = bending_length(runs.sp)
    if not (0.0 < lb and lb * AUTO_N[-1] < GRADE_LINKS):
        return ""
    n = graded_h(runs.chi, lb, 1).size
    if n > AUTO_GRADED_LINKS:
        return ""
    return (f"the bending length ({lb:.3g} L) is {lb * AUTO_N[-1]:.2g} links even on {AUTO_N[-1]} (< {GRADE_LINKS:g}): "
            f"uniform links up to {AUTO_N[-1]} do not resolve the free end, graded links (finer level {n} <= "
            f"{AUTO_GRADED_LINKS}) do")


def design(line=None, chis=(0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5), *, N: int | None = None, tol: float = 1e-6,
           max_tension=None, max_speed=None, max_acceleration=None, quantity: str = "sigma_peak",
           alone: bool = True, damping: float = GRID_DAMPING, stiff_tol: float = STIFF_TOL, graded="auto",
           combined: bool = False, **params) -> dict:
    """Which end separations keep the real line's peaks under the limits: :func:`cap` at each chi
    of ``chis`` (the ideal, full and, with ``alone``, each-mechanism-alone runs; no N/2 check).
    ``rows`` per chi: ``ideal`` and ``real`` peaks, ``factor`` (real/ideal per peak), ``cap``
    (the mechanism that capped the snap at that chi, decided on ``quantity``: :func:`cap`'s rule),
    ``graded`` (:func:`cap`'s: the real peaks from graded links, extrapolated, with their error),
    ``admissible`` (real peaks under every limit) and ``ideal_admissible`` beside it, ``unsure`` (why the
    real peaks may be off: :func:`unsure`; ``admissible_chi`` lists only rows under the limits with nothing
    unsure, ``admissible_unsure`` the others under them, with why), ``N`` (the
    row's links) and ``resolved``. ``N``: the links of every run; None (the default) or ``"auto"``:
    each chi on the links that resolve it, :func:`cap`'s ``N="auto"`` (since ``designres``; 200
    links for every chi before), a line of discrete links on its own. ``combined``: :func:`cap`'s (the
    combined model on graded links where a line with a body's stretching factor does not settle)."""
    sp = _as_spec(line, params)
    chis = _check_chis(chis)
    own = sp.own_links()
    if N is None or (isinstance(N, str) and N == "auto"):
        N = "auto" if own is None else own
    else:
        N = V.integer("N", N, 2, 20000)
    if quantity not in QUANTITIES:
        raise V.SnappingInputError(f"quantity={quantity!r} is not one of {tuple(QUANTITIES)}")
    limits = {}
    for k, q, v in (("max_tension", "sigma_peak", max_tension), ("max_speed", "v_peak", max_speed),
                    ("max_acceleration", "a_peak", max_acceleration)):
        if v is not None:
            limits[q] = _pos(k, v, QUANTITIES[q])
    if not limits:
        raise V.SnappingInputError("give at least one limit: max_tension (N), max_speed (m/s) or max_acceleration "
                                   "(m/s^2)")
    t0, c0 = time.perf_counter(), time.process_time()
    rows, n_rhs = [], 0
    from tqdm.auto import tqdm

    for chi in tqdm(sorted(chis), desc=f"design {sp.name or 'line'}", unit="chi", leave=False, disable=None):
        r = cap(sp, chi, N=N, tol=tol, check=False, alone=alone, quantity=quantity, damping=damping,
                stiff_tol=stiff_tol, graded=graded, combined=combined)
        n_rhs += r["n_rhs"]
        rows.append({"chi": r["chi"], "ideal": r["ideal"], "real": r["real"], "factor": r["factor"], "cap": r["cap"],
                     "alone": r["alone"], "mechanisms": r["mechanisms"], "graded": r["graded"],
                     "stretching": r["stretching"], "N": r.get("N", N), "resolved": _row_resolved(r),
                     "ideal_on": r.get("ideal_on"), "cap_why": r.get("cap_why"),
                     "admissible": all(r["real"][q] <= lim for q, lim in limits.items()),
                     "ideal_admissible": all(r["ideal"][q] <= lim for q, lim in limits.items())})
    for r in rows:
        r["unsure"] = unsure(r, limits)
    ok = [r["chi"] for r in rows if r["admissible"] and not r["unsure"]]
    maybe = [{"chi": r["chi"], "why": r["unsure"]} for r in rows if r["admissible"] and r["unsure"]]
    return {"line": sp.name, "N": N, "limits": limits, "quantity": quantity, "rows": rows, "admissible_chi": ok,
            "admissible_unsure": maybe,
            "numbers": sp.numbers(None if N == "auto" else N), "n_rhs": n_rhs, "wall": time.perf_counter() - t0,
            "cpu": time.process_time() - c0}


def unsure(row: dict, limits: dict) -> list[str]:
    """Why a design row's real peaks may not be what the line does (empty: nothing known against them): not
    resolved in its links (``resolved`` False), or a stretching factor left out (not resolved, no combined
    answer) on a peak under a limit -- stretching can raise it (the bungee cord's tension x1.21-1.28) or
    lower it (the climbing rope's x0.5-0.7). A row under the limits for which this is not empty is not
    counted admissible (:func:`design`'s ``admissible_unsure``)."""
    why = []
    if row.get("resolved") is False:
        why.append("not resolved in the links")
    st = row.get("stretching") or {}
    left = [q for q in limits if st.get("run") and not st.get("resolved", {}).get(q, True)]
    if left:
        why.append(f"stretching left out of {', '.join(left)} (its factor not resolved; combined=True answers it)")
    return why


def _row_resolved(r: dict):
    """A design row's verdict: :func:`cap`'s ``resolved`` where it gives one (``N="auto"``, own links),
    else None (given links: no check in a design)."""
    return r.get("resolved")
