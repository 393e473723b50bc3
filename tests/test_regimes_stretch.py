"""The stretching regime study (branch regstretch): the elastic cell's settings, its stop
rule's floor, and the shipped study ``data/regimes/stretching.nc``.

* a stretching cell runs the elastic line with the study's grid damping, RODAS4 and the stop
  floor of :mod:`snapping.regimes_spec` (caught at the call: a cell that drops one of them
  would run undamped, or on to t = 10);
* ``solve(stop_floor=)``: the stop rule arms at that running peak (a floor above the snap
  never arms: the run goes on to ``t_end_max``); bad values refused;
* the shipped study: its ideal limits agree with the end-mass study's (other levels, other
  runs: an independent computation) within the two error bars, and the smallest number
  (c = 442 sqrt(gL)) reproduces the ideal limit within the error bars, at every chi whose
  cells are resolved.
"""

import math

import numpy as np
import pytest

from richardson_by_hand import richardson as _richardson
from snapping import regimes as R
from snapping import regimes_spec as S
from snapping._validate import SnappingInputError


# ------------------------------------------------------------------ the cell's settings
def test_stretching_cell_runs_the_study_settings(monkeypatch):
    import snapping.simulate.elastic as E

    seen = {}
    real = E.solve

    def spy(problem, elastic, **kw):
        seen.update(kw, grid_damping=elastic.grid_damping, ea=float(elastic.ea))
        return real(problem, elastic, **kw)

    monkeypatch.setattr(E, "solve", spy)
    level = {"n_links": 4, "frac": 0.25}
    row = R._run_task(0.5, "stretching", 0.1, level, 1e-5, damping=0.7)
    assert seen["start"] == S.STRETCH_START == "matched"  # the study's start by default
    assert seen["grid_damping"] == 0.7 and seen["ea"] == pytest.approx(100.0, rel=1e-12)  # EA = lambda c^2, c = 10
    assert seen["method"] == S.STRETCH_METHOD == "rodas4-links"  # the shipped study's method (branch shipstretch)
    assert seen["stop_floor"] == S.STRETCH_STOP_FLOOR
    assert row["v_peak"] > S.STRETCH_STOP_FLOOR  # the snap was judged (stopped there, not at t = 10)


def test_stiff_lines_run_at_a_tolerance_scaled_as_c_squared(monkeypatch):
    """Above c = 450 a run's tolerance is the study's times (450/c)^2 (the tip links' stretch, ~ c^-2)."""
    import snapping.simulate.elastic as E

    seen = []

    class Stop(Exception):
        pass

    def spy(problem, elastic, **kw):
        seen.append(kw["tol"])
        raise Stop

    monkeypatch.setattr(E, "solve", spy)
    level = {"n_links": 4, "frac": 0.25}
    for c in (100.0, 450.0, 1000.0, 4500.0):
        with pytest.raises(Stop):
            R._run_task(0.5, "stretching", 1.0 / c, level, 1e-6)
    assert seen[:2] == [1e-6, 1e-6]
    assert seen[2] == pytest.approx(1e-6 * 0.45**2, rel=1e-12) and seen[3] == pytest.approx(1e-8, rel=1e-12)


def test_study_records_the_elastic_settings(monkeypatch):
    from snapping.continuum import QUANTITIES

    calls = []

    def fake(chi, mech, number, level, tol, damping=None, start=None, method=None):
        calls.append((mech, damping, start))
        return {**{q: 1.0 for q in QUANTITIES}, "n_links": 1, "n_rhs": 1, "cpu_time": 0.0}

    monkeypatch.setattr(R, "_run_task", fake)
    ds = R.regimes("stretching", [0.5], [0.1], levels=2, first=-4, damping=0.5, progress=False)
    assert ds.attrs["damping"] == 0.5 and ds.attrs["elastic_method"] == S.STRETCH_METHOD
    assert ds.attrs["stop_floor"] == S.STRETCH_STOP_FLOOR
    assert ("stretching", 0.5, "matched") in calls  # the cells get the study's grid damping and start
    assert ds.attrs["elastic_start"] == "matched" and '"elastic_start": "matched"' in ds.attrs["regimes_study"]
    key = R._study_key("stretching", [0.5], [0.1], {"damping": 1.0}, 0.5)
    assert key != R._study_key("stretching", [0.5], [0.1], {"damping": 0.5}, 0.5)
    calls.clear()
    old = R.regimes("stretching", [0.5], [0.1], levels=2, first=-4, damping=0.5, start="stretched", progress=False)
    assert ("stretching", 0.5, "stretched") in calls and old.attrs["elastic_start"] == "stretched"
    # the stop-29 study (run from "stretched") had no start in its key: the same key, so it resumes
    assert "elastic_start" not in old.attrs["regimes_study"]
    for bad in ("released", 1, None):
        with pytest.raises(SnappingInputError, match="start"):
            R.regimes("stretching", [0.5], [0.1], levels=2, first=-4, start=bad, progress=False)
    # no damping given: each mechanism's own default (stretching's tip links chatter slack at 1)
    calls.clear()
    dflt = R.regimes("stretching", [0.5], [0.1], levels=2, first=-4, progress=False)
    assert dflt.attrs["damping"] == S.STRETCH_DAMPING == 4.0 and ("stretching", 4.0, "matched") in calls


# ------------------------------------------------------------------ solve's stop floor
def test_stop_floor_arms_the_stop_rule():
    from snapping.simulate.elastic import Elastic, solve
    from snapping.simulate.problem import Links, Problem

    p = Problem.catenary(0.5, links=Links.uniform(4, lumping="shared"))
    el = Elastic.from_wave_speed(10.0, grid_damping=1.0)
    a = solve(p, el, tol=1e-5, stop_floor=1.0).dataset.attrs
    assert a["stop_reason"] == "snap" and a["stop_speed_floor"] == 1.0 and a["t_final"] < 2.0
    assert a["t_stop_armed"] > 0 and a["v_peak"] > 1.0
    never = solve(p, el, tol=1e-5, stop_floor=10 * a["v_peak"], t_end_max=a["t_final"] + 0.3).dataset.attrs
    assert never["stop_reason"] == "t_end_max" and math.isnan(never["t_stop_armed"])
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(SnappingInputError, match="stop_floor"):
            solve(p, el, stop_floor=bad)


# ------------------------------------------------------------------ the shipped study
#: the shipped study (branch shipstretch): benchmarks/stretch_scan.py's scan, rodas4-links, fold levels -1..2
CHIS = [0.1, 0.2, 0.3, 0.5]
NUMBERS = list(np.geomspace(1e-3, 0.3, 8))


@pytest.fixture(scope="module")
def shipped():
    try:
        return R.bundled_study("stretching")
    except SnappingInputError as exc:
        pytest.skip(str(exc))


def test_shipped_study_is_the_links_scan(shipped, monkeypatch):
    """The file is the links scan, and its key is the one regimes() writes with the defaults (so
    ``bench_regimes.py --study stretching`` resumes it: nothing to run, no refusal)."""
    ds = shipped
    assert ds.attrs["mechanism"] == "stretching" and ds.attrs["number_name"] == "inverse_stretching"
    assert ds.attrs["elastic_method"] == "rodas4-links" == S.STRETCH_METHOD and ds.attrs["tip_time"] == 3e-8
    assert ds.attrs["damping"] == S.STRETCH_DAMPING and ds.attrs["status"] == "complete"
    assert ds.attrs["elastic_start"] == "matched" and ds.attrs["tol_c"] == S.STRETCH_TOL_C
    assert ds.attrs["peaks"] == "snap" == S.STRETCH_PEAKS_KEY  # its a_peak, sigma_peak are the snap's (0.9 window)
    assert (ds.attrs["levels"], ds.attrs["first"], ds.attrs["tol"]) == (4, -1, 1e-6)
    assert (ds.attrs["escalate"], ds.attrs["extra_levels"]) == (S.STRETCH_ESCALATE, S.STRETCH_EXTRA_LEVELS) == (0.01, 1)
    assert list(ds.chi.values) == CHIS and ds.sizes["number"] == 8 and ds.sizes["level"] == 5
    np.testing.assert_allclose(ds.number.values, NUMBERS, rtol=1e-12)
    assert np.all(np.isfinite(ds.v_peak_level.values[:, :, :4])) and np.all(np.isfinite(ds.v_peak_ideal_level.values[:, :4]))
    from snapping.continuum import QUANTITIES

    def fake(*a, **k):
        return {**{q: 1.0 for q in QUANTITIES}, "n_links": 1, "n_rhs": 1, "cpu_time": 0.0}

    monkeypatch.setattr(R, "_run_task", fake)
    new = R.regimes("stretching", CHIS, NUMBERS, accuracy="medium", tol=1e-6, progress=False,
                    escalate=S.STRETCH_ESCALATE, extra_levels=S.STRETCH_EXTRA_LEVELS)
    assert new.attrs["regimes_study"] == ds.attrs["regimes_study"]


def test_shipped_ideal_runs_agree_with_the_bending_study(shipped):
    """The ideal's runs (fold levels -1..2, tol 1e-6) against the bending study's (the same links at
    tol 1e-7: other runs): level by level within 1e-6 relative, the limits within their bars."""
    other = R.bundled_study("bending")
    a, b = shipped.v_peak_ideal_level.values[:, :4], other.v_peak_ideal_level.sel(chi=shipped.chi).values[:, :4]
    np.testing.assert_allclose(a, b, rtol=1e-6)
    for chi in shipped.chi.values:
        va, ea = float(shipped.v_peak_ideal.sel(chi=chi)), float(shipped.v_peak_ideal_error.sel(chi=chi))
        vb, eb = float(other.v_peak_ideal.sel(chi=chi)), float(other.v_peak_ideal_error.sel(chi=chi))
        five = int(shipped.levels_run_ideal.sel(chi=chi)) == 5  # (escalated: a fifth level the bending study lacks)
        assert abs(va - vb) <= (1.0 if five else 1e-3) * (ea + eb) and ea <= 0.005 * va, (chi, va, ea, vb, eb)


def test_every_cell_is_resolved_to_one_percent(shipped):
    """Every cell's limit and error bar are the Richardson extrapolation of its levels (four, or five
    where escalated) by hand,
    within 1% of it (the scan's 32/32); the study's converged flag holds in at least 31 cells."""
    for i, chi in enumerate(shipped.chi.values):
        for j in range(shipped.sizes["number"]):
            lim, err = _richardson(shipped.v_peak_level.values[i, j])
            v, e = float(shipped.v_peak.values[i, j]), float(shipped.v_peak_error.values[i, j])
            assert v == pytest.approx(lim, rel=1e-12) and e == pytest.approx(err, rel=1e-9, abs=1e-15), (chi, j)
            assert e <= 0.01 * v, (chi, j, v, e)
    assert int(shipped.converged.values.sum()) >= 31


def test_snap_peaks_resolved_and_capped(shipped):
    """The snap's acceleration and tension (branch snappeaks): each cell's limit and bar are the
    Richardson extrapolation of its levels by hand (the escalated cells' five); within 1% in 31 and
    31 of 32 cells (30 in sigma before branch window ended the window at its exact edge) (24 and 24 on four levels for all; the run's peaks gave 23 and 17); the ideal's columns are the bending study's independent runs (the same
    links at tol 1e-7) within 1e-6; and stretching caps the snap's acceleration: no cell's a_peak is
    above the ideal's beyond twice its bar + 1e-3 (the run's peaks, taken in the recoil, were up to
    7.4 times it: chi 0.3, c 442), and the stiffest line at chi 0.5 (c = 220 v_ideal) has both
    within 0.5% of the ideal's."""
    other = R.bundled_study("bending")
    for q in ("a_peak", "sigma_peak"):
        np.testing.assert_allclose(shipped[f"{q}_ideal_level"].values[:, :4],
                                   other[f"{q}_ideal_level"].sel(chi=shipped.chi).values[:, :4], rtol=1e-6)
        n_ok = 0
        for i, chi in enumerate(shipped.chi.values):
            for j in range(shipped.sizes["number"]):
                lim, err = _richardson(shipped[f"{q}_level"].values[i, j])
                v, e = float(shipped[q].values[i, j]), float(shipped[f"{q}_error"].values[i, j])
                assert v == pytest.approx(lim, rel=1e-12) and e == pytest.approx(err, rel=1e-9, abs=1e-15), (q, chi, j)
                n_ok += e <= 0.01 * v
        # (branch stretch1pct's escalated scan: 31, 30; branch window's exact window end: sigma 31)
        assert n_ok >= {"a_peak": 31, "sigma_peak": 31}[q], (q, n_ok)
        r = shipped[f"{q}_ratio"].sel(chi=0.5).values[0]
        assert abs(r - 1.0) < 5e-3, (q, r)
    r, re = shipped.a_peak_ratio.values, shipped.a_peak_ratio_error.values
    assert np.all(r <= 1.0 + 2 * re + 1e-3), r


def test_smallest_number_is_the_ideal_limit(shipped):
    """The issue's check, c -> infinity is the ideal continuum limit: the three stiffest lines' limits
    (c = 196, 442, 1000), extrapolated in 1/c to 0 by hand (order from their differences), reproduce
    the ideal's limit (an independent run: the rigid chain by the fast method) within the error bars;
    at chi = 0.5 (c = 1000 is 220 v_ideal) the stiffest cell alone does."""
    for chi in shipped.chi.values:
        c = shipped.sel(chi=chi)
        v, e = c.v_peak.values[:3], c.v_peak_error.values[:3]  # c = 1000, 442, 196
        q = 1.0 / shipped.number.values[1] / (1.0 / shipped.number.values[0])  # c ratio, 1/2.26
        d2, d1 = v[0] - v[1], v[1] - v[2]
        assert d1 > 0 and d2 > 0 and d2 < d1  # rising towards the rigid chain, more slowly
        p = math.log(d1 / d2) / math.log(1.0 / q)
        corr = d2 / (q**-p - 1.0)
        ideal, ie = float(c.v_peak_ideal), float(c.v_peak_ideal_error)
        assert abs(v[0] + corr - ideal) <= abs(corr) + e[0] + ie, (chi, v[0] + corr, ideal)
        assert v[0] <= ideal + ie + e[0]
        if chi == 0.5:
            assert abs(v[0] - ideal) <= e[0] + ie


def test_stiffer_lines_approach_the_rigid_chain_monotonically(shipped):
    """On every level and in the limits, the elastic peak over the rigid chain's (independent runs)
    rises monotonically with c towards 1 and never passes it; at each c it rises with chi (a
    slower snap: v_ideal 33 -> 4.5), and the lines stiffer than 25 v_ideal are within 1% of it."""
    r_all = []
    for chi in shipped.chi.values:
        c = shipped.sel(chi=chi)
        r = c.v_peak_level.values / c.v_peak_ideal_level.values[None, :]  # numbers x levels
        lim = c.v_peak.values / float(c.v_peak_ideal)
        for col in list(r.T) + [lim]:  # the numbers ascending: c descending (an escalated level: its cells)
            col = col[np.isfinite(col)]
            assert np.all(np.diff(col) < 0) and np.all(col <= 1.0 + 1e-6), (chi, col)
        stiff = 1.0 / shipped.number.values >= 25.0 * float(c.v_peak_ideal)
        assert stiff.sum() >= 1 and np.all(lim[stiff] >= 0.99), (chi, lim[stiff])
        r_all.append(lim)
    assert np.all(np.diff(np.array(r_all), axis=0) > 0)  # rising with chi at every c


def test_stretching_speeds_by_hand():
    from snapping.caps_report import stretching_speeds

    a = {"chi": {0.2: {"crossover": {"bracketed": True, "number": 0.02, "lo": 0.016, "hi": 0.025, "statement": ""}},
                 0.5: {"crossover": {"bracketed": False, "number": float("nan"), "lo": float("nan"),
                                     "hi": float("nan"), "statement": "crossover above 0.3"}}}}
    out = stretching_speeds(a, {0.2: (15.0, "x")})
    assert out[0] == "chi=0.2: c_c = 50 (40..62.5), v_ideal = 15 (x), c_c/v_ideal = 3.33"  # 1/0.02, 50/15
    assert out[1] == "chi=0.5: no c_c (crossover above 0.3)"


def _planted(ds):
    """A copy with two cells' levels spoiled: chi = 0.1, c = 3.33 oscillating (a failed extrapolation)
    and chi = 0.2, c = 3.33 converging slowly (a ratio bar of 11%)."""
    bad = ds.copy(deep=True)
    v = bad.v_peak_level.values
    iv = bad.v_peak_ideal_level.values
    v[0, 7, :4] = iv[0, :4] * np.array([0.30, 0.60, 0.20, 0.40])
    v[1, 7, :4] = iv[1, :4] * np.array([0.30, 0.40, 0.48, 0.54])
    v[:2, 7, 4:] = np.nan  # (their four levels only)
    return bad


def test_level_ratios_extrapolate_the_same_links_ratio(shipped):
    """The ratio on the same links, level by level, and its Richardson limit by hand (_richardson);
    a failed extrapolation (none, or a bar over half the ratio) is left out (nan)."""
    from snapping.regimes_analysis import level_ratios

    n = failed = 0
    for ds in (shipped, _planted(shipped)):
        lr = level_ratios(ds)
        for chi in ds.chi.values:
            c = ds.sel(chi=chi)
            for j in range(ds.sizes["number"]):
                lim, err = _richardson(c.v_peak_level.values[j] / c.v_peak_ideal_level.values)
                got = lr["chi"][float(chi)]["ratio"][j]
                if not (0.0 < lim < 2.0 and err <= 0.5 * lim):
                    assert math.isnan(got), (chi, j)
                    failed += 1
                    continue
                assert got == pytest.approx(lim, rel=1e-9) and lr["chi"][float(chi)]["error"][j] == pytest.approx(
                    err, rel=1e-9, abs=1e-15)
                n += 1
    assert n >= 60 and failed >= 1


def test_ratio_map_flags_the_unconverged_ratios(shipped):
    """The map's "?" (with_level_ratios' converged) marks the same-links ratios whose error bar (by
    hand) exceeds 5% of them, or that failed: none in the shipped study, the planted ones in a copy."""
    from snapping.regimes_analysis import with_level_ratios

    for ds, want_bad in ((shipped, set()), (_planted(shipped), {(0, 7), (1, 7)})):
        m = with_level_ratios(ds)
        bad = set()
        for i, chi in enumerate(ds.chi.values):
            c = ds.sel(chi=chi)
            for j in range(ds.sizes["number"]):
                lim, err = _richardson(c.v_peak_level.values[j] / c.v_peak_ideal_level.values)
                good = 0.0 < lim < 2.0 and err <= 0.05 * lim
                assert int(m.converged.values[i, j]) == int(good), (chi, j)
                if not good:
                    bad.add((i, j))
        assert bad == want_bad


def test_report_section_gives_the_stretching_verdict(shipped):
    """c_c per chi from the report: bracketed at every chi, between the two cells whose same-links
    ratio brackets 0.9 (by hand), against the resolved ideal's speed; c_c/v_ideal between 1 and 4."""
    import re

    from snapping.caps_report import ideal_speeds, report_section, stretching_speeds
    from snapping.regimes_analysis import level_ratios

    other = R.bundled_study("end-mass")
    text = "\n".join(report_section([], [other, shipped]))
    want = "; ".join(stretching_speeds(level_ratios(shipped), ideal_speeds([other, shipped])))
    assert f"**Verdict (computed, stretching against the issue's guess, c ~ v): {want}.**" in text
    for chi in CHIS:
        # (the ideal's speed from the study with the smaller bar: at chi 0.1 the end-mass and stretching studies'
        # ideal runs are the same problem, their bars 0.0063130 apart in the 8th digit, so either may be named)
        m = re.search(rf"chi={chi:g}: c_c = ([0-9.]+) .*?v_ideal = ([0-9.]+) \((?:stretching|end-mass) study.*?"
                      r"c_c/v_ideal = ([0-9.]+)", want)
        assert m, (chi, want)
        cc, v, ratio = (float(x) for x in m.groups())
        c = shipped.sel(chi=chi)
        r = c.v_peak.values / float(c.v_peak_ideal)  # by hand, the limits' ratio
        j = int(np.flatnonzero(r < 0.9)[0])  # the first cell below 0.9 (c descending)
        assert 1.0 / shipped.number.values[j] <= cc <= 1.0 / shipped.number.values[j - 1], (chi, cc)
        assert v == pytest.approx(float(c.v_peak_ideal), rel=1e-3) and 1.0 < ratio < 4.0


def test_report_section_stretching_verdict_by_its_limits(shipped):
    """The study's ideal limits are resolved (bars <= 0.3%): the generic verdict gives each chi's
    crossover of the cells' own limits; a copy whose ideal bars are 20% points to the same-links
    ratio instead (the old node-method study's verdict)."""
    from snapping.caps_report import report_section

    def verdict(ds):
        text = "\n".join(report_section([], [ds]))
        return next(t for t in text.splitlines() if t.startswith("**Verdict (computed, v_peak): "))

    line = verdict(shipped)
    assert "same-links ratio's (below)" not in line
    assert all(f"chi={chi:g}: crossover at" in line for chi in CHIS[:3]) and "crossover ~ " in line
    loose = shipped.copy(deep=True)
    loose["v_peak_ideal_error"].values[:] = 0.2 * loose.v_peak_ideal.values
    line = verdict(loose)
    assert "no crossover" not in line and "same-links ratio's (below)" in line
    v = float(shipped.v_peak_ideal.sel(chi=0.5))
    assert f"chi=0.5: {v:.4g} +- " in line


def test_escalated_cells_are_those_over_one_percent_on_four_levels(shipped):
    """The escalation's record, by hand: a cell ran five levels exactly where the Richardson bar of its
    first four (v, a or sigma) exceeds 1% of its limit; the ideal ran five at every chi with such a
    cell; every other cell has level 4 empty."""
    for i, chi in enumerate(shipped.chi.values):
        any_cell = False
        for j in range(shipped.sizes["number"]):
            over = False
            for q in ("v_peak", "a_peak", "sigma_peak"):
                lim, err = _richardson(shipped[f"{q}_level"].values[i, j, :4])
                over |= not err <= 0.01 * abs(lim)
            assert int(shipped.levels_run.values[i, j]) == (5 if over else 4), (chi, j)
            assert np.isfinite(shipped.v_peak_level.values[i, j, 4]) == over
            any_cell |= over
        # (five where a cell ran five; the file of branch window resumed the ideal's runs of the one before,
        # whose chi 0.5 ideal had a fifth level for a cell that no longer needs one: kept, not dropped)
        assert int(shipped.levels_run_ideal.values[i]) >= (5 if any_cell else 4), chi
    # 13 cells before branch window; 8 since: the sigma levels at the window's exact edge converge
    assert int((shipped.levels_run.values == 5).sum()) == 8


def test_taut_tension_column(shipped):
    """The taut snap's tension beside the study's (never below it: its window holds the 0.9 one), and
    the ideal's equal to its sigma_peak (an inextensible chain is never slack); by hand, the soft line
    chi 0.1, c 7.53 grows with the levels by steps that do not shrink by half a level (no order 1)."""
    t, s = shipped.sigma_peak_taut_level.values, shipped.sigma_peak_level.values
    ok = np.isfinite(t)
    assert np.array_equal(ok, np.isfinite(s)) and np.all(t[ok] >= s[ok] * (1 - 1e-12))
    np.testing.assert_array_equal(shipped.sigma_peak_taut_ideal_level.values, shipped.sigma_peak_ideal_level.values)
    d = np.diff(t[0, 6])
    d = d[np.isfinite(d)]  # (four levels since branch window: the cell's sigma no longer escalates it)
    assert d.size >= 3 and np.all(d > 0) and np.all(d[1:] / d[:-1] > 0.5), d
