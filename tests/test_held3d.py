"""The held end of a 3D chain moving along a curve in space (snapping.spatial.held3d).

Checked against what is exact and independent of the code:

* the kinematics: a circle stays on its circle, at the steady speed R omega after its ramp;
  position, velocity and acceleration are one motion (finite differences); a cubic motion is
  reproduced exactly by the sampled table (not-a-knot splines); right limits at breakpoints;
* Galilean invariance: a held end moving at constant velocity (a table of samples of V t)
  gives the fixed-pin run's motion relative to the held end;
* the equivalence principle: an endless uniform acceleration A of the held end is the fixed
  run under the changed gravity g - A;
* the energy balance E - W (W: the held end's work, integrated with the state) of a chain spun
  up by its held end driven around a circle: the velocity and the acceleration of the circle
  are consistent with each other and with the dynamics.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.spatial import chain3d as C
from snapping.spatial.held3d import Pin3D, parse_pin3d
from snapping.spatial.solve3d import RECORD_NAMES, run3d
from snapping.spatial.starts3d import Problem3D


# ---------------------------------------------------------------- kinematics
@pytest.mark.parametrize("ramp,t0", [(0.4, 0.1), (0.0, 0.0)])
def test_circle_stays_on_its_circle_at_the_steady_speed(ramp, t0):
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    pin = Pin3D.circle(0.3, -2.5, ramp=ramp, t0=t0, axis=axis)
    a = np.asarray(pin.start_dir)
    centre = -0.3 * a
    ts = np.linspace(0.0, 3.0, 601)
    k = np.array([pin.kinematics(t) for t in ts])
    rel = k[:, :3] - centre
    assert np.abs(np.linalg.norm(rel, axis=1) - 0.3).max() < 1e-15
    assert np.abs(rel @ axis).max() < 1e-15  # (in the plane normal to the axis)
    after = ts > t0 + ramp
    speed = np.linalg.norm(k[:, 3:6], axis=1)
    assert np.abs(speed[after] - 0.75).max() < 1e-14
    # steady: the acceleration is centripetal, R omega^2 toward the centre
    np.testing.assert_allclose(k[after, 6:9], -(2.5 ** 2) * rel[after], rtol=0, atol=1e-13)
    # turning the right way: (r - c) x v along -axis for omega < 0
    assert np.all(np.cross(rel[after], k[after, 3:6]) @ axis < 0)
    if ramp > 0.0:
        assert np.all(k[ts <= t0] == 0.0)  # (at rest until t0; spun up from rest)


@pytest.mark.parametrize("pin", [Pin3D.circle(0.2, 3.0, 0.5, 0.1, axis=(0.0, 0.0, 1.0)),
                                 Pin3D.from_function(lambda t: (0.1 * math.sin(3 * t), -0.05 * t * t,
                                                                0.1 * (1 - math.cos(2 * t))), 0.5, 41)],
                         ids=["circle", "table"])
def test_position_velocity_and_acceleration_are_one_motion(pin):
    ts = np.linspace(0.0, 0.9, 9001)
    k = np.array([pin.kinematics(t) for t in ts])
    ok = np.ones(ts.size, bool)
    for b in pin.breakpoints:
        ok &= np.abs(ts - b) > 3e-4
    for i in range(3):
        v_num = np.gradient(k[:, i], ts)
        a_num = np.gradient(k[:, 3 + i], ts)
        assert np.abs(v_num - k[:, 3 + i])[ok][1:-1].max() < 1e-6
        assert np.abs(a_num - k[:, 6 + i])[ok][1:-1].max() < 2e-3 * max(1.0, np.abs(k[:, 6 + i]).max())


def test_table_reproduces_a_cubic_motion_exactly_and_continues_at_constant_velocity():
    def cubic(t):
        return np.array([0.3 * t - 0.2 * t ** 3, 0.5 * t * t, -0.1 * t + 0.4 * t ** 3])

    t = np.array([0.0, 0.13, 0.4, 0.55, 0.9, 1.0])
    pin = Pin3D.from_table(t, *np.array([cubic(v) for v in t]).T)
    for tt in (0.05, 0.3, 0.77, 1.0):
        k = np.array(pin.kinematics(tt))
        d1 = np.array([0.3 - 0.6 * tt * tt, tt, -0.1 + 1.2 * tt * tt])
        d2 = np.array([-1.2 * tt, 1.0, 2.4 * tt])
        np.testing.assert_allclose(k[:3], cubic(tt), rtol=0, atol=1e-14)
        np.testing.assert_allclose(k[3:6], d1, rtol=0, atol=1e-13)
        np.testing.assert_allclose(k[6:9], d2 if tt < 1.0 else 0.0, rtol=0, atol=1e-12)
    # after the last sample: constant velocity; at it, the right limit (acceleration 0, as planar)
    k2 = np.array(pin.kinematics(2.0))
    np.testing.assert_allclose(k2[:3], cubic(1.0) + np.array([-0.3, 1.0, 1.1]), rtol=0, atol=1e-13)
    assert pin.breakpoints == [1.0] and pin.settle_time == 1.0
    assert np.any(np.array(pin.kinematics(float(np.nextafter(1.0, 0.0)))[6:]) != 0.0)


def test_right_limits_at_breakpoints_and_settle_times():
    pull = Pin3D.pull((0.0, -2.0, 1.0), duration=0.5, t0=0.2)
    assert pull.kinematics(0.2)[6:] == (0.0, -2.0, 1.0) and pull.kinematics(0.7)[6:] == (0.0, 0.0, 0.0)
    assert pull.settle_time == 0.7
    circ = Pin3D.circle(0.1, 2.0, ramp=0.5, t0=0.25)
    assert circ.breakpoints == [0.25, 0.75] and circ.settle_time == 0.75
    assert Pin3D.circle(0.1, 2.0).breakpoints == [] and Pin3D.circle(0.1, 2.0).settle_time == 0.0
    assert Pin3D().settle_time == -1.0


# ---------------------------------------------------------------- exact equivalences
def _relative(res, N):
    return res["state"][:6 * N]


def test_constant_velocity_held_end_is_the_fixed_run_in_a_galilean_frame():
    """A table of samples of V t (constant velocity from t = 0): relative to the held end the
    chain moves exactly as with the held end fixed (same link directions and rates), and the
    moving-pin stop rule (speeds relative to the held end, from its last sample) stops at the
    fixed run's snap."""
    N = 10
    V = np.array([0.7, -0.4, 0.5])
    t = np.linspace(0.0, 0.2, 5)
    fixed = Problem3D.catenary(0.3, N).perturbed(0.05)
    moving = fixed.with_pin(Pin3D.from_table(t, *(np.outer(t, V).T)))
    assert np.allclose(moving.v - fixed.v, V) and moving.pin.velocity(0.0) == pytest.approx(tuple(V), abs=1e-15)
    a, b = run3d(fixed, tol=1e-10, t_end=0.9), run3d(moving, tol=1e-10, t_end=0.9)
    np.testing.assert_allclose(_relative(b, N), _relative(a, N), rtol=0, atol=1e-8)
    sa, sb = run3d(fixed, tol=1e-9), run3d(moving, tol=1e-9)
    assert sa["stop_reason"] == sb["stop_reason"] == "snap"
    vrel = sb["record"][:, RECORD_NAMES.index("v_rel_max")]
    assert vrel.max() == pytest.approx(sa["record"][:, RECORD_NAMES.index("v_max")].max(), rel=1e-3)  # (sampled)
    assert sb["t_final"] == pytest.approx(sa["t_final"], abs=0.02)


def test_uniform_acceleration_of_the_held_end_is_changed_gravity():
    N = 10
    A = np.array([0.6, -0.8, 0.9])
    base = Problem3D.catenary(0.3, N).perturbed(0.05)
    pulled = base.with_pin(Pin3D.pull(A))
    g = np.array([0.0, 1.0, 0.0]) - A
    changed = Problem3D(base.links, base.r, base.v, gravity=float(np.linalg.norm(g)),
                        g_dir=tuple(g / np.linalg.norm(g)))
    # the right-hand sides of the link directions and rates agree at any state
    y = pulled.initial_state()
    rng = np.random.default_rng(3)
    y[3 * N:6 * N] += 0.3 * rng.standard_normal(3 * N)
    C.project(N, y)
    f1, f2 = np.empty_like(y), np.empty_like(y)
    w = C.Work(N)
    C.rhs3d(N, 0.4, y, f1, w.T, w.cp, w.dp, *pulled.model())
    C.rhs3d(N, 0.4, y, f2, w.T, w.cp, w.dp, *changed.model())
    np.testing.assert_allclose(f1[:6 * N], f2[:6 * N], rtol=0, atol=1e-13)
    a, b = run3d(pulled, tol=1e-10, t_end=0.8), run3d(changed, tol=1e-10, t_end=0.8)
    np.testing.assert_allclose(_relative(a, N), _relative(b, N), rtol=0, atol=1e-8)


def test_spun_up_chain_keeps_its_energy_balance():
    p = Problem3D.spun_up(3.0, 8, radius=0.1, ramp=0.5)
    assert np.all(p.v == 0.0) and p.pin.settle_time == 0.5
    res = run3d(p, tol=1e-11, t_end=1.2)
    rec = res["record"]
    W = rec[:, RECORD_NAMES.index("pin_work")]
    Lg = rec[:, RECORD_NAMES.index("angular_momentum_g")]
    assert W[-1] > 0.01 and abs(Lg[-1]) > 0.01 and res["z_amp_max"] > 0.05  # (spun up: work done, whirling)
    assert res["energy_drift"] < 1e-10  # (measured 1e-12)


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize("make,word", [
    (lambda: Pin3D.circle(0.1, 2.0, axis=(0.0, 0.0, 0.0)), "axis"),
    (lambda: Pin3D.circle(0.1, 2.0, axis=(0.0, 2.0, 0.0)), "axis"),
    (lambda: Pin3D.circle(0.1, 2.0, start_dir=(0.0, 1.0, 0.0)), "start_dir"),
    (lambda: Pin3D.circle(0.0, 2.0), "radius"),
    (lambda: Pin3D.circle(0.1, float("nan")), "omega"),
    (lambda: Pin3D.circle(0.1, 2.0, ramp=0.0, t0=0.5), "ramp=0"),
    (lambda: Pin3D.from_table([0.0, 0.1, 0.2], [0] * 3, [0] * 3, [0] * 3), "length >= 4"),
    (lambda: Pin3D.from_table([0.0, 0.1, 0.2, 0.3], [1, 0, 0, 0], [0] * 4, [0] * 4), "origin"),
    (lambda: Pin3D.from_table([0.0, 0.1, 0.1, 0.3], [0] * 4, [0] * 4, [0] * 4), "increase"),
    (lambda: Pin3D.from_table([0.0, 0.1, 0.2, 0.3], [0] * 4, [0] * 4, [0, 0, float("inf"), 0]), r"z\[2\]=inf"),
    (lambda: Pin3D.pull((1.0, float("nan"), 0.0)), "accel"),
    (lambda: parse_pin3d("circle:0.1"), "circle:R,OMEGA"),
    (lambda: parse_pin3d("pull", axis=(0, 1, 0)), "pin_axis"),
    (lambda: Problem3D(Problem3D.catenary(0.3, 4).links, Problem3D.catenary(0.3, 4).r,
                       Problem3D.catenary(0.3, 4).v, pin=Pin3D.circle(0.1, 2.0)), "must move as the pin"),
])
def test_bad_held_end_is_named(make, word):
    with pytest.raises(SnappingInputError, match=word):
        make()
