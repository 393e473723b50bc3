"""The elastic line's automatic stop (snapping.simulate.elastic_solve): the release's ringing and
the integration's energy error are not the snap; where the rigid chain's rule was right the stop
time is unchanged. Expected values come from the physics (a line at rest has no snap), the
energy balance and the inextensible solver, never from the stop rule itself."""

from __future__ import annotations

import numpy as np
import pytest

from snapping.simulate import run
from snapping.simulate.elastic import Elastic, ElasticLine, solve
from snapping.simulate.elastic_solve import speed_floor
from snapping.simulate.problem import Links, Problem


def old_rule_stop(ds, f=0.5):
    """First recorded time at which v_max < f x its running peak (the rigid chain's rule)."""
    v = ds["v_max"].values
    hit = np.flatnonzero(v < f * np.maximum.accumulate(v))
    return float(ds["t"].values[hit[0]]) if hit.size else np.nan


@pytest.mark.parametrize("damping, method", [(1.0, "rodas4"), (0.0, "radau")])
def test_ringing_of_a_hanging_line_is_not_a_snap(damping, method):
    """A vertical line hanging at rest, its bottom link stretched by 1%: released, it rings and
    (damped) settles; nothing falls, so there is no snap. v_max spikes at the release and
    falls below half that spike (t = 0.14-0.18), where the old rule stopped with 'snap'."""
    N = 6
    links = Links.uniform(N, lumping="shared")
    p = Problem.nodes(np.zeros(N + 1), np.concatenate([np.cumsum(links.h[::-1])[::-1], [0.0]]), links=links)
    el = Elastic(ea=900.0, damping=damping)
    line = ElasticLine(p, el)
    x, y, vx, vy = (np.array(a) for a in line.unpack(line.statics(line.start("unstretched")), 0.0))
    y[0] += 0.01 * line.h[0]
    ds = solve(p, el, initial=(x, y, vx, vy), tol=1e-6, method=method, t_end_max=0.4).dataset
    assert old_rule_stop(ds) < 0.2  # the premise: the old rule was fooled here
    assert ds.attrs["snap_reached"] == 0 and ds.attrs["stop_reason"] == "t_end_max"
    assert np.isnan(ds.attrs["t_stop_armed"])
    # the floor's premise: the ringing's speed stays below sqrt(2 U0 / m_min)
    U0 = float(ds["elastic_energy"].values[0])
    assert ds.attrs["v_peak"] < np.sqrt(2.0 * U0 / line.m.min())
    assert ds.attrs["stop_speed_floor"] == pytest.approx(4.0 * np.sqrt(2.0 * U0 / line.m.min()), rel=1e-2)


def test_an_energy_error_is_not_a_snap():
    """Explicit DOP853 at tol = 1e-2 on a stiff line (c = 100): its error control lets the
    energy drift (the state's energy gains ~0.2, as much as the whole fall holds by then) and
    the spurious speeds rose and fell: the old rule reported a snap at t = 0.23 with v_peak
    2.0 (the converged snap: t = 1.19, v_peak 5.3). Now: no snap; status 'failed'."""
    p = Problem.catenary(0.25, links=Links.uniform(30, lumping="shared"))
    ds = solve(p, Elastic.from_wave_speed(100.0), tol=1e-2, method="dop853").dataset
    assert ds.attrs["snap_reached"] == 0 and ds.attrs["status"] == "failed"
    assert "energy error" in ds.attrs["stop_reason"]
    assert ds.attrs["t_final"] < 0.5
    assert ds.attrs["energy_drift"] > 0.1 * abs(ds.attrs["energy_initial"])


def test_stop_time_unchanged_where_the_old_rule_was_right():
    """chi = 0.25, N = 12, c = 30: the run stops at the first step where the old rule would
    (it armed long before the snap), and its snap is the inextensible chain's within 2%."""
    p = Problem.catenary(0.25, links=Links.uniform(12, lumping="shared"))
    ds = solve(p, Elastic.from_wave_speed(30.0), tol=1e-6, method="rodas4").dataset
    assert ds.attrs["stop_reason"] == "snap"
    assert ds.attrs["t_final"] == old_rule_stop(ds)
    assert ds.attrs["t_stop_armed"] < 0.5 * ds.attrs["t_snap_v"]
    ref = run(problem=p, method="fast", tol=1e-9).summary()
    assert ds.attrs["t_snap_v"] == pytest.approx(ref["t_snap_v"], rel=2e-2)


def test_speed_floor_is_the_derived_bound():
    """2 v_r / (1 - f) with v_r = sqrt(2 E / m): E = 0.02, m = 0.01 gives v_r = 2."""
    assert speed_floor(0.02, 0.01, 0.5) == pytest.approx(8.0, rel=1e-15)
    assert speed_floor(0.02, 0.01, 0.75) == pytest.approx(16.0, rel=1e-15)
