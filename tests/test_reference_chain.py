"""Checks of the independent chain references (tests/reference_chain.py) against exact facts
and against the project's uniform-chain reference :func:`snapping.simulate.angles.reference_rhs`."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))
import reference_chain as R  # noqa: E402

from snapping.simulate import angles  # noqa: E402


# ---------------------------------------------------------------- helpers
def chain_from_angles(th, om, h, pin=(0.0, 0.0), pin_vel=(0.0, 0.0)):
    """Nodes 0..N (pin last) of links d_j = h_j (cos th_j, sin th_j), summed from the pin."""
    th, om, h = (np.asarray(a, dtype=float) for a in (th, om, h))
    N = th.size
    x, y = np.zeros(N + 1), np.zeros(N + 1)
    vx, vy = np.zeros(N + 1), np.zeros(N + 1)
    x[N], y[N] = pin
    vx[N], vy[N] = pin_vel
    for j in range(N - 1, -1, -1):
        c, s = math.cos(th[j]), math.sin(th[j])
        x[j], y[j] = x[j + 1] - h[j] * c, y[j + 1] - h[j] * s
        # d_j' = h_j om_j (-sin, cos)
        vx[j], vy[j] = vx[j + 1] + h[j] * om[j] * s, vy[j + 1] - h[j] * om[j] * c
    return x, y, vx, vy


def angular_accelerations(th, ax, ay, h, pin_acc=(0.0, 0.0)):
    """theta_j'' = (a_{j+1} - a_j).n_j / h_j from node accelerations (a_N = pin_acc);
    the t_j component of d_j'' is -h_j theta_j'^2 and carries no theta''."""
    ax = np.append(ax, pin_acc[0])
    ay = np.append(ay, pin_acc[1])
    dax, day = np.diff(ax), np.diff(ay)
    return (-np.sin(th) * dax + np.cos(th) * day) / np.asarray(h, dtype=float)


RNG_SEED = 20240611


# ---------------------------------------------------------------- 1. dense KKT solve
@pytest.mark.parametrize("N", range(1, 9))
def test_dense_matches_angles_reference_rhs_and_sig(N):
    rng = np.random.default_rng(RNG_SEED + N)
    h = np.full(N, 1.0 / N)
    m = np.full(N, 1.0 / N)
    w = angles.Work(N)
    f = np.empty(2 * N)
    for _ in range(5):
        th = rng.uniform(-math.pi, math.pi, N)
        om = rng.normal(0.0, 3.0, N)
        x, y, vx, vy = chain_from_angles(th, om, h)
        ax, ay, T = R.dense_accelerations(x, y, vx, vy, h, m, 1.0)
        acc = angular_accelerations(th, ax, ay, h)
        ref = angles.reference_rhs(np.concatenate([th, om]))
        scale = 1.0 + np.abs(ref[N:]).max()
        np.testing.assert_allclose(acc, ref[N:], rtol=0, atol=1e-11 * scale)
        # angles' sig is the link tension T of reference_chain, same sign, scale 1
        angles.angle_rhs(N, np.concatenate([th, om]), f, w.c, w.s, w.S, w.cp, w.dp, w.sig)
        np.testing.assert_allclose(w.sig, T, rtol=0, atol=1e-12 * (1.0 + np.abs(T).max()))
        np.testing.assert_allclose(f[N:], acc, rtol=0, atol=1e-11 * scale)


def test_uniform_hanging_sig_scale():
    """The hanging uniform chain: sig_j = T_j = (j + 1)/N (g = 1, m = 1/N)."""
    N = 6
    th = np.full(N, -math.pi / 2)
    w = angles.Work(N)
    f = np.empty(2 * N)
    angles.angle_rhs(N, np.concatenate([th, np.zeros(N)]), f, w.c, w.s, w.S, w.cp, w.dp, w.sig)
    np.testing.assert_allclose(w.sig, np.arange(1, N + 1) / N, atol=1e-14)
    np.testing.assert_allclose(R.hanging_tension(np.full(N, 1.0 / N), 1.0), w.sig, atol=1e-14)


@pytest.mark.parametrize("N", [1, 2, 5, 13, 40])
def test_dense_hanging_chain_tension(N):
    rng = np.random.default_rng(RNG_SEED + 100 + N)
    h = rng.uniform(0.1, 2.0, N)
    m = rng.uniform(0.01, 5.0, N)
    g = rng.uniform(0.3, 10.0)
    x, y, vx, vy = chain_from_angles(np.full(N, -math.pi / 2), np.zeros(N), h, pin=(0.7, -1.3))
    assert np.all(np.diff(y) < 0)  # y down: the free end is lowest = largest y
    ax, ay, T = R.dense_accelerations(x, y, vx, vy, h, m, g)
    T_exact = R.hanging_tension(m, g)
    np.testing.assert_allclose(T_exact, g * np.cumsum(m))
    np.testing.assert_allclose(T, T_exact, rtol=1e-12, atol=0)
    assert np.abs(ax).max() < 1e-12 * g and np.abs(ay).max() < 1e-11 * g
    assert np.all(T > 0)  # tension positive when pulling


@pytest.mark.parametrize("N", [1, 3, 7])
def test_free_falling_pin_equivalence_principle(N):
    rng = np.random.default_rng(RNG_SEED + 200 + N)
    h = rng.uniform(0.2, 1.5, N)
    m = rng.uniform(0.1, 3.0, N)
    th = rng.uniform(-math.pi, math.pi, N)
    g = 1.0
    # at rest relative to a pin in free fall: no tension, every node falls with g e2
    x, y, vx, vy = chain_from_angles(th, np.zeros(N), h, pin=(0.3, 0.2), pin_vel=(-0.4, 1.1))
    ax, ay, T = R.dense_accelerations(x, y, vx, vy, h, m, g, pin_acc=(0.0, g))
    assert np.abs(T).max() < 1e-13
    np.testing.assert_allclose(ax, 0.0, atol=1e-13)
    np.testing.assert_allclose(ay, g, atol=1e-13)
    # moving: the same tensions as without gravity and a fixed pin; accelerations shifted by g e2
    om = rng.normal(0.0, 2.0, N)
    x, y, vx, vy = chain_from_angles(th, om, h, pin=(0.3, 0.2), pin_vel=(-0.4, 1.1))
    ax, ay, T = R.dense_accelerations(x, y, vx, vy, h, m, g, pin_acc=(0.0, g))
    ax0, ay0, T0 = R.dense_accelerations(x, y, vx, vy, h, m, 0.0)
    scale = 1.0 + np.abs(T0).max()
    np.testing.assert_allclose(T, T0, atol=1e-12 * scale)
    np.testing.assert_allclose(ax, ax0, atol=1e-11 * scale)
    np.testing.assert_allclose(ay, ay0 + g, atol=1e-11 * scale)
    if N == 1:  # a single spinning link without gravity: T = m h omega^2
        np.testing.assert_allclose(T0, m * h * om**2, rtol=1e-12)


def test_dense_rejects_inconsistent_state():
    h, m = np.array([1.0, 1.0]), np.array([1.0, 1.0])
    x, y, vx, vy = chain_from_angles([0.1, 0.2], [0.3, -0.2], h)
    with pytest.raises(ValueError):
        R.dense_accelerations(x * 1.01, y, vx, vy, h, m, 1.0)
    with pytest.raises(ValueError):
        R.dense_accelerations(x, y, vx + np.array([0.1, 0.0, 0.0]), vy, h, m, 1.0)


# ---------------------------------------------------------------- 2. sympy double pendulum
def test_double_pendulum_equations_match_dense():
    """The sympy Lagrange equations and the dense Cartesian KKT solve agree (N = 2),
    fixed pin and a pin with constant acceleration, unequal lengths and masses."""
    rng = np.random.default_rng(RNG_SEED + 300)
    for k in range(20):
        h = rng.uniform(0.2, 2.0, 2)
        m = rng.uniform(0.05, 4.0, 2)
        g = rng.uniform(0.0, 5.0)
        th = rng.uniform(-math.pi, math.pi, 2)
        om = rng.normal(0.0, 2.0, 2)
        pin = None if k % 2 == 0 else tuple(rng.normal(0.0, 2.0, 2))
        t = rng.uniform(0.0, 2.0)
        A = np.zeros(2) if pin is None else np.array(pin)
        f = R.double_pendulum_rhs(t, np.concatenate([th, om]), h, m, g, pin)
        x, y, vx, vy = chain_from_angles(th, om, h, pin=A * t**2 / 2, pin_vel=A * t)
        ax, ay, T = R.dense_accelerations(x, y, vx, vy, h, m, g, pin_acc=A)
        acc = angular_accelerations(th, ax, ay, h, pin_acc=A)
        np.testing.assert_allclose(f[:2], om)
        np.testing.assert_allclose(f[2:], acc, rtol=0, atol=1e-11 * (1.0 + np.abs(acc).max()))


def test_double_pendulum_conserves_energy():
    h, m, g = (0.7, 1.3), (0.4, 1.1), 2.5
    phi0, omega0 = (0.4, 2.1), (1.5, -0.8)  # a chaotic-looking swing
    sol = R.double_pendulum_solution(h, m, g, phi0, omega0, (0.0, 5.0))
    assert sol.success
    t = np.linspace(0.0, 5.0, 1001)
    s = sol.sol(t)
    E = R.double_pendulum_energy(h, m, g, s[:2], s[2:])
    E0 = R.double_pendulum_energy(h, m, g, phi0, omega0)
    assert np.abs(E - E0).max() < 1e-10 * max(1.0, abs(E0))
    # positions from the public entry point: link lengths kept, matching the solution
    x0, y0, x1, y1 = R.double_pendulum_reference(h, m, g, phi0, omega0, t)
    np.testing.assert_allclose(np.hypot(x1, y1), h[1], atol=1e-14)
    np.testing.assert_allclose(np.hypot(x0 - x1, y0 - y1), h[0], atol=1e-14)
    np.testing.assert_allclose(x1, -h[1] * np.cos(s[1]), atol=1e-14)
    np.testing.assert_allclose(y0, -h[1] * np.sin(s[1]) - h[0] * np.sin(s[0]), atol=1e-14)


def test_double_pendulum_hanging_and_free_fall():
    t = np.linspace(0.0, 3.0, 7)
    h, m = (0.5, 1.5), (2.0, 0.3)
    down = (-math.pi / 2, -math.pi / 2)
    x0, y0, x1, y1 = R.double_pendulum_reference(h, m, 1.0, down, (0.0, 0.0), t)
    np.testing.assert_allclose(np.stack([x0, x1]), 0.0, atol=1e-13)
    np.testing.assert_allclose(y1, 1.5, atol=1e-13)
    np.testing.assert_allclose(y0, 2.0, atol=1e-13)
    # a pin in free fall (A = g e2) carries any configuration at rest along unchanged
    phi = (0.3, 2.2)
    x0, y0, x1, y1 = R.double_pendulum_reference(h, m, 1.0, phi, (0.0, 0.0), t, pin=(0.0, 1.0))
    X0, Y0, X1, Y1 = R.double_pendulum_positions(0.0, phi, h)
    np.testing.assert_allclose(x0, X0, atol=1e-12)
    np.testing.assert_allclose(x1, X1, atol=1e-12)
    np.testing.assert_allclose(y0, Y0 + t**2 / 2, atol=1e-12)
    np.testing.assert_allclose(y1, Y1 + t**2 / 2, atol=1e-12)


@pytest.mark.parametrize("amplitude", [0.2, 1.0, 2.5])
def test_tiny_free_end_mass_gives_single_pendulum(amplitude):
    """m0 = 1e-12: node 1 swings as a simple pendulum of length h1 (released from rest with
    the chain straight at `amplitude` from the downward vertical)."""
    h, m, g = (0.6, 1.7), (1e-12, 0.8), 1.3
    th = -math.pi / 2 + amplitude  # angle of the link measured from hanging straight down
    P = R.pendulum_period(h[1], m[1], amplitude, g)

    def crossing(t, s):  # node 1 passes directly below the pin: theta_1 = -pi/2
        return s[1] + math.pi / 2

    sol = R.double_pendulum_solution(h, m, g, (th, th), (0.0, 0.0), (0.0, 1.3 * P), events=crossing)
    assert sol.success
    tc = sol.t_events[0]
    assert tc.size == 3  # at P/4, 3P/4, 5P/4
    assert abs(4 * tc[0] - P) < 1e-6
    assert abs(tc[2] - tc[0] - P) < 1e-6
    assert abs(2 * (tc[1] - tc[0]) - P) < 1e-6
    # node 1 at t = P is back at its release point
    x0, y0, x1, y1 = R.double_pendulum_reference(h, m, g, (th, th), (0.0, 0.0), [P])
    assert abs(x1[0] + h[1] * math.cos(th)) < 1e-6 and abs(y1[0] + h[1] * math.sin(th)) < 1e-6


# ---------------------------------------------------------------- 3./4. closed forms
def test_pendulum_period_exact():
    h, g = 0.8, 2.0
    # small amplitude series: 2 pi sqrt(h/g) (1 + a^2/16 + 11 a^4/3072)
    a = 1e-2
    series = 2 * math.pi * math.sqrt(h / g) * (1 + a**2 / 16 + 11 * a**4 / 3072)
    assert abs(R.pendulum_period(h, 1.0, a, g) - series) < 1e-12
    assert R.pendulum_period(h, 1.0, 0.9, g) == R.pendulum_period(h, 123.0, 0.9, g)  # mass-independent
    # against a direct integration of theta'' = -(g/h) sin theta (quarter period: theta = 0)
    for amp in (0.5, 1.5, 3.0):
        ev = lambda t, s: s[0]  # noqa: E731
        ev.terminal = True
        sol = solve_ivp(lambda t, s: [s[1], -(g / h) * math.sin(s[0])], (0.0, 100.0), [amp, 0.0],
                        method="DOP853", rtol=1e-13, atol=1e-13, events=ev)
        assert abs(4 * sol.t_events[0][0] - R.pendulum_period(h, 1.0, amp, g)) < 1e-9


def test_hanging_tension_profile():
    m = np.array([0.3, 1.0, 2.5, 0.1])
    np.testing.assert_allclose(R.hanging_tension(m, 2.0), [0.6, 2.6, 7.6, 7.8])
    np.testing.assert_array_equal(R.hanging_tension(m, 0.0), np.zeros(4))
