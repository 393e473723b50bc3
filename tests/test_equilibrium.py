"""The line at rest held at both ends (:mod:`snapping.simulate.equilibrium`), the start of a
line with bending: against the continuum heavy elastica (an independent boundary-value
solve with scipy's ``solve_bvp``, second order in the link length), against the dynamic
model (released, the line accelerates exactly as under the support's reaction reversed,
computed with a dense mass matrix), B -> 0 gives the catenary; the start's default and
its record; the automatic stop at a large bending number."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_bvp

from snapping._validate import SnappingInputError
from snapping.simulate import Body, Links, PinMotion, Problem, run
from snapping.simulate import forced as FR
from snapping.simulate.equilibrium import discrete_residual, hanging_equilibrium


# ---------------------------------------------------------------- the continuum heavy elastica
def elastica(B, X, Y, *, tip=0.0, kappa0=0.0, clamp=None, guess):
    """The heavy elastica of length 1, mass 1 (plus ``tip`` at the free end), g = 1, held at the
    origin (s = 0: hinged, or clamped leaving in the direction ``clamp``) and hinged at (X, Y):
    ``psi' = m/B - kappa0``, ``m' = -(Lambda(s) + mu_y) cos psi + mu_x sin psi``
    (Lambda: the mass beyond s), ``mu`` the support's force on the free end (parameters)."""
    def f(s, y, p):
        lam = (1.0 - s) + tip
        return np.vstack([np.cos(y[2]), np.sin(y[2]), y[3] / B - kappa0,
                          -(lam + p[1]) * np.cos(y[2]) + p[0] * np.sin(y[2])])

    def bc(a, b, p):
        first = a[3] if clamp is None else a[2] - clamp
        return np.array([a[0], a[1], first, b[3], b[0] - X, b[1] - Y])

    s = np.linspace(0.0, 1.0, 401)
    sg, xg, yg = guess
    y0 = np.vstack([np.interp(s, sg, xg), np.interp(s, sg, yg), np.zeros_like(s), np.zeros_like(s)])
    y0[2] = np.unwrap(np.arctan2(np.gradient(y0[1], s), np.gradient(y0[0], s)))
    sol = solve_bvp(f, bc, s, y0, p=[0.0, -0.5], tol=1e-10, max_nodes=100000)
    assert sol.success, sol.message
    return sol


def _node_s(links):
    return np.r_[np.cumsum(links.h[::-1])[::-1], 0.0]


@pytest.mark.parametrize("case", ["hinged", "clamped"])
def test_equilibrium_converges_to_the_heavy_elastica_at_second_order(case):
    X, Y = 0.25, 0.0
    kw = dict(B=1e-2) if case == "hinged" else dict(B=3e-2, tip=0.3, kappa0=0.5, clamp=1.2)
    errs, merrs, sol = [], [], None
    for N in (25, 50, 100, 200):
        links = Links.uniform(N, tip_mass=kw.get("tip", 0.0), lumping="shared")
        p = Problem.catenary(0.25, links=links, start="catenary")
        body = Body(kw["B"], curvature=kw.get("kappa0", 0.0), clamp=kw.get("clamp"))
        e = hanging_equilibrium(links, body, p.x, p.y, support=(X, Y))
        s = _node_s(links)
        if sol is None:  # (the guess picks the branch: the catenary's can lead solve_bvp to an arch standing up)
            g = (s[::-1], p.x[::-1], p.y[::-1]) if case == "hinged" else (s[::-1], e.x[::-1], e.y[::-1])
            sol = elastica(kw["B"], X, Y, tip=kw.get("tip", 0.0), kappa0=kw.get("kappa0", 0.0),
                           clamp=kw.get("clamp"), guess=g)
        xs, ys = sol.sol(s)[:2]
        errs.append(np.hypot(e.x - xs, e.y - ys).max())
        merrs.append(np.abs(e.reaction_free - sol.p).max())
    orders = np.log2(np.array(errs[:-1]) / errs[1:])
    morders = np.log2(np.array(merrs[:-1]) / merrs[1:])
    assert errs[-1] < 2e-4
    assert np.all(np.abs(orders - 2.0) < 0.1), orders
    assert np.all(np.abs(morders - 2.0) < 0.15), morders


# ---------------------------------------------------------------- released: the reaction alone
def _dense_angle_accelerations(links, theta, force0):
    """theta'' of the chain at rest (held end fixed) under a force ``force0`` on node 0 alone:
    M theta'' = J_0^T force0, ``M_kl = Mc_min(k,l) h_k h_l cos(theta_k - theta_l)``,
    ``dr_0/dtheta_k = -h_k n_k`` (dense; no gravity, no bending)."""
    h = links.h
    N = h.size
    Mc = np.cumsum(links.m)
    M = Mc[np.minimum.outer(np.arange(N), np.arange(N))] * np.outer(h, h) * np.cos(np.subtract.outer(theta, theta))
    J = -h[:, None] * np.stack([-np.sin(theta), np.cos(theta)], axis=1)
    return np.linalg.solve(M, J @ force0)


@pytest.mark.parametrize("body", [Body(1e-2), Body(3e-3, curvature=0.8, clamp=1.3),
                                  Body(Body.taper_profile(1e-2, 0.1, 4), clamp="start", drag_normal=1.0)])
def test_released_equilibrium_accelerates_as_the_reaction_reversed(body):
    links = Links.taper(30, 0.3, tip_mass=0.2)
    p = Problem.catenary(0.3, links=links, body=body, gravity=1.7)  # (the default start: the equilibrium)
    assert p.start["rest"] == "equilibrium"
    N = p.N
    cat = Problem.catenary(0.3, links=links, gravity=1.7)
    e = hanging_equilibrium(links, p.body, cat.x, cat.y, gravity=1.7)
    assert np.abs(e.x - p.x).max() < 1e-12 and np.abs(e.y - p.y).max() < 1e-12
    f = FR.evaluate_rhs(0.0, p.initial_angles(), p.model())  # the dynamic model, released
    acc = f[N:2 * N]
    ref = _dense_angle_accelerations(links, e.theta, -e.reaction_free)
    assert np.abs(acc - ref).max() < 1e-9 * np.abs(ref).max()
    # the held end's reaction balances the weight and the support's
    assert np.allclose(e.reaction_held + e.reaction_free + [0.0, 1.7 * links.m.sum()], 0.0, atol=1e-14)


def test_the_catenary_start_is_not_at_rest_with_bending():
    """(The check above fails for the catenary: its release is a jolt, not the reaction's pull.)"""
    links = Links.uniform(30)
    p = Problem.catenary(0.3, links=links, body=Body(1e-2), start="catenary")
    f = FR.evaluate_rhs(0.0, p.initial_angles(), p.model())
    e = hanging_equilibrium(links, p.body, p.x, p.y)
    ref = _dense_angle_accelerations(links, e.theta, -e.reaction_free)
    assert np.abs(f[30:60] - ref).max() > 10.0 * np.abs(ref).max()


def test_residual_vanishes_and_chords_are_exact():
    links = Links.taper(50, 0.2, lumping="shared")
    p = Problem.supports(0.4, 0.3, links=links, body=Body(2e-3, curvature=-0.3))
    th = np.unwrap(np.arctan2(np.diff(p.y), np.diff(p.x)))
    e = hanging_equilibrium(links, p.body, Problem.supports(0.4, 0.3, links=links).x,
                            Problem.supports(0.4, 0.3, links=links).y)
    G, c = discrete_residual(th, e.reaction_free, links, p.body, (p.x[0], p.y[0]))
    assert np.abs(G / links.h).max() < 1e-10 and np.abs(c).max() < 1e-14
    assert np.allclose(np.hypot(np.diff(p.x), np.diff(p.y)), links.h, rtol=0, atol=1e-14)


# ---------------------------------------------------------------- stable: a local minimum
def _dense_unstable(links, theta, mu, B, kappa0, clamp_link, g=1.0):
    """Negative eigenvalues of the Lagrangian's Hessian on the constraints' tangent space, dense:
    the energy written from node positions (turning angles by atan2), its Hessian by central
    differences, the tangent space from the SVD of the constraint Jacobian."""
    h, m = links.h, links.m
    N = h.size
    l = np.r_[0.0, 0.5 * (h[:-1] + h[1:]), 0.5 * h[-1]]

    def energy(th):
        d = h[:, None] * np.stack([np.cos(th), np.sin(th)], axis=1)
        r = -np.cumsum(d[::-1], axis=0)[::-1]  # nodes 0..N-1 (node N at the origin)
        v = -g * np.sum(m * r[:, 1])
        turn = np.arctan2(d[:-1, 0] * d[1:, 1] - d[:-1, 1] * d[1:, 0], np.sum(d[:-1] * d[1:], axis=1))
        v += np.sum(B / (2 * l[1:N]) * (turn - kappa0 * l[1:N]) ** 2)
        tc = math.remainder(clamp_link - th[-1], 2 * math.pi)
        return v + B / (2 * l[N]) * (tc - kappa0 * l[N]) ** 2 + mu @ np.sum(d, axis=0)

    e = 1e-4
    H = np.zeros((N, N))
    for i in range(N):
        for j in range(i, N):
            def f(a, b):
                t = theta.copy()
                t[i] += a
                t[j] += b
                return energy(t)
            H[i, j] = H[j, i] = (f(e, e) - f(e, -e) - f(-e, e) + f(-e, -e)) / (4 * e * e)
    C = np.stack([-h * np.sin(theta), h * np.cos(theta)], axis=1)
    Z = np.linalg.svd(C.T)[2][2:].T
    return int(np.sum(np.linalg.eigvalsh(Z.T @ H @ Z) < 0.0))


def test_the_rest_shape_is_stable_where_newton_alone_finds_an_arch():
    """Clamped at 1.2 rad with a natural curvature, Newton from the catenary converges to an
    arch standing up (unstable); the solver's answer is the hanging shape, a local minimum.
    The O(N) count of unstable directions agrees with a dense one on both."""
    from snapping.simulate import equilibrium as EQ

    links = Links.uniform(100)
    p = Problem.catenary(0.25, links=links, start="catenary")
    body = Body(3e-2, curvature=0.5, clamp=1.2)
    th0 = np.unwrap(np.arctan2(np.diff(p.y), np.diff(p.x)))
    h, Mc, Bl, K0L, phi, clamped = EQ._arrays(links, body, th0)
    G0, _ = EQ._gradient(th0, np.zeros(2), h, Mc, 1.0, Bl, K0L, phi, clamped)  # (mu: least squares, as the solver)
    mu0 = np.linalg.lstsq(np.stack([-np.sin(th0), np.cos(th0)], axis=1), -G0 / h, rcond=None)[0]
    arch, mu_a, r, _, ok = EQ._newton(th0.copy(), mu0, h, Mc, 1.0, Bl, K0L, phi, clamped, (p.x[0], p.y[0]),
                                      float(Mc[-1]), 1e-12, 60)
    e = hanging_equilibrium(links, body, p.x, p.y)
    assert ok and np.abs(arch - e.theta).max() > 0.5  # two equilibria
    n_arch = EQ.unstable_directions(arch, mu_a, h, Mc, 1.0, Bl)
    assert n_arch >= 1 and n_arch == _dense_unstable(links, arch, mu_a, 3e-2, 0.5, phi)
    assert EQ.unstable_directions(e.theta, e.reaction_free, h, Mc, 1.0, Bl) == 0
    assert _dense_unstable(links, e.theta, e.reaction_free, 3e-2, 0.5, phi) == 0
    assert e.y.max() > 0.3 > -np.sum(links.h * np.sin(arch))  # it hangs; the arch stands up


# ---------------------------------------------------------------- B -> 0: the catenary
def test_without_bending_the_equilibrium_is_the_catenary():
    errs = []
    for N in (50, 100, 200, 400):
        links = Links.uniform(N, lumping="shared")
        p = Problem.catenary(0.25, links=links)  # the continuum catenary's nodes (no body: bit for bit)
        e = hanging_equilibrium(links, None, p.x, p.y)
        errs.append(np.hypot(e.x - p.x, e.y - p.y).max())
        tiny = hanging_equilibrium(links, Body(1e-14), p.x, p.y)
        assert np.abs(tiny.x - e.x).max() < 1e-9
    orders = np.log2(np.array(errs[:-1]) / errs[1:])
    assert errs[-1] < 2e-5 and np.all(np.abs(orders - 2.0) < 0.15), (errs, orders)


# ---------------------------------------------------------------- the start: default and record
def test_default_start_is_the_equilibrium_only_with_bending():
    plain = Problem.catenary(0.3, 20)
    for body in (None, Body(), Body(drag_normal=1.0, damping=1e-3)):
        q = Problem.catenary(0.3, 20, body=body)
        assert np.array_equal(q.x, plain.x) and np.array_equal(q.y, plain.y) and "rest" not in q.start
    b = Problem.catenary(0.3, 20, body=Body(1e-3))
    assert b.start["rest"] == "equilibrium"
    c = Problem.catenary(0.3, 20, body=Body(1e-3), start="catenary")
    assert c.start["rest"] == "catenary" and np.array_equal(c.x, plain.x)
    # with_body builds the start again for the new body
    assert plain.with_body(Body(1e-3)).start == b.start
    assert np.array_equal(b.with_body(None).x, plain.x)
    eq0 = Problem.catenary(0.3, 20, start="equilibrium")  # no body: the discrete chain's own rest shape
    assert not eq0.is_paper and eq0.start["rest"] == "equilibrium"


def test_clamp_start_holds_the_rest_shape_without_a_moment():
    """clamp='start' clamps the direction in which the rest shape leaves the held end: the hinged
    equilibrium, which then is the clamped one too (its moment at the clamp is zero)."""
    hinged = Problem.catenary(0.3, 20, body=Body(1e-2))
    p = Problem.catenary(0.3, 20, body=Body(1e-2, clamp="start"))
    assert np.array_equal(p.x, hinged.x) and np.array_equal(p.y, hinged.y)
    assert p.body.clamp == math.atan2(p.y[-2], p.x[-2])
    G, c = discrete_residual(np.unwrap(np.arctan2(np.diff(p.y), np.diff(p.x))),
                             hanging_equilibrium(p.links, p.body, p.x, p.y).reaction_free, p.links, p.body,
                             (p.x[0], p.y[0]))
    assert np.abs(G / p.links.h).max() < 1e-10 and np.abs(c).max() < 1e-15


@pytest.mark.parametrize("kw,text", [(dict(start="elastica"), "start='elastica' is not one of"),
                                     (dict(start=3), "start=3 is not one of"),
                                     (dict(start="equilibrium", gravity=-1.0), "gravity=-1.0 is out of range")])
def test_bad_start_is_refused(kw, text):
    with pytest.raises(SnappingInputError, match=text):
        Problem.catenary(0.3, 20, **kw)


def test_no_valid_rest_shape_is_refused():
    """Ends 1e-3 apart and a stiff line: the elastica's arms would cross (no valid start: the
    continuation finds no stable shape, or one that crosses itself)."""
    with pytest.raises(SnappingInputError, match="start='equilibrium': .*use start='catenary'"):
        Problem.catenary(1e-3, 200, body=Body(1.0))
    Problem.catenary(1e-3, 200, body=Body(1.0), start="catenary")  # (the catenary is valid)


def test_no_convergence_says_so_with_the_residual(monkeypatch):
    from snapping.simulate import equilibrium as EQ

    monkeypatch.setattr(EQ, "MAX_NEWTON", 1)
    with pytest.raises(SnappingInputError, match=r"relative residual [0-9.e+-]+ \(at most 1e-12.*use start='catenary'"):
        Problem.catenary(0.3, 200, body=Body(1e-2))


def test_start_of_other_shapes_is_refused_by_with_body():
    p = Problem.curve(lambda s: (0.5 * s, 0.8 * s), 10)
    with pytest.raises(SnappingInputError, match="applies to the catenary and supports starts"):
        p.with_body(Body(1e-3), start="equilibrium")


def test_the_start_is_recorded_and_reruns(tmp_path):
    from snapping.simulate import load_run, rerun

    p = Problem.catenary(0.3, 16, body=Body(1e-3, clamp="start"), pin=PinMotion.pull((0.2, 0.0), 0.2))
    ds = run(p, t_end=0.2, progress=False, output=str(tmp_path / "r.nc")).dataset
    assert ds.attrs["start_rest"] == "equilibrium"
    assert json.loads(ds.attrs["problem"])["start"]["rest"] == "equilibrium"
    assert np.array_equal(ds["start_x"].values, p.x)
    again = rerun(load_run(str(tmp_path / "r.nc")), progress=False).dataset
    assert np.array_equal(again["v_max"].values, ds["v_max"].values)
    c = run(Problem.catenary(0.3, 16, body=Body(1e-3), start="catenary"), t_end=0.1, progress=False).dataset
    assert c.attrs["start_rest"] == "catenary"
    plain = run(Problem.catenary(0.3, 16, body=Body(drag_normal=1.0)), t_end=0.1, progress=False).dataset
    assert plain.attrs["start_rest"] == "catenary"
    assert "start_rest" not in run(Problem.catenary(0.3, 16, gravity=0.5), t_end=0.1, progress=False).dataset.attrs


# ---------------------------------------------------------------- the stop at a large bending number
def test_automatic_stop_finds_the_peak_of_a_stiff_line():
    """beta = 1e-2: released from the equilibrium the free end speeds up once, smoothly, and
    the automatic stop keeps that one peak: the largest speed of a run well past it."""
    p = Problem.catenary(0.25, 60, body=Body(1e-2))
    auto = run(p, progress=False).dataset
    long = run(p, t_end=1.6, progress=False).dataset
    assert auto.attrs["v_peak"] == pytest.approx(long.attrs["v_peak"], rel=1e-7)
    t_long = float(long["t"].values[int(np.argmax(long["v_max"].values))])
    assert abs(auto.attrs["t_snap_v"] - t_long) < 1e-2
    assert 0.8 < auto.attrs["t_snap_v"] < 1.0 < float(auto["t"].values[-1])
    # early on the line falls from rest: no jolt of waves (the catenary start's v_max is 0.5 at once)
    early = run(p, t_end=0.05, progress=False).dataset
    assert float(early["v_max"].values[-1]) < 0.12


# ---------------------------------------------------------------- the command line
def test_cli_start_option(capsys, tmp_path):
    from snapping.cli import main

    base = ["simulate", "--chi", "0.3", "--N", "12", "--t-end", "0.1", "--json", "--no-progress"]
    for extra, rest in (([], "equilibrium"), (["--start", "catenary"], "catenary"),
                        (["--start", "equilibrium"], "equilibrium")):
        assert main(base + ["--bending", "1e-3"] + extra) == 0
        assert json.loads(capsys.readouterr().out)["start_rest"] == rest
    assert main(base + ["--start", "equilibrium", "-o", str(tmp_path / "e.nc")]) == 0  # no body: the chain at rest
    capsys.readouterr()
    from snapping.simulate import load_run

    assert json.loads(load_run(str(tmp_path / "e.nc")).attrs["problem"])["start"]["rest"] == "equilibrium"
    shape = tmp_path / "s.csv"
    shape.write_text("x,y\n0,0\n0.3,0.6\n0.6,1.2\n")
    status = main(["simulate", "--shape", str(shape), "--N", "12", "--start", "equilibrium", "--no-progress"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "--start='equilibrium' applies to the catenary and supports" in err[0]


def test_one_or_two_links_held_at_both_ends_keep_their_start():
    for N in (1, 2):
        c = Problem.catenary(0.3, N)
        p = Problem.catenary(0.3, N, body=Body(1e-2))
        assert p.start["rest"] == "equilibrium" and np.array_equal(p.x, c.x) and np.array_equal(p.y, c.y)
