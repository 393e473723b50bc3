"""The extensible, tension-only line (snapping.simulate.elastic): checks against closed forms,
conservation laws and independent references (never the code under test)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.simulate import run
from snapping.simulate.elastic import Elastic, ElasticLine, solve
from snapping.simulate.pin import PinMotion
from snapping.simulate.problem import Links, Problem


def vertical(N, *, links=None, pin=None, gravity=1.0):
    """A straight line hanging from the origin (y downward), every link at rest length."""
    links = links or Links.uniform(N, lumping="shared")
    y = np.concatenate([np.cumsum(links.h[::-1])[::-1], [0.0]])
    return Problem.nodes(np.zeros(N + 1), y, links=links, pin=pin, gravity=gravity)


# ------------------------------------------------------------------ the Jacobian: a dense reference
@pytest.mark.parametrize("elastic", [Elastic(ea=400.0), Elastic(ea=np.linspace(100.0, 900.0, 8), damping=0.3),
                                     Elastic(table=([0.0, 0.01, 0.03], [0.0, 2.0, 9.0]), damping=0.1)])
def test_jacobian_is_the_derivative_at_random_states(elastic):
    p = Problem.catenary(0.3, links=Links.uniform(8, lumping="shared"))
    line = ElasticLine(p, elastic)
    rng = np.random.default_rng(3)
    for _ in range(3):
        z = line.start("unstretched") + 2e-3 * rng.standard_normal(4 * 8 + 2)
        z[2:32:4] += 0.3 * rng.standard_normal(8)
        T, E, _ = line.link_state(0.0, z)
        assert (E > 0).any() and (E < 0).any()  # taut and slack links both
        J = line.jac(0.0, z).toarray()
        Jn = np.zeros_like(J)
        for k in range(z.size):
            dz = np.zeros_like(z)
            dz[k] = 1e-7
            Jn[:, k] = (line.rhs(0.0, z + dz) - line.rhs(0.0, z - dz)) / 2e-7
        Jn[-2:] = 0.0  # (the W and D rows are left out of the Jacobian on purpose)
        assert np.abs(J - Jn).max() <= 1e-6 * np.abs(Jn).max()


# ------------------------------------------------------------------ statics
def test_hanging_line_stretches_by_lambda_g_L2_over_2EA():
    """Shared lumping: link j carries the weight below it, (j + 1/2) h, so the discrete total
    stretch is sum (j + 1/2) h^2/EA = L^2/(2 EA) exactly, the continuum value."""
    EA = 50.0
    line = ElasticLine(vertical(20), Elastic(ea=EA))
    z = line.statics(line.start("unstretched"))
    assert z[1] == pytest.approx(1.0 + 1.0 / (2.0 * EA), rel=0, abs=1e-12)
    assert np.abs(z[0:80:4]).max() < 1e-14


def test_hanging_line_with_a_table_against_quadrature():
    from scipy.integrate import quad

    e_tab = np.array([0.0, 0.002, 0.006, 0.02, 0.05])
    t_tab = np.array([0.0, 0.05, 0.3, 0.8, 1.6])
    N = 200
    line = ElasticLine(vertical(N), Elastic(table=(e_tab, t_tab)))
    z = line.statics(line.start("unstretched"))
    stretch = z[1] - 1.0
    # discrete: link j carries (j + 1/2) h; its strain from the inverse of the table
    h = 1.0 / N
    discrete = float(np.sum(h * np.interp((np.arange(N) + 0.5) * h, t_tab, e_tab)))
    assert stretch == pytest.approx(discrete, rel=1e-10)
    continuum = quad(lambda s: np.interp(s, t_tab, e_tab), 0.0, 1.0, points=t_tab[1:-1], limit=200)[0]
    assert stretch == pytest.approx(continuum, rel=1e-4)  # (the midpoint rule: O(h^2))


# ------------------------------------------------------------------ closed forms
def test_two_masses_on_springs_against_normal_modes():
    """Two masses hanging on two springs, displaced from equilibrium (both stay taut): the
    linear system M u'' = -K u solved by its normal modes."""
    h, m0, m1, EA = np.array([0.5, 0.5]), 0.7, 0.3, 40.0
    links = Links.explicit(h, [m0, m1])
    k0, k1 = EA / h
    y1 = h[1] * (1 + (m0 + m1) / EA)
    y0 = y1 + h[0] * (1 + m0 / EA)
    u0 = np.array([0.004, -0.002])  # (static stretches are 0.0125 and 0.0088: taut throughout)
    K = np.array([[k0, -k0], [-k0, k0 + k1]])
    Mh = np.diag([m0 ** -0.5, m1 ** -0.5])
    w2, Q = np.linalg.eigh(Mh @ K @ Mh)
    ts = np.linspace(0.0, 3.0, 31)
    expect = np.array([Mh @ Q @ (np.cos(np.sqrt(w2) * t) * (Q.T @ np.linalg.solve(Mh, u0))) for t in ts])
    p = vertical(2, links=links)
    r = solve(p, Elastic(ea=EA), initial=([0, 0, 0], [y0 + u0[0], y1 + u0[1], 0], [0, 0, 0], [0, 0, 0]),
              t_end=3.0, tol=1e-10, snapshot_times=ts[1:-1])
    ds = r.dataset
    got = ds["y"].sel(snapshot=ds["snapshot_kind"] != "peak").values[:, :2] - [y0, y1]
    assert ds["sigma_min"].values.min() > 0
    np.testing.assert_allclose(got, expect, rtol=0, atol=1e-8)


def test_a_mass_goes_taut_and_slack_again_as_the_closed_form():
    """One mass on a tension-only spring, no gravity, from half the rest length moving
    outward at v: free flight, half a period of sqrt(EA/(h m)) while taut, free flight back."""
    h, m, EA, v = 1.0, 1.0, 25.0, 0.2
    p = Problem.nodes([1.0, 0.0], [0.0, 0.0], links=Links.explicit([h], [m]), gravity=0.0)
    w = math.sqrt(EA / (h * m))
    t1 = 0.5 * h / v
    t2 = t1 + math.pi / w
    ts = np.linspace(0.1, t2 + 1.5, 40)

    def exact(t):
        if t < t1:
            return 0.5 * h + v * t
        if t < t2:
            return h + v / w * math.sin(w * (t - t1))
        return h - v * (t - t2)

    r = solve(p, Elastic(ea=EA), initial=([0.5 * h, 0.0], [0.0, 0.0], [v, 0.0], [0.0, 0.0]), t_end=ts[-1] + 0.1,
              tol=1e-11, snapshot_times=ts)
    ds = r.dataset
    sel = ds["snapshot_kind"] == "requested"
    np.testing.assert_allclose(ds["x"].sel(snapshot=sel).values[:, 0], [exact(t) for t in ts], rtol=0, atol=1e-8)
    assert r.summary()["sigma_peak"] == pytest.approx(EA * v / w / h, rel=1e-7)  # peak stretch v/w


def test_a_longitudinal_pulse_travels_at_the_wave_speed():
    """A straight line, no gravity, its held end pulled away quickly: the velocity front
    (half the end's final speed) crosses s = 0.3 and s = 0.7 a time 0.4/c apart."""
    N, c = 200, 10.0
    x = np.linspace(1.0, 0.0, N + 1)
    pin = PinMotion.pull((-1.0, 0.0), duration=0.02)  # the end reaches speed 0.02
    p = Problem.nodes(x, np.zeros(N + 1), links=Links.uniform(N, lumping="shared"), pin=pin, gravity=0.0)
    ts = np.linspace(0.0, 0.09, 361)
    r = solve(p, Elastic.from_wave_speed(c), start="unstretched", t_end=0.09, tol=1e-9, snapshot_times=ts[1:])
    ds = r.dataset
    sel = ds["snapshot_kind"] == "requested"
    vx = -ds["vx"].sel(snapshot=sel).values
    tt = ds["t_snapshot"].sel(snapshot=sel).values

    def crossing(j):
        k = int(np.flatnonzero(vx[:, j] >= 0.01)[0])
        return tt[k - 1] + (0.01 - vx[k - 1, j]) * (tt[k] - tt[k - 1]) / (vx[k, j] - vx[k - 1, j])

    j3, j7 = N - int(0.3 * N), N - int(0.7 * N)  # nodes at s = 0.3 and 0.7
    speed = 0.4 / (crossing(j7) - crossing(j3))
    assert speed == pytest.approx(c, rel=0.01)


def test_climbing_fall_with_a_light_rope_peaks_at_the_massless_formula():
    """A mass M on a rope of 1/10000 of its mass, caught after a free fall of f L (fall factor
    f = 1.77): F = M g (1 + sqrt(1 + 2 f EA/(M g))), here with EA = 25 M g (an 80 kg climber on
    a rope of EA = 20 kN). The peak of the largest link tension is within 1e-3 of it."""
    N, M, f = 10, 1e4, 1.77
    EA = 25.0 * M
    p = vertical(N, links=Links.uniform(N, tip_mass=M, lumping="shared"))
    v0 = math.sqrt(2.0 * f)
    vy = v0 * p.y  # (the rope just taut, stretching uniformly: the massless rope's velocities)
    r = solve(p, Elastic(ea=EA), initial=(p.x, p.y, p.vx, vy), t_end=0.6, tol=1e-8)
    F = M * (1.0 + math.sqrt(1.0 + 2.0 * f * EA / M))
    assert r.summary()["sigma_peak"] == pytest.approx(F, rel=1e-3)


# ------------------------------------------------------------------ energy
@pytest.mark.parametrize("damping", [0.0, 0.02])
def test_energy_balances_through_slack_and_taut(damping):
    """A falling elastic catenary (links going slack and taut again from the release on):
    kinetic + gravity + elastic - pin work + dissipated is conserved to the method's accuracy."""
    p = Problem.catenary(0.25, links=Links.uniform(12, lumping="shared"))
    r = solve(p, Elastic.from_wave_speed(20.0, damping=damping), t_end=0.8, tol=1e-9)
    s = r.summary()
    assert s["n_slack_steps"] > 10  # slack-taut transitions happened
    # (with damping the tension jumps by c de/dt where a link goes taut: a discontinuity; measured
    # 5e-9 at tol 1e-7 and 1e-9 alike. A dissipation rate left out where the damping cancels
    # the tension (T = 0 < f) made it 2.3e-7)
    assert s["energy_drift"] < (2e-8 if damping else 1e-8)
    ds = r.dataset
    if damping:
        assert s["dissipated_total"] > 5e-5  # the balance is not trivial (measured 8.0e-5, 1.6e4 x the drift)
        assert np.all(np.diff(ds["dissipated"].values) >= 0.0)
    else:
        assert s["dissipated_total"] == 0.0
    # the energy itself (not only the balance): E(t) + D(t) = E(0) from the recorded columns
    np.testing.assert_allclose(ds["energy"] + ds["dissipated"] - ds["pin_work"], s["energy_initial"],
                               atol=2e-8 if damping else 1e-8)


def test_energy_balances_with_a_moving_held_end():
    p = vertical(10, pin=PinMotion.pull((0.0, -2.0), duration=0.3))
    r = solve(p, Elastic(ea=300.0), start="unstretched", t_end=0.6, tol=1e-9)
    s = r.summary()
    assert abs(r.dataset["pin_work"].values[-1]) > 0.1
    assert s["energy_drift"] < 1e-8


# ------------------------------------------------------------------ EA -> infinity
@pytest.mark.slow
def test_stiff_line_approaches_the_inextensible_chain():
    """chi = 0.25, N = 12: the peak of v_max moves toward the inextensible run's as the wave
    speed grows (measured: -1.50e-2 at c = 30, -2.86e-3 at c = 100, a rate of about c^-1.4;
    N = 30: -4.7e-2 at c = 30, -9.6e-4 at c = 300). The peaks of a and sigma do not follow at
    these c (N = 12, c = 100: both about twice the inextensible's; N = 100, c = 300: sigma
    +48%): the elastic peak tension sits on the link at the free end at the snap, where links
    go slack and taut again; not yet explained (see the report of the elastic branch)."""
    p = Problem.catenary(0.25, links=Links.uniform(12, lumping="shared"))
    ref = run(problem=p, method="fast", tol=1e-11).summary()["v_peak"]
    err = [abs(solve(p, Elastic.from_wave_speed(c), tol=1e-6).summary()["v_peak"] / ref - 1.0) for c in (30.0, 100.0)]
    assert err[1] < err[0] / 4.0
    assert err[1] < 4e-3


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize("kwargs, match", [
    ({"ea": 0.0}, "^ea=0.0"), ({"ea": float("nan")}, "^ea=nan"), ({"ea": [1.0, -2.0]}, r"^ea\[1\]=-2.0"),
    ({"ea": 1.0, "damping": -0.1}, "^damping=-0.1"), ({}, "exactly one of ea"),
    ({"table": ([0.0, 0.1, 0.05], [0.0, 1.0, 2.0])}, "strains must increase"),
    ({"table": ([0.0, 0.1, 0.2], [0.0, 1.0, 0.5])}, "monotone"),
    ({"table": "rope.csv"}, "table"),
])
def test_bad_elastic_input_is_named(kwargs, match):
    with pytest.raises(SnappingInputError, match=match):
        Elastic(**kwargs)


def test_bad_solve_input_is_named():
    p = Problem.catenary(0.25, links=Links.uniform(4, lumping="shared"))
    with pytest.raises(SnappingInputError, match="^method='euler-richardson'"):
        solve(p, Elastic(ea=10.0), method="euler-richardson")
    with pytest.raises(SnappingInputError, match="^tol=0.0"):
        solve(p, Elastic(ea=10.0), tol=0.0)
    with pytest.raises(SnappingInputError, match="ea has 3 entries"):
        solve(p, Elastic(ea=[1.0, 2.0, 3.0]))
