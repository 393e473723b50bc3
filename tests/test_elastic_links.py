"""The extensible line in link coordinates (snapping.simulate.elastic_links and
elastic_links_rodas, method="rodas4-links"): its right-hand side against the node model's, its
Jacobian against differences, the maps between the states, and runs against the node
RODAS4 (peaks, energy balance)."""

from __future__ import annotations

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.simulate import elastic_links as EL
from snapping.simulate.elastic import Elastic, ElasticLine, solve
from snapping.simulate.elastic_links_rodas import LinksStepper
from snapping.simulate.pin import PinMotion
from snapping.simulate.problem import Links, Problem

N = 8


def _line(elastic, pin=None):
    p = Problem.catenary(0.3, links=Links.uniform(N, lumping="shared"), pin=pin or PinMotion.pull((0.7, -1.3)))
    return ElasticLine(p, elastic)


def _random_state(line, rng, t, slack=True):
    """A node state with taut and (``slack``) slack links, fast relative velocities, the held
    end's link taut; no link within 1e-4 of a kink of the law (differences stay smooth)."""
    while True:
        z = line.start("unstretched") + 2e-3 * rng.standard_normal(4 * N + 2)
        z[2:4 * N:4] += 0.5 * rng.standard_normal(N)
        z[3:4 * N:4] += 0.5 * rng.standard_normal(N)
        z[4 * N:] = rng.standard_normal(2)
        xs, ys = line.unpack(z, t)[:2]
        d = np.array([xs[-1] - xs[-2], ys[-1] - ys[-2]])
        z[4 * N - 4:4 * N - 2] = np.array([xs[-1], ys[-1]]) - d / np.hypot(*d) * line.h[-1] * 1.015
        T, E, ED = line.link_state(t, z)
        f = line.ea * E
        smooth = np.all(np.abs(E) > 1e-4) and np.all(np.abs(f + line.damp * ED) > 1e-4 * line.ea.max())
        if smooth and T[-1] > 0 and (not slack or (E < 0).any()) and (E > 0).any():
            return z


ELASTICS = [Elastic(ea=np.linspace(100.0, 900.0, N), damping=0.3),
            Elastic(table=([0.0, 0.01, 0.03], [0.0, 2.0, 9.0]), damping=0.1),
            Elastic(ea=400.0)]


@pytest.mark.parametrize("elastic", ELASTICS)
def test_rhs_is_the_node_models(elastic):
    """At random states (slack and taut links, damped, the held end accelerating) the link
    rates give the node model's accelerations: ``d_j'' = (l'' - l theta'^2) u + (l theta'' +
    2 l' theta') n`` equals ``a_{j+1} - a_j`` of the node rhs (a_N the held end's), and the
    W and D rates are the node model's."""
    line = _line(elastic)
    ll = EL.LinkLine(line)
    rng = np.random.default_rng(3)
    t = 0.4
    for _ in range(3):
        zn = _random_state(line, rng, t)
        zl = ll.from_nodes(t, zn)
        dl = ll.rhs(t, zl)
        dn = line.rhs(t, zn)
        l, th, ld, thd = (zl[k:4 * N:4] for k in range(4))
        u = np.array([np.cos(th), np.sin(th)])
        n = np.array([-np.sin(th), np.cos(th)])
        dd = (dl[2:4 * N:4] - l * thd ** 2) * u + (l * dl[3:4 * N:4] + 2 * ld * thd) * n
        pa = line.pin.kinematics(t)
        a = np.array([np.append(dn[2:4 * N:4], pa[4]), np.append(dn[3:4 * N:4], pa[5])])
        assert np.abs(dd - np.diff(a, axis=1)).max() <= 1e-12 * np.abs(a).max()
        assert np.allclose(dl[0:4 * N:4], ld) and np.allclose(dl[1:4 * N:4], thd)
        assert abs(dl[4 * N] - dn[4 * N]) <= 1e-12 * (1 + abs(dn[4 * N]))
        assert abs(dl[4 * N + 1] - dn[4 * N + 1]) <= 1e-12 * (1 + abs(dn[4 * N + 1]))


@pytest.mark.parametrize("elastic", ELASTICS)
def test_jacobian_is_the_derivative(elastic):
    """Central differences of the link rhs at random states with slack and taut links, damped,
    the held end moving (W row not zero): every row to 1e-6 of its scale."""
    line = _line(elastic)
    ll = EL.LinkLine(line)
    rng = np.random.default_rng(11)
    t = 0.4
    for _ in range(3):
        zl = ll.from_nodes(t, _random_state(line, rng, t))
        J = ll.full_jacobian(t, zl)
        Jn = np.zeros_like(J)
        for k in range(zl.size):
            dz = np.zeros_like(zl)
            dz[k] = 1e-7 * max(1e-2, abs(zl[k]))
            Jn[:, k] = (ll.rhs(t, zl + dz) - ll.rhs(t, zl - dz)) / (2 * dz[k])
        for rows in (slice(0, 4 * N), slice(4 * N, 4 * N + 1), slice(4 * N + 1, 4 * N + 2)):
            scale = np.abs(Jn[rows]).max()
            assert scale > 0 or elastic.damping == 0.0
            assert np.abs(J[rows] - Jn[rows]).max() <= 1e-6 * max(scale, 1.0)


def test_maps_round_trip_and_bad_input():
    """``to_nodes(from_nodes(z)) = z`` to rounding, and back; the lengths and angles are the
    links' own (hypot, atan2 of the node differences); a zero-length link is bad input."""
    line = _line(Elastic(ea=400.0))
    ll = EL.LinkLine(line)
    rng = np.random.default_rng(5)
    t = 0.3
    zn = _random_state(line, rng, t)
    zl = ll.from_nodes(t, zn)
    assert np.abs(ll.to_nodes(t, zl) - zn).max() <= 1e-14
    x, y = line.unpack(zn, t)[:2]
    assert np.allclose(zl[0:4 * N:4], np.hypot(np.diff(x), np.diff(y)), rtol=1e-14)
    assert np.allclose(zl[1:4 * N:4], np.arctan2(np.diff(y), np.diff(x)), rtol=1e-14)
    zl2 = zl.copy()
    zl2[1] += 2 * np.pi  # (an angle is known up to 2 pi: the nodes are the same)
    assert np.abs(ll.to_nodes(t, zl2) - zn).max() <= 1e-14
    assert EL.min_length_ratio(N, zl, line.h) == pytest.approx(np.min(zl[0:4 * N:4] / line.h), rel=1e-15)
    bad = zn.copy()
    bad[4:6] = bad[0:2]  # nodes 0 and 1 coincide
    with pytest.raises(SnappingInputError, match="link 0"):
        LinksStepper(line, t, bad, 1.0, 1e-6)


def test_node_error_is_the_node_difference():
    """The error norm maps a small link-state change to the change of the node state it makes
    (to first order), scaled as the node RODAS4 scales."""
    line = _line(Elastic(ea=400.0))
    ll = EL.LinkLine(line)
    rng = np.random.default_rng(9)
    zl = ll.from_nodes(0.2, _random_state(line, rng, 0.2))
    U = 1e-9 * rng.standard_normal(zl.size)
    zn0 = ll.to_nodes(0.2, zl)
    zn1 = ll.to_nodes(0.2, zl + U)
    tol = 1e-6
    want = np.max(np.abs(zn1 - zn0) / (tol * (1 + np.maximum(np.abs(zn0), np.abs(zn1)))))
    got = EL.node_error(N, zl, U, zn0, zn1, tol)
    assert got == pytest.approx(want, rel=1e-5)


def _catenary_run(method, tol, c=100.0, damping=0.0, t_end=None, pin=None, n=20, start="matched"):
    p = Problem.catenary(0.25, links=Links.uniform(n, lumping="shared"), pin=pin or PinMotion.fixed())
    return solve(p, Elastic.from_wave_speed(c, damping=damping), tol=tol, method=method, start=start,
                 t_end=t_end)


def test_run_agrees_with_node_rodas4_to_the_snap():
    """chi 0.25, N = 20, c = 100, matched start, to the snap (both at tol 1e-8): v's peak and its
    time agree with the node RODAS4's (measured 7e-9; a's and sigma's peaks at this N come
    from the few last links' whip and move by 1% with the tolerance in either method), and the
    links method takes fewer steps, every factorisation pivoted."""
    a = _catenary_run("rodas4-links", 1e-8).summary()
    b = _catenary_run("rodas4", 1e-8).summary()
    assert a["status"] == b["status"] == "completed" and a["stop_reason"] == b["stop_reason"] == "snap"
    assert a["v_peak"] == pytest.approx(b["v_peak"], rel=1e-7)
    assert a["t_snap_v"] == pytest.approx(b["t_snap_v"], abs=1e-5)
    assert a["n_steps"] < b["n_steps"]
    assert a["n_lu_pivoted"] == a["n_lu"]


def test_peaks_agree_with_node_rodas4_before_the_snap():
    """N = 20, c = 300, to t = 1.2 (before the whip): the peaks of v, a and sigma agree with
    the node RODAS4's (both tol 1e-8) to 1e-6."""
    a = _catenary_run("rodas4-links", 1e-8, c=300.0, t_end=1.2).summary()
    b = _catenary_run("rodas4", 1e-8, c=300.0, t_end=1.2).summary()
    for k in ("v_peak", "a_peak", "sigma_peak"):
        assert a[k] == pytest.approx(b[k], rel=1e-6), k


@pytest.mark.parametrize("damping", [0.0, 3.0])
def test_energy_balance_closes(damping):
    """From the stretched start (its release wave rings), the held end pulled (W not zero), c =
    10, N = 12, tol 1e-8, to t = 0.4: kinetic + gravity + elastic - W + D stays at its start to
    1e-7 (measured 3.5e-9 damped), undamped and damped (D then 6.3e-4); W, D and the final state
    agree with the node RODAS4's at tol 1e-9."""
    pin = PinMotion.pull((0.5, -1.0), duration=0.2)
    kw = dict(c=10.0, damping=damping, t_end=0.4, pin=pin, n=12, start="stretched")
    a = _catenary_run("rodas4-links", 1e-8, **kw)
    b = _catenary_run("rodas4", 1e-9, **kw)
    s = a.summary()
    assert s["status"] == "completed"
    assert abs(float(a.dataset["pin_work"][-1])) > 1e-2
    assert float(a.dataset["pin_work"][-1]) == pytest.approx(float(b.dataset["pin_work"][-1]), rel=1e-7)
    if damping:
        assert s["dissipated_total"] > 3e-4
        assert s["dissipated_total"] == pytest.approx(b.summary()["dissipated_total"], rel=1e-4)
    assert s["energy_drift"] < 1e-7
    assert np.abs(a.state - b.state).max() < 1e-6


def test_cli_method_rodas4_links(capsys):
    """``snapping simulate --stretching c --method rodas4-links`` runs the link method (its peaks
    those of --method rodas4 to 1e-5 at tol 1e-8); on the rigid chain it is bad input (exit 2)."""
    import json

    from snapping.cli import main

    base = ["simulate", "--chi", "0.25", "--N", "6", "--t-end", "0.3", "--tol", "1e-8", "--no-progress",
            "--stretching", "20", "--json"]
    out = {}
    for m in ("rodas4-links", "rodas4"):
        assert main(base + ["--method", m]) == 0
        out[m] = json.loads(capsys.readouterr().out)
    assert out["rodas4-links"]["method"] == "rodas4-links" and out["rodas4"]["method"] == "rodas4"
    for k in ("v_peak", "a_peak", "sigma_peak"):
        assert out["rodas4-links"][k] == pytest.approx(out["rodas4"][k], rel=1e-5)
    assert main(["simulate", "--chi", "0.25", "--N", "6", "--method", "rodas4-links", "--no-progress"]) == 2
    assert "extensible line only" in capsys.readouterr().err


def test_a_collapsing_link_fails_the_run_at_the_guard():
    """A slack free-end link at half its rest length closing at speed 20 (no force on it: its
    length falls linearly) reaches 1e-3 of its rest length at t = (0.5 - 1e-3) h/20: the link
    method stops there ('failed': an angle is undefined at zero length), where the node method
    lets the nodes pass each other."""
    p = Problem.catenary(0.25, links=Links.uniform(20, lumping="shared"))
    x, y = p.x.copy(), p.y.copy()
    vx, vy = np.zeros(21), np.zeros(21)
    d = np.array([x[1] - x[0], y[1] - y[0]])
    x[0], y[0] = x[1] - 0.5 * d[0], y[1] - 0.5 * d[1]
    vx[0], vy[0] = 20.0 * d / np.hypot(*d)
    kw = dict(tol=1e-6, t_end=0.01, initial=(x, y, vx, vy))
    s = solve(p, Elastic.from_wave_speed(30.0), method="rodas4-links", **kw).summary()
    assert s["status"] == "failed" and "too small" in s["stop_reason"]
    assert s["t_final"] == pytest.approx((0.5 - 1e-3) * p.links.h[0] / 20.0, rel=1e-5)
    assert solve(p, Elastic.from_wave_speed(30.0), method="rodas4", **kw).summary()["status"] == "completed"
