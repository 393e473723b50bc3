"""The regime study's physics choices and its analysis across chi (branch regstudy).

* the crossover law (crossover = A chi^q) on synthetic data with a known law, its
  uncertainty computed by hand;
* bending cells: the grid damping gives every node's shortest wave the damping ratio asked
  for (checked against :func:`snapping.simulate.stiffness.shortest_wave`, computed from the
  model independently), and the free end's links are floored at the bending scale;
* stretching: a stiff elastic line (c = 100 sqrt(gL)) on a small chain snaps as the
  inextensible chain of the same links (its number -> 0 limit);
* the shipped studies load and hold what the guide says.
"""

import math

import numpy as np
import pytest

from snapping import regimes as R
from snapping import regimes_analysis as A
from snapping._validate import SnappingInputError


# ------------------------------------------------------------------ crossover law (synthetic)
def test_crossover_law_recovers_a_known_law():
    chi = np.array([0.1, 0.2, 0.3, 0.5])
    x = 0.02 * chi**2.5
    f = A.crossover_law(chi, x, x / 1.1, x * 1.1)  # intervals +-log(1.1): sigma = log 1.1
    assert f["exponent"] == pytest.approx(2.5, abs=1e-12)
    assert f["prefactor"] == pytest.approx(0.02, rel=1e-12)
    X = np.log(chi)
    by_hand = math.log(1.1) / math.sqrt(np.sum((X - X.mean()) ** 2))  # equal weights 1/sigma^2, chi^2 = 0
    assert f["exponent_err"] == pytest.approx(by_hand, rel=1e-12)
    assert f["n_points"] == 4 and "chi^2.500" in f["statement"]


def test_crossover_law_scatter_inflates_the_error():
    chi = np.array([0.1, 0.2, 0.3, 0.5])
    noise = np.array([1.3, 1 / 1.3, 1.3, 1 / 1.3])  # far beyond the +-1% intervals
    x = 0.02 * chi**-1.0 * noise
    f = A.crossover_law(chi, x, x / 1.01, x * 1.01)
    X, Y = np.log(chi), np.log(x)
    q, a = np.polyfit(X, Y, 1)
    res = Y - (a + q * X)
    by_hand = math.sqrt(np.sum(res**2) / 2 / np.sum((X - X.mean()) ** 2))  # the scatter's error (equal weights)
    assert f["exponent"] == pytest.approx(q, rel=1e-10)
    assert f["exponent_err"] == pytest.approx(by_hand, rel=1e-10)


def test_crossover_law_too_few_points_and_bad_input():
    f = A.crossover_law([0.2], [1e-3])
    assert math.isnan(f["exponent"]) and "needs 2" in f["statement"]
    with pytest.raises(SnappingInputError, match="one length"):
        A.crossover_law([0.1, 0.2], [1e-3])


def test_analyze_fits_the_crossovers_across_chi():
    """A synthetic study: ratio = 0.9 (n/n_c)^-0.1, n_c = 0.01 chi^1.5, a straight line in
    (log n, log ratio), where the crossover's interpolation is exact: the crossover of each chi
    is n_c, their law 0.01 chi^1.5, and the capped regime's exponent -0.1."""
    import xarray as xr

    chis = np.array([0.1, 0.2, 0.3, 0.5])
    nums = np.geomspace(1e-5, 1e-1, 9)
    nc = 0.01 * chis**1.5
    r = 0.9 * (nums[None, :] / nc[:, None]) ** -0.1
    ideal = 10.0 * np.ones(chis.size)
    ds = xr.Dataset({"v_peak": (("chi", "number"), ideal[:, None] * r),
                     "v_peak_error": (("chi", "number"), 1e-4 * ideal[:, None] * r),
                     "v_peak_order": (("chi", "number"), np.full(r.shape, 2.0)),
                     "v_peak_ideal": ("chi", ideal), "v_peak_ideal_error": ("chi", 1e-4 * ideal),
                     "v_peak_ratio": (("chi", "number"), r), "v_peak_ratio_error": (("chi", "number"), 1e-4 * r)},
                    coords={"chi": chis, "number": nums}, attrs={"mechanism": "synthetic", "number_name": "n"})
    a = A.analyze(ds, "v_peak")
    law = a["crossover_law"]
    for i, (chi, row) in enumerate(a["chi"].items()):
        assert row["crossover"]["number"] == pytest.approx(nc[i], rel=1e-9)
        assert row["fit"]["exponent"] == pytest.approx(-0.1, abs=1e-9)
    assert law["exponent"] == pytest.approx(1.5, abs=1e-9)
    assert law["prefactor"] == pytest.approx(0.01, rel=1e-9)


# ------------------------------------------------------------------ bending cells
def test_bending_grid_damping_ratio_and_floor():
    from snapping.continuum import level_parameters
    from snapping.simulate import stiffness

    lv = level_parameters(3, first=-1)[0]
    beta = 1e-4
    for zeta in (0.5, 2.0):
        p = R.cell_problem(0.3, "bending", beta, lv, damping=zeta)
        om, z = stiffness.shortest_wave(p.model())
        assert z == pytest.approx(zeta, rel=0.1)  # (the tension adds a little to omega there)
        h = p.links.h
        assert h.min() >= R.BEND_FLOOR * lv["frac"] * math.sqrt(beta) * (1 - 1e-9)
        eta = p.body.node_values("damping", h)
        assert eta[0] == pytest.approx(0.5 * zeta * math.sqrt(beta) * h[0] ** 2, rel=1e-12)
    ideal = R.cell_problem(0.3, None, 0.0, lv)
    assert ideal.body is None and ideal.links.h.min() < p.links.h.min()


# ------------------------------------------------------------------ stretching: c -> infinity is the chain
def test_stiff_elastic_cell_is_the_inextensible_chain():
    # (matched start: c = 100: 2.4448 against the chain's 2.4452; c = 2: 2.123)
    level = {"n_links": 6, "frac": 1.0 / 6}
    stiff = R._run_task(0.5, "stretching", 1.0 / 100.0, level, 1e-5)
    chain = R._run_task(0.5, None, 0.0, level, 1e-6)
    assert stiff["v_peak"] == pytest.approx(chain["v_peak"], rel=2e-3)
    soft = R._run_task(0.5, "stretching", 1.0 / 2.0, level, 1e-5)
    assert soft["v_peak"] < 0.9 * chain["v_peak"]  # a soft line is capped


def test_bundled_studies():
    for m in R.BUNDLED:
        try:
            ds = R.bundled_study(m)
        except SnappingInputError as exc:  # not shipped (a partial checkout): said so
            assert "not shipped" in str(exc)
            continue
        assert ds.attrs["mechanism"] == m and ds.sizes["chi"] >= 2
    with pytest.raises(SnappingInputError, match="shipped"):
        R.bundled_study("twisting")
