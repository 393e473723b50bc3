"""The 3D chain (snapping.spatial) against independent physics.

* accelerations and tensions at random states against a dense Lagrange-multiplier (KKT)
  solve in node positions, written here (random links, masses, gravity, a moving held end);
* a fixed held end and gravity: the energy and the angular momentum about the held end
  along gravity are conserved to the method's accuracy; links stay unit to round-off;
* a planar problem in 3D gives the planar method's peaks and stays exactly planar;
* the steadily whirling chain (its discrete shape solved here by shooting) stays steady;
* bad input: one SnappingInputError naming the parameter.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from snapping._validate import SnappingInputError
from snapping.simulate.links import Links
from snapping.spatial import chain3d as C
from snapping.spatial.solve3d import run3d
from snapping.spatial.starts3d import Pin3D, Problem3D


# ---------------------------------------------------------------- a dense reference, independent of chain3d
def _kkt(r, v, m, g, A):
    """Node accelerations (N, 3) and link tensions (N,) of the chain with free nodes r[:N]
    (masses m), held node r[N] with acceleration A, from the dense system
    ``M a = m g + G^T mu``, ``G a = gamma`` of the constraints ``|r_{j+1} - r_j|^2 = h_j^2``."""
    N = len(m)
    n = 3 * N
    K = np.zeros((n + N, n + N))
    rhs = np.zeros(n + N)
    for j in range(N):
        K[3 * j:3 * j + 3, 3 * j:3 * j + 3] = m[j] * np.eye(3)
        rhs[3 * j:3 * j + 3] = m[j] * g
    for j in range(N):
        d = r[j + 1] - r[j]
        dv = v[j + 1] - v[j]
        G = np.zeros(n)  # d/dr of (|d|^2 - h^2)/2
        G[3 * j:3 * j + 3] = -d
        gam = -dv @ dv
        if j + 1 < N:
            G[3 * j + 3:3 * j + 6] = d
        else:
            gam -= d @ A
        K[:n, n + j] = -G
        K[n + j, :n] = G
        rhs[n + j] = gam
    sol = np.linalg.solve(K, rhs)
    a = sol[:n].reshape(N, 3)
    mu = sol[n:]
    T = -mu * np.linalg.norm(np.diff(r, axis=0), axis=1)  # force -mu d_j on node j, toward node j + 1 if mu < 0
    return a, T


@pytest.mark.parametrize("seed", range(6))
def test_accelerations_match_a_dense_kkt_solve(seed):
    rng = np.random.default_rng(seed)
    N = int(rng.integers(1, 9))
    h = rng.uniform(0.2, 2.0, N)
    m = rng.uniform(0.1, 3.0, N)
    e = rng.standard_normal((N, 3))
    e /= np.linalg.norm(e, axis=1)[:, None]
    u = rng.standard_normal((N, 3))
    u -= np.sum(u * e, axis=1)[:, None] * e
    gvec = rng.standard_normal(3)
    acc = rng.standard_normal(3)
    t = 0.7
    mdl = C.make_model(h, 1.0 / m, g=gvec, pin=(C.PIN_PULL, acc, 0.2, 5.0))
    p = C.pin3d(t, mdl[0])
    r, v = C.state_to_nodes(np.concatenate([e.T.ravel(), u.T.ravel(), [0.0]]), h, pin=np.array(p[:6]))
    a_ref, T_ref = _kkt(r, v, m, gvec, np.array(p[6:9]))
    y = np.concatenate([e.T.ravel(), u.T.ravel(), [0.3]])
    f = np.zeros_like(y)
    w = C.Work(N)
    C.rhs3d(N, t, y, f, w.T, w.cp, w.dp, *mdl)
    a_all = np.vstack([a_ref, np.array(p[6:9])])
    edd_ref = np.diff(a_all, axis=0) / h[:, None]
    scale = np.abs(edd_ref).max() + 1.0
    np.testing.assert_allclose(f[3 * N:6 * N].reshape(3, N).T, edd_ref, rtol=0, atol=1e-11 * scale)
    np.testing.assert_allclose(f[:3 * N], u.T.ravel(), rtol=0, atol=0)
    np.testing.assert_allclose(w.T, T_ref, rtol=0, atol=1e-11 * (np.abs(T_ref).max() + 1.0))
    assert f[6 * N] == pytest.approx(T_ref[-1] * (e[-1] @ np.array(p[3:6])), rel=1e-10, abs=1e-12)


def test_pin_kinematics_integrate_consistently():
    """Position, velocity and acceleration of the held end's presets are one motion."""
    for pin in (Pin3D("pull", (0.3, -1.0, 0.5), t0=0.1, duration=0.4), Pin3D("flick", (1.0, 0.2, -0.7), 0.05, 0.3)):
        ts = np.linspace(0.0, 0.6, 6001)
        k = np.array([pin.kinematics(t) for t in ts])
        for i in range(3):
            v_num = np.gradient(k[:, i], ts)
            a_num = np.gradient(k[:, 3 + i], ts)
            ok = np.ones(ts.size, bool)
            for b in (pin.t0, pin.t0 + pin.duration):
                ok &= np.abs(ts - b) > 2e-4
            assert np.abs(v_num - k[:, 3 + i])[ok][1:-1].max() < 1e-7
            assert np.abs(a_num - k[:, 6 + i])[ok][1:-1].max() < 1e-4


# ---------------------------------------------------------------- conservation laws
def _spun():
    """A 3D start: the catenary at chi = 0.4 with a large out-of-plane swing."""
    return Problem3D.catenary(0.4, 24, links=Links.uniform(24, tip_mass=0.2, lumping="shared")).perturbed(0.8)


def test_energy_and_vertical_angular_momentum_are_conserved():
    res = run3d(_spun(), tol=1e-11, t_end=1.2)
    rec = res["record"]
    from snapping.spatial.solve3d import RECORD_NAMES

    Lg = rec[:, RECORD_NAMES.index("angular_momentum_g")]
    v = rec[:, RECORD_NAMES.index("v_max")]
    assert abs(Lg[0]) > 0.05 and np.ptp(v) > 0.5  # (a genuinely 3D motion, kinetic energy exchanged)
    assert res["energy_drift"] < 1e-11  # (measured 6e-14; 2e-9 at tol 1e-7)
    assert res["angular_momentum_drift"] < 1e-11  # (measured 2e-14)
    assert res["z_amp_max"] > 0.1
    # every link unit to round-off in the (projected) state
    N = res["N"]
    e = res["state"][:3 * N].reshape(3, N)
    assert np.abs(np.linalg.norm(e, axis=0) - 1.0).max() < 4e-16
    # and the drift shrinks with tol (the method's accuracy, not a coincidence)
    loose = run3d(_spun(), tol=1e-7, t_end=1.2)
    assert loose["energy_drift"] > 10 * res["energy_drift"]


def test_energy_balance_with_a_held_end_moving_in_space():
    """E - W is conserved (W: the work of the held end, integrated with the state) while the
    held end is flicked along a vector out of the plane."""
    prob = Problem3D.catenary(0.3, 20)
    prob = Problem3D(prob.links, prob.r, prob.v, pin=Pin3D("flick", (0.8, -1.5, 1.2), 0.1, 0.3))
    res = run3d(prob, tol=1e-11, t_end=1.0)
    from snapping.spatial.solve3d import RECORD_NAMES

    W = res["record"][:, RECORD_NAMES.index("pin_work")]
    assert np.ptp(W) > 0.005 and res["z_amp_max"] > 0.01  # (work done, motion out of the plane)
    assert res["energy_drift"] < 1e-11  # (measured 5e-14; 3e-11 at tol 1e-8)


# ---------------------------------------------------------------- planar problems stay planar
@pytest.mark.parametrize("case", ["paper", "taper_pull"])
def test_planar_problem_gives_the_planar_peaks(case):
    from snapping.simulate import run
    from snapping.simulate.pin import PinMotion
    from snapping.simulate.problem import Problem

    if case == "paper":
        prob = Problem.catenary(0.25, 60)
    else:
        prob = Problem.catenary(0.3, 40, links=Links.taper(40, 0.3, tip_mass=0.1),
                                pin=PinMotion.pull((0.5, -0.3), duration=0.3))
    ds = run(problem=prob, method="fast", tol=1e-11).dataset
    res = run3d(Problem3D.from_planar(prob), tol=1e-11)
    for q in ("v", "a", "sigma"):
        assert res[f"{q}_peak"] == pytest.approx(float(ds.attrs[f"{q}_peak"]), rel=2e-11, abs=0)  # (measured <= 3e-12)
        assert res[f"t_snap_{q}"] == pytest.approx(float(ds.attrs[f"t_snap_{q}"]), rel=0, abs=3e-8)  # (a flat maximum: <= 6e-9)
    assert res["z_amp_max"] == 0.0 and res["vz_amp_max"] == 0.0
    N = res["N"]
    assert np.all(res["state"][2 * N:3 * N] == 0.0) and np.all(res["state"][5 * N:6 * N] == 0.0)


# ---------------------------------------------------------------- the whirling chain
def _whirl_shape(links, Omega, g=1.0):
    """The discrete chain rotating steadily at rate Omega about the vertical through its held
    end, free end out: shoot from the free end (radius x0) node by node,
    ``T_j e_j = T_{j-1} e_{j-1} - m_j (g yhat + Omega^2 x_j xhat)``, until the held end is on
    the axis (first mode). Returns node positions (N + 1, 2) relative to the held end."""
    h, m = links.h, links.m
    N = links.N

    def shoot(x0):
        x, y = x0, 0.0
        Fx, Fy = 0.0, 0.0  # T_{j-1} e_{j-1}
        pts = [(x, y)]
        for j in range(N):
            Fx, Fy = Fx - m[j] * Omega**2 * x, Fy - m[j] * g  # = T_j e_j
            T = math.hypot(Fx, Fy)
            x, y = x + h[j] * Fx / T, y + h[j] * Fy / T
            pts.append((x, y))
        return np.array(pts)

    xs = np.linspace(1e-3, 0.999 * links.length, 400)
    xN = np.array([shoot(x)[-1, 0] for x in xs])
    k = int(np.flatnonzero(np.sign(xN[1:]) != np.sign(xN[:-1]))[0])
    x0 = brentq(lambda x: shoot(x)[-1, 0], xs[k], xs[k + 1], xtol=1e-15, rtol=1e-15)
    P = shoot(x0)
    return P - P[-1]


def test_whirling_chain_stays_steady():
    N, Omega = 30, 2.5
    links = Links.uniform(N, lumping="shared")
    P = _whirl_shape(links, Omega)
    r = np.column_stack([P[:, 0], P[:, 1], np.zeros(N + 1)])
    v = np.column_stack([np.zeros(N + 1), np.zeros(N + 1), -Omega * P[:, 0]])  # Omega yhat x r
    prob = Problem3D(links, r, v)
    made = Problem3D.whirling(Omega, links=links)  # (the constructor's own shooting: the same shape)
    assert np.abs(made.r - r).max() < 1e-13 and np.abs(made.v - v).max() < 1e-13
    turns = 3
    res = run3d(prob, tol=1e-11, t_end=turns * 2 * math.pi / Omega)
    rn, vn = C.state_to_nodes(res["state"], links.h)
    rad = np.hypot(rn[:, 0], rn[:, 2])
    # (measured: 2e-15, 1e-14, 5e-14, 2e-14 at tol 1e-11)
    assert np.abs(rad - np.abs(P[:, 0])).max() < 1e-11
    assert np.abs(rn[:, 1] - P[:, 1]).max() < 1e-11
    # after whole turns, the same positions (phase advanced by Omega t)
    assert np.abs(rn - r).max() < 1e-10
    assert res["energy_drift"] < 1e-11


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize("make,word", [
    (lambda: Problem3D.catenary(0.25, 10).perturbed(float("nan")), "eps"),
    (lambda: Problem3D.catenary(0.25, 10).perturbed(1e-3, mode="wiggle"), "mode"),
    (lambda: Problem3D(Links.uniform(2), np.zeros((3, 2)), np.zeros((3, 3))), "3 columns"),
    (lambda: Problem3D(Links.uniform(2), [[0, 1.0, 0], [0, 0.5, 0], [0, 0, 0]], np.zeros((3, 3)),
                       g_dir=(0.0, 2.0, 0.0)), "g_dir"),
    (lambda: Problem3D(Links.uniform(2), [[0, 1.0, 0], [0, 0.5, 0], [0, 0, 0]], np.zeros((3, 3)),
                       g_dir=(0.0, 0.0, 0.0)), "g_dir"),
    (lambda: Problem3D(Links.uniform(2), [[0, 0.9, 0], [0, 0.5, 0], [0, 0, 0]], np.zeros((3, 3))), "link 0"),
    (lambda: Problem3D.nodes([[0, 1.0], [0, 0]]), "3 columns"),
    (lambda: Problem3D.whirling(1.0, 30), "omega"),
    (lambda: Problem3D.whirling(float("inf"), 30), "omega"),
])
def test_bad_input_is_named(make, word):
    with pytest.raises(SnappingInputError, match=word):
        make()
