"""The runs of a design answer (:func:`snapping.caps.cap`): the real model's problem of a line
(:func:`problem`), the method of each run (:func:`method_for`: stiff runs by RODAS4 on grid-damped
fast waves, the others by the fast method as they were), each run made once (:class:`Runs`),
and the stretching factor (:func:`stretch_factor`).

Why the rule. A bending line's shortest waves (frequency ~ 4 sqrt(B/lambda)/h^2) hold an
explicit method to steps ~ 6/omega: at 1000 links the bullwhip's full run took 809,892
evaluations of DOP853 (27 s of CPU) and the bungee cord's 511,706. RODAS4 (L-stable) is not held
by them once they are damped: :func:`snapping.simulate.stiffness.grid_damping` gives the waves
faster than ``omega_min`` (those that would hold DOP853 to more than :data:`STIFF_RATIO` times its
accuracy-limited steps) the damping ratio :data:`GRID_DAMPING`, a damping that vanishes as h^2.
Only those: damping every node (the regime studies' grid damping) moved the bending-alone peaks of
the thin lines (whose fold reaches the grid) by up to 19% at 1000 links; damping the fast waves
only moves every peak of every catalogue answer by at most 0.07% (N 100-1000,
``benchmarks/bench_caps.py``). A run with no such wave is DOP853's, undamped, bit for bit as before.
"""

from __future__ import annotations

import math
import time

import numpy as np

__all__ = ["problem", "method_for", "Runs", "stretch_factor", "GRID_DAMPING", "STIFF_TOL", "STIFF_RATIO",
           "STRETCH_N", "STRETCH_LEVELS", "STRETCH_START", "STRETCH_METHOD", "accept_factors",
           "stretch_factor_body", "STRETCH_BODY_LEVELS", "STRETCH_BODY_METHOD", "STRETCH_BODY_TOL", "body_stretch_words", "QUANTITIES",
           "MECHANISMS", "bending_length", "graded_h", "richardson", "GRADED_TOL",
           "GRADED_DAMPING", "GRADED_ORDER", "GRADE_LINKS", "COLLAPSE", "MAX_GRADED_LINKS", "grading_rule",
           "MAX_ESCALATED_LINKS", "FOLD_FRAC", "grading_for", "graded_levels", "observed_order", "GRADED_WITHIN"]

#: links of the coarser level of the elastic and rigid runs that give the stretching factor
STRETCH_N = 30
#: the stretching factor's two levels (:func:`accept_factors`: a peak's factor is applied only where they agree)
STRETCH_LEVELS = (STRETCH_N, 2 * STRETCH_N)
#: the elastic line's start in the stretching runs: the rigid chain's release (no release wave;
#: :func:`snapping.simulate.elastic_statics.matched`), the release the full run makes
STRETCH_START = "matched"
#: the elastic line's method in the stretching runs: the compiled RODAS4 (exact banded Jacobian); at tol 1e-6
#: its peaks are within 1e-5 of DOP853's on the nylon line's 30 and 60 links, at 0.13-0.56 s of CPU against 0.66-1.12
STRETCH_METHOD = "rodas4"
#: the stretching factor's two levels for a line with a body (bending or drag; :func:`stretch_factor_body`):
#: uniform links, shared lumping. 50/100: the bungee cord's factors at chi 0.25 agree within 1% there
#: (sigma 1.268 / 1.275 / 1.279 on 50 / 100 / 200; the combined runs 1.2 / 1.5 / 2.8 s of CPU)
STRETCH_BODY_LEVELS = (50, 100)
#: the combined model's method (the elastic line with a body): RODAS4 (a body since branch rodasbody), closer to the
#: converged factor than Radau at the same tolerance and 2-4x cheaper (the bungee cord at chi 0.05 on 100 links,
#: tol 1e-5 against Radau's and RODAS4's 1e-8, which agree to 1e-7: a_peak's factor off by 4.3e-5 (Radau 2.1e-4), v's
#: 4.2e-5 (1.1e-4); CPU of the two levels: the bungee cord 0.5-0.6 s (Radau 0.9-2.2), the climbing rope 0.4-1.2 s
#: (1.6-3.4), chi 0.05-0.4; factors moved by at most 1.7e-4)
STRETCH_BODY_METHOD = "rodas4"
#: ... at this tolerance: against 1e-6 its factors move by at most 3e-5 relative (the climbing rope at chi 0.15, the
#: bungee cord at 0.25, 50 and 100 links) at 55-90% of the CPU (1e-4 moved the bungee's a_peak factor 0.6%)
STRETCH_BODY_TOL = 1e-5
#: RODAS4's tolerance in the runs it takes (:func:`method_for`)
STIFF_TOL = 1e-4
#: a run is stiff when DOP853's stability limit needs more than this many times its accuracy-limited steps
STIFF_RATIO = 10.0
#: the damping ratio given to the stiff runs' fast waves (:func:`snapping.simulate.stiffness.grid_damping`)
GRID_DAMPING = 1.0
#: graded runs (:meth:`Runs.graded`): RODAS4's tolerance, the damping ratio of every node's shortest
#: bending wave, and the order of convergence their Richardson extrapolation assumes (measured on the
#: nylon line, chi 0.25, levels of 535, 1054 and 2091 links: 1.92 in the tension, 1.9 in the speed)
GRADED_TOL = 1e-3
#: the graded runs' stage solves where the line has drag (``run(drag_jacobian=...)``): ``"banded"`` (drag
#: left out of RODAS4's Jacobian) or ``"correct"`` (each stage corrected once for it; branch ``dragcorr``)
GRADED_DRAG_JACOBIAN = "correct"
GRADED_DAMPING = 0.01
GRADED_ORDER = 2.0
#: the coarser graded level, in bending lengths: links along the fold's path at most FOLD_LINK (at the
#: fold's scale there, ``grading.fold_following``), at the free end TIP_LINK, the held arm HELD_LINK;
#: the finer level halves them all
FOLD_LINK, TIP_LINK, HELD_LINK = 1.5, 0.4, 20.0
#: ... but the fold's links are never finer than FOLD_FRAC of the fold's radius on the crude law
#: ``a (2x)^(1/4)`` (``a`` the catenary parameter): where the catenary's fold is wider than FOLD_LINK/FOLD_FRAC
#: = 150 bending lengths (the climbing rope at chi > 0.2, a drag-capped fold: its smallest radius along the
#: path 338-572 l_b at chi 0.5, where FOLD_LINK alone gave links of 0.56-1.5 l_b, 1/600-1/380 of it;
#: ``bench_caps.py --profile climbing-rope --chi 0.5 --levels 0``) the links follow the fold, not the
#: bending length. Every other catalogue line's ladder is unchanged at chi <= 0.5 (the nylon line's
#: FOLD_LINK l_b/a is 0.013 at chi 0.5), and so is the climbing rope's at chi <= 0.2 (0.0103 at 0.2; at
#: chi 0.15, unresolved on the old ladder, a floor of 0.02 took the acceleration's error bar from 2.5% to
#: 4.7%: there bending holds the fold). The climbing rope at chi 0.5: 782/1552 links, 2.2 s of CPU, against
#: 2785/5552, 9.4 s; the peaks within 0.03% of the old ones (docs/guide/caps.md, "The climbing rope's ladder").
#: A floor on the held arm's links instead saves nothing: it holds 122 of the 2785 links (x > 0.6 from the free
#: end), the fold's path 2551; the held arm's links at 0.05 L give 2713.
FOLD_FRAC = 0.01
#: the peaks answered: (name, SI units)
QUANTITIES = {"v_peak": "m/s", "a_peak": "m/s^2", "sigma_peak": "N"}
#: the mechanisms, in the order they are tried
MECHANISMS = ("bending", "drag", "end-mass", "taper", "stretching")


def problem(sp, chi: float, N: int, on=MECHANISMS, *, lumping: str = "paper",
            damping: float = 0.0, omega_min: float = 0.0, h=None):
    """The catenary start of ``sp`` at ``chi`` on ``N`` links with the mechanisms ``on`` (the
    inextensible model's: stretching is not part of it); with bending, the grid damping of
    ratio ``damping`` on the waves faster than ``omega_min``
    (:func:`snapping.simulate.stiffness.grid_damping`; 0: none). ``h``: graded links instead
    (nondimensional lengths, index 0 at the free end, :func:`graded_h`; masses lumped
    ``"shared"``; ``N`` is then ignored)."""
    import numpy as np

    from .simulate import Body, Links, Problem

    tip = sp.end_mass / sp.mass if "end-mass" in on else 0.0
    if "taper" in on and sp.has("taper"):
        ln, L = sp.line, sp.length
        lam = sp.mass / L
        def density(u):  # lambda0 r^2 / lambda, r^2 by Python's float power: the numbers of a scalar call, bit for bit
            r = ln.ratio(L * (1.0 - u), L)
            return ln.mass_per_length * np.reshape([x ** 2 for x in r.ravel().tolist()], r.shape) / lam

        links = Links.from_density(np.full(N, 1.0 / N) if h is None else h, density, tip_mass=tip, kind="line",
                                   params={"line": ln.name}, vectorized=True)
    elif h is not None:
        links = Links.graded(h, tip_mass=tip)
    else:
        links = Links.uniform(N, tip_mass=tip, lumping=lumping)
    kw = {}
    if "bending" in on and sp.has("bending"):
        kw["ei"] = sp.ei
    if "drag" in on and sp.has("drag"):
        kw.update(diameter=sp.diameter, cd_normal=sp.cd_normal if sp.diameter is not None else None,
                  cd_tangential=sp.cd_tangential if sp.diameter is not None else None, air_density=sp.air_density,
                  tip_drag_area=sp.tip_drag_area)
    body = _on_nodes(Body.from_si(sp.length, sp.mass, sp.g, **kw), links.h) if kw else None
    if damping > 0.0 and "ei" in kw:
        from .simulate.stiffness import grid_damping

        eta = grid_damping(links.h, links.m, body.node_values("bending", links.h), damping, omega_min)
        body = Body(body.bending, damping=eta, wind=body.wind, tip_drag=body.tip_drag, clamp=body.clamp,
                    **{k: getattr(body, k) for k in ("curvature", "drag_normal", "drag_tangential",
                                                     "drag_linear_normal", "drag_linear_tangential")})
    return Problem.catenary(chi, links=links, body=body if body is not None and body.active else None)


_BODY_PROFILES = ("bending", "curvature", "damping", "drag_normal", "drag_tangential", "drag_linear_normal",
                  "drag_linear_tangential")


def _on_nodes(body, h):
    """``body`` with each profile given as a function of s (a taper's) replaced by its values at the nodes
    of the chain with links ``h`` (:meth:`snapping.simulate.Body.node_values`: the same numbers, bit for
    bit), so that the run reads them once rather than calling the function at every node each time it
    needs them (the fly line's answer at chi 0.1, 12 runs, called :meth:`Body.node_values` 358 times: 180,885
    calls of the profile functions; with the taper's masses, 1.3-2.2 s of its 11-13 s, load ~4)."""
    from .simulate import Body

    if not any(callable(getattr(body, k)) for k in _BODY_PROFILES):
        return body
    kw = {k: body.node_values(k, h) if callable(getattr(body, k)) else getattr(body, k) for k in _BODY_PROFILES}
    return Body(kw.pop("bending"), wind=body.wind, tip_drag=body.tip_drag, clamp=body.clamp, **kw)


def method_for(problem_, tol: float, stiff_tol: float = None) -> tuple[str, float, float]:
    """``(method, tol, omega_min)`` of one run of :func:`snapping.caps.cap`: a run whose bending waves would hold
    DOP853 to more than :data:`STIFF_RATIO` times its accuracy-limited steps (the shortest wave
    faster than ``omega_min = STIFF_RATIO R_DOP853 n_acc / T_SNAP``, with
    :func:`snapping.simulate.stiffness.accuracy_steps` ``n_acc`` and DOP853's stability boundary
    ``R_DOP853``) is stiff: RODAS4 (``"rodas4"``) at ``stiff_tol`` (default :data:`STIFF_TOL`),
    the waves faster than ``omega_min`` grid-damped (:func:`problem`); any other run is the fast
    method's (DOP853) at ``tol``, undamped, as without this rule (``omega_min`` 0)."""
    from .simulate import stiffness as S

    body = getattr(problem_, "body", None)
    if body is None or not body.has_bending:
        return "fast", tol, 0.0
    om, _ = S.shortest_wave(problem_.model())
    omega_min = STIFF_RATIO * S.R_DOP853 * S.accuracy_steps(problem_.N, tol) / S.T_SNAP
    if om > omega_min:
        return "rodas4", STIFF_TOL if stiff_tol is None else stiff_tol, omega_min
    return "fast", tol, 0.0


def bending_length(sp) -> float:
    """The bending length at the free end over the line's length, nondimensional: ``sqrt(EI /
    (lambda g L))/L`` with the free end's EI and mass per length (a taper's there), the length
    over which bending holds a fold against tension of the order of the line's weight (the
    nylon line: 1.0e-3, its snap's fold has radius 1.1e-3 L); 0 without bending there."""

    L = sp.length
    ei = sp.ei(L) if callable(sp.ei) else sp.ei
    lam = sp.mass / L
    if sp.line is not None and sp.line.taper is not None:
        lam = sp.line.mass_per_length * sp.line.ratio(0.0, L) ** 2
    return math.sqrt(ei / (lam * sp.g * L)) / L if ei > 0.0 else 0.0


def graded_h(chi: float, lb: float, level: int) -> np.ndarray:
    """The links of graded level ``level`` (0 or 1) of a line whose bending length is ``lb``
    (nondimensional, :func:`bending_length`): ``grading.fold_following`` with the links along the
    fold's path at most :data:`FOLD_LINK` lb but not below :data:`FOLD_FRAC` of its radius (the
    fold's at most half its radius), :data:`TIP_LINK` lb at the free end and :data:`HELD_LINK` lb on
    the held arm (each at most 0.5 L), all halved on level 1 (the nylon line: 545 and 1072 links, at
    every chi <= 0.5; the climbing rope: 2785 and 5552 at chi <= 0.2, 782 and 1552 at 0.5)."""
    from . import estimates
    from .simulate import grading

    k = 0.5 ** int(level)
    a = estimates.catenary_parameter(chi)
    h_max = min(0.5, HELD_LINK * lb)  # level 0's, capped before the halving: the levels stay halvings
    h_min = min(h_max, TIP_LINK * lb)
    frac = min(0.5, max(FOLD_LINK * lb / a, FOLD_FRAC))  # the fold's links: FOLD_LINK l_b, or FOLD_FRAC of its radius
    return grading.fold_following(chi, frac=frac * k, h_min=h_min * k, h_max=h_max * k)


#: graded links are used when the bending length is under this many links at the free end (uniform links
#: converge at first order there: the nylon line's tension is still 6% off at 3 links per bending length,
#: so 1% needs about 20) ...
GRADE_LINKS = 20.0
#: ... and without bending the fold collapses onto one link: the curvature peak times the free end's link
#: at least this (pi/2: folded past a right angle at one node; the nylon line's drag alone: pi at N >= 200,
#: 2.3 at 100; every other catalogue line's run without bending: at most 0.7 at N >= 100, falling as 1/N;
#: at N = 20 they reach 1.2-2.2, and the bungee cord's, 0.8 links per bending length, is graded there).
#: Below it, a fold that collapses is told by links half as long: its curvature peak times the link does
#: not fall (the nylon line's drag alone at chi 0.2: 0.61 on 100 links, 1.50 on 200, 3.14 on 400), where a
#: fold held above the links narrows with them (every other catalogue line's, chi 0.1-0.5, 25-400 links:
#: by a factor 0.5-0.8 per halving)
COLLAPSE = 1.5707963267948966
#: the most links of the finer graded level (the nylon line's: 1072; their cost grows as 1/lb): a line
#: whose bending length is shorter is answered on its uniform links, and the answer says it is not resolved
MAX_GRADED_LINKS = 2500
#: the most links of a level run by the escalation (:func:`graded_levels`): the fly line's level 3 at
#: chi 0.1 (3810 links; 4.8 s of CPU with drag in the stage solves, `caps_runs.GRADED_DRAG_JACOBIAN`)
#: fits, the nylon line's at chi 0.25 (4236) does not
MAX_ESCALATED_LINKS = 4000


def grading_rule(lb: float, h_tip: float, kappa_h=None, where: str = "without bending",
                 halved=None) -> tuple[bool, str]:
    """``(graded, why)``: whether an answer needs graded links (:meth:`Runs.graded`) rather than
    uniform links of length ``h_tip`` (nondimensional) at the free end. Graded when bending holds
    the fold and the links cannot: the bending length ``lb`` (:func:`bending_length`; 0: none) is
    under :data:`GRADE_LINKS` links, and a run on those links folds onto one link -- ``kappa_h`` (its
    curvature peak times ``h_tip``; None: not run) at least :data:`COLLAPSE`, or ``halved`` (the same
    on links half as long; None: not run) not below ``kappa_h``, a fold that does not narrow as the
    links do -- the run ``where`` (without bending: nothing else holds the fold; or with it: its fold
    is below the links).

    >>> grading_rule(1e-3, 1e-3, 3.14)[0], grading_rule(0.0, 1e-3, 3.14)[0], grading_rule(1e-3, 1e-3, 0.5)[0]
    (True, False, False)
    >>> grading_rule(1e-3, 1e-2, 0.61, halved=1.5)[0], grading_rule(1e-3, 1e-2, 0.56, halved=0.36)[0]
    (True, False)
    """
    if lb <= 0.0:
        return False, "no bending at the free end (without it the links, not a continuum, set the fold)"
    if lb >= GRADE_LINKS * h_tip:
        return False, f"the bending length ({lb:.3g} L) is {lb / h_tip:.3g} links (>= {GRADE_LINKS:g}): resolved"
    kh = kappa_h if kappa_h is not None else float("nan")
    if halved is not None and kappa_h is not None and kappa_h < COLLAPSE and halved >= kappa_h:
        return True, (f"the bending length ({lb:.3g} L) is {lb / h_tip:.3g} links (< {GRADE_LINKS:g}) and {where} "
                      f"the fold does not narrow as the links halve (curvature peak x link {kh:.3g}, then "
                      f"{halved:.3g}): it collapses onto the links; bending sets it, graded links resolve it")
    if kappa_h is None or kappa_h < COLLAPSE:
        return False, (f"with and without bending the fold stays above the link scale (curvature peak x link "
                       f"{kh:.3g} < pi/2" + (f", {halved:.3g} on links half as long" if halved is not None else "")
                       + "): the links resolve what caps it")
    return True, (f"the bending length ({lb:.3g} L) is {lb / h_tip:.3g} links (< {GRADE_LINKS:g}) and {where} "
                  f"the fold collapses onto one link (curvature peak x link {kappa_h:.3g} >= pi/2): bending sets the "
                  f"fold, graded links resolve it")


def grading_for(runs, N: int, present: list, graded="auto") -> dict:
    """Whether the answer of :class:`Runs` ``runs`` on ``N`` links takes graded links
    (:func:`grading_rule`; ``present``: the line's mechanisms; ``graded``: "auto", True or False):
    only when the bending length is under :data:`GRADE_LINKS` links, the run without bending on N
    links; when its fold stays under pi/2 at one node, the full run on N links (the uniform answer's
    own: graded when its fold reaches pi/2); when that one's stays under too, the run without bending
    on 2N links (does its fold narrow with them? graded when not), and when it does but the bending
    length is under one link, the full run on 2N links: a full run whose fold does not narrow as the
    links halve is graded (the fly line at chi 0.25 on 100 links: curvature peak x link 0.59 on 100,
    0.76 on 200). Graded when any of these says so, whatever the order they are asked in: the full
    run on N is asked before the run without bending on 2N, which it makes moot when it collapses."""
    if graded is False or "bending" not in present:
        return {"used": False, "why": "off (graded=False)" if graded is False else "no bending"}
    lb = bending_length(runs.sp)
    if graded is True:
        return {"used": lb > 0.0, "why": "graded=True", "bending_length": lb}
    kh, kh2, where = None, None, "without bending"
    if 0.0 < lb < GRADE_LINKS / N:
        bare = tuple(m for m in present if m != "bending")
        kh = runs.get(bare, N)["kappa_peak"] / N
        if kh < COLLAPSE:
            # the full run (made anyway when not graded): its fold below the links? Asked before the run without
            # bending on 2N links, which a full run that collapses makes moot (graded either way: the same
            # decision, one run fewer; the fly line at chi 0.1: 0.4 s of CPU; the reported collapse is then the
            # full run's). When neither collapses and the bare fold does not narrow on 2N, graded too, and this
            # uniform full run was one run more than before (the nylon line at chi 0.2 on 100 links)
            kf = runs.get(tuple(present), N)["kappa_peak"] / N
            if kf >= COLLAPSE:
                kh, kh2, where = kf, None, "with bending"
            else:  # on links half as long: a fold above the links narrows with them (kappa h falls)
                kh2 = runs.get(bare, 2 * N)["kappa_peak"] / (2 * N)
                if kh2 < kh and lb * N < 1.0:  # it does, and the bending length is under one link: does the
                    # full run's fold narrow on 2N?
                    kh, kh2, where = kf, runs.get(tuple(present), 2 * N)["kappa_peak"] / (2 * N), "with bending"
    used, why = grading_rule(lb, 1.0 / N, kh, where, halved=kh2)
    if used:
        n = graded_h(runs.chi, lb, 1).size
        if n > MAX_GRADED_LINKS:
            return {"used": False, "bending_length": lb, "collapse": kh, "halved": kh2, "collapse_run": where,
                    "too_fine": n,
                    "why": f"{why}; but its finer level would need {n} links (> {MAX_GRADED_LINKS}): answered on "
                           f"{N} uniform links, where the fold is NOT resolved"}
    return {"used": used, "why": why, "bending_length": lb, "collapse": kh, "halved": kh2, "collapse_run": where}


def richardson(coarse: float, fine: float, order: float = GRADED_ORDER, ratio: float = 2.0) -> tuple[float, float]:
    """``(extrapolated, error)`` from two levels whose links differ by ``ratio``, converging at
    ``order``: ``fine + (fine - coarse)/(ratio^order - 1)``; the error estimate is that correction
    (the finer level's own error, a bound on the extrapolation's once the order holds).

    >>> [round(x, 12) for x in richardson(1.0 + 0.04, 1.0 + 0.01)]      # 1 + c h^2 at h = 0.2, 0.1
    [1.0, 0.01]
    """
    d = (fine - coarse) / (ratio ** order - 1.0)
    return fine + d, abs(d)


def _run(problem_, method: str, tol: float, drag_jacobian: str = "banded") -> dict:
    from .simulate import run

    t0, c0 = time.perf_counter(), time.process_time()
    r = run(problem_, method=method, tol=tol, progress=False, drag_jacobian=drag_jacobian)
    a = r.dataset.attrs
    if a.get("status") != "completed":
        raise RuntimeError(f"a run of the real model did not complete ({a.get('status')}: {a.get('stop_reason', '')})")
    return {**{q: float(a[q]) for q in QUANTITIES}, "kappa_peak": float(a["kappa_peak"]), "n_rhs": int(a["n_rhs"]),
            "method": str(a["method"]), "tol": tol, "wall": time.perf_counter() - t0, "cpu": time.process_time() - c0}


def stretch_factor(sp, chi: float, tol: float = 1e-6, N: int = STRETCH_N, start: str = STRETCH_START,
                   method: str = STRETCH_METHOD) -> dict:
    """The elastic line over the rigid chain on the same ``N`` uniform links (shared lumping),
    peak by peak: one level of the stretching factor of :func:`snapping.caps.cap` (which takes two,
    :data:`STRETCH_LEVELS`, and applies a peak's factor only where they agree: :func:`accept_factors`).
    The elastic line starts ``start`` (:data:`STRETCH_START`), grid damping 1, by
    ``method`` (default :data:`STRETCH_METHOD`; ``"rodas4-links"``: link coordinates) at ``tol``; the rigid
    chain by the fast method at ``tol``.
    Besides the ratios: ``s_sigma`` and ``t_sigma``, where (arclength from the held end) and when the
    elastic line's tension peaks, ``t_snap`` the rigid chain's (its tension peak's) time."""
    from .simulate import Links, Problem, run
    from .simulate.elastic import Elastic, solve

    t0, c0 = time.perf_counter(), time.process_time()
    p = Problem.catenary(chi, links=Links.uniform(N, lumping="shared"))
    rigid = run(p, method="fast", tol=tol, progress=False).dataset.attrs
    el = solve(p, Elastic(ea=sp.ea / (sp.mass * sp.g), grid_damping=1.0), tol=tol, method=method,
               start=start).dataset.attrs
    if el.get("status") != "completed":
        raise RuntimeError(f"the elastic run did not complete ({el.get('stop_reason', '')}"
                           + (f"; {el['peak_note']})" if el.get("peak_note") else ")"))
    return {**{q: float(el[q]) / float(rigid[q]) for q in QUANTITIES}, "N": N,
            "n_rhs": int(el["n_rhs"]) + int(rigid["n_rhs"]), "wall": time.perf_counter() - t0,
            "cpu": time.process_time() - c0, "strain_peak": float(el["strain_peak"]),
            "s_sigma": float(el["s_sigma_peak"]), "t_sigma": float(el["t_snap_sigma"]),
            "t_snap": float(rigid["t_snap_sigma"])}


def stretch_factor_body(sp, chi: float, N: int, on, tol: float = 1e-6, stiff_tol: float = None,
                        damping: float = GRID_DAMPING, start: str = STRETCH_START,
                        combined_tol: float = STRETCH_BODY_TOL) -> dict:
    """One level of the stretching factor of a line with a body (bending or drag): the combined model
    (the elastic line, ``Elastic(ea=EA/(m g), grid_damping=1)``, carrying the line's body -- bending,
    drag, tip drag, and its taper and end mass in the links -- :data:`STRETCH_BODY_METHOD` at ``combined_tol``,
    start ``start``) over the inextensible full run on the same problem (:func:`problem` with the
    mechanisms ``on``, ``N`` uniform links, ``lumping="shared"``; the method :func:`snapping.caps.cap`
    takes for it at ``tol``, :func:`method_for`, with its grid damping of ratio ``damping`` on the fast waves, which
    the combined run then carries too), peak by peak. Besides the ratios (``v_peak``, ``a_peak``,
    ``sigma_peak``): ``s_sigma``/``t_sigma`` (where and when the combined run's tension peaks),
    ``t_snap`` (the inextensible run's), ``strain_peak``, ``N``, ``n_rhs``, ``wall``, ``cpu``."""
    from .simulate import run
    from .simulate.elastic import Elastic, solve

    t0, c0 = time.perf_counter(), time.process_time()
    on = tuple(on)
    p = problem(sp, chi, N, on, lumping="shared")
    method, itol, omega_min = ("fast", tol, 0.0) if damping <= 0.0 else method_for(p, tol, stiff_tol)
    if method == "rodas4":
        p = problem(sp, chi, N, on, lumping="shared", damping=damping, omega_min=omega_min)
    inext = run(p, method=method, tol=itol, progress=False).dataset.attrs
    el = solve(p, Elastic(ea=sp.ea / (sp.mass * sp.g), grid_damping=1.0), tol=combined_tol,
               method=STRETCH_BODY_METHOD, start=start).dataset.attrs
    for what, a in (("inextensible", inext), ("combined", el)):
        if a.get("status") != "completed":
            raise RuntimeError(f"the {what} run of the stretching factor did not complete ({a.get('stop_reason', '')})")
    return {**{q: float(el[q]) / float(inext[q]) for q in QUANTITIES}, "N": int(N),
            "n_rhs": int(el["n_rhs"]) + int(inext["n_rhs"]), "wall": time.perf_counter() - t0,
            "cpu": time.process_time() - c0, "strain_peak": float(el["strain_peak"]),
            "s_sigma": float(el["s_sigma_peak"]), "t_sigma": float(el["t_snap_sigma"]),
            "t_snap": float(inext["t_snap_sigma"]), "method": f"combined {STRETCH_BODY_METHOD} / {method} {itol:g}"}


def body_stretch_words(sp, levels: list, resolved: dict) -> str:
    """What the stretching factor of a line with a body is (:func:`stretch_factor_body`'s ``levels``), and,
    where a peak's is not resolved, why: the fold is held by bending at the bending length
    (:func:`bending_length`), and where that is under a link of the finer level the uniform links cannot
    hold it -- the fold collapses onto them, with stretching as without (the climbing rope)."""
    n0, n1 = levels[0]["N"], levels[-1]["N"]
    words = (f"the factor is the combined model's (the elastic line with the line's bending and drag, "
             f"{STRETCH_BODY_METHOD}) over the inextensible full run, on {n0} and {n1} uniform links")
    if all(resolved.values()):
        return words + ": resolved"
    lb = bending_length(sp)
    if 0.0 < lb * n1 < 1.0:
        why = (f"the bending length ({lb:.3g} L) is {lb * n1:.2g} links on {n1}: the fold is below the uniform "
               f"links and collapses onto them, with stretching as without (graded links would hold it)")
    else:
        why = f"the two levels differ by more than 1% (the bending length {lb:.3g} L, {lb * n1:.3g} links on {n1})"
    return words + ": NOT resolved: " + why


def accept_factors(coarse: dict, fine: dict, tol: float) -> tuple[dict, dict]:
    """``(applied, resolved)`` per peak of two levels of the stretching factor (``coarse`` on
    :data:`STRETCH_N` links, ``fine`` on twice as many; {peak: factor}): a peak's factor is resolved
    when the two agree to ``tol`` relative, ``|fine - coarse| <= tol |fine|``, and then the fine
    level's is applied; otherwise it is left out (1.0), never applied unverified.

    >>> accept_factors({"v_peak": 0.995, "sigma_peak": 0.996}, {"v_peak": 0.989, "sigma_peak": 1.483}, 0.01)
    ({'v_peak': 0.989, 'sigma_peak': 1.0}, {'v_peak': True, 'sigma_peak': False})
    """
    resolved = {q: bool(abs(fine[q] - coarse[q]) <= tol * abs(fine[q])) for q in fine}
    return {q: (fine[q] if resolved[q] else 1.0) for q in fine}, resolved


class Runs:
    """The runs of one answer of :func:`snapping.caps.cap`, each made once: ``get(on, N)`` (``on``
    the mechanisms, () the ideal) runs it or returns it; ``log`` says what each cost."""

    def __init__(self, sp, chi, tol, stiff_tol, damping, stretch_method=STRETCH_METHOD, bar=None, combined=False):
        self.sp, self.chi, self.tol, self.stiff_tol, self.damping = sp, chi, tol, stiff_tol, damping
        self.combined = bool(combined)  # the combined model on graded links where the uniform factor does not settle
        self.limit = False  # a limit answer (N="auto"): the ideal's continuum limit beside it (snapping.caps_ideal)
        self.stretch_method = stretch_method  # the stretching factor's elastic method (:func:`stretch_factor`)
        self.done, self.log = {}, []
        self.bar = bar  # a progress bar (tqdm): one step per run made, the last run in its postfix

    def _logged(self, entry: dict) -> None:
        self.log.append(entry)
        if self.bar is not None:
            self.bar.set_postfix_str(f"{entry['run']}: {entry['N']} links, {entry['cpu']:.1f} s", refresh=False)
            self.bar.update(1)

    def get(self, on, N: int, h=None, where: str = "") -> dict:
        """The run with the mechanisms ``on`` on ``N`` uniform links, or on the links ``h`` (``where`` names
        them, in the key and the log), by the fast method or, where bending waves are stiff, RODAS4 with
        them grid-damped (:func:`method_for`); made once."""
        key = (tuple(on), int(N)) + ((where,) if where else ())
        if key not in self.done:
            p = problem(self.sp, self.chi, N, on, h=h)
            method, tol, omega_min = ("fast", self.tol, 0.0) if self.damping <= 0.0 else method_for(
                p, self.tol, self.stiff_tol)
            if method == "rodas4":
                p = problem(self.sp, self.chi, N, on, damping=self.damping, omega_min=omega_min, h=h)
            r = _run(p, method, tol)
            self.done[key] = r
            self._logged({"run": ("+".join(on) or "ideal") + (f" ({where})" if where else ""), "N": int(N),
                          "method": r["method"], "tol": r["tol"], "n_rhs": r["n_rhs"], "cpu": r["cpu"]})
        return self.done[key]

    def ideal_on(self, links: list) -> dict:
        """The ideal chain on two levels of graded links (``links``: [(h, where), (h, where)], coarse first;
        :meth:`get`, the fast method) extrapolated at :data:`GRADED_ORDER` (:func:`richardson`): the ideal beside
        a graded answer, on its links: ``levels`` (the two runs' peaks), ``extrapolated``, ``error`` and
        ``relative_error`` per peak (nondimensional), ``links`` (their sizes). Its own fold is not the real
        line's: where the links stop refining at the line's bending length, the ideal's estimate can stay large
        (said: ``relative_error``)."""
        lv = [self.get((), h.size, h=h, where=where) for h, where in links]
        ext = {q: richardson(lv[0][q], lv[1][q], GRADED_ORDER) for q in QUANTITIES}
        return {"levels": lv, "extrapolated": {q: ext[q][0] for q in QUANTITIES}, "links": [h.size for h, _ in links],
                "error": {q: ext[q][1] for q in QUANTITIES},
                "relative_error": {q: ext[q][1] / abs(ext[q][0]) for q in QUANTITIES}}

    def stretching_body(self, present) -> list:
        """The stretching factor's two levels for a line with a body (bending or drag among ``present``):
        :func:`stretch_factor_body` on :data:`STRETCH_BODY_LEVELS` (:func:`snapping.caps.cap` takes any other
        line's by :func:`stretch_factor`, the elastic line over the rigid chain, on :data:`STRETCH_LEVELS`)."""
        return [stretch_factor_body(self.sp, self.chi, n, tuple(present), self.tol, self.stiff_tol, self.damping)
                for n in STRETCH_BODY_LEVELS]

    def graded(self, on, level: int) -> dict:
        """The run with the mechanisms ``on`` on graded level ``level`` (:func:`graded_h`): RODAS4 at
        :data:`GRADED_TOL`, every node's shortest bending wave damped at the ratio
        :data:`GRADED_DAMPING` (it stops the release's ringing of the tiny links, which would hold
        either method to tiny steps; its effect on the peaks vanishes as h^2 and is below 0.1% on
        the finer nylon levels); made once."""
        key = (tuple(on), "graded", int(level))
        if key not in self.done:
            h = graded_h(self.chi, bending_length(self.sp), level)
            p = problem(self.sp, self.chi, h.size, on, damping=GRADED_DAMPING, omega_min=0.0, h=h)
            r = _run(p, "rodas4", GRADED_TOL, GRADED_DRAG_JACOBIAN if "drag" in on else "banded")
            r["links"] = int(h.size)
            self.done[key] = r
            self._logged({"run": ("+".join(on) or "ideal") + f" (graded {level})", "N": int(h.size),
                             "method": r["method"], "tol": r["tol"], "n_rhs": r["n_rhs"], "cpu": r["cpu"]})
        return self.done[key]


#: a graded answer's error estimate per peak above which a finer level is run (:func:`graded_levels`)
GRADED_WITHIN = 0.01


def observed_order(f0: float, f1: float, f2: float, ratio: float = 2.0) -> float:
    """The observed order of convergence of three levels whose links shrink by ``ratio`` from one to
    the next: ``log((f1 - f0)/(f2 - f1))/log(ratio)``; nan when a difference vanishes or the two change
    sign (the levels are not in the asymptotic range).

    >>> round(observed_order(1.0 + 0.3 * 0.4 ** 2, 1.0 + 0.3 * 0.2 ** 2, 1.0 + 0.3 * 0.1 ** 2), 12)
    2.0
    """
    d0, d1 = f1 - f0, f2 - f1
    if d0 == 0.0 or d1 == 0.0 or (d0 > 0.0) != (d1 > 0.0) or not (math.isfinite(d0) and math.isfinite(d1)):
        return float("nan")
    return math.log(d0 / d1) / math.log(ratio)


def graded_levels(run_level, links_of, within: float = GRADED_WITHIN, max_links: int = MAX_ESCALATED_LINKS,
                  order: float = GRADED_ORDER, quantities=QUANTITIES, min_levels: int = 2) -> dict:
    """The graded levels of an answer, escalated: levels 0 and 1 (``run_level(k)``: the peaks of level
    k, {peak: value}), then each next level (``links_of(k)``: its links, without running it) while any
    peak's error estimate -- the Richardson correction of the last two levels at ``order``
    (:func:`richardson`) over the extrapolated value -- exceeds ``within``, unless the next level's
    links would pass ``max_links``. Returns ``levels`` (the peaks of each level run), ``pair`` (the
    two levels extrapolated: the last two), ``extrapolated``, ``error`` and ``relative_error`` per
    peak, ``observed_order`` per peak (:func:`observed_order` of the last three levels; None with two),
    ``stopped`` (``"within"``: every error <= ``within``; ``"max_links"``: the next level would pass
    ``max_links``) and ``why`` (in words). ``min_levels`` (>= 3): at least that many levels, and from three on a
    peak whose last three levels do not converge at first order at least (:func:`observed_order` under 1 or
    nan: not in the asymptotic range, where the order-2 estimate of two levels means nothing) counts as not
    within (``asymptotic`` per peak).

    >>> f = lambda k: {"x": 1.0 + 0.5 * 0.5 ** (2 * k)}                  # 1 + c h^2, h halving
    >>> g = graded_levels(f, lambda k: 100 * 2 ** k, within=0.01, quantities=("x",))
    >>> g["pair"], g["stopped"], round(g["extrapolated"]["x"], 12), round(g["observed_order"]["x"], 9)
    ((2, 3), 'within', 1.0, 2.0)
    """
    lv = [run_level(0), run_level(1)]
    while True:
        ext = {q: richardson(lv[-2][q], lv[-1][q], order) for q in quantities}
        rel = {q: (ext[q][1] / abs(ext[q][0]) if ext[q][0] != 0.0 else float("inf")) for q in quantities}
        asym = {q: True for q in quantities}
        if min_levels >= 3 and len(lv) >= 3:
            asym = {q: observed_order(lv[-3][q], lv[-2][q], lv[-1][q]) >= 1.0 for q in quantities}  # (nan: False)
        judged = {q: rel[q] if asym[q] else float("inf") for q in quantities}
        worst = max(judged, key=lambda q: judged[q])
        if judged[worst] <= within and len(lv) >= min_levels:
            stopped, why = "within", (f"every peak's error estimate <= {within:.0%} on levels {len(lv) - 2}-"
                                      f"{len(lv) - 1}")
            break
        n = int(links_of(len(lv)))
        if n > max_links:
            short = (f"{worst} +- {rel[worst]:.2%} > {within:.0%}" if asym[worst] else
                     f"{worst} converges at no order >= 1 over levels {len(lv) - 3}-{len(lv) - 1} (not asymptotic)")
            stopped, why = "max_links", (f"{short} on levels {len(lv) - 2}-{len(lv) - 1}, but level {len(lv)} would "
                                         f"need {n} links (> {max_links})")
            break
        lv.append(run_level(len(lv)))
    obs = None
    if len(lv) >= 3:
        obs = {q: observed_order(lv[-3][q], lv[-2][q], lv[-1][q]) for q in quantities}
    return {"levels": lv, "pair": (len(lv) - 2, len(lv) - 1), "extrapolated": {q: ext[q][0] for q in quantities},
            "error": {q: ext[q][1] for q in quantities}, "relative_error": rel, "observed_order": obs,
            "stopped": stopped, "why": why, "asymptotic": asym}
