"""A regime study's per-cell ``converged`` flag (branch bendconv, issue 24).

* :func:`fold_link` and :func:`bending_resolution` against links and lengths worked by hand;
* a bending study's ``bending_resolution`` against the finest level's links rebuilt from the
  grading and walked link by link (a plain loop, not the searchsorted of the module);
* :func:`analyze` leaves a cell flagged not converged out of the crossover even where its
  extrapolation looks converged (the shipped study's false "x1.76" cell was such);
* the shipped bending study carries the flag, and its unconverged cells are named.
"""

import math

import numpy as np
import pytest

from richardson_by_hand import richardson as _richardson
from snapping import regimes as R
from snapping import regimes_analysis as A
from snapping import regimes_resolution as RR
from snapping._validate import SnappingInputError


def test_fold_link_by_hand():
    h = np.array([0.1, 0.2, 0.3, 0.4])  # link ends at 0.1, 0.3, 0.6, 1.0 from the free end
    assert RR.fold_link(h, 1 / 0.05) == 0.1
    assert RR.fold_link(h, 1 / 0.25) == 0.2
    assert RR.fold_link(h, 1 / 0.3) == 0.2  # on a link's far end: that link
    assert RR.fold_link(h, 1 / 0.31) == 0.3
    assert RR.fold_link(h, 1 / 5.0) == 0.4  # beyond the chain: its last link
    with pytest.raises(SnappingInputError, match="kappa"):
        RR.fold_link(h, 0.0)
    with pytest.raises(SnappingInputError, match="positive"):
        RR.fold_link([0.1, -0.1], 1.0)


def test_bending_resolution_by_hand():
    h = np.array([1e-4, 2e-4, 4e-4])
    # l_B = sqrt(4e-8 / 100) = 2e-5; fold at arclength 1/4000 = 2.5e-4: the second link (2e-4)
    assert RR.bending_resolution(h, 4e-8, 100.0, 4000.0) == pytest.approx(0.1, rel=1e-13)
    assert math.isnan(RR.bending_resolution(h, 4e-8, float("nan"), 4000.0))
    assert RR.converged([2.0, float("nan"), 2.0, 2.0], [1.5, 3.0, 0.5, float("nan")]).tolist() == [
        True, False, False, False]
    assert RR.converged([2.0, float("nan")]).tolist() == [True, False]
    # levels agreeing to AGREE of the value converge without an order; wider ones do not
    agree = RR.converged([float("nan")] * 2, value=[10.0, 10.0], error=[0.9e-3 * 10, 1.1e-3 * 10])
    assert agree.tolist() == [True, False]


def _bending_study(chis, betas, levels=3, first=-3):
    """A bending study's Dataset with synthetic runs (no run: the flag needs only the ideal's
    peaks, the orders and the links)."""
    acc = {"levels": levels, "first": first, "n0": 50, "tol": 1e-7, "damping": 1.0}
    lev = R._levels("fold", acc, 0.5)
    ds = R._empty("bending", chis, betas, lev, lev, "synthetic", acc, 0.5)
    hs = np.array([p["frac"] for p in lev])
    for q in ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "t_snap_v"):
        ds[f"{q}_ideal_level"].values[:] = 10.0 - hs[None, :] ** 2  # converging at order 2
        ds[f"{q}_level"].values[:] = 9.0 - hs[None, None, :] ** 2
    return ds, lev


def test_study_flag_from_the_finest_links():
    chis, betas = [0.3], [1e-8, 1e-2]
    ds = R._finish(_bending_study(chis, betas)[0])
    last = _bending_study(chis, betas)[1][-1]
    sig = kap = float(ds.sigma_peak_ideal[0])  # the synthetic ideal's limit, 10
    for j, beta in enumerate(betas):
        from snapping.simulate import grading

        h_min = max(last["h_min"], R.BEND_FLOOR * last["frac"] * math.sqrt(beta))
        h = grading.fold_following(0.3, frac=last["frac"], h_min=h_min, h_max=max(last["h_max"], h_min))
        s, link = 0.0, None
        for hi in h:  # walk from the free end to arclength 1/kappa
            s += hi
            if s >= 1.0 / kap:
                link = hi
                break
        expect = math.sqrt(beta / sig) / link
        assert float(ds.bending_resolution[0, j]) == pytest.approx(expect, rel=1e-12)
    assert ds.converged.values.tolist() == [[int(float(ds.bending_resolution[0, j]) >= RR.BEND_RESOLVED)
                                             for j in range(2)]]
    assert ds.converged.values.tolist() == [[0, 1]]


def _walked_resolution(chi, beta, level, sig, kap):
    """l_B / h_fold on ``level``'s links rebuilt from the grading, walked link by link from the free end."""
    from snapping.simulate import grading

    h_min = max(level["h_min"], R.BEND_FLOOR * level["frac"] * math.sqrt(beta))
    h = grading.fold_following(chi, frac=level["frac"], h_min=h_min, h_max=max(level["h_max"], h_min))
    s = 0.0
    for hi in h:
        s += hi
        if s >= 1.0 / kap:
            return math.sqrt(beta / sig) / hi
    return math.sqrt(beta / sig) / h[-1]


def test_escalated_cell_flag_from_its_own_finest_links():
    """(branch bendesc) An escalating bending study (3 base levels + 1): the cell that ran the extra
    level has its bending_resolution from that level's links, the one that did not from the third's;
    the fold link halves with the level, so the escalated cell's is about twice the base level's."""
    chis, betas = [0.3], [1e-8, 2e-8]
    ds, lev = _bending_study(chis, betas, levels=4)
    ds.attrs.update(levels=3, escalate=0.01, extra_levels=1)
    for q in ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "t_snap_v"):
        ds[f"{q}_level"].values[0, 0, 3] = np.nan  # beta 1e-8: three levels; 2e-8: escalated to four
    ds = R._finish(ds)
    assert ds.levels_run.values.tolist() == [[3, 4]]
    sig = kap = float(ds.sigma_peak_ideal[0])
    assert float(ds.bending_resolution[0, 0]) == pytest.approx(_walked_resolution(0.3, 1e-8, lev[2], sig, kap),
                                                                 rel=1e-12)
    four = _walked_resolution(0.3, 2e-8, lev[3], sig, kap)
    assert float(ds.bending_resolution[0, 1]) == pytest.approx(four, rel=1e-12)
    assert four > 1.8 * _walked_resolution(0.3, 2e-8, lev[2], sig, kap)


def test_analyze_leaves_unconverged_cells_out():
    """Synthetic: ratios 1.0, 0.5 (a false, flagged cap), 0.95, 0.5 against the number. With the
    flag the crossover lies between the third and the fourth number, not the first and second."""
    import xarray as xr

    nums = np.array([1e-6, 1e-5, 1e-4, 1e-3])
    r = np.array([[1.0, 0.5, 0.95, 0.5]])
    ds = xr.Dataset({"v_peak": (("chi", "number"), 10 * r), "v_peak_error": (("chi", "number"), 1e-4 * r),
                     "v_peak_order": (("chi", "number"), np.full(r.shape, 2.0)),
                     "v_peak_ideal": ("chi", [10.0]), "v_peak_ideal_error": ("chi", [1e-3]),
                     "v_peak_ratio": (("chi", "number"), r), "v_peak_ratio_error": (("chi", "number"), 1e-5 * r),
                     "resolution": ("level", [0.1, 0.05, 0.025])},
                    coords={"chi": [0.2], "number": nums}, attrs={"mechanism": "synthetic", "number_name": "n",
                                                                   "mechanism_description": "", "grading": "fold",
                                                                   "status": "complete"})
    before = A.analyze(ds)["chi"][0.2]["crossover"]["number"]
    assert 1e-6 < before < 1e-5
    ds["converged"] = (("chi", "number"), np.array([[1, 0, 1, 1]], dtype=np.int8))
    row = A.analyze(ds)["chi"][0.2]
    assert 1e-4 < row["crossover"]["number"] < 1e-3 and row["unresolved"] == ["1e-05"]
    assert any(ln.startswith("  * not converged") for ln in A.report(ds, quantities=("v_peak",)))


def test_shipped_bending_study_names_its_unconverged_cells():
    ds = R.bundled_study("bending")
    assert "converged" in ds and "bending_resolution" in ds
    ok = ds.converged.values.astype(bool)
    assert not ok.all() and ok.any()
    # every converged cell resolves the bending length at its finest level, every flagged one converges not
    assert np.all(ds.bending_resolution.values[ok] >= RR.BEND_RESOLVED)
    assert np.all((ds.bending_resolution.values[~ok] < RR.BEND_RESOLVED) | ~np.isfinite(ds.v_peak_order.values[~ok]))
    a = A.analyze(ds)
    assert "1e-08" in a["chi"][0.1]["unresolved"]


def test_report_verdict_names_unconverged_cells_and_rises():
    """caps_report's verdict: the flagged cells named; a rise claimed only from converged cells
    above 1 by three error bars (synthetic ratios: 1.5 flagged, 1.2 +- 0.01 converged, 1.02 +- 0.01
    converged but within three bars)."""
    import xarray as xr

    from snapping.caps_report import convergence_words

    r = np.array([[1.5, 1.2, 1.02, 0.5]])
    err = np.array([[1e-3, 1e-2, 1e-2, 1e-3]])
    ds = xr.Dataset({"v_peak": (("chi", "number"), 10 * r), "v_peak_error": (("chi", "number"), 10 * err),
                     "v_peak_order": (("chi", "number"), np.full(r.shape, 2.0)),
                     "v_peak_ratio": (("chi", "number"), r), "v_peak_ratio_error": (("chi", "number"), err),
                     "converged": (("chi", "number"), np.array([[0, 1, 1, 1]], dtype=np.int8))},
                    coords={"chi": [0.2], "number": [1e-8, 1e-7, 1e-6, 1e-5]}, attrs={"number_name": "beta"})
    w = convergence_words(ds)
    assert "1 of 4 cells not converged" in w and "chi=0.2 beta=1e-08" in w
    assert "x1.200 +- 0.01 at chi=0.2, beta=1e-07" in w
    ds["converged"].values[:] = 1
    assert "x1.500" in convergence_words(ds) and "every cell converged" in convergence_words(ds)
    ds["v_peak_ratio"].values[:] = [[0.99, 1.01, 1.0, 0.5]]
    assert "no converged cell has its peak raised" in convergence_words(ds)


def test_module_example():
    import doctest

    res = doctest.testmod(RR)
    assert res.attempted >= 1 and res.failed == 0


def test_shipped_bending_study_escalated_exactly_the_cheap_misses():
    """(branch bendesc) The shipped study escalated at 1% with one extra level, capped at 40,000
    evaluations: by hand from its four base levels, the cells over 1% in v/a/sigma whose level 3 took at
    most 40,000 evaluations ran five (the three pre-asymptotic cells), those over it are marked capped
    (chi 0.1's four small betas, chi 0.5 beta 1e-2); the three are now within 1% in a_peak (their
    five-level limits by hand); the ideal ran five at chi 0.1-0.3 (with its cells, or its own a_peak bar
    at chi 0.1), four at 0.5; the file carries the fifth peak kappa_peak_approach."""
    ds = R.bundled_study("bending")
    assert (ds.attrs["escalate"], ds.attrs["extra_levels"], ds.attrs["escalate_max_rhs"]) == (0.01, 1, 40_000)
    five, capped = [], []
    for i, chi in enumerate(ds.chi.values):
        for j, beta in enumerate(ds.number.values):
            over = any(e > 0.01 * abs(v) for v, e in (_richardson(ds[f"{q}_level"].values[i, j, :4])
                                                      for q in ("v_peak", "a_peak", "sigma_peak")))
            if over:
                (five if ds.n_rhs_level.values[i, j, 3] <= 40_000 else capped).append((float(chi), float(beta)))
    assert five == [(0.2, 7.2e-8), (0.2, 5.18e-7), (0.3, 5.18e-7)]
    assert capped == [(0.1, 1e-8), (0.1, 7.2e-8), (0.1, 5.18e-7), (0.1, 3.73e-6), (0.5, 0.01)]
    for i, chi in enumerate(ds.chi.values):
        for j, beta in enumerate(ds.number.values):
            assert int(ds.levels_run.values[i, j]) == (5 if (chi, beta) in five else 4)
            assert int(ds.escalation_capped.values[i, j]) == ((chi, beta) in capped)
    for chi, beta in five:
        row = ds.a_peak_level.sel(chi=chi, number=beta).values
        lim, err = _richardson(row)
        assert np.isfinite(row).sum() == 5 and err <= 0.01 * lim
        assert float(ds.a_peak.sel(chi=chi, number=beta)) == pytest.approx(lim, rel=1e-12)
    assert ds.levels_run_ideal.values.tolist() == [5, 5, 5, 4]
    e = _richardson(ds.a_peak_ideal_level.values[0, :4])
    assert e[1] > 0.01 * e[0]  # chi 0.1's ideal over 1% on four levels: it ran its fifth on its own bar
    assert np.isfinite(ds.kappa_peak_approach_level.values[:, :, :4]).all()


def test_bench_regimes_bending_settings_are_the_shipped_files(monkeypatch):
    """``bench_regimes.py --study bending`` (its STUDIES entry) writes the shipped file's study key, so it
    resumes the file (nothing to run) instead of refusing it (fake runs: only the key is compared)."""
    import importlib.util
    import pathlib

    from snapping.continuum import QUANTITIES

    path = pathlib.Path(__file__).resolve().parents[1] / "benchmarks" / "bench_regimes.py"
    spec = importlib.util.spec_from_file_location("bench_regimes_for_test", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    s = dict(bench.STUDIES["bending"])
    monkeypatch.setattr(R, "_run_task", lambda *a, **k: {**{q: 1.0 for q in QUANTITIES}, "n_links": 1, "n_rhs": 1,
                                                         "cpu_time": 0.0})
    ds = R.regimes("bending", s.pop("chis"), bench._numbers(s.pop("numbers")), progress=False, **s)
    assert ds.attrs["regimes_study"] == R.bundled_study("bending").attrs["regimes_study"]
