"""The elastic run's peaks and requested snapshots are states the method reaches, not values of
its dense output (whose error along a link the stiffness EA/h multiplies: the a_peak "plateau"
of the EA -> infinity study, ``benchmarks/elastic_ea_limit.py``).

The check is a stiff pendulum: one link of rest length 1 (node masses 1/2, 1/2, the tip's
moving), released from the horizontal at rest (``start="matched"``: no tension at t = 0). As
EA -> infinity it is the rigid pendulum, whose acceleration sqrt(1 + 3 sin^2 theta) g peaks
at the bottom at exactly 2 g with the tension 3 m g. On the slow manifold the stretch shifts
the bottom's acceleration by -3 m g^2/EA (the centripetal term loses 9 m g^2/EA to the elastic
energy, the radial acceleration r'' = l T''/EA gives back 6 m g^2/EA); the release excites a
radial ringing of acceleration amplitude 3 m g^2/EA (T''(0) = 3 m g^2/l against omega^2 =
EA/(m l)). So |a_peak - 2| <= 6 m/c^2 = 3e-6 at c = 1000 (m = 1/2), |sigma_peak - 3/2| <= half
that; the bound below adds the run's own error at tol 1e-8 (3e-7). Reading the peak off RODAS4's
order-3 dense output gave +1.8e-5 and +8.4e-6 there.
"""

from __future__ import annotations

import numpy as np

from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem

C = 1000.0
M_TIP = 0.5


def _pendulum():
    return Problem.nodes([-1.0, 0.0], [0.0, 0.0], links=Links.uniform(1, lumping="shared"))


def test_stiff_pendulum_peaks_against_the_rigid_pendulum():
    p = _pendulum()
    assert p.links.m[0] == M_TIP
    s = solve(p, Elastic.from_wave_speed(C), tol=1e-8, method="rodas4", start="matched", t_end=2.2).summary()
    bound = 6.0 * M_TIP / C**2 + 1e-6
    assert abs(s["a_peak"] - 2.0) < bound, s["a_peak"] - 2.0
    assert abs(s["sigma_peak"] - 3.0 * M_TIP) < M_TIP * bound, s["sigma_peak"] - 3.0 * M_TIP


def test_requested_snapshot_is_the_state_a_run_ending_there_reaches():
    # the snapshot at ts (inside a step) is the state the method reaches at ts from the step's
    # start: the last state of the same run stopped at t_end = ts (the same steps up to there)
    p, el, ts = _pendulum(), Elastic.from_wave_speed(C), 0.7
    ds = solve(p, el, tol=1e-6, method="rodas4", start="matched", t_end=1.0, snapshot_times=[ts]).dataset
    k = int(np.flatnonzero(ds["snapshot_kind"].values == "requested")[0])
    assert float(ds["t_snapshot"].values[k]) == ts
    assert not np.any(np.isclose(ds["t"].values, ts, rtol=0.0, atol=1e-9))  # ts falls inside a step
    fs = solve(p, el, tol=1e-6, method="rodas4", start="matched", t_end=ts).dataset
    f = int(np.flatnonzero(fs["snapshot_kind"].values == "final")[0])
    for name in ("tension", "x", "y", "vx", "vy"):
        np.testing.assert_allclose(ds[name].values[k], fs[name].values[f], rtol=0.0, atol=1e-12, err_msg=name)
