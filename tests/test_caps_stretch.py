"""The stretching factor of a design answer (snapping.caps, issue 24): it is taken on two levels of
links (STRETCH_LEVELS) and a peak's factor is applied only where the two agree within caps.RESOLVED;
otherwise it is left out (1.0) and the answer says so. Expected values are written out by hand or
come from a direct elastic and rigid run, never from the rule itself. Small N: about 2 s."""

from __future__ import annotations

import math

import pytest

from snapping import caps, caps_runs
from snapping.simulate import Links, Problem, run
from snapping.simulate.elastic import Elastic, solve

G, L, M = 9.81, 2.0, 0.1
N = 16
Q = ("v_peak", "a_peak", "sigma_peak")


def test_two_levels_that_agree_are_applied_and_others_left_out():
    coarse = {"v_peak": 0.990, "a_peak": 10.35, "sigma_peak": 0.996}
    fine = {"v_peak": 0.985, "a_peak": 0.957, "sigma_peak": 1.483}
    applied, ok = caps_runs.accept_factors(coarse, fine, 0.01)
    # |0.985 - 0.990| = 0.005 <= 0.00985: resolved, the fine level's applied; the other two differ by 10x and 49%
    assert ok == {"v_peak": True, "a_peak": False, "sigma_peak": False}
    assert applied == {"v_peak": 0.985, "a_peak": 1.0, "sigma_peak": 1.0}
    # at the edge: 1.0 -> 1.0099 agree within 1% of 1.0099 (0.0099 <= 0.010099); 1.0 -> 1.0102 do not
    applied, ok = caps_runs.accept_factors({"v_peak": 1.0, "a_peak": 1.0}, {"v_peak": 1.0099, "a_peak": 1.0102}, 0.01)
    assert ok == {"v_peak": True, "a_peak": False} and applied == {"v_peak": 1.0099, "a_peak": 1.0}


def _fake_levels(monkeypatch, levels):
    calls = []

    def fake(sp, chi, tol=1e-6, N=caps.STRETCH_N, start=caps.STRETCH_START, method=caps.STRETCH_METHOD):
        calls.append(N)
        return {**levels[N], "N": N, "n_rhs": 7, "wall": 0.0, "cpu": 0.0, "strain_peak": 0.01,
                "s_sigma": 0.5, "t_sigma": 1.2, "t_snap": 1.19}

    monkeypatch.setattr(caps, "stretch_factor", fake)
    return calls


def test_cap_multiplies_only_the_resolved_factors(monkeypatch):
    calls = _fake_levels(monkeypatch, {30: {"v_peak": 0.90, "a_peak": 0.5, "sigma_peak": 11.26},
                                       60: {"v_peak": 0.905, "a_peak": 0.8, "sigma_peak": 1.06}})
    judged, decide = [], caps.decide
    monkeypatch.setattr(caps, "decide", lambda f, real, alone, *a: judged.append(alone) or decide(f, real, alone, *a))
    r = caps.cap(None, 0.3, N=N, check=False, length=L, mass=M, ea=40.0)
    assert calls == [30, 60]
    assert judged == [{}]  # the unresolved stretching is not among the mechanisms that may have capped the tension
    s = r["stretching"]
    assert s["run"] and s["resolved"] == {"v_peak": True, "a_peak": False, "sigma_peak": False}
    assert s["factor"] == {"v_peak": 0.905, "a_peak": 1.0, "sigma_peak": 1.0}
    assert r["real"]["v_peak"] == pytest.approx(r["full"]["v_peak"] * 0.905, rel=1e-14)
    assert r["real"]["a_peak"] == r["full"]["a_peak"] and r["real"]["sigma_peak"] == r["full"]["sigma_peak"]
    assert "NOT applied" in s["why"] and "a_peak (0.5 -> 0.8)" in s["why"] and "sigma_peak (11.26 -> 1.06)" in s["why"]
    text = "\n".join(caps.format_answer(r))
    assert "NOT applied" in text and "v_peak x0.9050" in text
    # stretching alone: the ideal's tension (not applied), so it cannot be the mechanism that capped it
    assert r["alone"]["stretching"]["sigma_peak"] == r["ideal"]["sigma_peak"]
    assert r["cap"] != "stretching"
    assert [x["N"] for x in r["runs"] if x["run"] == "stretching"] == [30, 60]


def test_cap_applies_agreeing_factors_and_names_stretching(monkeypatch):
    _fake_levels(monkeypatch, {30: {"v_peak": 0.80, "a_peak": 0.40, "sigma_peak": 0.301},
                               60: {"v_peak": 0.802, "a_peak": 0.401, "sigma_peak": 0.300}})
    r = caps.cap(None, 0.3, N=N, check=False, length=L, mass=M, ea=40.0)
    for q, f in (("v_peak", 0.802), ("a_peak", 0.401), ("sigma_peak", 0.300)):
        assert r["real"][q] == pytest.approx(r["full"][q] * f, rel=1e-14)
    assert all(r["stretching"]["resolved"].values()) and "NOT applied" not in r["stretching"]["why"]
    assert "do not hold stretching" not in r["stretching"]["why"]  # (designres: said only when left out)
    assert r["cap"] == "stretching"  # the line has nothing else: 0.3 of the ideal's tension


def test_design_says_which_chi_left_the_factor_out(monkeypatch):
    _fake_levels(monkeypatch, {30: {"v_peak": 0.90, "a_peak": 0.5, "sigma_peak": 11.26},
                               60: {"v_peak": 0.905, "a_peak": 0.8, "sigma_peak": 1.06}})
    d = caps.design(None, (0.3,), N=N, max_tension=1e3, length=L, mass=M, ea=40.0)
    assert d["rows"][0]["stretching"]["resolved"]["sigma_peak"] is False
    assert "stretching factor NOT applied" in "\n".join(caps.format_design(d))


def test_one_level_is_the_elastic_line_over_the_rigid_chain():
    """A direct elastic run (the matched start, grid damping 1) and a direct rigid run on 30 links."""
    sp = caps.spec(None, length=L, mass=M, ea=40.0)
    p = Problem.catenary(0.3, links=Links.uniform(30, lumping="shared"))
    rigid = run(p, method="fast", tol=1e-6, progress=False).dataset.attrs
    el = solve(p, Elastic.from_wave_speed(math.sqrt(40.0 / (M / L)) / math.sqrt(G * L), grid_damping=1.0),
               tol=1e-6, method="rodas4", start="matched").dataset.attrs
    f = caps_runs.stretch_factor(sp, 0.3, 1e-6, 30)
    for q in Q:
        assert f[q] == pytest.approx(float(el[q]) / float(rigid[q]), rel=1e-9)
    assert f["t_snap"] == pytest.approx(float(rigid["t_snap_sigma"]), rel=1e-12)


def test_stretching_judged_at_the_speed_the_line_reaches(monkeypatch):
    """Whether stretching matters is judged on the full run's peak speed (drag slows the line), not
    the ideal chain's: a wave speed between the two speeds' 1/STRETCH_MATTERS leaves it out. The
    two speeds come from an answer without EA (no stretching), not from the rule."""
    kw = dict(check=False, alone=False, length=L, mass=M, ei=1e-9, diameter=0.05)
    base = caps.cap(None, 0.3, N=N, **kw)
    v_ideal, v_full = base["ideal"]["v_peak"], base["full"]["v_peak"]
    assert v_full < 0.95 * v_ideal  # drag slows the line (0.88 here)
    c = 0.5 * (v_ideal + v_full) / caps.STRETCH_MATTERS  # m/s
    called = _fake_levels(monkeypatch, {30: dict.fromkeys(Q, 0.5), 60: dict.fromkeys(Q, 0.5)})
    r = caps.cap(None, 0.3, N=N, ea=c**2 * M / L, **kw)
    s = r["stretching"]
    assert called == [] and s["run"] is False and r["real"] == r["full"]
    assert s["v_over_c"] == pytest.approx(v_full / c, rel=1e-9)
    assert s["v_over_c_ideal"] == pytest.approx(v_ideal / c, rel=1e-9) and s["v_over_c_ideal"] > caps.STRETCH_MATTERS
    assert "the full run's" in s["why"]
