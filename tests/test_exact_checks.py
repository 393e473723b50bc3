"""Exact checks of rules, boundaries, error bars and conversions that the broader tests only
bound loosely: each expected value is computed here independently (a closed form, a direct
numpy computation, a synthetic table whose answer is known), at a tolerance near what the
code computes. These are the tests that catch the mutations of tools/mutations.toml
(``python tools/mutate.py``); the last test keeps that list from rotting.

Fast: no run here takes more than a few hundred milliseconds after numba's cache is warm.
"""

from __future__ import annotations

import math
import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from snapping import design, estimates
from snapping import table as T
from snapping._validate import SnappingInputError

ROOT = Path(__file__).resolve().parent.parent
CHAIN = estimates.Chain(length=2.0, mass=0.05, g=9.81)
MG = 0.05 * 9.81  # the chain's weight: the unit of tension
QS = ("v_peak", "a_peak", "sigma_peak", "t_snap_v")


def lagrange(nodes, values, x):
    """The polynomial through (nodes, values) at x, by Neville's scheme (independent of the
    table's weights)."""
    p = [float(v) for v in values]
    n = len(nodes)
    for k in range(1, n):
        for i in range(n - k):
            p[i] = ((x - nodes[i + k]) * p[i] + (nodes[i] - x) * p[i + 1]) / (nodes[i] - nodes[i + k])
    return p[0]


# ============================================================ design: intervals and neighbours
def test_intervals_interpolate_in_log_chi_and_include_a_zero():
    chi = np.array([1.0, 2.0, 4.0, 8.0])
    # g: 3, -1, -1, 3: crossings a quarter of the way (in log chi) from the inside samples
    (lo, hi), = design._intervals(chi, np.array([3.0, -1.0, -1.0, 3.0]))
    assert lo == pytest.approx(2.0 ** 0.75, rel=1e-14) and hi == pytest.approx(4.0 * 2.0 ** 0.25, rel=1e-14)
    # a sample exactly at the limit meets it (g <= 0): a one-point interval
    assert design._intervals(chi, np.array([1.0, 0.0, 1.0, 1.0])) == [(2.0, 2.0)]
    # meeting everywhere: the whole range, its ends the samples
    assert design._intervals(chi, np.array([-1.0, -1.0, -2.0, -1.0])) == [(1.0, 8.0)]
    assert design._intervals(chi, np.array([1.0, 1.0, 2.0, 1.0])) == []


def test_both_neighbours_is_the_maximum_over_a_sample_and_its_two_neighbours():
    rng = np.random.default_rng(3)
    for _ in range(20):
        g = rng.normal(size=9)
        padded = np.concatenate([[-np.inf], g, [-np.inf]])
        expected = np.max([padded[:-2], padded[1:-1], padded[2:]], axis=0)
        np.testing.assert_array_equal(design._both_neighbours(g), expected)


# ============================================================ design over a synthetic table
CHI_B = 0.2  # where the synthetic tension meets the limit with its bound
LIMIT = 20.0  # N
ERR = 0.02


class FakeTable:
    """A table whose peaks are closed forms in chi: tension S0 (1 + b ln(chi / CHI_B)) (so the
    design's g is exactly linear in log chi and its boundaries are known to rounding), speed
    and acceleration given by functions; errors by a function."""

    tip = np.array([0.0, 0.5])
    n_tip_max = 100
    ranges = {"chi": (0.05, 0.9), "N": (10, 10000), "tip_mass": (0.0, 1.0), "n_tip_max": 100}

    def __init__(self, b=-0.3, v=None, err=None, cpu=1.0):
        self.S0 = LIMIT / (MG * (1.0 + ERR))
        self.b = b
        self.v = v or (lambda c: np.full(np.shape(c), 1.0))
        self.err = err or (lambda c: np.full(np.shape(c), ERR))
        self.cpu = cpu

    def sigma(self, chi):
        return self.S0 * (1.0 + self.b * np.log(np.asarray(chi) / CHI_B))

    def check(self, *a):
        pass

    def evaluate(self, chi, links, tip=0.0):
        chi = np.asarray(chi, float)
        e = self.err(chi)
        values = {"sigma_peak": self.sigma(chi), "v_peak": self.v(chi), "a_peak": np.full(chi.shape, 1.0),
                  "t_snap_v": np.full(chi.shape, 1.0), "delta_kappa_m": np.full(chi.shape, 0.01),
                  "cpu_s": np.full(chi.shape, self.cpu)}
        return values, {q: e for q in QS}

    def values(self, q, chi, links, tip_mass=0.0, *, with_error=False):
        return float(self.evaluate(np.asarray(chi), links, tip_mass)[0][q])


@pytest.fixture
def fake(monkeypatch):
    def use(tab):
        monkeypatch.setattr(T, "load_table", lambda path=None: tab)
        return tab
    return use


def test_design_boundaries_are_the_closed_form_crossings(fake):
    tab = fake(FakeTable())
    res = design.design(CHAIN, 100, max_tension=LIMIT, tip_mass=0.0)
    (lo, hi), = res.rows[0].admissible
    # with the bound: S0 (1 + b ln(chi/CHI_B)) (1 + ERR) MG = LIMIT at chi = CHI_B exactly
    assert lo == pytest.approx(CHI_B, rel=1e-12) and hi == 0.9
    # without: the peak alone meets the limit where 1 + b ln(chi/CHI_B) = 1 + ERR
    (nlo, nhi), = res.rows[0].nominal
    assert nlo == pytest.approx(CHI_B * math.exp(ERR / tab.b), rel=1e-12) and nhi == 0.9
    # the SI record: metres are chi times the length, the minimum's upper end includes its bound
    d = res.to_dict()["rows"][0]
    assert d["admissible_chi"] == [[lo, hi]] and d["admissible_separation_m"] == [[2.0 * lo, 2.0 * hi]]
    assert d["nominal_separation_m"] == [[2.0 * nlo, 2.0 * nhi]]
    m = res.rows[0].minimum["max_tension"]
    assert m["chi"] == 0.9 and m["peak"] == pytest.approx(tab.sigma(0.9) * MG, rel=1e-14)
    assert m["error"] == ERR and m["upper"] == pytest.approx(m["peak"] * (1 + ERR), rel=1e-14)
    assert d["minimum"]["max_tension"]["separation_m"] == 1.8 and "upper" not in d["minimum"]["max_tension"]
    # and printed in metres, with the bound in percent
    import io

    out = io.StringIO()
    design.print_design(res, file=out)
    text = out.getvalue()
    assert f"admissible: {2 * lo:.3g}-1.8 m (chi {lo:.3g}-0.9)" in text
    assert f"nominal:    {2 * nlo:.3g}-1.8 m (chi {nlo:.3g}-0.9)" in text
    assert f"smallest tension: {m['peak']:.4g} N (+-2%) at 1.8 m" in text


def test_design_minimum_is_the_smallest_upper_end_and_its_message(fake):
    # the bound grows towards wide ends: the smallest peak (chi 0.9) is not the smallest upper end
    fake(FakeTable(err=lambda c: 0.02 + 2.0 * (np.asarray(c) - 0.05) ** 4))
    chi = np.geomspace(0.05, 0.9, design.N_SCAN)
    tab = FakeTable(err=lambda c: 0.02 + 2.0 * (np.asarray(c) - 0.05) ** 4)
    peak = tab.sigma(chi) * MG
    upper = peak * (1.0 + tab.err(chi))
    i = int(np.argmin(upper))
    assert i != chi.size - 1  # (not the smallest peak's: a real test of the bound's part)
    lim = 0.5 * (peak[i] + upper[i])  # under the smallest upper end, over the peak there
    with pytest.raises(design.NoAdmissibleSeparation) as exc:
        design.design(CHAIN, 100, max_tension=lim, tip_mass=0.0)
    msg = str(exc.value)
    assert "no separation keeps the tension under it" in msg
    assert f"the minimum is {peak[i]:.4g} N" in msg and f"at separation {2.0 * chi[i]:.3g} m (chi = {chi[i]:.3g})" in msg


def test_design_with_limits_met_apart_says_no_separation_meets_them_all(fake):
    # tension falls with chi (met at wide ends), speed rises with chi (met at narrow ends)
    fake(FakeTable(v=lambda c: 10.0 * (1.0 + 0.5 * np.log(np.asarray(c) / 0.1))))
    v_lim = CHAIN.velocity(10.0) * (1 + ERR)  # the speed (with its bound) meets its limit at chi = 0.1
    alone_v = design.design(CHAIN, 100, max_speed=v_lim, tip_mass=0.0).rows[0].admissible
    alone_s = design.design(CHAIN, 100, max_tension=LIMIT, tip_mass=0.0).rows[0].admissible
    assert alone_v[0][1] == pytest.approx(0.1, rel=1e-12) and alone_s[0][0] == pytest.approx(CHI_B, rel=1e-12)
    with pytest.raises(design.NoAdmissibleSeparation, match="each is met at some separation, but no separation "
                       "meets them all") as exc:
        design.design(CHAIN, 100, max_tension=LIMIT, max_speed=v_lim, tip_mass=0.0)
    assert "tension: the minimum is" in str(exc.value) and "speed: the minimum is" in str(exc.value)


def test_design_treats_a_bound_above_trust_as_unknown_and_at_trust_as_a_bound(fake):
    # a bound above BOUND_TRUST on chi in (0.5, 0.6), exactly BOUND_TRUST on (0.3, 0.4); the tension
    # there is far under the limit, with or without the bound
    def err(c):
        c = np.asarray(c)
        return np.where((c > 0.5) & (c < 0.6), 0.6, np.where((c > 0.3) & (c < 0.4), T.BOUND_TRUST, ERR))

    fake(FakeTable(b=-0.1, err=err))
    lim = LIMIT * 4.0
    res = design.design(CHAIN, 100, max_tension=lim, tip_mass=0.0)
    for rows in (res.rows[0].admissible, res.rows[0].nominal):
        assert len(rows) == 2 and rows[0][1] < 0.5 < 0.6 < rows[1][0]
        assert rows[0][0] == 0.05 and rows[1][1] == 0.9  # (0.3-0.4, bound exactly at the trust: admissible)


def test_few_link_chains_are_run_and_each_sample_needs_both_neighbours(fake, monkeypatch):
    fake(FakeTable())
    calls = []
    spike = 77

    def scan(chi, links, tip):  # runs that meet the limit everywhere but at one sample
        calls.append(links)
        sig = np.full(chi.size, 0.5 * LIMIT / MG)
        sig[spike] = 2.0 * LIMIT / MG
        return ({"sigma_peak": sig, "v_peak": np.ones(chi.size), "a_peak": np.ones(chi.size),
                 "t_snap_v": np.ones(chi.size)}, {q: np.zeros(chi.size) for q in QS})

    monkeypatch.setattr(design, "_scan_runs", scan)
    res = design.design(CHAIN, T.FEW_LINKS, max_tension=LIMIT, tip_mass=0.0)
    assert calls == [T.FEW_LINKS] and res.source == "runs"
    chi = np.geomspace(0.05, 0.9, design.N_SCAN_RUNS)
    (a, b), (c, d) = res.rows[0].admissible
    # samples spike-1, spike, spike+1 are out (each has a failing sample beside it or is one)
    assert a == 0.05 and chi[spike - 2] < b < chi[spike - 1] and chi[spike + 1] < c < chi[spike + 2] and d == 0.9
    assert design.design(CHAIN, T.FEW_LINKS + 1, max_tension=LIMIT, tip_mass=0.0).source == "table"
    assert calls == [T.FEW_LINKS]


def test_design_scans_every_tip_mass_up_to_n_tip_max():
    tab = T.load_table()
    rows = design.design(CHAIN, tab.n_tip_max, max_tension=40.0).rows
    assert [r.tip_mass for r in rows] == [float(t) for t in tab.tip]
    more = design.design(CHAIN, tab.n_tip_max + 1, max_tension=40.0)
    assert [r.tip_mass for r in more.rows] == [0.0] and "tip masses only up to" in more.notes[0]


# ============================================================ run_instead: the thresholds
def test_run_instead_thresholds():
    cost = float(T.load_table().values("cpu_s", 0.3, 100, 0.0))
    at = dict(design.TARGETS)
    assert design.run_instead(0.3, 100, 0.0, {"v": at["v"], "a": at["a"], "sigma": at["sigma"]}) == (False, "")
    over = {q: 1.5 * e for q, e in at.items()}
    run, why = design.run_instead(0.3, 100, 0.0, over, max_seconds=cost)  # a run that costs exactly the budget
    assert run and "above the target" in why
    run, why = design.run_instead(0.3, 100, 0.0, over, max_seconds=cost * (1 - 1e-9))
    assert not run and "would take about" in why
    few = {q: 0.0 for q in at}
    assert design.run_instead(0.3, T.FEW_LINKS, 0.0, few)[0]
    assert design.run_instead(0.3, T.FEW_LINKS + 1, 0.0, few) == (False, "")
    note = estimates.design_estimate(CHAIN, chi=0.3, links=T.FEW_LINKS).computed_note
    assert f"a chain of {T.FEW_LINKS} links snaps erratically" in note
    assert "snaps erratically" not in estimates.design_estimate(CHAIN, chi=0.3, links=T.FEW_LINKS + 1).computed_note
    assert T.FEW_LINKS == 48  # the table's N axis holds every integer up to here (few-link chains)
    n = T.load_table().N
    assert np.array_equal(n[n <= 49], np.arange(10, 49))


# ============================================================ the table: interpolation and bounds
def _table_dataset():
    """The shipped table file as an xarray Dataset (loaded, closed)."""
    import xarray as xr

    with xr.open_dataset(T.TABLE_FILE, engine="netcdf4") as f:
        return f.load()


def test_interpolation_is_the_centred_cubic_in_each_axis():
    """Off the grid along one axis at a time, the table's value is the cubic through the two
    nodes on each side (one-sided at the ends) of the log quantity, in log chi, log N and
    asinh(tip / 1e-3): computed here from the stored numbers by Neville's scheme."""
    tab = T.load_table()
    ds = _table_dataset()  # (the stored numbers, read by xarray: the table reads them with netCDF4 alone)
    chis, Ns, tips = list(ds.chi.values), list(ds.N.values), list(ds.tip_mass.values)

    def stencil(axis, x):
        i = int(np.searchsorted(axis, x)) - 1
        s = min(max(i - 1, 0), len(axis) - 4)
        return list(range(s, s + 4))

    cases = []
    lx = np.log(tab.chi)
    for c in (0.052, 0.33, 0.88):  # chi: first cell, inside, last cell
        idx = stencil(lx, math.log(c))
        cases.append(((c, 229, 0.0), [math.log(tab.chi[k]) for k in idx], math.log(c),
                      [ds[q].sel(N=229, tip_mass=0.0).values[idx] for q in QS]))
    lN = np.log(tab.N.astype(float))
    for n in (100, 2000):
        idx = stencil(lN, math.log(n))
        cases.append(((0.27, n, 0.0), [lN[k] for k in idx], math.log(n),
                      [ds[q].sel(chi=0.27, tip_mass=0.0).values[idx] for q in QS]))
    z = np.arcsinh(np.array(tips) / 1e-3)
    for tip in (0.003, 0.4):
        idx = stencil(z, math.asinh(tip / 1e-3))
        cases.append(((0.27, 229, tip), [z[k] for k in idx], math.asinh(tip / 1e-3),
                      [ds[q].sel(chi=0.27, N=229).values[idx] for q in QS]))
    assert chis and Ns
    for (c, n, tip), nodes, x, vals in cases:
        p = tab.lookup(c, n, tip)
        for q, v in zip(QS, vals):
            expected = math.exp(lagrange(nodes, np.log(v.astype(float)), x))
            assert p.values[q] == pytest.approx(expected, rel=1e-11), (c, n, tip, q)


def test_error_bound_is_twice_the_sum_over_axes_of_the_worst_cell_corner():
    rng = np.random.default_rng(7)
    axes = [np.log(np.geomspace(0.05, 0.9, 7)), np.log(np.geomspace(10, 1000, 9))]
    errs = [rng.uniform(0, 0.1, (7, 9, 2)), rng.uniform(0, 0.1, (7, 9, 2))]
    for i, j in ((0, 0), (2, 5), (5, 7)):  # cells [i, i+1] x [j, j+1]
        x = 0.3 * axes[0][i] + 0.7 * axes[0][i + 1]
        y = 0.8 * axes[1][j] + 0.2 * axes[1][j + 1]
        got = T.Table._bound(axes, errs, np.array([[x, y]]))[0]
        cell = (slice(i, i + 2), slice(j, j + 2))
        expected = 2.0 * (errs[0][cell].max(axis=(0, 1)) + errs[1][cell].max(axis=(0, 1)))
        np.testing.assert_allclose(got, expected, rtol=1e-15)
        # on a node of axis 0: that axis adds nothing, the other's corners are on the node's line
        on = T.Table._bound(axes, errs, np.array([[axes[0][i + 1], y]]))[0]
        np.testing.assert_allclose(on, 2.0 * errs[1][i + 1, j:j + 2].max(axis=0), rtol=1e-15)
    assert T.BOUND_FACTOR == 2.0


def test_leave_one_out_is_the_relative_error_of_the_nearest_four_others():
    ax = np.log(np.geomspace(0.05, 0.9, 10))
    f = np.exp(0.7 * ax) + np.sin(3 * ax)  # no cubic: every stencil gives its own error
    loo = T._loo_axis(ax, f[:, None], 0)[:, 0]
    n = ax.size
    for m in range(1, n - 1):
        others = [k for k in range(n) if k != m]
        near = sorted(others, key=lambda k: (abs(k - m), k))[:4]
        near = near if max(near) - min(near) <= 4 else others[:4] if m < 3 else others[-4:]
        pred = lagrange(ax[near], f[near], ax[m])
        assert loo[m] == pytest.approx(abs(math.expm1(pred - f[m])), rel=1e-9), m
    assert loo[0] == loo[1] and loo[n - 1] == loo[n - 2] and loo[1] != loo[n - 2]
    # a 10% spike on a cubic: the others miss it by exactly its own relative size
    g = 0.3 * ax**3 - ax + 2.0
    g[1] += math.log(1.1)
    loo = T._loo_axis(ax, g[:, None], 0)[:, 0]
    assert loo[1] == pytest.approx(1 - 1 / 1.1, rel=1e-9) and loo[0] == loo[1]


def test_table_ranges_include_their_ends():
    tab = T.load_table()
    for args in ((0.05, 10, 0.0), (0.9, 10000, 0.0), (0.9, tab.n_tip_max, 1.0)):
        tab.lookup(*args)
    with pytest.raises(T.OutsideTable, match=f"only for links <= {tab.n_tip_max}"):
        tab.lookup(0.3, tab.n_tip_max + 1, 0.001)
    assert T.TIP_SCALE == 1e-3


# ============================================================ estimators over the table
def test_estimator_factors_against_the_whirling_rod_over_the_stored_peaks():
    from snapping.estimates.rules import estimator_factors

    tab = T.load_table()
    N = 229  # a node: the stored peaks themselves
    row = _table_dataset().sel(N=N, tip_mass=0.0)
    chis = tab.chi
    peaks = {q: row[var].values.astype(float) for q, var in (("v", "v_peak"), ("a", "a_peak"),
                                                               ("sigma", "sigma_peak"))}
    scales = {"delta_kappa0": [estimates.delta_kappa0(c) for c in chis], "delta_c": [estimates.delta_crude(c)
                                                                                    for c in chis],
              "delta_N": [1.0 / N] * len(chis), "delta_kappa_m": row["delta_kappa_m"].values.astype(float)}
    got = estimator_factors(N)
    for s, d in scales.items():
        for q in ("v", "a", "sigma"):
            r = []
            for c, dd, k in zip(chis, d, range(len(chis))):
                if not (np.isfinite(dd) and dd > 0):
                    continue
                P = estimates.available_energy(float(c))
                omega = math.sqrt(6.0 * P / dd**3)  # a rod of length dd whirling with energy P = omega^2 dd^3/6
                v = omega * dd
                pred = {"v": v, "a": omega**2 * dd, "sigma": 0.5 * v**2}[q]  # tension: rho v^2/2 at the pivot
                r.append(pred / peaks[q][k])
            r = np.array(r)
            mean, lo, hi = got[s][q]
            assert mean == pytest.approx(math.exp(np.log(r).mean()), rel=1e-5), (s, q)
            assert lo == pytest.approx(r.min(), rel=1e-5) and hi == pytest.approx(r.max(), rel=1e-5), (s, q)
    # the whirling rod itself (paper eq. estimates)
    w = estimates.whirling_rod(0.3, 0.2)
    assert w["v"] == pytest.approx(3.0, rel=1e-15) and w["a"] == pytest.approx(45.0, rel=1e-14)
    assert w["sigma"] == pytest.approx(4.5, rel=1e-14)


def test_wide_bound_note_from_the_trust_level():
    tab = T.load_table()
    est = estimates.design_estimate(CHAIN, chi=0.55, links=100, tip_mass=0.3)
    wide = {k: e for k, e in est.computed_errors.items() if e > T.BOUND_TRUST}
    assert wide and max(wide.values()) < 2 * T.BOUND_TRUST  # a bound between the trust level and twice it
    assert "may fail" in est.computed_note
    assert tab is T.load_table()


# ============================================================ continuum: the error bars
H5 = 0.2 * 0.5 ** np.arange(5)


def test_error_bar_floor_and_three_level_bar_exact():
    from snapping.continuum import extrapolate

    for n in (4, 5):  # an exact power law: the last two extrapolations agree; the bar is its floor
        h = H5[:n]
        e = extrapolate(h, 100.0 * (1.0 + h**2))
        assert e["converging"] and e["limit"] == pytest.approx(100.0, rel=1e-13)
        assert e["order"] == pytest.approx(2.0, rel=1e-9)
        assert e["error"] == pytest.approx(0.1 * 100.0 * h[-1] ** 2, rel=1e-6)
    e = extrapolate(H5[:3], 100.0 * (1.0 + H5[:3] ** 2))  # three levels: the correction itself
    assert e["error"] == pytest.approx(100.0 * H5[2] ** 2, rel=1e-9)
    # digits: floor(-log10(error / |limit|)): 1.5625e-5 relative -> 4
    assert extrapolate(H5, 100.0 * (1.0 + H5**2))["digits"] == 4
    assert extrapolate(H5[:3], 100.0 * (1.0 + H5[:3] ** 2))["digits"] == 2  # 2.5e-3 relative


def test_error_bar_of_two_triples_is_their_spread_and_order_is_the_last_triples():
    from snapping.continuum import extrapolate

    h = H5[:4]
    q = 1.0 + h**2 + 3.0 * h**3
    d = np.diff(q)
    p = [math.log(d[k - 2] / d[k - 1]) / math.log(2.0) for k in (2, 3)]
    ests = [q[k] + d[k - 1] / (2.0 ** p[k - 2] - 1.0) for k in (2, 3)]
    e = extrapolate(h, q)
    assert e["order"] == pytest.approx(p[1], rel=1e-12) and p[0] != pytest.approx(p[1], rel=1e-3)
    assert e["limit"] == pytest.approx(ests[1], rel=1e-14)
    assert e["error"] == pytest.approx(max(abs(ests[1] - ests[0]), 0.1 * abs(ests[1] - q[-1])), rel=1e-9)
    # equal differences are no convergence (no order, no limit): the spread of the last three
    assert extrapolate([0.1, 0.05, 0.025], [2.0, 2.0, 2.0])["digits"] == 16  # no difference: exact to the doubles
    for q in ([1.0, 2.0, 3.0], [1.0, 1.5, 2.0, 2.5]):
        e = extrapolate(0.1 * 0.5 ** np.arange(len(q)), q)
        assert not e["converging"] and math.isnan(e["order"])
        assert e["error"] == pytest.approx(q[-1] - q[-3], rel=1e-15)


def test_level_parameters_cap_the_held_arm():
    from snapping.continuum import level_parameters

    p = level_parameters(2, 0.5, first=-7, frac0=1e-4, h_min0=1e-6, h_max0=0.01)
    assert p[0]["h_max"] == 0.5 and p[1]["h_max"] == 0.5 and p[0]["frac"] == pytest.approx(1e-4 * 128)


def test_a_resumed_level_must_have_the_same_tolerance_and_masses(tmp_path):
    from snapping.continuum import _run_level

    params = {"frac": 0.5, "h_min": 0.02, "h_max": 0.05}
    path = str(tmp_path / "level.nc")
    first, _ = _run_level((0.5, params, "shared", None, 1e-6, path, None))
    assert first["cpu_time"] > 0 and first["n_links"] < 60
    again, _ = _run_level((0.5, params, "shared", None, 1e-6, path, None))
    assert math.isnan(again["cpu_time"]) and again["v_peak"] == first["v_peak"]  # resumed
    other_tol, _ = _run_level((0.5, params, "shared", None, 1e-7, path, None))
    assert not math.isnan(other_tol["cpu_time"])  # run again at its own tolerance
    other_mass, _ = _run_level((0.5, params, "paper", None, 1e-7, path, None))
    assert not math.isnan(other_mass["cpu_time"])  # and with its own masses


# ============================================================ gradings: the link-count function
def _n_tip(x, h_min, h_max, gamma):
    """n(x) = int_0^x dx'/min(h_max, h_min + gamma x') in closed form."""
    x1 = (h_max - h_min) / gamma
    x = np.asarray(x, float)
    return np.where(x <= x1, np.log((h_min + gamma * x) / h_min) / gamma,
                    math.log(h_max / h_min) / gamma + (x - x1) / h_max)


@pytest.mark.parametrize("h_min,h_max,gamma", [(1e-5, 1e-3, 0.1), (1e-4, 2e-2, 0.5), (3e-6, 1e-2, 0.05)])
def test_tip_grading_nodes_are_equal_divisions_of_the_exact_link_count(h_min, h_max, gamma):
    from snapping.simulate import grading

    h = grading.tip_graded(h_min, h_max, gamma)
    total = float(_n_tip(1.0, h_min, h_max, gamma))
    assert h.size == math.ceil(total)
    xs = np.concatenate([[0.0], np.cumsum(h)])
    n = _n_tip(xs, h_min, h_max, gamma)
    assert np.abs(n - np.arange(h.size + 1) * total / h.size).max() < 2e-4  # (the code: ~1e-5; left sums 1e-1)


def test_fold_grading_follows_its_spacing_everywhere():
    from snapping.simulate import grading

    chi, frac, h_min, h_max, gamma, margin = 0.3, 0.02, 1e-5, 2e-3, 0.1, 0.1
    h = grading.fold_following(chi, frac=frac, h_min=h_min, h_max=h_max, gamma=gamma, margin=margin)
    a = estimates.catenary_parameter(chi)
    x = np.concatenate([[0.0], np.cumsum(h)])[:-1] + 0.5 * h
    xf = 0.5 + margin
    fold = frac * a * np.minimum(2 * x, 1.0) ** 0.25
    target = np.where(x <= xf, fold, frac * a + gamma * (x - xf))
    spacing = np.maximum(h_min, np.minimum(np.minimum(target, h_max), h_min + gamma * x))
    assert np.abs(h / spacing - 1).max() < 2e-3  # (a link spans a change of the spacing of up to gamma h)
    # each link spans one unit of the link-count function n(x) = int dx/spacing, scaled to N links:
    # int over the link of dx/spacing is the same for every link (Gauss-Legendre, 32 points a link)
    def spacing_of(x):
        fold = frac * a * np.minimum(2 * x, 1.0) ** 0.25
        target = np.where(x <= xf, fold, frac * a + gamma * (x - xf))
        return np.maximum(h_min, np.minimum(np.minimum(target, h_max), h_min + gamma * x))

    g, wg = np.polynomial.legendre.leggauss(32)
    edges = np.concatenate([[0.0], np.cumsum(h)])
    pts = edges[:-1, None] + 0.5 * h[:, None] * (1 + g[None, :])
    count = 0.5 * h * (wg[None, :] / spacing_of(pts)).sum(axis=1)
    dev = np.abs(count / np.median(count) - 1)
    assert np.quantile(dev, 0.9) < 1e-5 and dev.max() < 2e-3  # (the code: 1.2e-6 and, at a kink, 8e-4)


# ============================================================ general chains
def test_curvature_profile_of_unequal_chords_on_a_circle():
    from snapping.simulate.chain import curvature_profile

    R = 0.7
    alpha = np.array([0.05, 0.2, 0.08, 0.15, 0.3, 0.1])  # central angles of unequal chords
    phi = np.concatenate([[0.0], np.cumsum(alpha)])
    x, y = R * np.cos(phi), R * np.sin(phi)
    h = 2 * R * np.sin(alpha / 2)
    k = curvature_profile(x, y, h)
    # the turning angle at a node is the mean of the two central angles; over the mean chord
    expected = (alpha[:-1] + alpha[1:]) / (h[:-1] + h[1:])
    np.testing.assert_allclose(k[1:-1], expected, rtol=1e-12)
    assert np.isnan(k[0]) and np.isnan(k[-1])


def test_general_run_initial_curvature_and_energy_of_unequal_links():
    """A chain of unequal links and masses released from a circular arc: the first record's
    largest curvature is the turning angle over the mean adjacent link (closed form on the
    arc), and its energy is sum m_j g (s_j - y_j) (zero for the chain hanging straight)."""
    from snapping.simulate import Links, Problem, run

    R = 0.6
    h = np.array([0.1, 0.25, 0.15, 0.3, 0.2])  # index 0 at the free end
    alpha = 2 * np.arcsin(h / (2 * R))
    # nodes from the held end (origin, index N) along the arc to the free end (index 0)
    phi = np.concatenate([[0.0], np.cumsum(alpha[::-1])])[::-1]
    x = R * np.sin(phi)
    y = R * (1 - np.cos(phi))
    m = np.array([0.3, 0.5, 0.2, 0.4, 0.35])
    links = Links.explicit(h, m, tip_mass=0.1)
    ds = run(Problem.nodes(x, y, links=links), t_end=1e-3, method="fast", progress=False).dataset
    kappa = (alpha[:-1] + alpha[1:]) / (h[:-1] + h[1:])
    assert float(ds.attrs["kappa_max_0"]) == pytest.approx(kappa.max(), rel=1e-12)
    s = np.concatenate([np.cumsum(h[::-1])[::-1], [0.0]])  # node j: arclength to the held end
    E0 = float(np.sum(links.m * (s[:-1] - y[:-1])))
    assert float(ds.energy[0]) == pytest.approx(E0, rel=1e-12)


def test_held_end_kinematics_closed_forms_and_the_cli_spec():
    from snapping.simulate.pin import PinMotion, parse_pin_motion

    p = PinMotion.pull((1.0, -2.0), duration=0.5, t0=0.2)
    x, y, vx, vy, ax, ay = p.kinematics(0.5)  # accelerating: tau = 0.3
    assert (x, y, vx, vy, ax, ay) == pytest.approx((0.045, -0.09, 0.3, -0.6, 1.0, -2.0), rel=1e-14)
    x, y, vx, vy, ax, ay = p.kinematics(2.2)  # coasting: 0.5^2/2 + 0.5 * 1.5
    assert (x, y, vx, vy, ax, ay) == pytest.approx((0.875, -1.75, 0.5, -1.0, 0.0, 0.0), rel=1e-14)
    f = PinMotion.flick((2.0, 0.0), 0.5, t0=0.1)
    w = 2 * math.pi / 0.5
    t = 0.3
    x, _, vx, _, ax, _ = f.kinematics(t + 0.1)
    assert x == pytest.approx(2.0 * (t - math.sin(w * t) / w) / w, rel=1e-13)
    assert vx == pytest.approx(2.0 * (1 - math.cos(w * t)) / w, rel=1e-13) and vx > 0
    assert ax == pytest.approx(2.0 * math.sin(w * t), rel=1e-13)
    x, _, vx, _, ax, _ = f.kinematics(0.1 + 0.5 + 0.2)  # after its period: displaced by accel T^2/(2 pi), at rest
    assert x == pytest.approx(2.0 * 0.5**2 / (2 * math.pi), rel=1e-13) and abs(vx) < 1e-15 and ax == 0.0
    q = parse_pin_motion("pull:1,2,0.3,0.1")
    assert (q.kind, q.accel, q.duration, q.t0) == ("pull", (1.0, 2.0), 0.3, 0.1)
    q = parse_pin_motion("pull:1,2,0.3")
    assert (q.duration, q.t0) == (0.3, 0.0)
    q = parse_pin_motion("flick:1,2,0.3,0.1")
    assert (q.kind, q.duration, q.t0) == ("flick", 0.3, 0.1)


def test_lumped_masses_of_unequal_links():
    from snapping.simulate import Links

    h = [0.5, 0.3, 0.2]  # unit density: link masses = lengths; index 0 at the free end
    shared = Links.graded(h, lumping="shared")
    np.testing.assert_allclose(shared.m, [0.25, 0.4, 0.25], rtol=1e-15)  # half of each adjacent link
    np.testing.assert_allclose(Links.graded(h, lumping="paper").m, h, rtol=1e-15)
    np.testing.assert_allclose(Links.graded(h, free_end="half").m, [0.25, 0.4, 0.25], rtol=1e-15)
    np.testing.assert_allclose(Links.graded(h, free_end="whole").m, [0.5, 0.4, 0.25], rtol=1e-15)


# ============================================================ files and sweeps
def test_replaced_file_keeps_its_permissions_and_a_new_file_follows_the_umask(tmp_path):
    from snapping._files import write_atomic

    p = tmp_path / "out.txt"
    write_atomic(p, lambda tmp: Path(tmp).write_text("one"))
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~umask
    os.chmod(p, 0o640)
    write_atomic(p, lambda tmp: Path(tmp).write_text("two"))
    assert p.read_text() == "two" and stat.S_IMODE(p.stat().st_mode) == 0o640


def test_free_space_margin_is_required(tmp_path, monkeypatch):
    import shutil
    from collections import namedtuple

    from snapping import _files

    usage = namedtuple("usage", "total used free")
    need = 5_000_000
    monkeypatch.setattr(shutil, "disk_usage", lambda d: usage(10**12, 0, need + _files.FULL_MARGIN))
    _files.check_output(tmp_path / "a.nc", need_bytes=need)  # exactly the need and the margin: fits
    monkeypatch.setattr(shutil, "disk_usage", lambda d: usage(10**12, 0, need + _files.FULL_MARGIN - 1))
    with pytest.raises(SnappingInputError, match="the file needs about"):
        _files.check_output(tmp_path / "a.nc", need_bytes=need)
    assert _files.FULL_MARGIN >= 1 << 20


def test_sweep_room_check_boundary(tmp_path, monkeypatch):
    import shutil
    from collections import namedtuple

    from snapping import sweep
    from snapping.simulate.driver import check_inputs

    usage = namedtuple("usage", "total used free")
    todo = [({"chi": 0.3, "N": 50}, None), ({"chi": 0.4, "N": 80}, None)]
    need = sum(check_inputs(0.3, 50)["file_bytes"] for _ in [0]) + check_inputs(0.4, 80)["file_bytes"]
    monkeypatch.setattr(shutil, "disk_usage", lambda d: usage(10**12, 0, need))
    sweep._check_room(tmp_path, todo)
    monkeypatch.setattr(shutil, "disk_usage", lambda d: usage(10**12, 0, need - 1))
    with pytest.raises(SnappingInputError, match="need about"):
        sweep._check_room(tmp_path, todo)


def test_combined_sweep_file_that_is_not_a_sweeps_is_not_replaced(tmp_path):
    import xarray as xr

    from snapping.sweep import Grid, check_combined

    grid = Grid(chi=[0.3], N=[20])
    for name, make in (("foreign.nc", lambda p: xr.Dataset({"a": ("x", [1.0])}).to_netcdf(p)),
                       ("text.nc", lambda p: p.write_text("not netCDF"))):
        p = tmp_path / name
        make(p)
        before = p.read_bytes()
        with pytest.raises(SnappingInputError, match="not this sweep's combined runs"):
            check_combined(p, grid)
        assert p.read_bytes() == before
        assert check_combined(p, grid, overwrite=True) == p
    assert check_combined(tmp_path / "new.nc", grid) == tmp_path / "new.nc"


# ============================================================ fits: the standard errors
def test_weighted_fit_standard_errors_against_the_linear_estimator():
    """The intercept and slope are linear in the data, a = sum c_i y_i: with residual variance
    s2 per normalised weight their variances are s2 sum c_i^2 (covariance included)."""
    from snapping.scaling._loglog import _wls

    rng = np.random.default_rng(11)
    for xm_shift in (-3.0, 2.0):  # the window centre on both sides of x = 0 (the covariance's sign)
        X = np.sort(rng.uniform(0, 1.5, 30)) + xm_shift
        Y = 0.4 - 1.3 * X + rng.normal(0, 0.05, X.size)
        w = rng.uniform(0.2, 2.0, X.size)
        f = _wls(X, Y, w)
        n_eff = w.sum() ** 2 / (w @ w)
        wn = w * n_eff / w.sum()
        xm = wn @ X / n_eff
        Sxx = wn @ (X - xm) ** 2
        c_b = wn * (X - xm) / Sxx
        c_a = wn / n_eff - xm * c_b
        assert f.b == pytest.approx(c_b @ Y, rel=1e-12) and f.a == pytest.approx(c_a @ Y, rel=1e-12)
        s2 = wn @ (Y - f.a - f.b * X) ** 2 / (n_eff - 2.0)
        assert f.s2 == pytest.approx(s2, rel=1e-12)
        assert f.se_b == pytest.approx(math.sqrt(s2 * c_b @ c_b), rel=1e-10)
        assert f.se_a == pytest.approx(math.sqrt(s2 * c_a @ c_a), rel=1e-10)


# ============================================================ the mutation list stays valid
@pytest.mark.skipif(bool(os.environ.get("SNAPPING_MUTATION")), reason="inside a mutation run (the copy is mutated)")
def test_mutation_list_is_valid():
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "mutate.py"), "--check"], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0, r.stderr
