"""Bending stiffness and air drag on the exact chain (issue 21): the node-force equations
(:mod:`snapping.simulate.forced`) against an independent dense Cartesian solve, the bending
forces against the gradient of the bending energy, a clamped cantilever against beam
theory, the energy balance of a drag run, the terminal velocity of a falling line, and the
bit-for-bit identity of runs without a body."""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.simulate import Body, Links, PinMotion, Problem, run
from snapping.simulate import forced as FR
from snapping.simulate import general as G

RNG = np.random.default_rng(21)


# ---------------------------------------------------------------- an independent Cartesian model
def _turn(a, b):
    """Turning angle from vector a to vector b, and its gradients with respect to a and b."""
    ang = math.atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1])
    ga = np.array([a[1], -a[0]]) / (a @ a)
    gb = np.array([-b[1], b[0]]) / (b @ b)
    return ang, ga, gb


class Cartesian:
    """The chain as N free point masses (node N prescribed) with bending, damping and drag
    written from node positions and velocities (no link angles), solved with the link-length
    constraints by a dense KKT system."""

    def __init__(self, h, m, g, B, k0, eta, cn, ct, kn, kt, wind, cd, clamp_dir=None):
        self.h, self.m, self.g = h, m, g
        self.B, self.k0, self.eta = B, k0, eta
        self.cn, self.ct, self.kn, self.kt, self.wind, self.cd = cn, ct, kn, kt, np.asarray(wind), cd
        self.clamp_dir = clamp_dir  # callable t -> (phi, phi') (a link angle), or None
        N = h.size
        self.l = np.zeros(N + 1)
        self.l[0] = h[0] / 2
        self.l[1:N] = (h[:-1] + h[1:]) / 2
        self.l[N] = h[-1] / 2

    def nodes(self, th, om, pin):
        N = self.h.size
        r = np.zeros((N + 1, 2))
        v = np.zeros((N + 1, 2))
        r[N], v[N] = pin[0:2], pin[2:4]
        for j in range(N - 1, -1, -1):
            t = np.array([math.cos(th[j]), math.sin(th[j])])
            n = np.array([-t[1], t[0]])
            r[j] = r[j + 1] - self.h[j] * t
            v[j] = v[j + 1] - self.h[j] * om[j] * n
        return r, v

    def _turns(self, r, v, t):
        """(node, angle, rate, {node: gradient}) of every bending term."""
        N = self.h.size
        out = []
        for i in range(1, N + 1):
            if i == N and self.clamp_dir is None:
                break
            a, da = r[i] - r[i - 1], v[i] - v[i - 1]
            if i < N:
                b, db = r[i + 1] - r[i], v[i + 1] - v[i]
            else:
                phi, phid = self.clamp_dir(t)
                b = np.array([math.cos(phi), math.sin(phi)])
                db = phid * np.array([-b[1], b[0]])
            ang, ga, gb = _turn(a, b)
            rate = ga @ da + gb @ db
            grads = {i - 1: -ga, i: ga.copy()}
            if i < N:
                grads[i] = grads[i] - gb
                grads[i + 1] = gb
            out.append((i, ang, rate, grads, (phid if i == N else 0.0)))
        return out

    def bending_energy(self, r, t):
        return sum(self.B[i] * (ang - self.k0[i] * self.l[i]) ** 2 / (2 * self.l[i])
                   for i, ang, _, _, _ in self._turns(r, np.zeros_like(r), t))

    def forces(self, r, v, t):
        """Bending + damping + drag forces on nodes 0..N, and the energy rates
        (dV/dt, dissipation rate, drag power)."""
        N = self.h.size
        F = np.zeros((N + 1, 2))
        dV = 0.0
        diss = 0.0
        for i, ang, rate, grads, phid in self._turns(r, v, t):
            M = self.B[i] * (ang - self.k0[i] * self.l[i]) / self.l[i]
            Md = self.eta[i] * rate / self.l[i]
            for k, gk in grads.items():
                F[k] -= (M + Md) * gk
                dV += M * gk @ v[k]
            dV += M * phid  # (the clamp's rotation changes the turning angle too)
            diss += self.eta[i] * rate ** 2 / self.l[i]
        pdrag = 0.0
        for j in range(N):
            d1 = r[j + 1] - r[j]
            tau = d1 / np.linalg.norm(d1)
            if j > 0:
                d0 = r[j] - r[j - 1]
                bis = tau + d0 / np.linalg.norm(d0)
                tau = bis / np.linalg.norm(bis)
            u = v[j] - self.wind
            ut = (u @ tau) * tau
            un = u - ut
            f = (-self.cn[j] * self.l[j] * np.linalg.norm(un) * un - self.ct[j] * self.l[j] * np.linalg.norm(ut) * ut
                 - self.kn[j] * self.l[j] * un - self.kt[j] * self.l[j] * ut)
            if j == 0:
                f = f - self.cd * np.linalg.norm(u) * u
            F[j] += f
            pdrag += f @ v[j]
        return F, dV, diss, pdrag

    def accelerations(self, th, om, t, pin):
        """theta'', and the rates W' (held end's power) and D' (dissipation) of the energy balance."""
        N = self.h.size
        r, v = self.nodes(th, om, pin)
        A = np.asarray(pin[4:6])
        F, dV, diss, pdrag = self.forces(r, v, t)
        n = 2 * N
        Mm = np.diag(np.repeat(self.m, 2))
        J = np.zeros((N, n))
        b = np.zeros(N)
        for j in range(N):
            d = r[j + 1] - r[j]
            dd = v[j + 1] - v[j]
            J[j, 2 * j:2 * j + 2] = -d
            if j + 1 < N:
                J[j, 2 * j + 2:2 * j + 4] = d
            else:
                b[j] -= d @ A
            b[j] -= dd @ dd
        rhs = F[:N].ravel() + np.repeat(self.m, 2) * np.tile([0.0, self.g], N)
        K = np.block([[Mm, -J.T], [J, np.zeros((N, N))]])
        sol = np.linalg.solve(K, np.concatenate([rhs, b]))
        a = np.vstack([sol[:n].reshape(N, 2), A])
        acc = np.array([((a[j + 1] - a[j]) @ np.array([-math.sin(th[j]), math.cos(th[j])])) / self.h[j]
                        for j in range(N)])
        dK = sum(self.m[j] * v[j] @ a[j] for j in range(N))
        dP = -self.g * sum(self.m[j] * v[j, 1] for j in range(N))
        D = diss - pdrag
        self.last = {"a": a, "pin_force": sol[n + N - 1] * (r[N] - r[N - 1]) + F[N], "r": r, "v": v}
        return acc, dK + dP + dV + D, D


def _measure(mdl, y, t):
    """The kernel's per-step diagnostics (meas) and position-form state Z at (t, y)."""
    from snapping.simulate import kernels as K

    par, h, invm, invh, snode, tab = mdl
    N = h.size
    tab = tab.copy()
    w = G.Work(N)
    f = np.empty(2 * N + 2)
    FR.forced_rhs(N, t, y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, par, h, invm, invh, snode, tab)
    Z = np.zeros((K.NROWS, N + 1))
    meas = np.zeros(FR.NMEAS_B)
    FR.forced_measure(N, t, y, w.c, w.s, w.sig, Z, np.zeros(N), meas, par, h, invm, invh, snode, tab)
    assert (K.RAX, K.RAY, K.M_PFX, K.M_PFY, K.M_ENERGY) == (4, 5, 9, 10, 11)
    return Z, meas


def _random_case(N, clamped, moving_clamp):
    h = RNG.uniform(0.5, 1.5, N)
    h /= h.sum()
    m = RNG.uniform(0.5, 1.5, N) / N
    m[0] += 0.3  # a tip mass
    g = 1.0
    node = lambda lo, hi: RNG.uniform(lo, hi, N + 1)  # noqa: E731
    B, k0, eta = node(1e-3, 1e-2), node(-2.0, 2.0), node(1e-4, 1e-3)
    cn, ct, kn, kt = node(0.5, 2.0), node(0.01, 0.1), node(0.0, 0.3), node(0.0, 0.1)
    wind = RNG.uniform(-0.5, 0.5, 2)
    cd = 0.7
    clamp = None
    if clamped:
        clamp = (np.linspace(0.0, 2.0, 9), 0.3 + 0.4 * np.sin(np.linspace(0.0, 2.0, 9))) if moving_clamp else 0.8
    body = Body(bending=B, curvature=k0, damping=eta, drag_normal=cn, drag_tangential=ct, drag_linear_normal=kn,
                drag_linear_tangential=kt, wind=wind, tip_drag=cd, clamp=clamp)
    ax, ay, t0 = 0.7, -0.4, 0.1
    mdl0 = G.make_model(h, 1.0 / m, g=g, pin=(G.PIN_PULL, ax, ay, t0, math.inf))
    # angles: a smooth random curve, turning less than pi at every node
    th = np.cumsum(RNG.uniform(-0.8, 0.8, N)) + RNG.uniform(0, 2 * math.pi)
    om = RNG.normal(0.0, 2.0, N)
    mdl = body.model(mdl0, h, float(th[-1]))
    t = 0.37
    tau = t - t0
    pin = np.array([ax * tau * tau / 2, ay * tau * tau / 2, ax * tau, ay * tau, ax, ay])
    clamp_dir = None
    if clamped:
        def clamp_dir(tt):
            return FR.clamp_angle(tt, mdl[0], mdl[-1])  # (phi, phi'), checked against the spline below

        if moving_clamp:
            from scipy.interpolate import CubicSpline

            sp = CubicSpline(*body.clamp, bc_type="clamped")
            phi, phid = FR.clamp_angle(t, mdl[0], mdl[-1])
            wrap = (phi - (float(sp(t)) + math.pi)) / (2 * math.pi)
            assert abs(wrap - round(wrap)) < 1e-12 and abs(phid - float(sp(t, 1))) < 1e-12
        # the clamp's link angle is the held link's direction within pi
        assert abs(clamp_dir(t)[0] - th[-1]) < math.pi + 1.0
    cart = Cartesian(h, m, g, body.node_values("bending", h), body.node_values("curvature", h),
                     body.node_values("damping", h), cn, ct, kn, kt, wind, cd, clamp_dir)
    return mdl, th, om, t, pin, cart


@pytest.mark.parametrize("N,clamped,moving", [(1, True, True), (2, False, False), (7, False, False),
                                              (7, True, False), (9, True, True)])
def test_accelerations_against_dense_cartesian_solve(N, clamped, moving):
    for _ in range(3):
        mdl, th, om, t, pin, cart = _random_case(N, clamped, moving)
        y = np.concatenate([th, om, [0.0, 0.0]])
        f = FR.evaluate_rhs(t, y, mdl)
        acc, dW, dD = cart.accelerations(th, om, t, pin)
        scale = 1.0 + np.abs(acc).max()
        assert np.abs(f[:N] - om).max() == 0.0
        assert np.abs(f[N:2 * N] - acc).max() < 1e-10 * scale
        assert abs(f[2 * N + 1] - dD) < 1e-10 * (1.0 + abs(dD))
        assert abs(f[2 * N] - dW) < 1e-9 * (1.0 + abs(dW))
        # the recorded diagnostics: node accelerations (with the node forces), the force of the
        # chain on the held end (tension and the held link's bending couple), the energy
        Z, meas = _measure(mdl, y, t)
        a = cart.last["a"]
        assert np.abs(Z[4, :N] - a[:N, 0]).max() < 1e-10 * scale and np.abs(Z[5, :N] - a[:N, 1]).max() < 1e-10 * scale
        pf = cart.last["pin_force"]
        assert abs(meas[9] - pf[0]) < 1e-10 * scale and abs(meas[10] - pf[1]) < 1e-10 * scale
        r, v = cart.last["r"], cart.last["v"]
        e = (0.5 * np.sum(cart.m * np.sum(v[:N] ** 2, axis=1)) - cart.g * np.sum(cart.m * r[:N, 1])
             + cart.bending_energy(r, t) + mdl[0][G.P_EOFF])
        assert abs(meas[11] - e) < 1e-12 * (1 + abs(e)) and meas[FR.M_BEND] == pytest.approx(cart.bending_energy(r, t))


# ---------------------------------------------------------------- the bending forces are -grad V_b
def _generalised_forces(mdl, y, t=0.0):
    """Q_j = sum_k F_k . dr_k/dtheta_j of the kernel's node forces (dr_k/dtheta_j = -h_j n_j, k <= j)."""
    par, h, invm, invh, snode, tab = mdl
    N = h.size
    tab = tab.copy()
    c, s = np.cos(y[:N]), np.sin(y[:N])
    FR.node_forces(N, t, y, c, s, par, h, invh, tab, 0.0, 0.0)
    o, n1 = int(par[FR.P_BOFF]), N + 1
    FX, FY = tab[o + FR.B_FX * n1:o + FR.B_FX * n1 + N], tab[o + FR.B_FY * n1:o + FR.B_FY * n1 + N]
    cx, cy = np.cumsum(FX), np.cumsum(FY)
    return -h * (-s * cx + c * cy)


@pytest.mark.parametrize("clamped", [False, True])
def test_bending_forces_are_minus_the_gradient_of_the_energy(clamped):
    N = 8
    h = RNG.uniform(0.5, 1.5, N)
    h /= h.sum()
    m = np.full(N, 1.0 / N)
    body = Body(bending=RNG.uniform(1e-3, 1e-2, N + 1), curvature=RNG.uniform(-1, 1, N + 1),
                clamp=0.4 if clamped else None)
    th = np.cumsum(RNG.uniform(-0.6, 0.6, N)) + 1.0
    mdl = body.model(G.make_model(h, 1.0 / m), h, float(th[-1]))
    cart = Cartesian(h, m, 1.0, body.node_values("bending", h), body.node_values("curvature", h), np.zeros(N + 1),
                     *(np.zeros(N + 1),) * 4, (0.0, 0.0), 0.0,
                     (lambda t: FR.clamp_angle(t, mdl[0], mdl[-1])) if clamped else None)
    y = np.concatenate([th, np.zeros(N), [0.0, 0.0]])
    Q = _generalised_forces(mdl, y)

    def V(theta):
        r, _ = cart.nodes(theta, np.zeros(N), np.zeros(6))
        return cart.bending_energy(r, 0.0)

    eps = 1e-6
    grad = np.array([(V(th + eps * e) - V(th - eps * e)) / (2 * eps) for e in np.eye(N)])
    assert np.abs(Q + grad).max() < 1e-7 * np.abs(grad).max()
    # and the kernel's reported bending energy is the same V_b
    from snapping.simulate import force_bending as FB

    par, tab = mdl[0], mdl[-1]
    o, n1 = int(par[FR.P_BOFF]), N + 1
    vb = FB.bending_energy(N, y, tab[o:o + n1], tab[o + n1:o + 2 * n1], clamped, FR.clamp_angle(0.0, par, tab)[0])
    assert abs(vb - V(th)) < 1e-14 * max(1.0, V(th))


# ---------------------------------------------------------------- B = 0, no drag: today's runs bit for bit
def test_inactive_body_gives_todays_runs_bit_for_bit():
    assert not Body().active and not Body(curvature=3.0, wind=(1.0, 0.0)).active
    p = Problem.catenary(0.4, 12, body=Body())
    assert p.body is None and p.is_paper
    a, b = run(0.4, 12, progress=False).dataset, run(p, progress=False).dataset
    for k in ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "t_snap_v", "n_steps"):
        assert a.attrs[k] == b.attrs[k]
    assert bool((a.v_max == b.v_max).all())
    links = Links.taper(12, 0.3)
    pin = PinMotion.flick((0.5, 0.0), 0.3)
    a = run(Problem.catenary(0.4, links=links, pin=pin), t_end=0.4, progress=False).dataset
    b = run(Problem.catenary(0.4, links=links, pin=pin, body=Body(wind=(0.2, 0.0))), t_end=0.4,
            progress=False).dataset
    assert "bending_energy" not in b and "body" not in b.attrs
    for k in ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "n_steps"):
        assert a.attrs[k] == b.attrs[k]
    assert bool((a.energy == b.energy).all())


# ---------------------------------------------------------------- static: the clamped cantilever
def test_clamped_cantilever_tip_deflection_converges_to_beam_theory():
    """A horizontal cantilever (clamped straight out, alpha = 0) under its own weight q = 1 with
    a large stiffness (small deflection): the static equilibrium of the discrete chain (theta''
    = 0 at rest, solved from the kernel) has the tip deflection q L^4/(8 B) to O(1/N^2)."""
    from scipy.optimize import root

    B = 1000.0
    errs = []
    Ns = (5, 10, 20)
    for N in Ns:
        links = Links.uniform(N, lumping="shared")
        h = links.h
        mdl = Body(bending=B, clamp=0.0).model(G.make_model(h, 1.0 / links.m), h, math.pi)

        def F(th):
            return FR.evaluate_rhs(0.0, np.concatenate([th, np.zeros(N), [0.0, 0.0]]), mdl)[N:2 * N]

        th = root(F, np.full(N, math.pi), method="hybr", tol=1e-14).x
        assert np.abs(F(th)).max() < 1e-9 * B * N ** 3
        tip = -float(np.sum(h * np.sin(th)))  # (y downward)
        errs.append(tip / (1.0 / (8.0 * B)) - 1.0)
    errs = np.abs(errs)
    assert errs[-1] < 3e-3
    orders = np.log2(errs[:-1] / errs[1:])
    assert np.all(np.abs(orders - 2.0) < 0.05), orders


# ---------------------------------------------------------------- dynamic: drag
def test_line_falling_broadside_follows_the_quadratic_drag_fall():
    """A straight horizontal line whose held end falls as a body of the same mass per drag,
    y(t) = (v_t^2/g) ln cosh(g t/v_t): with drag c_n l_j |v|^2 on every node (shared lumping:
    m_j = l_j) each node falls the same way, so the line stays straight, slack and level and
    its free end reaches the terminal speed v_t = sqrt(m g/(c_n L)) = 1/sqrt(c_n)."""
    cn = 4.0
    vt = 1.0 / math.sqrt(cn)
    T = 3.0
    ts = np.linspace(0.0, T, 601)
    pin = PinMotion.from_table(ts, np.zeros_like(ts), vt ** 2 * np.log(np.cosh(ts / vt)))
    N = 10
    x = np.linspace(1.0, 0.0, N + 1)
    p = Problem.nodes(x, np.zeros(N + 1), links=Links.uniform(N, lumping="shared"), pin=pin,
                      body=Body(drag_normal=cn, drag_tangential=0.3))
    ds = run(p, t_end=T, tol=1e-10, progress=False).dataset
    v_exact = vt * np.tanh(ds.t.values / vt)
    assert np.abs(ds.v_end.values - v_exact).max() < 1e-6
    assert abs(float(ds.v_end[-1]) - vt) < 1e-4 * vt
    fin = ds.isel(snapshot=-1)
    assert float(np.ptp(fin.y.values)) < 1e-7
    # without drag the same held end drags a line that falls faster than it (and hangs from it)
    q = Problem.nodes(x, np.zeros(N + 1), links=Links.uniform(N, lumping="shared"), pin=pin)
    ds0 = run(q, t_end=1.0, progress=False).dataset
    assert float(np.ptp(ds0.isel(snapshot=-1).y.values)) > 0.1


def test_energy_balance_of_a_run_with_bending_damping_drag_wind_and_a_moving_clamp():
    t = np.linspace(0.0, 0.6, 7)
    body = Body(bending=2e-3, damping=1e-4, drag_normal=1.0, drag_tangential=0.05, drag_linear_normal=0.1,
                wind=(0.3, -0.1), tip_drag=0.5, clamp=(t, 0.3 * np.sin(5 * t)))
    p = Problem.catenary(0.3, links=Links.uniform(24, lumping="shared"), pin=PinMotion.flick((0.8, -0.3), 0.4),
                         body=body)
    ds = run(p, t_end=1.0, tol=1e-9, progress=False).dataset
    bal = ds.energy - ds.pin_work + ds.dissipated
    drift = float(np.abs(bal - bal[0]).max())
    D = float(ds.dissipated[-1])
    assert D > 0.05 and float(ds.bending_energy.max()) > 1e-3 and float(np.abs(ds.pin_work).max()) > 0.005
    assert drift < 1e-7 and drift == pytest.approx(ds.attrs["energy_drift"], rel=1e-6, abs=1e-15)
    # the stepper's check is on the balance: a bound below the dissipated energy is not hit
    run(p, t_end=1.0, tol=1e-9, max_energy_drift=1e-6, progress=False)


# ---------------------------------------------------------------- bad input, before any work
@pytest.mark.parametrize("kw, name", [
    ({"bending": -1.0}, "bending="), ({"bending": math.nan}, "bending="), ({"bending": math.inf}, "bending="),
    ({"bending": [1.0, -1.0, 0.0]}, "bending[1]="), ({"damping": -1e-3}, "damping="),
    ({"drag_normal": -2.0}, "drag_normal="), ({"drag_tangential": math.inf}, "drag_tangential="),
    ({"drag_linear_normal": -1.0}, "drag_linear_normal="), ({"drag_linear_tangential": math.nan},
                                                              "drag_linear_tangential="),
    ({"curvature": math.nan}, "curvature="), ({"tip_drag": -0.1}, "tip_drag="), ({"wind": 1.0}, "wind="),
    ({"wind": (1.0, 2.0, 3.0, 4.0)}, "wind="), ({"wind": (math.nan, 0.0)}, "wind="), ({"clamp": 0.3}, "clamp="),
    ({"bending": 1e-3, "clamp": math.inf}, "clamp="), ({"bending": 1e-3, "clamp": ([0.5, 1.0], [0.0, 0.1])}, "clamp"),
    ({"bending": [[1.0]]}, "bending"),
])
def test_bad_body_is_refused_naming_the_parameter(kw, name):
    with pytest.raises(SnappingInputError) as exc:
        Body(**kw)
    msg = str(exc.value)
    assert name in msg and "\n" not in msg


def test_per_node_profiles_are_checked_against_the_chain():
    with pytest.raises(SnappingInputError, match=r"curvature has 3 entries; the chain has 11 nodes"):
        Problem.catenary(0.3, 10, body=Body(bending=1e-3, curvature=[0.0, 1.0, 2.0]))
    with pytest.raises(SnappingInputError, match=r"bending\(s\) failed"):
        Problem.catenary(0.3, 10, body=Body(bending=lambda s: 1 / 0))
    with pytest.raises(SnappingInputError, match=r"bending\[6\]=-1.0 is out of range"):  # (node 6: s = 0.4)
        Problem.catenary(0.3, 10, body=Body(bending=lambda s: -1.0 if s < 0.45 else 1.0))
    with pytest.raises(SnappingInputError, match="stiffness at the held end"):
        Problem.catenary(0.3, 10, body=Body(bending=np.r_[np.ones(10), 0.0], clamp=0.0))
    with pytest.raises(SnappingInputError, match="body=str"):
        Problem.catenary(0.3, 10, body="stiff")
    # a taper profile is fine, and recorded with its node values
    p = Problem.catenary(0.3, 10, body=Body(bending=Body.taper_profile(1e-3, 0.1, 4)))
    d = p.describe()["body"]
    assert d["bending"]["function"].startswith("taper") and len(d["nodes"]["bending"]) == 11


@pytest.mark.parametrize("start", ["catenary", "equilibrium"])
def test_clamp_at_the_start_direction(start):
    p = Problem.catenary(0.3, 10, body=Body(bending=1e-3, clamp="start"), start=start)
    x, y = p.x, p.y
    assert p.body.clamp == math.atan2(y[-2] - y[-1], x[-2] - x[-1])
    assert math.pi / 4 < p.body.clamp < math.pi / 2  # (the catenary leaves the held end down and to the right)
    with pytest.raises(SnappingInputError, match="clamp="):
        Body(clamp="start")
    with pytest.raises(SnappingInputError, match="clamp="):
        Body(bending=1.0, clamp="begin")


def test_euler_richardson_refuses_a_body_by_name():
    p = Problem.catenary(0.3, 10, body=Body(drag_normal=1.0))
    with pytest.raises(SnappingInputError, match="a body \\(bending stiffness, damping, drag"):
        run(p, method="euler-richardson", t_end=0.01)


def test_a_body_run_is_recorded_and_reruns_bit_for_bit(tmp_path):
    import json

    from snapping.simulate import rerun

    body = Body(bending=Body.taper_profile(2e-3, 0.2), curvature=0.5, drag_normal=1.0, wind=(0.2, 0.0), clamp=1.2)
    p = Problem.catenary(0.3, 12, body=body)
    r = run(p, t_end=0.3, progress=False, output=tmp_path / "b.nc")
    ds = r.dataset
    assert json.loads(ds.attrs["body"])["clamp"] == 1.2 and "body" in json.loads(ds.attrs["problem"])
    import xarray as xr

    back = xr.open_dataset(tmp_path / "b.nc").load()
    r2 = rerun(back, output=None)
    assert r2.dataset.attrs["v_peak"] == ds.attrs["v_peak"] and bool((r2.dataset.dissipated == ds.dissipated).all())


CLI_BAD = [("--bending", "-1"), ("--bending", "nan"), ("--bending", "1e308"), ("--bending-damping", "-1"),
           ("--drag-normal", "-2"), ("--drag-normal", "inf"), ("--drag-tangential", "abc"),
           ("--drag-linear", "1,2,3"), ("--drag-linear", "-1"), ("--wind", "1"), ("--wind", "1,2,3"),
           ("--wind", "nan,0"), ("--tip-drag", "-1"), ("--clamped", "0.3"), ("--clamped", "abc")]


@pytest.mark.parametrize("opt, value", CLI_BAD)
def test_cli_bad_body_option_is_one_line_exit_2(opt, value, capsys):
    from snapping.cli import main

    argv = ["simulate", "--chi", "0.3", "--N", "10", "--t-end", "1e-3", "--json", "--no-progress", opt, value]
    if opt == "--clamped" and value == "abc":
        argv += ["--bending", "1e-3"]
    try:
        status = main(argv)
    except SystemExit as exc:  # (argparse's own type errors)
        status = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and opt in err[-1] and "error" in err[-1], err


def test_cli_runs_a_body(capsys, tmp_path):
    import json

    from snapping.cli import main

    status = main(["simulate", "--chi", "0.3", "--N", "12", "--t-end", "0.2", "--json", "--no-progress", "--bending",
                   "1e-3", "--drag-normal", "1", "--drag-tangential", "0.05", "--drag-linear", "0.1,0.01", "--wind",
                   "0.3,0", "--tip-drag", "0.2", "--clamped", "-o", str(tmp_path / "c.nc")])
    out = json.loads(capsys.readouterr().out)
    assert status == 0 and out["status"] == "completed" and out["energy_drift"] < 1e-8
    import xarray as xr

    ds = xr.open_dataset(tmp_path / "c.nc")
    b = json.loads(ds.attrs["body"])
    assert b["drag_linear_tangential"] == 0.01 and b["wind"] == [0.3, 0.0] and b["clamp"] is not None
    x, y = ds.start_x.values, ds.start_y.values
    assert b["clamp"] == pytest.approx(math.atan2(y[-2] - y[-1], x[-2] - x[-1]), abs=1e-15)  # the start's direction
    ds.close()


# ---------------------------------------------------------------- small oscillations with bending
def test_small_oscillations_of_a_hanging_line_with_bending_against_an_eigen_solve():
    """Linearise the kernel about the line hanging straight down (finite differences of theta''
    in theta) and compare its frequencies with those of the Lagrangian written independently:
    mass matrix M_jk = h_j h_k sum_{i <= min(j,k)} m_i, stiffness diag(g h_k sum_{i<=k} m_i)
    (gravity) + D^T diag(B_i/l_i) D (bending, D the turning-angle difference operator)."""
    N = 12
    h = RNG.uniform(0.7, 1.3, N)
    h /= h.sum()
    m = RNG.uniform(0.7, 1.3, N) / N
    B = RNG.uniform(5e-3, 2e-2, N + 1)
    body = Body(bending=B)
    mdl = body.model(G.make_model(h, 1.0 / m), h, -math.pi / 2)
    th0 = np.full(N, -math.pi / 2)
    eps = 1e-6
    J = np.zeros((N, N))
    for k in range(N):
        e = np.zeros(N)
        e[k] = eps
        fp = FR.evaluate_rhs(0.0, np.concatenate([th0 + e, np.zeros(N), [0.0, 0.0]]), mdl)[N:2 * N]
        fm = FR.evaluate_rhs(0.0, np.concatenate([th0 - e, np.zeros(N), [0.0, 0.0]]), mdl)[N:2 * N]
        J[:, k] = (fp - fm) / (2 * eps)
    w_kernel = np.sort(np.sqrt(np.linalg.eigvals(-J).real))
    cm = np.cumsum(m)
    M = np.outer(h, h) * cm[np.minimum.outer(np.arange(N), np.arange(N))]
    l = (h[:-1] + h[1:]) / 2
    D = np.zeros((N - 1, N))
    D[np.arange(N - 1), np.arange(N - 1)] = -1.0
    D[np.arange(N - 1), np.arange(1, N)] = 1.0
    Kmat = np.diag(h * cm) + D.T @ np.diag(B[1:N] / l) @ D
    from scipy.linalg import eigh

    w_eigen = np.sqrt(eigh(Kmat, M, eigvals_only=True))
    assert np.abs(w_kernel / w_eigen - 1.0).max() < 1e-7
    # bending stiffens the line: every frequency above the chain's
    K0 = np.diag(h * cm)
    assert np.all(w_eigen > np.sqrt(eigh(K0, M, eigvals_only=True)))


def test_body_docstring_examples():
    import doctest

    from snapping.simulate import body

    assert doctest.testmod(body).failed == 0


def test_a_body_run_interrupted_resumes_bit_for_bit(tmp_path, monkeypatch):
    from snapping.simulate import RunInterrupted, resume
    from snapping.simulate import driver as stepper
    from snapping.simulate import rk as R
    from snapping.simulate.methods import dop853 as HO

    monkeypatch.setattr(HO, "NODE_EVALS_PER_CALL", R.NS * 20 * 5)
    p = Problem.catenary(0.3, 20, body=Body(bending=1e-3, damping=1e-4, drag_normal=1.0, clamp=1.0))
    kw = dict(t_end=0.6, tol=1e-8, progress=False)
    ref = run(p, **kw).dataset
    calls = []

    def hook(eng):
        calls.append(eng.t)
        return signal_int if len(calls) == 2 else None  # (chunks of 20 steps; the run from rest takes 48)

    import signal

    signal_int = signal.SIGINT
    monkeypatch.setattr(stepper, "_chunk_hook", hook)
    path = tmp_path / "r.nc"
    with pytest.raises(RunInterrupted):
        run(p, **kw, output=path, checkpoint_every=None)
    monkeypatch.setattr(stepper, "_chunk_hook", None)
    ds = resume(path).dataset
    for k in ("energy", "dissipated", "bending_energy", "v_max", "pin_work"):
        np.testing.assert_array_equal(ds[k].values, ref[k].values)
    assert ds.attrs["energy_drift"] == ref.attrs["energy_drift"]


def test_energy_bound_failure_names_the_balance():
    from snapping.simulate import EnergyDriftError

    p = Problem.catenary(0.3, 12, body=Body(bending=1e-3, drag_normal=1.0))
    with pytest.raises(EnergyDriftError, match=r"\|E - E0\| = [0-9.e+-]+ > max_energy_drift=1e-13") as exc:
        run(p, t_end=0.5, tol=1e-4, max_energy_drift=1e-13, progress=False)
    de = float(str(exc.value).split("|E - E0| = ")[1].split(" ")[0])
    assert de < 1e-6  # (the balance's drift, not the dissipated energy)


def test_small_oscillations_of_a_hanging_chain_without_bending_are_the_bessel_frequencies():
    """The frequencies of the hanging chain (no bending, consistent lumping) converge to
    (j_{0,n}/2) sqrt(g/L) (zeros of J0) at second order in 1/N."""
    from scipy.special import jn_zeros

    errs = []
    for N in (50, 100):
        links = Links.uniform(N, lumping="shared")
        mdl = G.make_model(links.h, 1.0 / links.m)
        th0 = np.full(N, -math.pi / 2)
        eps = 1e-7
        w = G.Work(N)
        f = np.empty(2 * N + 1)
        J = np.zeros((N, N))
        for k in range(N):
            cols = []
            for sgn in (1.0, -1.0):
                y = np.concatenate([th0, np.zeros(N), [0.0]])
                y[k] += sgn * eps
                G.general_rhs(N, 0.0, y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, *mdl)
                cols.append(f[N:2 * N].copy())
            J[:, k] = (cols[0] - cols[1]) / (2 * eps)
        wk = np.sort(np.sqrt(np.abs(np.linalg.eigvals(-J).real)))[:3]
        errs.append(np.abs(wk / (jn_zeros(0, 3) / 2) - 1.0))
    assert np.all(errs[1] < 2e-3)
    assert np.all(np.abs(np.log2(errs[0] / errs[1]) - 2.0) < 0.1)


def test_large_deflection_cantilever_converges_to_the_elastica():
    """A soft horizontal cantilever (B = 0.1, tip rotation ~60 degrees) against the heavy
    elastica B theta'' = -q (L - s) cos theta, theta(0) = 0, theta'(L) = 0, shot with scipy:
    the static chain's tip converges to the elastica's at second order."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq, root

    B = 0.1

    def rhs(s, z):
        return [z[1], -(1.0 - s) * math.cos(z[0]) / B, math.cos(z[0]), math.sin(z[0])]

    def shoot(k0):
        return solve_ivp(rhs, (0.0, 1.0), [0.0, k0, 0.0, 0.0], rtol=1e-12, atol=1e-13).y[:, -1]

    k0 = brentq(lambda k: shoot(k)[1], 0.1, 1.0 / (2.0 * B) + 1.0, xtol=1e-14)
    _, _, xe, ye = shoot(k0)
    assert 0.9 < shoot(k0)[0] < 1.2  # (a large deflection: the tip turns by about 60 degrees)
    errs = []
    for N in (10, 20, 40):
        links = Links.uniform(N, lumping="shared")
        h = links.h
        mdl = Body(bending=B, clamp=0.0).model(G.make_model(h, 1.0 / links.m), h, math.pi)

        def F(th):
            return FR.evaluate_rhs(0.0, np.concatenate([th, np.zeros(N), [0.0, 0.0]]), mdl)[N:2 * N]

        th = root(F, np.full(N, 3.0), method="hybr", tol=1e-13).x
        assert np.abs(F(th)).max() < 1e-8
        errs.append(math.hypot(-np.sum(h * np.cos(th)) - xe, -np.sum(h * np.sin(th)) - ye))
    assert errs[-1] < 5e-4
    assert np.all(np.abs(np.log2(np.array(errs[:-1]) / errs[1:]) - 2.0) < 0.05), errs


def test_a_damped_run_relaxes_to_the_static_cantilever():
    """Through run(): a straight horizontal line clamped at its held end (alpha = 0) released
    at rest, with bending damping and linear drag, sags and comes to rest at the static
    equilibrium of the same discrete chain (theta'' = 0 at rest, solved by root finding), and
    the energy it lost is what was dissipated."""
    from scipy.optimize import root

    N, B = 10, 0.1
    links = Links.uniform(N, lumping="shared")
    body = Body(bending=B, clamp=0.0, damping=0.01, drag_linear_normal=2.0)
    p = Problem.nodes(np.linspace(1.0, 0.0, N + 1), np.zeros(N + 1), links=links, body=body)
    ds = run(p, t_end=15.0, tol=1e-9, progress=False).dataset
    fin = ds.isel(snapshot=-1)
    mdl = p.model()

    def F(th):
        return FR.evaluate_rhs(0.0, np.concatenate([th, np.zeros(N), [0.0, 0.0]]), mdl)[N:2 * N]

    th = root(F, np.full(N, 3.0), method="hybr", tol=1e-13).x
    h = links.h
    tip = (-np.sum(h * np.cos(th)), -np.sum(h * np.sin(th)))
    assert float(fin.speed.max()) < 1e-6
    assert abs(float(fin.x[0]) - tip[0]) < 5e-7 and abs(float(fin.y[0]) - tip[1]) < 5e-7  # (measured 1e-7 at t = 15)
    lost = float(ds.energy[0] - ds.energy[-1])
    assert lost > 0.1 and abs(float(ds.dissipated[-1]) - lost) < 1e-9
