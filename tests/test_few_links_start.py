"""The catenary start of a chain of one to three links (``chords="exact"``): held at both ends.

A walk along the catenary with chords of a link's length overshot the curve's free end by
about a link when the links are as long as the sag (one link at chi 0.25: its node at
(0.291, -0.957), 0.96 L above the pin; three links: the free end 0.27 L above). Expected
values here are computed independently: the static equilibrium of the N-link chain held at
(0, 0) and (chi, 0), equal node masses, by minimising its potential energy under the links'
length constraints (scipy SLSQP on the link angles, from several first guesses), never from
the code's own placement.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize

from snapping.simulate import initial_state
from snapping.simulate.problem import Links, Problem

CHIS = (0.05, 0.25, 0.5, 0.9)


def hanging_equilibrium(chi: float, h) -> tuple[np.ndarray, np.ndarray]:
    """Nodes (index 0 the free end, y down) of the chain of links ``h`` (``h[0]`` at the free
    end) held at the pin (0, 0) and its free end (chi, 0), every interior node of equal mass:
    the lowest potential energy -sum(y) over the link angles, both ends fixed (SLSQP, the best
    of several first guesses)."""
    h = np.asarray(h, dtype=float)[::-1]  # walking from the pin
    n = h.size

    def nodes(th):
        return np.concatenate([[0.0], np.cumsum(h * np.cos(th))]), np.concatenate([[0.0], np.cumsum(h * np.sin(th))])

    def energy(th):
        return -float(np.sum(nodes(th)[1][1:-1]))

    cons = [{"type": "eq", "fun": lambda th: nodes(th)[0][-1] - chi},
            {"type": "eq", "fun": lambda th: nodes(th)[1][-1]}]
    best = None
    for lean in (0.3, 0.8, 1.2, 1.5):
        th0 = np.linspace(lean, -lean, n) + 0.01 * np.arange(n)
        r = minimize(energy, th0, constraints=cons, method="SLSQP", options={"ftol": 1e-15, "maxiter": 1000})
        if r.success and (best is None or r.fun < best.fun - 1e-12):
            best = r
    x, y = nodes(best.x)
    return x[::-1], y[::-1]


@pytest.mark.parametrize("chi", CHIS)
@pytest.mark.parametrize("N", [2, 3])
def test_two_and_three_links_start_at_their_hanging_equilibrium(N, chi):
    xe, ye = hanging_equilibrium(chi, np.full(N, 1.0 / N))
    for x, y in ((initial_state(chi, N, chords="exact").x, initial_state(chi, N, chords="exact").y),
                 (Problem.catenary(chi, N).x, Problem.catenary(chi, N).y),  # the default chords: exact
                 (Problem.catenary(chi, links=Links.uniform(N, lumping="shared")).x,
                  Problem.catenary(chi, links=Links.uniform(N, lumping="shared")).y)):
        assert np.max(np.hypot(x - xe, y - ye)) < 1e-6, (x, y, xe, ye)
        assert np.allclose(np.hypot(np.diff(x), np.diff(y)), 1.0 / N, rtol=0, atol=1e-14)  # chords exact
        assert (x[0], y[0], x[-1], y[-1]) == (chi, 0.0, 0.0, 0.0)  # held at (chi, 0) and the pin


def test_two_unequal_links_meet_where_their_lengths_say():
    """Two links of any lengths: the free node is fixed by the lengths alone (law of cosines)."""
    h = np.array([0.7, 0.3])  # h[0] at the free end
    links = Links.explicit(h, [0.5, 0.5])
    chi = 0.6
    p = Problem.catenary(chi, links=links)
    # the angle at the pin between the chord to (chi, 0) and the link of length 0.3, below
    cos_a = (0.3 ** 2 + chi ** 2 - 0.7 ** 2) / (2 * 0.3 * chi)
    expect = (0.3 * cos_a, 0.3 * math.sqrt(1 - cos_a ** 2))
    assert p.x[1] == pytest.approx(expect[0], abs=1e-14) and p.y[1] == pytest.approx(expect[1], abs=1e-14)
    assert (p.x[0], p.y[0]) == (chi, 0.0)
    xe, ye = hanging_equilibrium(chi, h)
    assert np.max(np.hypot(p.x - xe, p.y - ye)) < 1e-6


@pytest.mark.parametrize("chi", CHIS)
def test_one_link_hangs_below_at_the_separation(chi):
    """One link cannot span chi < 1 level: its end at horizontal distance chi, below the pin."""
    for p in (initial_state(chi, 1, chords="exact"), Problem.catenary(chi, 1)):
        assert p.x[0] == chi and p.y[0] == pytest.approx(math.sqrt(1 - chi * chi), abs=1e-15)
        assert p.y[0] > 0.0  # y grows downward: below the pin, not above it as the walk had it


def test_ten_links_keep_the_documented_walk():
    """Longer chains keep the walk along the catenary (bit for bit as before): every node on the
    paper's catenary (extended past s = 1), chords exactly 1/N; at N = 10 this is not the hanging
    equilibrium (free end 0.013 beyond (chi, 0) at chi 0.25) but within 0.02 of it."""
    from snapping.estimates import catenary_parameter

    chi, N = 0.25, 10
    st = initial_state(chi, N, chords="exact")
    assert np.allclose(st.link_lengths(), 1.0 / N, rtol=0, atol=1e-14)
    a = catenary_parameter(chi)
    for x, y in zip(st.x, st.y):  # on the curve: x -> u, then y from the curve's formula
        u = a * math.sinh((x - 0.5 * chi) / a)
        assert y == pytest.approx(math.sqrt(a * a + 0.25) - math.sqrt(a * a + u * u), abs=1e-12)
    assert math.hypot(st.x[0] - chi, st.y[0]) == pytest.approx(0.0132458, abs=1e-6)
    xe, ye = hanging_equilibrium(chi, np.full(N, 1.0 / N))
    assert 1e-3 < np.max(np.hypot(st.x - xe, st.y - ye)) < 0.02

