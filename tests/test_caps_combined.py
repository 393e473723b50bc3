"""The combined route of a design answer (snapping.caps_combined; caps.cap(..., combined=True)): where a line
with a body's stretching factor does not settle on uniform links, the real answer is the combined model (the
extensible line carrying the body) on fold-graded levels, extrapolated. A level is the direct elastic.solve of the
problem built here by hand; the extrapolation and escalation are checked on levels of a known law; the route
replaces the unsettled factor by the extrapolated peaks, and is off by default."""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping import caps, caps_combined, caps_runs, continuum
from snapping.simulate import Body, Links, Problem, grading
from snapping.simulate.elastic import Elastic, solve

Q = ("v_peak", "a_peak", "sigma_peak")


def test_a_level_is_the_direct_solve_on_its_graded_links():
    """The climbing rope without bending (drag and stretching: no grid damping), chi 0.3, the coarsest level of
    first = -4: the problem built here (SI drag written out), the stretching study's settings."""
    sp = caps.spec("climbing-rope", ei=0.0)
    k = 0.5 ** -4
    h = grading.fold_following(0.3, frac=continuum.FRAC0 * k, h_min=continuum.H_MIN0 * k,
                               h_max=min(0.5, continuum.H_MAX0 * k))
    lam = sp.mass / sp.length
    rho = 1.2
    body = Body(0.0, drag_normal=0.5 * rho * sp.cd_normal * sp.diameter * sp.length / lam,
                drag_tangential=0.5 * rho * sp.cd_tangential * math.pi * sp.diameter * sp.length / lam)
    p = Problem.catenary(0.3, links=Links.graded(h, lumping="shared"), body=body)
    a = solve(p, Elastic(ea=sp.ea / (sp.mass * sp.g), grid_damping=4.0), tol=1e-6, method="rodas4", start="matched",
              stop_floor=1.0).dataset.attrs
    x = caps_combined.combined_level(sp, 0.3, ("drag",), 0, first=-4)
    assert x["links"] == h.size
    assert x["v_peak"] == pytest.approx(float(a["v_peak"]), rel=1e-12)
    assert x["a_peak"] == pytest.approx(float(a["a_peak_snap"]), rel=1e-12)
    assert x["sigma_peak"] == pytest.approx(float(a["sigma_peak_snap"]), rel=1e-12)


def _law(k):
    """Peaks 1 + c h^2 on links halving per level (h = 2^-k), one c per peak."""
    return {"v_peak": 30.0 * (1.0 + 0.4 * 4.0 ** -k), "a_peak": 1e5 * (1.0 - 2.0 * 4.0 ** -k),
            "sigma_peak": 100.0 * (1.0 + 0.1 * 4.0 ** -k), "links": 100 * 2 ** k, "n_rhs": 7, "cpu": 0.0,
            "wall": 0.0, "strain_peak": 0.2, "method": "combined rodas4 1e-06"}


def test_the_answer_extrapolates_and_escalates_on_a_known_law(monkeypatch):
    monkeypatch.setattr(caps_combined, "combined_level", lambda sp, chi, on, k, **kw: _law(k))
    monkeypatch.setattr(caps_combined, "combined_links", lambda chi, k, first=-1: np.ones(100 * 2 ** k))
    g = caps_combined.combined_answer(None, 0.1, ("bending",))
    # a_peak's order-2 estimate on levels (k, k+1): |f_k+1 - f_k| / 3 over the limit = 0.5 * 4^-k (v's 0.1 * 4^-k,
    # sigma's 0.025 * 4^-k): 50%, 12.5%, 3.1%, 0.78%: within 1% first on levels (3, 4)
    assert g["pair"] == (3, 4) and g["stopped"] == "within"
    for q, limit in (("v_peak", 30.0), ("a_peak", 1e5), ("sigma_peak", 100.0)):
        assert g["extrapolated"][q] == pytest.approx(limit, rel=1e-12), q
    assert all(g["resolved"].values())
    # links 100 * 2^k: level 3's 800 would pass 500: stopped on (1, 2), a_peak +-12.5%
    g = caps_combined.combined_answer(None, 0.1, ("bending",), max_links=500)
    assert g["pair"] == (1, 2) and g["stopped"] == "max_links" and not g["resolved"]["a_peak"]


def _unsettled(monkeypatch):
    def fake(sp, chi, N, on, tol=1e-6, stiff_tol=None, damping=1.0, start="matched", combined_tol=1e-5):
        f = {50: 1.30, 100: 1.10}[N]
        return {"v_peak": f, "a_peak": f, "sigma_peak": f, "N": N, "n_rhs": 5, "wall": 0.0, "cpu": 0.0,
                "strain_peak": 0.02, "s_sigma": 0.9, "t_sigma": 1.2, "t_snap": 1.19, "method": "combined rodas4"}

    def same(runs, present, cg):  # the ideal's sigma 200 (1 - 0.5 h^2) and v 20, a 1e5; the inextensible's 400 M g
        ideal = [{"v_peak": 20.0, "a_peak": 1e5, "sigma_peak": 200.0 * (1.0 - 0.5 * 4.0 ** -k)}
                 for k in range(len(cg["levels"]))]
        return {"ideal": {"levels": ideal, "extrapolated": {"v_peak": 20.0, "a_peak": 1e5, "sigma_peak": 200.0},
                          "links": [800, 1600],
                          "relative_error": {q: 0.0 for q in Q}},
                "inextensible": [{"v_peak": 20.0, "a_peak": 1e5, "sigma_peak": 400.0} for _ in ideal]}

    monkeypatch.setattr(caps_runs, "stretch_factor_body", fake)
    monkeypatch.setattr(caps_combined, "combined_level", lambda sp, chi, on, k, **kw: _law(k))
    monkeypatch.setattr(caps_combined, "combined_links", lambda chi, k, first=-1: np.ones(100 * 2 ** k))
    monkeypatch.setattr(caps_combined, "same_links", same)


def test_cap_answers_from_the_combined_model_where_the_factor_does_not_settle(monkeypatch):
    _unsettled(monkeypatch)
    sp = caps.spec("bungee-cord")
    r = caps.cap("bungee-cord", 0.05, N=16, check=False, graded=False, alone=False, combined=True)
    s = r["stretching"]
    assert s["model"] == "combined (elastic + body) on graded links" and all(s["resolved"].values())
    si = {"v_peak": math.sqrt(sp.g * sp.length), "a_peak": sp.g, "sigma_peak": sp.mass * sp.g}
    for q, limit in (("v_peak", 30.0), ("a_peak", 1e5), ("sigma_peak", 100.0)):
        assert r["real"][q] == pytest.approx(limit * si[q], rel=1e-12), q
        assert s["factor"][q] == pytest.approx(limit * si[q] / r["full"][q], rel=1e-12), q
    assert "did not settle" in s["why"] and "graded links (100/200/400/800/1600)" in s["why"]
    assert [x["N"] for x in r["runs"] if x["run"] == "combined"] == [100, 200, 400, 800, 1600]
    # the ideal beside it is the ideal chain's continuum limit (not the 16 uniform links'), the factor against it;
    # on the finest level stretching's step 100.04/400 outweighs the body's 400/199.6: stretching caps it
    from snapping.table.limits import ideal_limit

    lim = ideal_limit(0.05)["sigma_peak"][0]
    assert r["ideal"]["sigma_peak"] == pytest.approx(lim * si["sigma_peak"], rel=1e-12)
    assert r["factor"]["sigma_peak"] == pytest.approx(100.0 / lim, rel=1e-12) and 100.0 / lim < 0.9
    assert r["ideal_on"]["uniform"]["sigma_peak"] < 0.5 * lim * si["sigma_peak"]
    assert r["cap"] == "stretching" and "x0.25" in r["cap_why"] and "x2" in r["cap_why"]
    assert "ideal chain: its continuum limit (shipped, snapping.table.limits): v_peak +- " in "\n".join(caps.format_answer(r))


def _cg(real, inext, ideal):
    return {"levels": [{"links": 10, "sigma_peak": 1.0}, {"links": 20, "sigma_peak": real}],
            "inextensible": [{"sigma_peak": 1.0}, {"sigma_peak": inext}],
            "ideal": {"levels": [{"sigma_peak": 1.0}, {"sigma_peak": ideal}]}}


@pytest.mark.parametrize("real, inext, ideal, factor, expect", [
    (146.1, 864.4, 203.3, 0.71, "stretching"),      # the rope at chi 0.1: the body raises it x4.25, stretching x0.169
    (80.0, 100.0, 200.0, 0.40, "drag"),            # the body halves it, stretching takes 20% more: the body's
    (50.0, 180.0, 200.0, 0.25, "stretching"),      # both lower it, stretching more (x0.28 vs x0.9)
    (150.0, 180.0, 200.0, 0.85, "stretching"),     # x0.833 vs the body's x0.9: stretching's step is the larger
    (70.0, 80.0, 200.0, 0.40, "drag"),             # x0.875 vs the body's x0.4
    (150.0, 140.0, 200.0, 0.80, "drag"),           # stretching raises it (x1.07): the body's
    (190.0, 210.0, 200.0, 0.93, "none"),           # within 10% of the ideal's limit
    (240.0, 1200.0, 200.0, 0.50, "stretching"),    # the body raises it x6 (takes nothing down), stretching x0.2
    (95.0, 97.5, 100.0, 0.80, "stretching"),       # neither step below 0.9 on the finest level: the larger, said
])
def test_combined_verdict_splits_the_ratio_on_the_finest_level(real, inext, ideal, factor, expect):
    got, why = caps_combined.combined_verdict(_cg(real, inext, ideal), "sigma_peak", factor, {"drag": 1.0},
                                              lambda alone: min(alone))
    assert got == expect
    assert f"({20} links)" in why and f"x{inext / ideal:.3g}" in why and f"x{real / inext:.3g}" in why
    assert ("neither below 0.9" in why) == (factor < 0.9 and min(real / inext, inext / ideal) >= 0.9)


def test_off_by_default_the_unsettled_factor_is_left_out(monkeypatch):
    _unsettled(monkeypatch)
    monkeypatch.setattr(caps_combined, "combined_level", lambda *a, **k: pytest.fail("the combined route ran"))
    r = caps.cap("bungee-cord", 0.3, N=16, check=False, graded=False, alone=False)
    assert r["stretching"]["factor"] == {q: 1.0 for q in Q} and r["real"] == r["full"]
    assert "combined" not in r["stretching"]


def test_cli_estimate_combined(monkeypatch, capsys):
    import json

    from snapping.cli import main

    _unsettled(monkeypatch)
    assert main(["estimate", "--line", "bungee-cord", "--chi", "0.3", "--links", "16", "--combined", "--json"]) == 0
    s = json.loads(capsys.readouterr().out)["stretching"]
    assert s["model"] == "combined (elastic + body) on graded links" and s["combined"]["pair"] == [3, 4]
    assert main(["estimate", "--chi", "0.3", "--combined"]) == 2
    assert "--combined is a real line's option" in capsys.readouterr().err


def test_same_links_runs_the_ideal_and_the_inextensible_line_on_the_combined_levels(monkeypatch):
    """The rope without bending (drag: the fast method) at chi 0.3 on the levels of first = -4: the ideal chain and
    the inextensible line with drag built here by hand, run directly; the ideal's pair extrapolated by hand."""
    from snapping.simulate import run

    sp = caps.spec("climbing-rope", ei=0.0)

    def links(chi, k, first=-1):
        s = 0.5 ** (-4 + k)
        return grading.fold_following(chi, frac=continuum.FRAC0 * s, h_min=continuum.H_MIN0 * s,
                                      h_max=min(0.5, continuum.H_MAX0 * s))

    monkeypatch.setattr(caps_combined, "combined_links", links)
    runs = caps_runs.Runs(sp, 0.3, 1e-6, 1e-4, caps_runs.GRID_DAMPING)
    got = caps_combined.same_links(runs, ("drag",), {"levels": [{}, {}], "pair": (0, 1)})
    lam, rho = sp.mass / sp.length, 1.2
    drag = Body(0.0, drag_normal=0.5 * rho * sp.cd_normal * sp.diameter * sp.length / lam,
                drag_tangential=0.5 * rho * sp.cd_tangential * math.pi * sp.diameter * sp.length / lam)
    ideal = []
    for k in (0, 1):
        h = links(0.3, k)
        for body, out in ((None, got["ideal"]["levels"][k]), (drag, got["inextensible"][k])):
            a = run(Problem.catenary(0.3, links=Links.graded(h), body=body), method="fast", tol=1e-6,
                    progress=False).dataset.attrs
            for q in Q:
                assert out[q] == pytest.approx(float(a[q]), rel=1e-12), (k, body, q)
            if body is None:
                ideal.append(a)
    for q in Q:
        f0, f1 = float(ideal[0][q]), float(ideal[1][q])
        assert got["ideal"]["extrapolated"][q] == pytest.approx((4.0 * f1 - f0) / 3.0, rel=1e-12), q
        assert got["ideal"]["relative_error"][q] == pytest.approx(abs(f1 - f0) / 3.0 / abs((4.0 * f1 - f0) / 3.0),
                                                                   rel=1e-9), q
    assert [x["run"] for x in runs.log] == ["ideal (combined level 0)", "ideal (combined level 1)",
                                            "drag (combined level 0)", "drag (combined level 1)"]
    assert got["ideal"]["links"] == [links(0.3, 0).size, links(0.3, 1).size]


def test_design_takes_the_combined_route(monkeypatch, capsys):
    import json

    from snapping.cli import main

    _unsettled(monkeypatch)
    d = caps.design("bungee-cord", chis=(0.05,), N=16, max_tension=1e9, alone=False, graded=False, combined=True)
    row = d["rows"][0]
    assert row["stretching"]["model"] == "combined (elastic + body) on graded links" and row["cap"] == "stretching"
    assert row["factor"]["sigma_peak"] < 0.9
    text = "\n".join(caps.format_design(d))
    assert "real peaks from the combined model (elastic + body) on graded links" in text
    assert row["cap_why"] and row["cap_why"] in text and "stretching takes it down" in text
    assert row["ideal_on"]["source"] == {q: "limit" for q in Q}
    assert "stretching factor NOT applied" not in text
    assert main(["design", "--line", "bungee-cord", "--chis", "0.3", "--links", "16", "--max-tension", "1e9",
                 "--combined", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["rows"][0]
    assert row["stretching"]["model"] == "combined (elastic + body) on graded links"
    assert main(["design", "--max-tension", "1e9", "--combined"]) == 2
    assert "--combined is a real line's option" in capsys.readouterr().err


def test_design_counts_admissible_only_rows_with_nothing_unsure(monkeypatch):
    """Rows under the limit: resolved (admissible), not resolved in the links, stretching left out of the limited
    peak, stretching left out of another peak only; and one over the limit."""
    LV = [{"N": 50}, {"N": 100}]
    rows = {0.1: {"resolved": False, "stretching": {}},
            0.2: {"resolved": True, "stretching": {"run": True, "levels": LV, "resolved": {
                "v_peak": True, "a_peak": True, "sigma_peak": False}}},
            0.3: {"resolved": True, "stretching": {"run": True, "levels": LV, "resolved": {
                "v_peak": True, "a_peak": False, "sigma_peak": True}}},
            0.4: {"resolved": True, "stretching": {"run": False}},
            0.5: {"resolved": True, "stretching": {}, "T": 5.0}}

    def fake(sp, chi, **kw):
        x = rows[chi]
        peaks = {"v_peak": 1.0, "a_peak": 1.0, "sigma_peak": x.get("T", 1.0)}
        return {"chi": chi, "ideal": peaks, "real": peaks, "factor": peaks, "cap": "none", "alone": {},
                "mechanisms": [], "graded": {}, "stretching": x["stretching"], "n_rhs": 1, "resolved": x["resolved"]}

    monkeypatch.setattr(caps, "cap", fake)
    d = caps.design("bungee-cord", chis=sorted(rows), max_tension=2.0)
    assert d["admissible_chi"] == [0.3, 0.4]
    assert [x["chi"] for x in d["admissible_unsure"]] == [0.1, 0.2]
    assert d["admissible_unsure"][0]["why"] == ["not resolved in the links"]
    assert "stretching left out of sigma_peak" in d["admissible_unsure"][1]["why"][0]
    text = "\n".join(caps.format_design(d))
    assert "under the limits but NOT counted admissible: 0.1 (not resolved in the links); 0.2 (stretching" in text
    assert "admissible chi (real line): 0.3, 0.4" in text and " yes?" in text


def test_a_peak_out_of_the_asymptotic_range_escalates_and_is_not_resolved(monkeypatch):
    """v and T on an order-2 law; a agrees to 0.1% on levels 0-1 (the two-level estimate says +-0.03%) and then
    jumps (the rope's acceleration at chi 0.5: 38.7, 39.3, 57.0, 187.8): a third level is run, a's order is
    negative, so levels are added to max_links and a is left unresolved; v and T stay resolved."""
    def law(k):
        x = _law(k)
        x["a_peak"] = [100.0, 100.1, 150.0, 400.0, 900.0, 2000.0][k]
        return x

    monkeypatch.setattr(caps_combined, "combined_level", lambda sp, chi, on, k, **kw: law(k))
    monkeypatch.setattr(caps_combined, "combined_links", lambda chi, k, first=-1: np.ones(100 * 2 ** k))
    g = caps_combined.combined_answer(None, 0.1, ("bending",), max_links=1000)
    assert len(g["levels"]) == 4 and g["stopped"] == "max_links"  # (level 4 would need 1600 links)
    assert not g["resolved"]["a_peak"] and g["resolved"]["v_peak"] and g["resolved"]["sigma_peak"]
    assert g["asymptotic"] == {"v_peak": True, "a_peak": False, "sigma_peak": True}
    assert "a_peak converges at no order >= 1" in g["why"]
    # a creeping a (differences 0.1, 0.4, 0.4: order 0) whose last two levels agree within 1% (+-0.13%): not resolved
    def creep(k):
        x = _law(k)
        x["a_peak"] = [100.0, 100.1, 100.5, 100.9, 101.3][k]
        return x

    monkeypatch.setattr(caps_combined, "combined_level", lambda sp, chi, on, k, **kw: creep(k))
    g = caps_combined.combined_answer(None, 0.1, ("bending",), max_links=1000)
    assert g["relative_error"]["a_peak"] < 0.01 and not g["asymptotic"]["a_peak"] and not g["resolved"]["a_peak"]
    # the order-2 law alone still stops where it did (three levels at least): pair (3, 4)
    monkeypatch.setattr(caps_combined, "combined_level", lambda sp, chi, on, k, **kw: _law(k))
    assert caps_combined.combined_answer(None, 0.1, ("bending",))["pair"] == (3, 4)
