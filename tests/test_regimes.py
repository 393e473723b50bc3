"""Regime studies (snapping.regimes, snapping.regimes_analysis, `snapping regimes`).

Synthetic laws with values computed by hand; a tiny study whose number -> 0 cell and ideal
column are compared with an independent, finer continuum study (snapping.continuum.converge);
resuming, refusing another study's file, and the command line.
"""

import math
import os
import subprocess
import sys

import numpy as np
import pytest

from snapping import regimes as R
from snapping import regimes_analysis as A
from snapping._validate import SnappingInputError


# ------------------------------------------------------------------ power laws (synthetic, by hand)
def test_power_law_exact():
    x = np.array([1e-4, 1e-3, 1e-2, 1e-1])
    f = A.power_law(x[::-1], (2.0 * x**-0.5)[::-1])  # (unsorted input)
    assert f["constant"] and f["n_points"] == 4
    assert f["exponent"] == pytest.approx(-0.5, abs=1e-13)
    assert f["prefactor"] == pytest.approx(2.0, rel=1e-12)
    assert f["exponent_err"] < 1e-12


def test_power_law_error_bars_by_hand():
    # y = 3 x^0.25 with 1% error bars: weights 1e4 on X = ln x spaced ln 10 apart (4 points):
    # sum w (X - mean)^2 = 1e4 (2.25 + 0.25 + 0.25 + 2.25) ln(10)^2 -> stderr 1/sqrt(that)
    x = np.array([1e-4, 1e-3, 1e-2, 1e-1])
    y = 3.0 * x**0.25
    f = A.power_law(x, y, 0.01 * y)
    assert f["exponent"] == pytest.approx(0.25, abs=1e-13)
    assert f["exponent_err"] == pytest.approx(1.0 / (math.sqrt(5e4) * math.log(10.0)), rel=1e-9)  # 0.0019422


def test_power_law_on_the_constant_slope_only():
    # flat (the ideal) up to 1e-4, then 10 (x/1e-4)^-1: local slopes 0, 0, -1, -1, -1
    x = 10.0 ** np.arange(-6, 0)
    y = np.where(x <= 1e-4, 10.0, 10.0 * (x / 1e-4) ** -1.0)
    f = A.power_law(x, y)
    assert f["constant"] and f["n_points"] == 4
    assert (f["x_lo"], f["x_hi"]) == (pytest.approx(1e-4), pytest.approx(1e-1))
    assert f["exponent"] == pytest.approx(-1.0, abs=1e-12)
    assert f["prefactor"] == pytest.approx(1e-3, rel=1e-10)  # 10 * 1e-4


def test_power_law_says_when_there_is_none():
    x = np.array([0.1, 1.0, 3.0, 10.0])
    f = A.power_law(x, np.exp(-x))  # local slopes -0.041, -1.65, -7.3
    assert not f["constant"] and math.isnan(f["exponent"])
    assert f["statement"].startswith("no power law")


# ------------------------------------------------------------------ crossovers (by hand)
def test_crossover_log_interpolation():
    # log r goes from (1/2) log 0.9 to (5/2) log 0.9 over two decades: 0.9 is a quarter of the way,
    # at 1e-4 * 100^(1/4) = 1e-4 sqrt(10)
    x = [1e-6, 1e-4, 1e-2]
    r = [1.0, 0.9**0.5, 0.9**2.5]
    c = A.crossover(x, r)
    assert c["bracketed"]
    assert c["number"] == pytest.approx(1e-4 * math.sqrt(10.0), rel=1e-12)
    assert A.crossover([1e-4, 1e-2], [1.0, 0.81])["number"] == pytest.approx(1e-3, rel=1e-12)


def test_crossover_interval_and_unbracketed():
    x = [1e-4, 1e-2]
    c = A.crossover(x, [1.0, 0.81], [0.0, 0.0])
    assert c["lo"] == pytest.approx(1e-3) and c["hi"] == pytest.approx(1e-3)
    c = A.crossover(x, [1.0, 0.81], [0.0, 0.81 - 0.9**4])  # r2 - e = 0.9^4: log fraction 1/4
    assert c["lo"] == pytest.approx(1e-4 * 10**0.5, rel=1e-12)
    above = A.crossover(x, [1.0, 0.95])
    below = A.crossover(x, [0.8, 0.7])
    assert not above["bracketed"] and "above" in above["statement"]
    assert not below["bracketed"] and "below" in below["statement"]


# ------------------------------------------------------------------ a tiny study
CHI = 0.5


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("regimes") / "em.nc"
    ds = R.regimes("end-mass", [CHI], [1e-7, 1e-1], out=out, progress=False)
    return ds, out


@pytest.fixture(scope="module")
def reference():
    from snapping.continuum import converge

    return converge(CHI, levels=4, first=-1).dataset.attrs  # finer than the study's levels


def test_number_to_zero_is_the_ideal_continuum_limit(study, reference):
    ds, _ = study
    assert ds.attrs["status"] == "complete"
    for q in ("v_peak", "a_peak", "sigma_peak"):
        ref, ref_err = reference[q + "_limit"], reference[q + "_error"]
        for val, err in ((float(ds[q + "_ideal"][0]), float(ds[q + "_ideal_error"][0])),
                         (float(ds[q].sel(number=1e-7)[0]), float(ds[q + "_error"].sel(number=1e-7)[0]))):
            assert abs(val - ref) <= err + ref_err, (q, val, err, ref, ref_err)
            assert err < 0.02 * ref  # (a real error bar, not a blanket)


def test_ratios_are_peak_over_ideal(study):
    ds, _ = study
    for q in ("v_peak", "sigma_peak"):
        c = ds.sel(number=1e-1, chi=CHI)
        assert float(c[q + "_ratio"]) == pytest.approx(float(c[q]) / float(c[q + "_ideal"]), rel=1e-12)
    # a heavy tip (a tenth of the chain) slows the snap: about half the ideal's speed at chi = 0.5
    assert 0.3 < float(ds.v_peak_ratio.sel(number=1e-1)[0]) < 0.7


def test_resume_computes_nothing_done(study, monkeypatch):
    ds, out = study
    calls = []
    monkeypatch.setattr(R, "_run_task", lambda *a: calls.append(a))
    again = R.regimes("end-mass", [CHI], [1e-7, 1e-1], out=out, progress=False)
    assert calls == []
    np.testing.assert_array_equal(again.v_peak.values, ds.v_peak.values)


def test_interrupted_study_keeps_its_runs(tmp_path, monkeypatch):
    out = tmp_path / "s.nc"
    real, n = R._run_task, [0]

    def stop_after_two(*a):
        if n[0] == 2:
            raise KeyboardInterrupt
        n[0] += 1
        return real(*a)

    monkeypatch.setattr(R, "_run_task", stop_after_two)
    with pytest.raises(KeyboardInterrupt):
        R.regimes("drag", [CHI], [1e-3], levels=2, first=-3, out=out, progress=False)
    kept = R.load_study(out)
    assert kept.attrs["status"] == "partial"
    assert np.isfinite(kept.v_peak_ideal_level.values).sum() + np.isfinite(kept.v_peak_level.values).sum() == 2
    count = []
    monkeypatch.setattr(R, "_run_task", lambda *a: (count.append(a), real(*a))[1])
    done = R.regimes("drag", [CHI], [1e-3], levels=2, first=-3, out=out, progress=False)
    assert len(count) == 2 and done.attrs["status"] == "complete"  # 4 runs in all, 2 kept


def test_refuses_another_study_and_foreign_files(study, tmp_path):
    _, out = study
    before = out.read_bytes()
    with pytest.raises(SnappingInputError, match="another study"):
        R.regimes("end-mass", [CHI], [1e-2], out=out, progress=False)
    assert out.read_bytes() == before
    foreign = tmp_path / "f.nc"
    import xarray as xr

    xr.Dataset({"a": ("x", [1.0])}).to_netcdf(foreign)
    with pytest.raises(SnappingInputError, match="not a regime study"):
        R.regimes("end-mass", [CHI], [1e-2], out=foreign, progress=False)


@pytest.mark.parametrize("kw, match", [({"mechanism": "twisting"}, "mechanism"), ({"numbers": [0.0]}, "numbers"),
                                       ({"numbers": [1e-3, 1e-3]}, "distinct"), ({"chis": [1.5]}, "chi"),
                                       ({"accuracy": "best"}, "accuracy")])
def test_bad_input(kw, match):
    args = {"mechanism": "drag", "chis": [0.5], "numbers": [1e-3], **kw}
    with pytest.raises(SnappingInputError, match=match):
        R.regimes(args.pop("mechanism"), args.pop("chis"), args.pop("numbers"), progress=False, **args)


def test_analysis_and_map(study, tmp_path):
    ds, _ = study
    a = A.analyze(ds)
    assert a["mechanism"] == "end-mass" and set(a["chi"]) == {CHI}
    lines = A.report(ds)
    assert any("ideal" in ln for ln in lines)
    png = tmp_path / "map.png"
    import matplotlib.pyplot as plt

    plt.close(A.regime_map(ds, png))
    assert png.stat().st_size > 1000


def _cli(*args):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "snapping.cli", *args], capture_output=True, text=True, env=env,
                          timeout=300)


def test_cli_load_and_plot(study, tmp_path):
    _, out = study
    r = _cli("regimes", "--load", str(out), "--plot", str(tmp_path / "m.png"))
    assert r.returncode == 0, r.stderr
    assert "end_mass=0.1" in r.stdout and (tmp_path / "m.png").exists()


def test_cli_bad_input_exits_2(tmp_path):
    r = _cli("regimes", "--mechanism", "drag", "--chi", "0.5", "--numbers", "-1", "-o", str(tmp_path / "x.nc"))
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "x.nc").exists()


def test_unresolved_cells_are_left_out():
    ok = A.resolved([10.0, 10.0, 10.0, 10.0], [0.1, 0.6, 0.1, float("nan")], [1.5, 1.5, float("nan"), 1.5])
    assert ok.tolist() == [True, False, False, False]  # 6% error bar; no order; no error bar


def test_dask_scheduler_gives_the_local_result():
    distributed = pytest.importorskip("dask.distributed")
    kw = dict(levels=2, first=-3, progress=False)
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as client:
        remote = R.regimes("drag", [CHI], [1e-3], scheduler=client, **kw)
    local = R.regimes("drag", [CHI], [1e-3], **kw)
    assert remote.attrs["status"] == "complete"
    np.testing.assert_array_equal(remote.v_peak_level.values, local.v_peak_level.values)
