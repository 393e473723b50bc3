"""The elastic line's static equilibrium (snapping.simulate.elastic_statics): the stretched
start of a long, stiff line in a few Newton steps, checked against the rigid chain's own
equilibrium (an independent solver) and a closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from snapping.simulate.elastic import Elastic, ElasticLine
from snapping.simulate.problem import Links, Problem


def test_stretched_catenary_at_N_1000_in_a_few_newton_steps_and_O_c_minus_2_from_the_rigid_one():
    """chi = 0.25, N = 1000 (the issue's benchmark line), c = 300 and 3000: the stretched start
    takes at most 5 Newton steps (the damped Newton on the stiffness alone took 2,000 at
    c = 30 and failed at 200), its free nodes balance to the force's round-off (eps EA/h,
    from the model's forces), and it lies O(1/c^2) from the rigid chain's discrete
    equilibrium between the same end nodes (snapping.simulate.equilibrium, no elastic code):
    |r - r_rigid| c^2 the same at both c (next term O(1/c^4): 1e-5 relative at c = 300)."""
    N = 1000
    links = Links.uniform(N, lumping="shared")
    rigid = Problem.catenary(0.25, links=links, start="equilibrium")
    p = Problem.catenary(0.25, links=links)
    dist = {}
    for c in (300.0, 3000.0):
        line = ElasticLine(p, Elastic.from_wave_speed(c))
        z = line.start("stretched")
        assert line.statics_iterations <= 5
        x, y = z[0:4 * N:4], z[1:4 * N:4]
        assert (x[0], y[0]) == (p.x[0], p.y[0])  # the free end held where it starts
        force = line.rhs(0.0, z)[4:4 * N].reshape(-1, 4)[:, 2:] * line.m[1:, None]
        assert np.abs(force).max() <= 20.0 * np.finfo(float).eps * c * c * N
        assert line.link_state(0.0, z)[0].min() > 0.0  # taut throughout
        dist[c] = np.hypot(x - rigid.x[:N], y - rigid.y[:N]).max() * c * c
    assert dist[300.0] == pytest.approx(dist[3000.0], rel=1e-4)
    assert 0.05 < dist[3000.0] < 0.5  # (a stretch of order L^2 lambda g/EA: 0.133 measured)


def test_a_straight_line_across_gravity_sags_as_the_closed_form():
    """Three links held level at both ends exactly at their rest length (no rigid equilibrium
    near: the stiffness has nothing sideways), EA = 1e6: by symmetry the middle link stays
    level at tension T cos(theta), the outer ones at T with T sin(theta) = m g = 1/3, and the
    stretched lengths span the ends: 2 h (1 + T/EA) cos(theta) + h (1 + T cos(theta)/EA) = 1."""
    EA, h, w = 1e6, 1.0 / 3.0, 1.0 / 3.0
    p = Problem.nodes(np.linspace(1.0, 0.0, 4), np.zeros(4), links=Links.uniform(3, lumping="shared"))
    line = ElasticLine(p, Elastic(ea=EA))
    z = line.start("stretched")

    def span(th):
        T = w / math.sin(th)
        return 2 * h * (1 + T / EA) * math.cos(th) + h * (1 + T * math.cos(th) / EA) - 1.0

    th = brentq(span, 1e-6, 0.5, xtol=1e-15)
    sag = h * (1 + w / math.sin(th) / EA) * math.sin(th)
    assert z[5] == pytest.approx(sag, rel=1e-9) and z[9] == pytest.approx(sag, rel=1e-9)
    assert z[4] == pytest.approx(1.0 - h * (1 + w / math.sin(th) / EA) * math.cos(th), rel=1e-9)
