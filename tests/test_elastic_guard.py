"""The elastic run's peak guard (issue 22, snapping.simulate.elastic_checks): synthetic records with
closed-form measures, and real runs judged against a dense reference (tol 1e-7), not the guard."""

import numpy as np
import pytest

from snapping.simulate import elastic_checks as EC
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem

C = 3000.0
T = np.linspace(0.0, 1.0, 40001)  # 1.25e-3 steps of 2.5e-5: ~100 a window 8/c = 2.7e-3


def _rec(sigma, n_slack=None, sigma0=0.5):
    n = T.size
    return {"sigma_max": sigma, "dt": np.concatenate([[0.0], np.diff(T)]),
            "n_slack": np.zeros(n) if n_slack is None else n_slack, "sigma_min": np.full(n, sigma0)}


def _guard(rec, start="stretched", drift=0.0, c=C):
    return EC.peak_guard(T, rec, wave_speed=c, length=1.0, start=start, t_snap_sigma=1.0, energy_drift=drift,
                         energy_scale=1.0)


def test_synthetic_ringing_measure_is_half_range_over_level():
    # 2 + A sin: many periods in a window, so the half range is A and the median 2 (closed form)
    for amp in (0.2, 0.6, 1.4):
        sig = 2.0 + amp * np.sin(2.0 * np.pi * 7000.0 * T)
        ring = EC.ringing_tension(T, sig, C, 1.0, 1.0)
        assert ring == pytest.approx(amp / 2.0, rel=0.02)
    # a smooth rise: half the rise over a window (slope 1 x 8/c / 2) over the level ~1.5
    assert EC.ringing_tension(T, 1.0 + T, C, 1.0, 1.0) < 1e-3


def test_synthetic_verdicts():
    wave = np.sin(2.0 * np.pi * 7000.0 * T)
    ok = _guard(_rec(2.0 + 0.6 * wave))  # release: 0.3 < RING_RELEASE
    assert ok[1] and ok[2] == ""
    bad = _guard(_rec(2.0 + 1.4 * wave))  # 0.7 > 0.5
    assert not bad[1] and bad[2].startswith("ringing")
    m = _guard(_rec(2.0 + 0.6 * wave), start="matched")  # matched: 0.3 > 0.1
    assert not m[1] and "ringing" in m[2]
    assert _guard(_rec(2.0 + 0.6 * wave, sigma0=0.0), start="matched")[1]  # a slack start is judged as a release
    # small c: the ringing and the fall share a time scale, not judged (NaN)
    small = _guard(_rec(2.0 + 1.4 * wave), c=30.0)
    assert np.isnan(small[0]) and small[1]
    assert not _guard(_rec(2.0 + 0 * T), drift=0.02)[1]  # energy: drift 0.02 > 0.01 of the scale
    assert _guard(_rec(2.0 + 0 * T), drift=0.005)[1]


def test_slack_share_is_the_slack_time_before_the_cut():
    n = np.where((T > 0.2) & (T <= 0.5), 3, 0)  # slack on (0.2, 0.5]: 0.3 of the cut 0.9
    assert EC.slack_share(T, _rec(T)["dt"], n, 1.0) == pytest.approx(0.3 / 0.9, abs=1e-4)
    late = np.where(T > 0.95, 1, 0)  # slack after the cut only: the snap's own
    assert EC.slack_share(T, _rec(T)["dt"], late, 1.0) == 0.0
    rec = _rec(2.0 + 0 * T, n_slack=n)
    assert not _guard(rec, start="matched")[1] and "slack" in _guard(rec, start="matched")[2]
    assert _guard(rec, start="stretched")[1]  # a release may go slack


def _run(tol, N=12, c=C, start="matched", t_end=0.3):
    return solve(Problem.catenary(0.25, links=Links.uniform(N, lumping="shared")), Elastic(ea=c * c), tol=tol,
                 method="rodas4", start=start, t_end=t_end).dataset.attrs


def test_real_ringing_run_flagged_and_converged_run_passes():
    ref = _run(1e-7)
    loose = _run(1e-3)
    # the reference decides which is ringing: the loose run's peaks are not the line's
    assert loose["a_peak"] > 10.0 * ref["a_peak"] and loose["sigma_peak"] > 5.0 * ref["sigma_peak"]
    assert loose["status"] == "failed" and loose["stop_reason"] == "t_end" and loose["peaks_resolved"] == 0
    assert loose["peak_note"] and loose["peak_ringing"] > EC.RING_MATCHED
    assert ref["status"] == "completed" and ref["peaks_resolved"] == 1 and ref["peak_note"] == ""
    # a second converged run agrees with the reference and passes too
    mid = _run(1e-6, c=300.0)
    assert mid["peaks_resolved"] == 1 and mid["status"] == "completed"
    assert mid["peak_ringing"] < EC.RING_MATCHED
