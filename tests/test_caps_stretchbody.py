"""The stretching factor of a line with a body (branch stretchbody): the combined model (the elastic
line carrying the line's bending and drag, snapping.simulate.elastic.solve with a body) over the
inextensible full run on the same uniform links, on caps_runs.STRETCH_BODY_LEVELS, applied per peak
only where the two levels agree within caps.RESOLVED. Expected values come from runs made here on a
problem built by hand (not by caps_runs.problem), or are written out; a line without a body keeps the
elastic-over-rigid factor. Small N: a few seconds."""

from __future__ import annotations

import math

import pytest

from snapping import caps, caps_runs
from snapping.simulate import Body, Links, Problem, run
from snapping.simulate.elastic import Elastic, solve

Q = ("v_peak", "a_peak", "sigma_peak")


def _by_hand(sp, chi, N):
    """The bungee cord's problem with its bending and drag on N uniform links (shared lumping), built here."""
    body = Body.from_si(sp.length, sp.mass, sp.g, ei=sp.ei, diameter=sp.diameter, cd_normal=sp.cd_normal,
                        cd_tangential=sp.cd_tangential, air_density=sp.air_density, tip_drag_area=sp.tip_drag_area)
    return Problem.catenary(chi, links=Links.uniform(N, lumping="shared"), body=body)


def test_one_level_is_the_combined_model_over_the_inextensible_run():
    sp, chi, N = caps.spec("bungee-cord"), 0.3, 12
    assert sp.has("bending") and sp.has("drag") and not sp.has("taper") and not sp.has("end-mass")
    p = _by_hand(sp, chi, N)
    inext = run(p, method="fast", tol=1e-6, progress=False).dataset.attrs
    el = solve(p, Elastic(ea=sp.ea / (sp.mass * sp.g), grid_damping=1.0), tol=1e-5, method="rodas4",
               start="matched").dataset.attrs
    f = caps_runs.stretch_factor_body(sp, chi, N, ("bending", "drag"), 1e-6, damping=0.0)
    for q in Q:
        assert f[q] == pytest.approx(float(el[q]) / float(inext[q]), rel=1e-12), q
    assert f["N"] == N and f["t_snap"] == pytest.approx(float(inext["t_snap_sigma"]), rel=1e-12)
    assert f["strain_peak"] == pytest.approx(float(el["strain_peak"]), rel=1e-12) and f["strain_peak"] > 0.0
    # stretching with the body is not the ideal chain's: this factor is not the elastic-over-rigid one
    bare = caps_runs.stretch_factor(sp, chi, 1e-6, N)
    assert abs(bare["sigma_peak"] - f["sigma_peak"]) > 1e-3


def test_stiff_line_tends_to_the_inextensible_run_as_one_over_c_squared():
    # EA x 25 and x 100 (c = 88 and 177 sqrt(gL), against 17.7): the combined model tends to the inextensible one
    # as 1/c^2, so each factor's distance from 1 falls by 4 (measured: 4.0-4.4; at the real EA the tension's
    # factor is 1.26 on these 12 links)
    sp = caps.spec("bungee-cord")
    d = [caps_runs.stretch_factor_body(caps.spec("bungee-cord", ea=sp.ea * k), 0.3, 12, ("bending", "drag"), 1e-6,
                                       damping=0.0) for k in (25.0, 100.0)]
    for q in Q:
        assert abs(d[1][q] - 1.0) < 4e-3 and (d[0][q] - 1.0) / (d[1][q] - 1.0) == pytest.approx(4.0, rel=0.15), q


def _fake_body_levels(monkeypatch, levels):
    calls = []

    def fake(sp, chi, N, on, tol=1e-6, stiff_tol=None, damping=1.0, start="matched", combined_tol=1e-5):
        calls.append((N, tuple(on)))
        return {**levels[N], "N": N, "n_rhs": 5, "wall": 0.0, "cpu": 0.0, "strain_peak": 0.02, "s_sigma": 0.9,
                "t_sigma": 1.2, "t_snap": 1.19, "method": "combined rodas4 / fast 1e-06"}

    monkeypatch.setattr(caps_runs, "stretch_factor_body", fake)
    monkeypatch.setattr(caps, "stretch_factor", lambda *a, **k: pytest.fail("the bodiless factor was run"))
    return calls


def test_cap_takes_the_combined_factor_where_the_line_has_a_body(monkeypatch):
    calls = _fake_body_levels(monkeypatch, {50: {"v_peak": 0.997, "a_peak": 0.99, "sigma_peak": 1.268},
                                            100: {"v_peak": 0.9977, "a_peak": 0.93, "sigma_peak": 1.275}})
    r = caps.cap("bungee-cord", 0.3, N=16, check=False, graded=False)
    assert calls == [(50, ("bending", "drag")), (100, ("bending", "drag"))]
    s = r["stretching"]
    assert s["body"] is True and s["resolved"] == {"v_peak": True, "a_peak": False, "sigma_peak": True}
    assert s["factor"] == {"v_peak": 0.9977, "a_peak": 1.0, "sigma_peak": 1.275}
    assert r["real"]["sigma_peak"] == pytest.approx(r["full"]["sigma_peak"] * 1.275, rel=1e-14)
    assert r["real"]["a_peak"] == r["full"]["a_peak"]
    assert "combined model's" in s["why"] and "50 and 100 uniform links" in s["why"]
    assert [x["N"] for x in r["runs"] if x["run"] == "stretching"] == [50, 100]
    # the combined factor is stretching's with the body, not alone: no "stretching alone" to be the cap
    assert set(r["alone"]) == {"bending", "drag"} and r["cap"] in ("bending", "drag")


def test_a_line_without_a_body_keeps_the_elastic_over_rigid_factor(monkeypatch):
    monkeypatch.setattr(caps_runs, "stretch_factor_body", lambda *a, **k: pytest.fail("the combined factor was run"))
    r = caps.cap(None, 0.3, N=16, check=False, length=2.0, mass=0.1, ea=40.0)
    s = r["stretching"]
    assert s["run"] and s["body"] is False and [x["N"] for x in s["levels"]] == [30, 60]
    sp = caps.spec(None, length=2.0, mass=0.1, ea=40.0)
    for lv in s["levels"]:
        direct = caps_runs.stretch_factor(sp, 0.3, r["tol"], lv["N"])
        assert all(lv[q] == direct[q] for q in Q)  # bit for bit
    assert "elastic over rigid on 30 and 60 links" in s["why"]


def test_a_drag_only_line_takes_the_combined_factor(monkeypatch):
    calls = _fake_body_levels(monkeypatch, {50: {"v_peak": 1.0, "a_peak": 1.0, "sigma_peak": 1.1},
                                            100: {"v_peak": 1.0, "a_peak": 1.0, "sigma_peak": 1.3}})
    r = caps.cap(None, 0.3, N=16, check=False, alone=False, length=2.0, mass=0.1, ea=40.0, diameter=0.003)
    assert [c[1] for c in calls] == [("drag",), ("drag",)]
    assert r["stretching"]["resolved"]["sigma_peak"] is False and r["stretching"]["factor"]["sigma_peak"] == 1.0


def test_the_words_say_why_the_rope_is_not_resolved():
    lv = [{"N": 50}, {"N": 100}]
    rope, bungee = caps.spec("climbing-rope"), caps.spec("bungee-cord")
    lb = math.sqrt(rope.ei / (rope.mass / rope.length * rope.g * rope.length)) / rope.length  # by hand
    assert lb * 100 < 1.0
    w = caps_runs.body_stretch_words(rope, lv, {"v_peak": False, "a_peak": True, "sigma_peak": False})
    assert "NOT resolved" in w and "below the uniform links" in w and f"{lb * 100:.2g} links on 100" in w
    w = caps_runs.body_stretch_words(bungee, lv, {q: True for q in Q})
    assert w.endswith(": resolved") and "50 and 100 uniform links" in w
