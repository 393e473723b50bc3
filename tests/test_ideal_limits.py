"""The ideal chain's shipped continuum limits (snapping.table.limits) and the ideal beside a real line's limit
answer (snapping.caps_ideal). The shipped limits against independent studies (the regime studies' ideal limits,
computed on their own levels; the paper-level limits quoted in issue 24); the interpolation against a study at a
separation off the nodes, within its error bar, and exact on a power law; the stand-ins where no limit exists."""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping import caps, caps_ideal
from snapping._validate import SnappingInputError
from snapping.table import limits

Q = ("v_peak", "a_peak", "sigma_peak")


@pytest.mark.parametrize("chi, v", [(0.05, 69.63), (0.1, 32.97), (0.25, 11.28)])
def test_nodes_agree_with_the_limits_quoted_in_issue_24(chi, v):
    x = limits.ideal_limit(chi)["v_peak"]
    assert abs(x[0] - v) <= 0.005 + 2 * x[1] * x[0]  # (quoted to the last digit shown: half a unit of it)


def test_nodes_agree_with_the_regime_studies_ideal_limits():
    """The stretching study's ideal on its own levels (first = -1, five levels, escalated) at chi 0.1-0.5."""
    import importlib.resources

    import xarray as xr

    with importlib.resources.as_file(importlib.resources.files("snapping") / "data" / "regimes" / "stretching.nc") as f:
        ds = xr.open_dataset(f).load()
    for chi in ds.chi.values:
        x = limits.ideal_limit(float(chi))
        for q in Q:
            ref, err = float(ds[f"{q}_ideal"].sel(chi=chi)), float(ds[f"{q}_ideal_error"].sel(chi=chi))
            tol = 3 * (x[q][1] * x[q][0] + abs(err)) + 1e-4 * ref
            assert abs(x[q][0] - ref) <= tol, (chi, q, x[q], ref, err)


def test_between_nodes_within_the_error_bar_of_a_direct_study():
    from snapping.continuum import converge

    chi = 0.45
    ds = converge(chi, levels=4, first=-1).dataset
    x = limits.ideal_limit(chi)
    for q in Q:
        ref = float(ds.attrs[f"{q}_limit"])
        assert abs(x[q][0] / ref - 1.0) <= x[q][1] + abs(float(ds.attrs[f"{q}_error"]) / ref), (q, x[q], ref)
        assert x[q][1] < 0.02


def _fake(monkeypatch, a_nan=()):
    chis = np.array(limits.CHIS)
    t = {"chi": chis, "attrs": {}}
    for q, (c, p) in zip(Q, ((3.0, -1.5), (50.0, -3.0), (2.0, -2.0))):
        y = c * chis ** p
        if q == "a_peak":
            y = y.copy()
            y[list(a_nan)] = np.nan
        t[q] = {"limit": y, "error": 1e-3 * y}
    monkeypatch.setattr(limits, "load_limits", lambda path=None: t)


def test_interpolation_is_exact_on_a_power_law_and_refuses_where_a_neighbour_has_no_limit(monkeypatch):
    _fake(monkeypatch, a_nan=(len(limits.CHIS) - 1,))
    for chi in (0.05, 0.055, 0.113, 0.33, 0.77):
        x = limits.ideal_limit(chi)
        assert x["v_peak"][0] == pytest.approx(3.0 * chi ** -1.5, rel=1e-12)
        assert x["sigma_peak"][0] == pytest.approx(2.0 * chi ** -2.0, rel=1e-12)
        assert x["v_peak"][1] == pytest.approx(1e-3, abs=1e-9)  # the nodes' bars; a power law interpolates exactly
    assert limits.ideal_limit(0.85)["a_peak"] is None and limits.ideal_limit(0.9)["a_peak"] is None
    assert limits.ideal_limit(0.75)["a_peak"][0] == pytest.approx(50.0 * 0.75 ** -3.0, rel=1e-12)
    for bad in (0.04, 0.95):
        with pytest.raises(SnappingInputError, match=rf"chi={bad!r} is out of range.*\[0.05, 0.9\]"):
            limits.ideal_limit(bad)


class _Runs:
    def __init__(self, chi):
        self.chi, self.asked = chi, []

    def ideal_on(self, links):
        self.asked.append(links)
        return {"extrapolated": {q: 7.0 for q in Q}, "relative_error": {q: 0.02 for q in Q}, "links": [10, 20]}


def test_beside_takes_the_limit_else_the_graded_stand_in_else_the_uniform_links(monkeypatch):
    _fake(monkeypatch, a_nan=(len(limits.CHIS) - 1,))
    uniform = {"v_peak": 1.0, "a_peak": 2.0, "sigma_peak": 3.0, "method": "dop853"}
    runs = _Runs(0.3)
    ideal, info = caps_ideal.beside(runs, uniform, [("h0", "graded 0"), ("h1", "graded 1")])
    assert ideal["v_peak"] == pytest.approx(3.0 * 0.3 ** -1.5, rel=1e-12) and runs.asked == []  # (no stand-in run)
    assert info["source"] == {q: "limit" for q in Q} and info["uniform"] is uniform
    runs = _Runs(0.88)  # the acceleration has no limit beside 0.9: the graded stand-in
    ideal, info = caps_ideal.beside(runs, uniform, [("h0", "graded 0"), ("h1", "graded 1")])
    assert info["source"]["a_peak"] == "graded" and ideal["a_peak"] == 7.0 and len(runs.asked) == 1
    assert math.isnan(info["relative_error"]["a_peak"]) and "no continuum limit" in info["why"]["a_peak"]
    assert info["relative_error"]["v_peak"] > 0.0 and "v_peak" not in info["why"]
    big = {"v_peak": 10.0, "a_peak": 20.0, "sigma_peak": 30.0, "method": "dop853"}  # the graded stand-in falls short
    ideal, info = caps_ideal.beside(_Runs(0.88), big, [("h0", "graded 0"), ("h1", "graded 1")])
    assert info["source"]["a_peak"] == "uniform" and ideal["a_peak"] == 20.0
    assert ideal["sigma_peak"] == pytest.approx(2.0 * 0.88 ** -2.0, rel=1e-12) and info["links"] == [10, 20]
    ideal, info = caps_ideal.beside(_Runs(0.95), uniform, None)  # outside, no graded links: the uniform ideal
    assert [ideal[q] for q in Q] == [1.0, 2.0, 3.0] and info["source"] == {q: "uniform" for q in Q}
    assert all(math.isnan(info["relative_error"][q]) for q in Q)


def test_a_default_answer_compares_with_the_limit_and_given_links_with_the_same_links():
    """A light drag-only line (no stiff runs): N="auto" (the default) against the shipped limit in SI; N = 16 against
    the ideal chain on those 16 links, run here."""
    from snapping.simulate import Links, Problem, run

    kw = {"length": 2.0, "mass": 0.1, "diameter": 2e-3, "cd_normal": 1.2}
    sp = caps.spec(None, **kw)
    si = {"v_peak": math.sqrt(sp.g * sp.length), "a_peak": sp.g, "sigma_peak": sp.mass * sp.g}
    r = caps.cap(None, 0.3, check=False, alone=False, **kw)
    lim = limits.ideal_limit(0.3)
    for q in Q:
        assert r["ideal"][q] == pytest.approx(lim[q][0] * si[q], rel=1e-12), q
        assert r["factor"][q] == pytest.approx(r["real"][q] / (lim[q][0] * si[q]), rel=1e-12), q
    assert r["ideal_on"]["source"] == {q: "limit" for q in Q}
    assert "continuum limit" in "\n".join(caps.format_answer(r))
    r = caps.cap(None, 0.3, N=16, check=False, alone=False, **kw)
    a = run(Problem.catenary(0.3, links=Links.uniform(16)), method="fast", tol=1e-6, progress=False).dataset.attrs
    assert r["ideal_on"] is None
    for q in Q:
        assert r["ideal"][q] == pytest.approx(float(a[q]) * si[q], rel=1e-9), q


def test_a_study_is_accepted_where_it_converges_or_its_levels_settle():
    assert limits._accepted(1.5, 2.0, 4, 1.49, 1e-3) == 1.5  # converging: the extrapolation
    assert limits._accepted(math.nan, math.nan, 0, 2.36, 2.36e-5) == 2.36  # levels within 1e-5: the finest
    assert math.isnan(limits._accepted(math.nan, math.nan, 0, 118.0, 66.0))  # growing: no limit
    assert math.isnan(limits._accepted(math.nan, math.nan, 0, 2.36, 2.36 * 2e-4))  # just past SETTLED


def test_the_bar_between_nodes_carries_the_spline_s_leave_one_out_error(monkeypatch):
    """A peak with a wiggle (a power law times 1 + 0.02 sin(6 log chi)): between nodes the bar is the larger node
    bar plus the larger leave-one-out error at the two nodes, computed here with scipy's spline directly."""
    from scipy.interpolate import CubicSpline

    chis = np.array(limits.CHIS)
    y = 3.0 * chis ** -1.5 * (1.0 + 0.02 * np.sin(6.0 * np.log(chis)))
    t = {"chi": chis, "attrs": {}}
    for q in Q:
        t[q] = {"limit": y, "error": 1e-3 * y}
    monkeypatch.setattr(limits, "load_limits", lambda path=None: t)
    x = np.log(chis)

    def loo(i):
        keep = np.arange(chis.size) != i
        return abs(math.exp(CubicSpline(x[keep], np.log(y[keep]))(x[i])) / y[i] - 1.0)

    for chi in (0.115, 0.33):
        j = int(np.searchsorted(chis, chi))
        got = limits.ideal_limit(chi)["v_peak"]
        assert got[0] == pytest.approx(math.exp(CubicSpline(x, np.log(y))(math.log(chi))), rel=1e-12)
        assert got[1] == pytest.approx(1e-3 + max(loo(j - 1), loo(j)), rel=1e-9)
        assert max(loo(j - 1), loo(j)) > 1e-4  # (the term is there)
