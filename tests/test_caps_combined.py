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

    monkeypatch.setattr(caps_runs, "stretch_factor_body", fake)
    monkeypatch.setattr(caps_combined, "combined_level", lambda sp, chi, on, k, **kw: _law(k))
    monkeypatch.setattr(caps_combined, "combined_links", lambda chi, k, first=-1: np.ones(100 * 2 ** k))


def test_cap_answers_from_the_combined_model_where_the_factor_does_not_settle(monkeypatch):
    _unsettled(monkeypatch)
    sp = caps.spec("bungee-cord")
    r = caps.cap("bungee-cord", 0.3, N=16, check=False, graded=False, alone=False, combined=True)
    s = r["stretching"]
    assert s["model"] == "combined (elastic + body) on graded links" and all(s["resolved"].values())
    si = {"v_peak": math.sqrt(sp.g * sp.length), "a_peak": sp.g, "sigma_peak": sp.mass * sp.g}
    for q, limit in (("v_peak", 30.0), ("a_peak", 1e5), ("sigma_peak", 100.0)):
        assert r["real"][q] == pytest.approx(limit * si[q], rel=1e-12), q
        assert s["factor"][q] == pytest.approx(limit * si[q] / r["full"][q], rel=1e-12), q
    assert "did not settle" in s["why"] and "graded links (100/200/400/800/1600)" in s["why"]
    assert [x["N"] for x in r["runs"] if x["run"] == "combined"] == [100, 200, 400, 800, 1600]


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
