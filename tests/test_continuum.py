"""The continuum limit (snapping.continuum, snapping.simulate.grading): the extrapolation
against synthetic sequences with known limits, gradings against their definitions, the
refinement of a smooth problem at the order its discretisation predicts, and a small
convergence study with its invariants."""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping import SnappingInputError
from snapping.continuum import converge, extrapolate, level_parameters
from snapping.simulate import Links, Problem, grading, run

FAST = dict(method="fast", progress=False)


@pytest.mark.parametrize("seed", range(40))
def test_extrapolation_recovers_a_synthetic_limit_within_its_error_bar(seed):
    """q(h) = q_inf + C h^p (1 + c2 h) + noise, random p in [1, 3]: the stated error bar
    covers the true limit, and the order is recovered."""
    rng = np.random.default_rng(seed)
    p, C, q_inf = rng.uniform(1.0, 3.0), rng.uniform(0.5, 5.0) * rng.choice([-1, 1]), rng.uniform(1, 100)
    h = 0.2 * 0.5 ** np.arange(5)
    q = q_inf + C * h**p * (1 + rng.uniform(-1, 1) * h) + rng.normal(0, 1e-9, h.size)
    e = extrapolate(h, q)
    assert e["converging"]
    assert abs(e["limit"] - q_inf) <= e["error"]
    assert abs(e["order"] - p) < 0.15
    assert abs(e["limit"] - q_inf) < abs(q[-1] - q_inf)  # better than the finest level


def test_extrapolation_says_when_there_is_no_convergence():
    h = 0.1 * 0.5 ** np.arange(4)
    e = extrapolate(h, [1.0, 1.2, 0.9, 1.15])  # oscillating
    assert not e["converging"] and e["error"] == pytest.approx(0.3)
    assert not extrapolate(h, [1.0, 1.1, 1.3, 1.7])["converging"]  # differences growing
    with pytest.raises(SnappingInputError, match="constant ratio"):
        extrapolate([0.1, 0.05, 0.02], [1, 2, 3])
    with pytest.raises(SnappingInputError, match="finite"):
        extrapolate([0.1, 0.05], [1.0, math.nan])


def test_fold_grading_follows_its_definition():
    chi, frac, h_min, h_max, gamma = 0.25, 0.01, 1e-6, 1e-3, 0.1
    h = grading.fold_following(chi, frac=frac, h_min=h_min, h_max=h_max, gamma=gamma)
    from snapping import estimates

    a = estimates.catenary_parameter(chi)
    x = np.concatenate([[0.0], np.cumsum(h)])[:-1] + 0.5 * h  # link midpoints, from the free end
    assert h.sum() == pytest.approx(1.0, abs=1e-15) and h.min() >= h_min * (1 - 1e-6)
    on_fold = (x > 0.05) & (x < 0.5)
    target = np.minimum(frac * a * (2 * x[on_fold]) ** 0.25, h_min + gamma * x[on_fold])
    assert np.abs(h[on_fold] / target - 1).max() < 5e-4  # (the grading follows it to 3.1e-4 here)
    assert h.max() <= h_max * (1 + 1e-9) and h[-1] == pytest.approx(h_max, rel=1e-3)
    assert np.abs(np.diff(h)).max() <= gamma * h.max() * 1.01  # no kinks: the spacing changes by <= gamma h
    # the first link spans one unit of n(x) = ln(1 + gamma x / h_min) / gamma (times N/n(1) <= 1)
    assert h_min < h[0] <= h_min * math.expm1(gamma) / gamma * (1 + 1e-6)


def test_graded_chain_with_equal_links_is_the_uniform_chain_bit_for_bit():
    h = grading.tip_graded(1 / 40, 1 / 40)
    assert h.size == 40 and np.all(h == 1 / 40)
    a = run(Problem.catenary(0.35, links=Links.graded(h, lumping="paper")), **FAST).dataset
    b = run(0.35, 40, **FAST).dataset
    assert np.array_equal(a.v_max.values, b.v_max.values) and a.attrs["v_peak"] == b.attrs["v_peak"]
    c = run(Problem.catenary(0.35, links=Links.graded(h)), **FAST).dataset
    d = run(Problem.catenary(0.35, links=Links.uniform(40, lumping="shared")), **FAST).dataset
    assert np.array_equal(c.v_max.values, d.v_max.values) and np.array_equal(c.x.values, d.x.values)


def test_smooth_problem_refines_at_the_order_of_its_lumping():
    """A chain falling from a shallow catenary (chi = 0.8, no snap by t = 0.5): the free
    end's position converges at first order with the paper's lumping (its mass is displaced
    by half a link towards the free end) and faster with the consistent lumping (whose
    error is smaller at every N; the free end, where the tension vanishes, keeps it below
    second order)."""
    Ns = (25, 50, 100, 200)
    res = {}
    for lump in ("paper", "shared"):
        y = [float(run(Problem.catenary(0.8, links=Links.uniform(N, lumping=lump), chords="exact"), t_end=0.5,
                       tol=1e-12, **FAST).dataset.y[-1, 0]) for N in Ns]
        res[lump] = (y, extrapolate(1.0 / np.array(Ns), y))
    assert 0.9 < res["paper"][1]["order"] < 1.15
    assert 1.3 < res["shared"][1]["order"] < 2.1
    lim = res["shared"][1]["limit"]
    assert abs(res["paper"][1]["limit"] - lim) < 2e-5  # one string, two lumpings
    assert all(abs(s - lim) < abs(p - lim) for s, p in zip(res["shared"][0], res["paper"][0]))


def test_converge_small_study_keeps_its_invariants(tmp_path):
    c = converge(0.5, levels=3, first=-2, output=tmp_path / "conv")
    ds = c.dataset
    assert ds.sizes["level"] == 3 and np.all(np.diff(ds.n_links.values) > 0)
    assert np.all(ds.energy_drift.values < 1e-8) and np.all(ds.link_drift.values < 1e-13)
    for q in ("v_peak", "a_peak", "sigma_peak"):
        assert ds.attrs[q + "_order"] > 1.0
        assert abs(ds.attrs[q + "_limit"] - float(ds[q][-1])) <= abs(float(ds[q][-1] - ds[q][-2]))
    assert (tmp_path / "conv" / "convergence.nc").is_file() and len(c.paths) == 3
    again = converge(0.5, levels=3, first=-2, output=tmp_path / "conv")  # resumed: the same levels
    assert np.array_equal(again.dataset.v_peak.values, ds.v_peak.values)
    assert again.dataset.attrs["wall_time_total"] < ds.attrs["wall_time_total"] + 1.0
    # each level's CPU time where it ran (NaN where it was resumed: not measured again)
    assert np.all(ds.cpu_time.values > 0) and np.all(np.isnan(again.dataset.cpu_time.values))
    assert "CPU s" in c.table()
    for q in ("v_peak", "a_peak", "sigma_peak"):  # every quantity, not any one
        assert f"{q}: converged to {ds.attrs[q + '_digits']} significant digits" in ds.attrs["verdict"]
    # the figure of a study alone (no uniform chains beside it), as `snapping converge --plot` draws it
    png = tmp_path / "conv.png"
    c.plot(png)
    assert png.stat().st_size > 5000
    from snapping.cli import main

    assert main(["converge", "--chi", "0.5", "--levels", "3", "--first", "-2", "-o", str(tmp_path / "conv"),
                 "--plot", str(tmp_path / "cli.png"), "--json"]) == 0
    assert (tmp_path / "cli.png").stat().st_size > 5000


def test_level_parameters_and_bad_input():
    p = level_parameters(3, 0.5, first=1)
    assert p[0]["frac"] == pytest.approx(0.02) and p[2]["h_min"] == pytest.approx(5e-7)
    for kw, name in ((dict(levels=0), "levels"), (dict(ratio=1.5), "ratio"), (dict(workers=0), "workers")):
        with pytest.raises(SnappingInputError, match=name):
            converge(0.3, **kw)
    with pytest.raises(SnappingInputError, match="chi"):
        converge(1.3)
    with pytest.raises(SnappingInputError, match="h_max"):
        grading.fold_following(0.3, h_min=1e-3, h_max=1e-4)
    with pytest.raises(SnappingInputError, match="free_end"):
        Links.graded([0.5, 0.5], free_end="none")


@pytest.mark.parametrize("name", ["continuum", "simulate.grading"])
def test_docstring_examples_run(name):
    import doctest
    import importlib

    module = importlib.import_module(f"snapping.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0
