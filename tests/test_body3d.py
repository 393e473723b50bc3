"""A line's body in space (snapping.spatial.forces3d) against independent physics.

* accelerations, the held end's power and the dissipation rate at random 3D states with
  bending, damping, drag, a 3D wind and a tip body, against a dense Lagrange-multiplier
  (KKT) solve in node positions written here (the bending energy and its gradient from node
  positions; the damping from the rate of the turning angle);
* the same reference's energy rate (kinetic + gravity + bending) equals the held end's
  power less the dissipation (the balance the run integrates);
* a planar problem with bending (and a natural curvature), damping and drag run in space
  gives the planar run's peaks and stays exactly planar;
* the energy balance of a 3D run closes to the method's accuracy; the angular momentum along
  gravity is conserved with bending and damping (fixed end, no drag);
* B -> 0 gives the body-less run (an inactive body bit for bit, a tiny B at O(B));
* bad input: a clamp, a natural curvature out of a plane, a planar out-of-plane wind.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.simulate import Body, Links, PinMotion, Problem, run
from snapping.spatial import chain3d as C
from snapping.spatial.solve3d import run3d
from snapping.spatial.starts3d import Pin3D, Problem3D


# ---------------------------------------------------------------- an independent Cartesian reference
class Cartesian3D:
    """N free point masses in space (node N prescribed) with the body's forces written from
    node positions and velocities, and the link constraints solved densely (KKT)."""

    def __init__(self, h, m, g, B, eta, cn, ct, kn, kt, wind, cd):
        self.h, self.m, self.g = h, m, np.asarray(g, float)
        self.B, self.eta, self.cn, self.ct, self.kn, self.kt = B, eta, cn, ct, kn, kt
        self.wind, self.cd = np.asarray(wind, float), cd
        N = h.size
        self.l = np.zeros(N + 1)
        self.l[0] = h[0] / 2
        self.l[1:N] = (h[:-1] + h[1:]) / 2
        self.l[N] = h[-1] / 2

    @staticmethod
    def _angle(A, B):
        """The angle between A and B and its gradients with respect to A and B."""
        nA, nB = np.linalg.norm(A), np.linalg.norm(B)
        a, b = A / nA, B / nB
        cos = a @ b
        sin = np.linalg.norm(np.cross(a, b))
        ang = math.atan2(sin, cos)
        gA = -(b - cos * a) / (nA * sin)
        gB = -(a - cos * b) / (nB * sin)
        return ang, gA, gB

    def energy_and_forces(self, r, v):
        N = self.h.size
        F = np.zeros((N + 1, 3))
        Vb = diss = 0.0
        for i in range(1, N):
            A, dA = r[i] - r[i - 1], v[i] - v[i - 1]
            Bv, dB = r[i + 1] - r[i], v[i + 1] - v[i]
            ang, gA, gB = self._angle(A, Bv)
            rate = gA @ dA + gB @ dB
            Vb += self.B[i] * ang ** 2 / (2 * self.l[i])
            M = (self.B[i] * ang + self.eta[i] * rate) / self.l[i]
            diss += self.eta[i] * rate ** 2 / self.l[i]
            # dpsi/dr: A = r_i - r_{i-1}, B = r_{i+1} - r_i
            F[i - 1] += M * gA
            F[i] -= M * (gA - gB)
            F[i + 1] -= M * gB
        pdrag = 0.0
        for j in range(N):
            tau = (r[j + 1] - r[j]) / self.h[j]
            if j > 0:
                tau = tau + (r[j] - r[j - 1]) / self.h[j - 1]
                tau /= np.linalg.norm(tau)
            u = v[j] - self.wind
            ut = (u @ tau) * tau
            un = u - ut
            f = -(self.cn[j] * np.linalg.norm(un) + self.kn[j]) * self.l[j] * un \
                - (self.ct[j] * np.linalg.norm(ut) + self.kt[j]) * self.l[j] * ut
            if j == 0:
                f -= self.cd * np.linalg.norm(u) * u
            F[j] += f
            pdrag += f @ v[j]
        return Vb, F, diss - pdrag

    def solve(self, r, v, A):
        """Node accelerations (N + 1, 3), the held end's power and dD/dt, and d(K + P + Vb)/dt."""
        N = self.h.size
        Vb, F, dD = self.energy_and_forces(r, v)
        n = 3 * N
        K = np.zeros((n + N, n + N))
        rhs = np.zeros(n + N)
        for j in range(N):
            K[3 * j:3 * j + 3, 3 * j:3 * j + 3] = self.m[j] * np.eye(3)
            rhs[3 * j:3 * j + 3] = self.m[j] * self.g + F[j]
        for j in range(N):
            d, dv = r[j + 1] - r[j], v[j + 1] - v[j]
            G = np.zeros(n)
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
        a = np.vstack([sol[:n].reshape(N, 3), A])
        mu = sol[n:]
        # the held end's force on the chain: the constraint force on node N's side of the
        # held link, -(-mu d) = mu d ... written as its pull on node N - 1 reversed, less F_N
        d_last = r[N] - r[N - 1]
        held = -mu[-1] * d_last - F[N]
        p_held = held @ v[N]
        # energy rate from the accelerations (kinetic + gravity) and the bending energy's rate
        dKP = sum(self.m[j] * (v[j] @ a[j]) - self.m[j] * (self.g @ v[j]) for j in range(N))
        eps = 1e-6
        Vp = self.energy_and_forces(r + eps * v, v)[0]
        Vm = self.energy_and_forces(r - eps * v, v)[0]
        return a, p_held, dD, dKP + (Vp - Vm) / (2 * eps)


def _random_case(seed, N):
    rng = np.random.default_rng(seed)
    h = rng.uniform(0.3, 1.5, N)
    m = rng.uniform(0.2, 2.0, N)
    e = rng.standard_normal((N, 3))
    e /= np.linalg.norm(e, axis=1)[:, None]
    u = rng.standard_normal((N, 3))
    u -= np.sum(u * e, axis=1)[:, None] * e
    prof = {k: rng.uniform(0.1, 1.0, N + 1) for k in ("B", "eta", "cn", "ct", "kn", "kt")}
    wind = rng.standard_normal(3)
    return rng, h, m, e, u, prof, wind


@pytest.mark.parametrize("seed", range(4))
def test_accelerations_with_a_body_match_a_dense_kkt_solve(seed):
    N = 6
    rng, h, m, e, u, prof, wind = _random_case(seed, N)
    gvec = rng.standard_normal(3)
    acc = rng.standard_normal(3)
    cd = 0.3
    body = Body(prof["B"], damping=prof["eta"], drag_normal=prof["cn"], drag_tangential=prof["ct"],
                drag_linear_normal=prof["kn"], drag_linear_tangential=prof["kt"], wind=wind, tip_drag=cd)
    t = 0.7
    par, hh, invm = C.make_model(h, 1.0 / m, g=gvec, pin=(C.PIN_PULL, acc, 0.2, 5.0),
                                 body={"arrays": body.node_arrays(h), "wind": body.wind, "tip_drag": cd})
    p = C.pin3d(t, par)
    y = np.concatenate([e.T.ravel(), u.T.ravel(), [0.3, 0.1]])
    r, v = C.state_to_nodes(y, h, pin=np.array(p[:6]))
    ref = Cartesian3D(h, m, gvec, prof["B"], prof["eta"], prof["cn"], prof["ct"], prof["kn"], prof["kt"], wind,
                      cd)
    a, p_held, dD, dE = ref.solve(r, v, np.array(p[6:9]))
    f = np.zeros_like(y)
    w = C.Work(N)
    C.rhs3d(N, t, y, f, w.T, w.cp, w.dp, par, hh, invm)
    edd = np.diff(a, axis=0) / h[:, None]
    scale = np.abs(edd).max() + 1.0
    np.testing.assert_allclose(f[3 * N:6 * N].reshape(3, N).T, edd, rtol=0, atol=1e-11 * scale)
    assert f[6 * N] == pytest.approx(p_held, rel=1e-10, abs=1e-12)
    assert f[6 * N + 1] == pytest.approx(dD, rel=1e-10, abs=1e-12)
    # the balance the run integrates: d(K + P + Vb)/dt = W' - D' (a finite difference of Vb: 1e-9)
    assert dE == pytest.approx(f[6 * N] - f[6 * N + 1], rel=1e-7, abs=1e-8)
    assert abs(dD) > 0.1 and abs(p_held) > 0.01  # (every term at work)


def test_bending_forces_vanish_on_a_straight_node_and_are_bounded_folded_back():
    """Through a straight node the force is continuous (psi/s -> 1); folded back exactly it
    is left out (a cone point of the energy), and nearby it is bounded by B pi/l."""
    N = 3
    h = np.ones(N)
    arrays = Body(1.0).node_arrays(h)
    par, hh, invm = C.make_model(h, np.ones(N), g=(0.0, 0.0, 0.0), body={"arrays": arrays})
    f = np.zeros(6 * N + 2)
    w = C.Work(N)
    for delta in (0.0, 1e-12, 1e-6):
        e = np.array([[0.0, 1.0, 0.0], [math.sin(delta), math.cos(delta), 0.0], [0.0, 1.0, 0.0]])
        y = np.concatenate([e.T.ravel(), np.zeros(3 * N), [0.0, 0.0]])
        C.rhs3d(N, 0.0, y, f, w.T, w.cp, w.dp, par, hh, invm)
        assert np.all(np.isfinite(f))
        assert np.abs(f[3 * N:6 * N]).max() < 10 * delta + 1e-15  # (restoring force ~ B delta)


# ---------------------------------------------------------------- planar problems stay planar
@pytest.mark.parametrize("curved", [False, True])
def test_planar_body_run_in_space_gives_the_planar_peaks(curved):
    body = Body(1e-3, damping=1e-4, drag_normal=0.5, drag_tangential=0.05, drag_linear_normal=0.1, wind=(0.2, -0.1),
                tip_drag=0.01, curvature=0.8 if curved else 0.0)
    prob = Problem.catenary(0.3, 16, body=body, pin=PinMotion.pull((0.4, -0.2), duration=0.2))
    ds = run(problem=prob, method="dop853", tol=1e-12).dataset
    res = run3d(Problem3D.from_planar(prob), tol=1e-12)
    for q in ("v", "a", "sigma"):  # (measured <= 4.5e-11; at tol 1e-11 <= 1.6e-10: each method's own error)
        assert res[f"{q}_peak"] == pytest.approx(float(ds.attrs[f"{q}_peak"]), rel=1e-10, abs=0)
        assert res[f"t_snap_{q}"] == pytest.approx(float(ds.attrs[f"t_snap_{q}"]), rel=0, abs=3e-8)
    assert res["z_amp_max"] == 0.0 and res["vz_amp_max"] == 0.0
    N = res["N"]
    assert np.all(res["state"][2 * N:3 * N] == 0.0) and np.all(res["state"][5 * N:6 * N] == 0.0)
    names = res["record_names"]
    Vb = res["record"][:, names.index("bending_energy")]
    D = res["record"][:, names.index("dissipated")]
    assert Vb.max() > 1e-4 and D[-1] > 1e-3
    assert Vb[0] == pytest.approx(float(ds["bending_energy"].values[0]), rel=1e-12)  # (the start's: the same energy)


# ---------------------------------------------------------------- conservation in space
def _swung(body, N=14, pin=None):
    p = Problem3D.catenary(0.4, N).perturbed(0.8)
    return dataclasses.replace(p, body=body, **({} if pin is None else {"pin": pin}))


def test_energy_balance_of_a_3d_run_with_bending_damping_drag_and_wind():
    body = Body(2e-3, damping=2e-4, drag_normal=0.4, drag_tangential=0.04, drag_linear_tangential=0.05,
                wind=(0.1, 0.0, -0.3), tip_drag=0.02)
    prob = _swung(body, pin=Pin3D("flick", (0.5, -1.0, 0.8), 0.05, 0.3))
    res = run3d(prob, tol=1e-11, t_end=0.8)
    names = res["record_names"]
    D = res["record"][:, names.index("dissipated")]
    assert D[-1] > 0.01 and res["z_amp_max"] > 0.1
    assert res["energy_drift"] < 1e-10  # (measured ~1e-13)
    loose = run3d(prob, tol=1e-7, t_end=0.8)
    assert loose["energy_drift"] > 10 * res["energy_drift"]


def test_vertical_angular_momentum_is_conserved_with_bending_and_damping():
    res = run3d(_swung(Body(2e-3, damping=5e-4)), tol=1e-11, t_end=0.8)
    names = res["record_names"]
    Lg = res["record"][:, names.index("angular_momentum_g")]
    assert abs(Lg[0]) > 0.05
    assert res["angular_momentum_drift"] < 1e-11  # (measured ~1e-14)
    assert res["energy_drift"] < 1e-10
    assert res["record"][-1, names.index("dissipated")] > 1e-4


def test_vanishing_bending_gives_the_bodyless_run():
    bare = run3d(_swung(None), tol=1e-12, t_end=0.6)
    same = run3d(_swung(Body(0.0)), tol=1e-12, t_end=0.6)  # (an inactive body: the same run, bit for bit)
    assert np.array_equal(bare["record"], same["record"]) and np.array_equal(bare["state"], same["state"])
    d = []
    for B in (1e-9, 1e-10):
        res = run3d(_swung(Body(B)), tol=1e-12, t_end=0.6)
        d.append(np.abs(res["state"][:6 * res["N"]] - bare["state"][:6 * bare["N"]]).max())
    # O(B): measured 7.6e-6 and 7.6e-7 (and 7.6e-3 at B = 1e-6: linear over four decades)
    assert 5e-6 < d[0] < 1e-5 and 9.5 < d[0] / d[1] < 10.5


# ---------------------------------------------------------------- bad input
def test_bad_body_input_is_named():
    p = Problem3D.catenary(0.3, 8)
    with pytest.raises(SnappingInputError, match="clamp"):
        dataclasses.replace(p, body=Body(1e-3, clamp=1.0))
    with pytest.raises(SnappingInputError, match="curvature.*material frame.*v leave"):
        dataclasses.replace(p.perturbed(1e-3), body=Body(1e-3, curvature=1.0))
    dataclasses.replace(p, body=Body(1e-3, curvature=1.0))  # (planar: accepted)
    with pytest.raises(SnappingInputError, match="wind"):
        Body(wind=(1.0, 2.0, 3.0, 4.0))
    with pytest.raises(SnappingInputError, match="wind.*out of the plane"):
        Problem.catenary(0.3, 8, body=Body(drag_normal=1.0, wind=(0.0, 0.0, 1.0)))
    with pytest.raises(SnappingInputError, match="body=str"):
        dataclasses.replace(p, body="stiff")


def test_body_run_dataset_has_the_planar_body_names():
    from snapping.spatial.dataset3d import run3d_dataset

    prob = _swung(Body(1e-3, drag_normal=0.3, wind=(0.0, 0.0, 0.2)), N=8)
    ds = run3d_dataset(prob, tol=1e-8, t_end=0.3)
    assert {"bending_energy", "dissipated"} <= set(ds.data_vars)
    assert '"wind": [0.0, 0.0, 0.2]' in ds.attrs["body"]
    bal = ds["energy"] - ds["pin_work"] + ds["dissipated"]
    assert float(abs(bal - bal[0]).max()) < 1e-7


def test_a_stiff_3d_run_warns_and_a_hopeless_one_is_refused_before_any_work():
    from snapping.simulate.stiffness import CostWarning, shortest_wave
    from snapping.spatial.stiffness3d import check_cost3d, shortest_wave3d

    planar = Problem.catenary(0.25, 40, body=Body(1e7, damping=1e-6))
    assert shortest_wave3d(Problem3D.from_planar(planar)) == shortest_wave(planar.model())  # (the planar wave)
    with pytest.warns(CostWarning, match="no stiff method in space"):
        check_cost3d(Problem3D.from_planar(planar))  # (omega_max ~ 4 N^2 sqrt(beta) = 2e7: ~4e6 steps to t = 1.2)
    with pytest.raises(SnappingInputError, match="refused above"):
        run3d(Problem3D.catenary(0.25, 400, body=Body(1e8)))
    check_cost3d(Problem3D.from_planar(planar), t_end=1e-3)  # (a short run is not warned about)


def test_cli_runs_a_3d_body_with_a_3d_wind(capsys):
    from snapping.cli import main

    argv = ["simulate", "--dims", "3", "--chi", "0.3", "--N", "10", "--bending", "1e-3", "--drag-normal", "0.5",
            "--wind", "0.1,0,0.3", "--t-end", "0.4", "--json"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert '"wind": [' in out and '"dissipated"' in out
    assert main(["simulate", "--chi", "0.3", "--N", "10", "--drag-normal", "0.5", "--wind", "0.1,0,0.3"]) == 2
    assert "out of the plane" in capsys.readouterr().err
