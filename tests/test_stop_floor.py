"""The stop rule judges a snap only after the chain's speed has risen above its start's own speed
and above STOP_FLOOR sqrt(g L) (``rk.Q_VFLOOR``): a chain hanging straight down from its held end
and set swinging gently is a pendulum, whose largest node speed only falls at first and which
never snaps. Before the floor, both runs below stopped at t ~ 1 reporting "snap detected" with
v_peak = 1e-5 and 1e-2 (the start's own speed, t_snap_v = 0)."""

import numpy as np
import pytest

from snapping.simulate import run
from snapping.simulate.problem import Links, Problem


@pytest.mark.parametrize("omega, method", [(1e-5, "fast"), (1e-2, "fast"), (1e-5, "euler-richardson")])
def test_a_gently_swinging_hanging_chain_is_not_a_snap(omega, method):
    N = 4
    y = np.linspace(1.0, 0.0, N + 1)  # node 0 the free end 1 below the held end (y grows downward)
    x = np.zeros(N + 1)
    q = Problem.nodes(x, y, links=Links.uniform(N), vx=omega * y, vy=np.zeros(N + 1))  # a rigid rotation
    ds = run(problem=q, method=method, t_end_max=3.0).dataset
    assert "snap" not in ds.attrs["stop_reason"], ds.attrs["stop_reason"]
    assert float(ds["t"].values[-1]) == pytest.approx(3.0)
    # hanging straight down is the least potential energy, so the kinetic energy never exceeds the
    # start's, KE0 = sum m_j (omega y_j)^2 / 2, and no node is faster than sqrt(2 KE0 / m_min)
    m = np.asarray(q.links.m, dtype=float)  # the moving nodes' masses (node N is the held end)
    ke0 = 0.5 * float(np.sum(m * (omega * y[:N]) ** 2))
    assert ds.attrs["v_peak"] <= np.sqrt(2.0 * ke0 / m.min()) * (1 + 1e-6)


@pytest.mark.parametrize("method", ["fast", "euler-richardson"])
def test_the_papers_chain_still_stops_at_its_snap(method):
    ds = run(chi=0.5, N=16, method=method).dataset
    assert ds.attrs["stop_reason"].startswith("snap detected")
    assert ds.attrs["v_peak"] > 1.0  # far above the floor (1e-3 sqrt(g L))


def test_the_3d_solver_too():
    from snapping.spatial.solve3d import run3d
    from snapping.spatial.starts3d import Problem3D

    N, omega = 4, 1e-5
    s = np.linspace(1.0, 0.0, N + 1)
    r, v = np.zeros((N + 1, 3)), np.zeros((N + 1, 3))
    r[:, 1], v[:, 0] = s, omega * s  # hanging along gravity (+y), swinging about the held end
    out = run3d(Problem3D.nodes(r, v), t_end_max=3.0)
    assert out["stop_reason"] != "snap", out["stop_reason"]
    ke0 = 0.5 * float(np.sum(0.25 * (omega * s[:N]) ** 2))  # uniform links: node masses 1/N = 0.25
    assert out["v_peak"] <= np.sqrt(2.0 * ke0 / 0.25) * (1 + 1e-6)
