"""Graded links in design answers (snapping.caps, snapping.caps_runs; issue 24): the rule that
takes them, checked against the line's numbers computed by hand (the nylon line takes them, the
ball chain does not), and the graded answer against direct runs of the same problem built here
from the simulator's parts, with the two levels' extrapolation computed here. Small: ~2 s."""

from __future__ import annotations

import math

import numpy as np

import pytest

from snapping import caps, caps_runs, estimates
from snapping.simulate import Body, Links, Problem, grading, run
from snapping.simulate.stiffness import grid_damping

# the nylon line's raw numbers (snapping.lines: 0.30 mm, 1140 kg/m^3, E = 2 GPa, 10 m)
D, RHO, E, LN, G = 0.30e-3, 1140.0, 2.0e9, 10.0, 9.81


def test_bending_length_of_the_nylon_line_by_hand():
    # EI = E pi d^4/64, lambda = rho pi d^2/4: sqrt(EI/(lambda g L))/L = (d/4) sqrt(E/(rho g L))/L
    lb = D / 4.0 * math.sqrt(E / (RHO * G * LN)) / LN
    assert lb == pytest.approx(1.0030e-3, rel=1e-4)
    assert caps_runs.bending_length(caps.spec("nylon-monofilament")) == pytest.approx(lb, rel=1e-12)
    assert caps_runs.bending_length(caps.spec("ball-chain")) == 0.0


def test_rule_takes_grading_for_nylon_like_numbers_only():
    lb = D / 4.0 * math.sqrt(E / (RHO * G * LN)) / LN
    for N in (100, 1000, 19000):  # under 20 links per bending length, the fold collapsing without bending
        assert caps_runs.grading_rule(lb, 1.0 / N, math.pi)[0]
    assert not caps_runs.grading_rule(lb, 1.0 / 20000, math.pi)[0]  # 20.06 links: resolved
    assert not caps_runs.grading_rule(lb, 1.0 / 1000, 0.7)[0]  # a fold held above the links without bending
    assert not caps_runs.grading_rule(0.0, 1.0 / 1000, math.pi)[0]  # no bending: the ball chain
    # the whole rule on the lines themselves: the ball chain makes no run for it; the nylon line's drag
    # alone on 100 links folds past a right angle at one node
    runs = caps_runs.Runs(caps.spec("ball-chain"), 0.25, 1e-6, 1e-4, 1.0)
    assert caps._grading(runs, 229, ["drag"], "auto")["used"] is False and runs.log == []
    runs = caps_runs.Runs(caps.spec("nylon-monofilament"), 0.25, 1e-6, 1e-4, 1.0)
    g = caps._grading(runs, 100, ["bending", "drag"], "auto")
    assert g["used"] and g["collapse"] >= math.pi / 2 and [x["run"] for x in runs.log] == ["drag"]
    # at chi = 0.1 drag alone keeps its fold above the links (it narrows as they halve), but the full
    # run's folds onto one link
    runs = caps_runs.Runs(caps.spec("nylon-monofilament"), 0.1, 1e-6, 1e-4, 1.0)
    g = caps._grading(runs, 200, ["bending", "drag"], "auto")
    assert g["used"] and g["collapse_run"] == "with bending" and g["collapse"] >= math.pi / 2
    # (the full run on N asked before drag alone on 2N, which it makes moot: one run fewer)
    assert [(x["run"], x["N"]) for x in runs.log] == [("drag", 200), ("bending+drag", 200)]
    # at chi = 0.2 on 100 links drag alone turns by less than pi/2 at one node, but it turns more on
    # 200: a fold that does not narrow with the links (the nylon line at design's chi 0.2)
    runs = caps_runs.Runs(caps.spec("nylon-monofilament"), 0.2, 1e-6, 1e-4, 1.0)
    g = caps._grading(runs, 100, ["bending", "drag"], "auto")
    assert g["used"] and g["collapse"] < math.pi / 2 and g["halved"] >= g["collapse"]
    # (the full run on 100 links asked first: its fold stays under pi/2, so drag alone on 200 decides)
    assert [(x["run"], x["N"]) for x in runs.log] == [("drag", 100), ("bending+drag", 100), ("drag", 200)]
    assert runs.log[1]["n_rhs"] > 0 and runs.done[(("bending", "drag"), 100)]["kappa_peak"] / 100 < math.pi / 2
    # the rule itself on those numbers, and on a fold that narrows (the fly line's drag at chi 0.2)
    assert caps_runs.grading_rule(lb, 1.0 / 100, 0.61, halved=1.50)[0]
    assert not caps_runs.grading_rule(lb, 1.0 / 100, 0.56, halved=0.36)[0]
    assert caps_runs.grading_rule(lb, 1.0 / 100, 0.61, halved=0.62)[0]  # the boundary: does not fall ...
    assert not caps_runs.grading_rule(lb, 1.0 / 100, 0.61, halved=0.60)[0]  # ... falls
    assert not caps_runs.grading_rule(lb, 1.0 / 100, 0.56, halved=None)[0]
    # a bending length far below the nylon line's: graded links too many, the uniform answer said unresolved
    runs = caps_runs.Runs(caps.spec(None, length=2.0, mass=0.1, ei=1e-9, diameter=0.05), 0.3, 1e-6, 1e-4, 1.0)
    g = caps._grading(runs, 16, ["bending", "drag"], "auto")
    assert not g["used"] and g["too_fine"] > caps_runs.MAX_GRADED_LINKS and "NOT resolved" in g["why"]


def test_graded_answer_matches_direct_runs_and_their_extrapolation():
    Lc, Mc, chi = 1.0, 0.1, 0.5
    lb = 0.03  # EI from the bending length: EI = lb^2 lambda g L^3
    ei = lb ** 2 * (Mc / Lc) * G * Lc ** 3
    kw = {"ei": ei, "diameter": 2e-3, "cd_normal": 1.2}
    r = caps.cap(None, chi, N=12, check=False, alone=False, graded=True, length=Lc, mass=Mc, **kw)
    g = r["graded"]
    assert g["used"] and g["bending_length"] == pytest.approx(lb, rel=1e-12)
    a = estimates.catenary_parameter(chi)
    peaks = []
    for k in (0, 1):  # fold path 1.5 lb, free end 0.4 lb, held arm 20 lb (max 0.5), halved on level 1
        s = 0.5 ** k
        h = grading.fold_following(chi, frac=1.5 * lb * s / a, h_min=0.4 * lb * s, h_max=min(0.5, 20 * lb * s))
        links = Links.graded(h)
        eta = grid_damping(h, links.m, np.full(h.size + 1, lb ** 2), 0.01)
        body = Body.from_si(Lc, Mc, G, **kw)
        body = Body(body.bending, damping=eta, drag_normal=body.drag_normal, drag_tangential=body.drag_tangential)
        ds = run(Problem.catenary(chi, links=links, body=body), method="rodas4", tol=1e-3, progress=False,
                 drag_jacobian="correct").dataset  # (caps' stage solves with drag: a literal, so a change of caps' fails)
        peaks.append({"v_peak": float(ds.attrs["v_peak"]) * math.sqrt(G * Lc), "a_peak": float(ds.attrs["a_peak"]) * G,
                      "sigma_peak": float(ds.attrs["sigma_peak"]) * Mc * G})
        assert g["levels"][k] == h.size
    for q in caps.QUANTITIES:
        assert g["levels_peaks"][0][q] == pytest.approx(peaks[0][q], rel=1e-9)
        assert g["levels_peaks"][1][q] == pytest.approx(peaks[1][q], rel=1e-9)
        assert r["real"][q] == pytest.approx(peaks[1][q] + (peaks[1][q] - peaks[0][q]) / 3.0, rel=1e-9)
        assert g["error"][q] == pytest.approx(abs(peaks[1][q] - peaks[0][q]) / 3.0, rel=1e-9)
    assert r["resolution"]["sigma_peak"] == pytest.approx(1.0 - peaks[0]["sigma_peak"] / peaks[1]["sigma_peak"])
    assert [x["N"] for x in r["runs"] if x["run"].startswith("bending+drag (graded")] == g["levels"]
    # the ideal beside it is the ideal chain's continuum limit (shipped; a graded answer is a limit), its run on the
    # 12 uniform links kept beside: a different, coarser number
    from snapping.table.limits import ideal_limit

    lim = ideal_limit(chi)
    si = {"v_peak": math.sqrt(G * Lc), "a_peak": G, "sigma_peak": Mc * G}
    for q in caps.QUANTITIES:
        assert r["ideal"][q] == pytest.approx(lim[q][0] * si[q], rel=1e-12), q
        assert r["factor"][q] == pytest.approx(r["real"][q] / (lim[q][0] * si[q]), rel=1e-12), q
    ds = run(Problem.catenary(chi, links=Links.uniform(12)), method="fast", tol=1e-6, progress=False).dataset
    assert r["ideal_on"]["uniform"]["sigma_peak"] == pytest.approx(float(ds.attrs["sigma_peak"]) * Mc * G, rel=1e-9)
    assert r["ideal_on"]["source"] == {q: "limit" for q in caps.QUANTITIES}
