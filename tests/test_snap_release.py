"""The snap's peaks without the release (issue 24, branch snapbend): :func:`release_window`,
:func:`run_snap_peaks` of :mod:`snapping.simulate.snap_window` and the bending study's use of them.

* synthetic records: a speed bump v = exp(-(t - 1)^2 / (2 s^2)) on t in [0, 1.5] (closed form: v is
  1/2 at 1 -+ s sqrt(2 ln 2)), an acceleration with a release spike at t = 0 (the run's refined peak
  there) and a snap peak with the speed: the window runs from the last step before the peak with
  v < 1/2 to the first after it, the spike is excluded, the snap's refined run peak kept as is, a
  spike inside the window kept (also one after the 0.9 point: a stiff rod's peaks come while the tip
  slows), a run peak before or after the window replaced;
* a real bending run (chi 0.5, beta 0.01, fold level -3, 38 links) whose run a_peak is the release's
  at t = 0: the windowed peak is the largest a_max over the steps found by hand (plain loops), lies
  near the speed peak, below the release's, and agrees with the finer level's within 2% (the release
  spike doubles: 11.8 at level -4, 23.7 at -3); a small-beta run keeps the run's peaks bit for bit;
* the study's worker takes the windowed peaks for bending (the ideal keeps the run's), and a study
  file of the run's peaks (no ``"peaks"`` in its key) is refused.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping import _validate as V
from snapping import regimes as R
from snapping.continuum import level_parameters
from snapping.simulate import run
from snapping.simulate.snap_window import RELEASE_FRACTION, release_start, release_window, run_snap_peaks

S_W = 0.2
T = np.linspace(0.0, 1.5, 1501)  # step 1e-3
V_ = np.exp(-((T - 1.0) ** 2) / (2 * S_W**2))
T_HALF = 1.0 - S_W * math.sqrt(2 * math.log(2))  # v = 1/2 (closed form), rising
T_FALL = 1.0 + S_W * math.sqrt(2 * math.log(2))  # v = 1/2, falling
T_NINE = 1.0 + S_W * math.sqrt(2 * math.log(1 / 0.9))  # v = 0.9, falling
I_START = int(np.flatnonzero(T < T_HALF)[-1])  # last step below half before the peak, by hand
I_END = int(np.flatnonzero(T > T_FALL)[0])  # first step below half after it


def _a():
    a = 100.0 * V_**4  # the snap's acceleration, peaking with the speed (100 at t = 1)
    a[:5] += 1000.0 * np.exp(-T[:5] / 1e-3)  # the release's spike: 1000 at t = 0
    return a


def test_window_starts_at_the_last_step_below_half_the_peak():
    assert RELEASE_FRACTION == 0.5
    assert release_start(T, V_, 1.0) == I_START
    assert T[I_START] == pytest.approx(T_HALF, abs=1.01e-3) and T[I_START] < T_HALF
    assert T[I_END] == pytest.approx(T_FALL, abs=1.01e-3) and T[I_END] > T_FALL
    assert release_start(T, V_, float("nan")) == 0
    # a speed never below half before its peak: the window from the start
    assert release_start(T, 0.6 + 0.4 * V_, 1.0) == 0
    w = release_window(T, V_, {}, {}, 1.0)
    assert w["t_snap_start"] == T[I_START] and w["t_snap_end"] == T[I_END]


def test_release_spike_is_excluded_and_snap_peak_kept_as_is():
    a = _a()
    out = release_window(T, V_, {"a": a}, {"a": (1000.0, 0.0)}, 1.0)  # the run's peak: the release
    assert out["a"] == pytest.approx(100.0, rel=1e-12)  # the bump's own maximum at t = 1 exactly
    # the run's refined peak inside the window is returned as is (not the recorded maximum)
    out = release_window(T, V_, {"a": a}, {"a": (100.25, 1.0003)}, 1.0)
    assert out["a"] == 100.25
    # the window's start and end are inside it: a run peak there is kept
    assert release_window(T, V_, {"a": a}, {"a": (7.0, T[I_START])}, 1.0)["a"] == 7.0
    assert release_window(T, V_, {"a": a}, {"a": (7.0, T[I_END])}, 1.0)["a"] == 7.0
    # one a step before the start, or after the end: the window's largest record
    assert release_window(T, V_, {"a": a}, {"a": (7.0, T[I_START - 1])}, 1.0)["a"] == pytest.approx(100.0)
    assert release_window(T, V_, {"a": a}, {"a": (7.0, T[I_END + 1])}, 1.0)["a"] == pytest.approx(100.0)


def test_spikes_inside_and_outside_the_window():
    a = _a()
    j = I_START + 3  # inside, v just above 1/2
    a[j] = 500.0
    k = I_START - 3  # before the window (v just below 1/2)
    a[k] = 900.0
    out = release_window(T, V_, {"a": a, "s": a}, {"a": (900.0, T[k]), "s": (500.0, T[j])}, 1.0)
    assert out["a"] == 500.0 and out["s"] == 500.0
    m = int(np.flatnonzero(T > T_NINE)[0]) + 20  # after the 0.9 point (v ~ 0.8), before the half: inside
    a[m] = 700.0
    assert release_window(T, V_, {"a": a}, {"a": (900.0, T[k])}, 1.0)["a"] == 700.0
    a[I_END + 1] = 800.0  # after the window: out
    assert release_window(T, V_, {"a": a}, {"a": (800.0, T[I_END + 1])}, 1.0)["a"] == 700.0


def _lv(first):
    return level_parameters(1, 0.5, first=first)[0]


@pytest.fixture(scope="module")
def big_beta():
    """chi 0.5, beta 0.01 (the shipped study's largest) at fold levels -4 and -3, the study's RODAS4."""
    return {f: run(R.cell_problem(0.5, "bending", 0.01, _lv(f)), method="rodas4", tol=1e-6, progress=False).dataset
            for f in (-4, -3)}


def test_real_run_release_excluded_by_hand(big_beta):
    ds = big_beta[-3]
    a = ds.attrs
    t, v, am = ds.t.values, ds.v_max.values, ds.a_max.values
    # the run's a_peak is the release's: at t = 0, and it doubles with the level (grid scale)
    assert a["t_snap_a"] == 0.0 and am[0] == pytest.approx(a["a_peak"], rel=1e-12)
    assert big_beta[-4].attrs["t_snap_a"] == 0.0
    assert a["a_peak"] / big_beta[-4].attrs["a_peak"] == pytest.approx(2.0, rel=0.05)
    # the window by hand: plain loops over the records
    vp = max(v)
    ip = 0
    while t[ip] < a["t_snap_v"]:
        ip += 1
    js = ip - 1
    while v[js] >= 0.5 * vp:
        js -= 1
    je = ip
    while v[je] >= 0.5 * vp:
        je += 1
    best = -1.0
    for i in range(js, je + 1):
        best = max(best, am[i])
    out = run_snap_peaks(ds)
    assert out["a_peak"] == best and out["t_snap_start"] == t[js] and out["t_snap_end"] == t[je] == t[-1]
    assert out["a_peak"] < 0.5 * a["a_peak"]
    i_best = int(np.flatnonzero(am == best)[0])
    assert abs(t[i_best] - a["t_snap_v"]) < 0.3  # the snap's, near the speed peak (t 1.09), not the start
    # the tension peak is the snap's already: the run's, kept as is
    assert js > 0 and t[js] <= a["t_snap_sigma"] <= t[je] and out["sigma_peak"] == a["sigma_peak"]
    # the windowed peak converges with the level (the release's doubles)
    assert run_snap_peaks(big_beta[-4])["a_peak"] == pytest.approx(out["a_peak"], rel=0.02)


def test_small_beta_run_keeps_its_peaks_bit_for_bit():
    ds = run(R.cell_problem(0.3, "bending", 1e-6, _lv(-4)), method="rodas4", tol=1e-6, progress=False).dataset
    a = ds.attrs
    assert a["t_snap_a"] > 0.5  # the snap's, not the release's
    out = run_snap_peaks(ds)
    assert out["a_peak"] == a["a_peak"] and out["sigma_peak"] == a["sigma_peak"]


def test_study_worker_takes_the_windowed_peaks(big_beta):
    row = R._run_task(0.5, "bending", 0.01, _lv(-3), 1e-6)
    ds = big_beta[-3]
    assert row["a_peak"] == run_snap_peaks(ds)["a_peak"] < ds.attrs["a_peak"]
    assert row["v_peak"] == ds.attrs["v_peak"] and row["kappa_peak"] == ds.attrs["kappa_peak"]
    ideal = R._run_task(0.5, None, 0.0, _lv(-4), 1e-6)  # the ideal: the run's own peaks
    di = run(R.cell_problem(0.5, None, 0.0, _lv(-4)), method="fast", tol=1e-6, progress=False).dataset
    assert ideal["a_peak"] == di.attrs["a_peak"]


def test_study_of_the_runs_peaks_is_not_resumed(tmp_path):
    from snapping.sweep_files import atomic_to_netcdf

    chis, betas = [0.5], [0.01]
    acc = {"levels": 2, "first": -4, "n0": 50, "tol": 1e-6, "damping": 1.0}  # the key before branch snapbend
    lev = R._levels("fold", acc, 0.5)
    old = R._empty("bending", chis, betas, lev, lev, R._study_key("bending", chis, betas, acc, 0.5), acc, 0.5)
    out = tmp_path / "old.nc"
    atomic_to_netcdf(old, str(out))
    with pytest.raises(V.SnappingInputError, match="holds another study"):
        R.regimes("bending", chis, betas, levels=2, first=-4, tol=1e-6, out=str(out), progress=False)
    with pytest.raises(V.SnappingInputError, match='"peaks": "snap"'):
        R.regimes("bending", chis, betas, levels=2, first=-4, tol=1e-6, out=str(out), progress=False)


def test_shipped_bending_study_keeps_the_snaps_peaks():
    from snapping.regimes_analysis import report

    ds = R.bundled_study("bending")
    assert '"peaks": "snap"' in ds.attrs["regimes_study"] and ds.attrs["peaks"] == "snap"
    assert any("without the release" in line for line in report(ds))
    # the release's spike doubled with each level (chi 0.5, beta 0.01: 96, 197, 395, 789); the snap's does not:
    # each level's a_peak within 5% of the one before, and far below the release's at the first level (96)
    a = ds.a_peak_level.sel(chi=0.5, number=0.01).values
    a = a[np.isfinite(a)]
    assert a.size >= 4 and np.all(np.abs(np.diff(a)) <= 0.05 * a[1:]) and a[0] < 20.0


def test_release_start_ignores_nan_and_a_late_peak_time():
    """(review) a NaN speed record does not void the window (it was all-False, start 0, the release kept), and a
    peak time past the recorded peak does not move the start after it: by hand, the last record before the
    recorded peak (index 3) below half its speed."""
    t = np.arange(7.0)
    v = np.array([0.0, np.nan, 0.3, 1.0, 0.6, 0.2, 0.1])
    assert release_start(t, v, 3.0) == 2
    assert release_start(t, v, 6.5) == 2   # (searched past index 3 the start would be 6)
    assert release_start(t, np.full(7, np.nan), 3.0) == 0
