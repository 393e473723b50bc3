"""The general chain (snapping.simulate.problem / general): unequal links and masses, tip
masses, tapers, any start, a moving held end, any gravity; checked against independent
results: a dense Cartesian Lagrange (KKT) solve, the symbolic double pendulum, the
elliptic-integral pendulum period, the static hanging tension, the equivalence principle,
energy conservation and the held end's work, and the paper's runs bit for bit."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import reference_chain as RC  # noqa: E402
from test_reference_chain import chain_from_angles as _nodes_from_angles  # noqa: E402

from snapping._validate import SnappingInputError  # noqa: E402
from snapping.simulate import Links, PinMotion, Problem, load_run, rerun, resume, run  # noqa: E402
from snapping.simulate import general as G  # noqa: E402

FAST = dict(method="fast", progress=False)


def _rhs(N, t, y, mdl):
    w = G.Work(N)
    f = np.empty(2 * N + 1)
    G.general_rhs(N, t, y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig, *mdl)
    return f, w


# ---------------------------------------------------------------- the right-hand side
@pytest.mark.parametrize("N", [1, 2, 3, 7, 20])
def test_general_rhs_equals_dense_cartesian_lagrange_solve(N):
    """Tensions and node accelerations of random chains (unequal links and masses, gravity
    0..2, a held end accelerating with a flick at a random phase) equal a dense KKT solve of
    the Lagrange equations in Cartesian coordinates (tests/reference_chain.py)."""
    rng = np.random.default_rng(100 + N)
    for _ in range(5):
        h = rng.uniform(0.05, 1.0, N)
        m = rng.uniform(0.01, 2.0, N)
        g = rng.uniform(0.0, 2.0)
        pin = PinMotion.flick((rng.normal(), rng.normal()), period=rng.uniform(0.5, 2.0))
        t = rng.uniform(0.0, 0.5)
        mdl = G.make_model(h, 1.0 / m, g=g, **pin.model_args())
        th, om = rng.uniform(-4, 4, N), rng.uniform(-3, 3, N)
        y = np.concatenate([th, om, [0.0]])
        f, w = _rhs(N, t, y, mdl)
        px, py, pvx, pvy, pax, pay = pin.kinematics(t)
        x, yy, vx, vy = _nodes_from_angles(th, om, h, (px, py), (pvx, pvy))
        ax_ref, ay_ref, T_ref = RC.dense_accelerations(x, yy, vx, vy, h, m, g, pin_acc=(pax, pay))
        Z = np.zeros((7, N + 1))
        G.general_to_Z(N, t, y, w.c, w.s, w.sig, Z, *mdl)
        scale = 1.0 + np.abs(np.concatenate([ax_ref, ay_ref])).max()
        assert np.abs(Z[4, :N] - ax_ref).max() < 1e-11 * scale
        assert np.abs(Z[5, :N] - ay_ref).max() < 1e-11 * scale
        assert np.abs(w.sig - T_ref).max() < 1e-11 * (1.0 + np.abs(T_ref).max())
        # and the dense solve of the angle form's own rows (a second, independent derivation path)
        assert np.allclose(f, G.dense_reference_rhs(t, y, mdl), rtol=1e-11, atol=1e-11 * scale)
        # the held end's power T_{N-1} t_{N-1}.v_p
        assert f[2 * N] == pytest.approx(w.sig[-1] * (w.c[-1] * pvx + w.s[-1] * pvy), rel=1e-12, abs=1e-14)


def test_general_rhs_reduces_to_the_uniform_kernel():
    from snapping.simulate import angles as AG

    rng = np.random.default_rng(5)
    for N in (1, 2, 9, 300):
        mdl = G.make_model(np.full(N, 1.0 / N), np.full(N, float(N)))
        y = np.concatenate([rng.uniform(-3, 3, N), rng.uniform(-2, 2, N), [0.0]])
        f, w = _rhs(N, 0.0, y, mdl)
        f2 = np.empty(2 * N)
        w2 = AG.Work(N)
        AG.angle_rhs(N, y[:2 * N], f2, w2.c, w2.s, w2.S, w2.cp, w2.dp, w2.sig)
        assert np.abs(f[:2 * N] - f2).max() <= 1e-13 * np.abs(f2).max()
        assert np.abs(w.sig - w2.sig).max() <= 1e-13 * np.abs(w2.sig).max()


# ---------------------------------------------------------------- runs against exact results
def test_paper_problem_is_the_paper_run_bit_for_bit():
    for kw in (dict(method="fast"), dict(method="euler-richardson")):
        a = run(0.4, 30, **kw).dataset
        b = run(Problem.catenary(0.4, 30), **kw).dataset
        for k in a.variables:
            va, vb = a[k].values, b[k].values
            assert np.array_equal(va, vb, equal_nan=va.dtype.kind == "f"), k
        for k, v in a.attrs.items():
            if k not in ("wall_time", "integrity_sha256"):  # the digest covers the wall time
                assert np.array_equal(np.asarray(v), np.asarray(b.attrs[k]), equal_nan=isinstance(v, float)), k
    c = run(Problem.catenary(0.4, 30, chords="exact"), method="fast").dataset
    d = run(0.4, 30, method="fast", chords="exact").dataset
    assert np.array_equal(c.v_max.values, d.v_max.values)


def test_double_pendulum_against_symbolic_lagrange_equations():
    """Two unequal links and masses, released from an arbitrary configuration with angular
    velocities: node positions against sympy's Lagrange equations integrated by scipy."""
    h, m, g = np.array([0.7, 0.3]), np.array([0.4, 1.3]), 1.0
    th0, om0 = np.array([-0.3, 0.9]), np.array([0.5, -1.1])
    x, y, vx, vy = _nodes_from_angles(th0, om0, h)
    p = Problem.nodes(x, y, vx=vx, vy=vy, links=Links.explicit(h, m), gravity=g)
    times = (0.5, 1.3, 1.7)
    ds = run(p, tol=1e-12, t_end=2.0, snapshot_times=times, **FAST).dataset
    x0, y0, x1, y1 = RC.double_pendulum_reference(h, m, g, th0, om0, np.array(times))
    req = ds.isel(snapshot=np.flatnonzero(ds.snapshot_kind.values == "requested"))
    assert np.abs(req.x.values[:, 0] - x0).max() < 1e-9
    assert np.abs(req.y.values[:, 0] - y0).max() < 1e-9
    assert np.abs(req.x.values[:, 1] - x1).max() < 1e-9
    assert np.abs(req.y.values[:, 1] - y1).max() < 1e-9
    assert ds.attrs["energy_drift"] < 1e-10


def test_double_pendulum_with_a_uniformly_accelerated_pin_against_lagrange():
    h, m, g = np.array([0.5, 0.8]), np.array([1.0, 0.6]), 0.7
    th0, om0 = np.array([0.4, 1.7]), np.array([0.0, 0.0])
    A = (0.3, -0.2)
    x, y, _, _ = _nodes_from_angles(th0, om0, h)
    p = Problem.nodes(x, y, links=Links.explicit(h, m), gravity=g, pin=PinMotion.pull(A))
    times = (0.7, 1.4)
    ds = run(p, tol=1e-12, t_end=1.5, snapshot_times=times, **FAST).dataset
    x0, y0, x1, y1 = RC.double_pendulum_reference(h, m, g, th0, om0, np.array(times), pin=A)
    req = ds.isel(snapshot=np.flatnonzero(ds.snapshot_kind.values == "requested"))
    assert np.abs(req.x.values[:, 0] - x0).max() < 1e-9 and np.abs(req.y.values[:, 1] - y1).max() < 1e-9
    assert np.allclose(req.x.values[:, 2], [0.5 * A[0] * t * t for t in times], atol=1e-14)


@pytest.mark.parametrize("amplitude", [0.3, 2.0])
def test_single_link_with_a_massive_bob_has_the_elliptic_period(amplitude):
    """N = 1 with any node mass (a tip mass on a light link) is the rigid pendulum: released
    at rest at ``amplitude`` from the downward vertical, it reaches the mirror position at
    half the period 4 sqrt(h/g) K(sin^2(amplitude/2)) and is back at the full period."""
    h, g = 0.8, 1.0
    links = Links.explicit([h], [1e-3], tip_mass=2.5)
    x = np.array([-h * math.sin(amplitude), 0.0])
    y = np.array([h * math.cos(amplitude), 0.0])
    P = RC.pendulum_period(h, 2.5, amplitude, g)
    ds = run(Problem.nodes(x, y, links=links, gravity=g), tol=1e-12, t_end=P, snapshot_times=(P / 2,),
             **FAST).dataset
    half = ds.isel(snapshot=int(np.flatnonzero(ds.snapshot_kind.values == "requested")[0]))
    assert float(half.x[0]) == pytest.approx(-x[0], abs=1e-9)
    assert float(half.y[0]) == pytest.approx(y[0], abs=1e-9)
    fin = ds.isel(snapshot=-1)
    assert float(fin.x[0]) == pytest.approx(x[0], abs=1e-9) and float(fin.y[0]) == pytest.approx(y[0], abs=1e-9)


def test_hanging_nonuniform_chain_keeps_its_static_tension():
    """A tapered chain with a tip mass hanging straight down at rest stays at rest, with the
    tension of each link the weight of everything below it."""
    links = Links.taper(40, 0.2, power=2.0, tip_mass=0.3)
    h = links.h
    y = np.concatenate([np.cumsum(h[::-1])[::-1], [0.0]])
    g = 0.9
    ds = run(Problem.nodes(np.zeros(41), y, links=links, gravity=g), t_end=2.0, tol=1e-12, **FAST).dataset
    assert float(ds.v_max.max()) < 1e-10
    T = ds.tension.values[-1]
    assert np.allclose(T, RC.hanging_tension(links.m, g), rtol=1e-13, atol=1e-15)
    assert ds.attrs["energy_drift"] < 1e-14


def test_uniformly_accelerated_pin_is_changed_gravity():
    """Equivalence principle: the held end accelerating downward with a for ever is the fixed
    held end under gravity 1 - a (same shapes relative to the held end at the same times),
    which is the g = 1 chain with times scaled by sqrt(1 - a)."""
    a = 0.4
    links = Links.taper(60, 0.3, tip_mass=0.1)
    t1 = 1.1
    pulled = run(Problem.catenary(0.3, links=links, pin=PinMotion.pull((0.0, a))), t_end=t1, tol=1e-11,
                 **FAST).dataset
    light = run(Problem.catenary(0.3, links=links, gravity=1.0 - a), t_end=t1, tol=1e-11, **FAST).dataset
    normal = run(Problem.catenary(0.3, links=links), t_end=t1 * math.sqrt(1 - a), tol=1e-11, **FAST).dataset
    fp, fl, fn = (d.isel(snapshot=-1) for d in (pulled, light, normal))
    pin_y = 0.5 * a * t1 * t1
    assert float(fp.y[-1]) == pytest.approx(pin_y, rel=1e-13)
    assert np.abs((fp.x.values - fp.x.values[-1]) - fl.x.values).max() < 1e-9
    assert np.abs((fp.y.values - fp.y.values[-1]) - fl.y.values).max() < 1e-9
    assert np.abs(fl.x.values - fn.x.values).max() < 1e-9 and np.abs(fl.y.values - fn.y.values).max() < 1e-9
    # velocities scale by sqrt(g): v_light(t) = sqrt(1 - a) v_normal(t sqrt(1 - a))
    assert np.abs(fl.vx.values - math.sqrt(1 - a) * fn.vx.values).max() < 1e-8


def test_energy_changes_by_the_held_ends_work():
    """Fixed held end: energy conserved. Moving (a flick): the energy changes by the work the
    held end does, E(t) - W(t) = E(0), while W itself is of order one."""
    links = Links.uniform(80, tip_mass=0.2)
    fixed = run(Problem.catenary(0.4, links=links), t_end=0.8, tol=1e-10, **FAST).dataset
    assert fixed.attrs["energy_drift"] < 1e-9 and float(np.abs(fixed.pin_work).max()) == 0.0
    moved = run(Problem.catenary(0.4, links=links, pin=PinMotion.flick((6.0, -3.0), 0.4)), t_end=0.8, tol=1e-10,
                **FAST).dataset
    W = moved.pin_work.values
    E = moved.energy.values
    assert np.abs(W).max() > 0.05
    assert np.abs((E - W) - E[0]).max() < 1e-8
    assert moved.attrs["energy_drift"] < 1e-8
    # the held end is displaced by accel T^2/(2 pi) and at rest after the flick
    assert float(moved.pin_x[-1]) == pytest.approx(6.0 * 0.4**2 / (2 * math.pi), rel=1e-12)
    assert float(moved.pin_vx[-1]) == 0.0


def test_table_pin_motion_follows_the_function_it_samples():
    r = lambda t: (0.05 * math.sin(3 * t), 0.02 * t * t)  # noqa: E731
    pin = PinMotion.from_function(r, 1.0, samples=401)
    for t in (0.1, 0.55, 0.93):
        x, y, vx, vy, ax, ay = pin.kinematics(t)
        assert x == pytest.approx(r(t)[0], abs=1e-9) and y == pytest.approx(r(t)[1], abs=1e-12)
        assert vx == pytest.approx(0.15 * math.cos(3 * t), abs=1e-6)
        assert ax == pytest.approx(-0.45 * math.sin(3 * t), abs=1e-3) and ay == pytest.approx(0.04, abs=1e-9)
    ds = run(Problem.catenary(0.5, 20, pin=pin), t_end=0.5, tol=1e-10, **FAST).dataset
    assert float(ds.pin_x[-1]) == pytest.approx(r(0.5)[0], abs=1e-9)
    assert np.abs((ds.energy - ds.pin_work).values - float(ds.energy[0])).max() < 1e-9


def test_tip_mass_and_taper_change_the_snap_as_physics_says():
    """A tapered whip snaps harder than the uniform chain; a heavy tip mass softens the snap
    (the free end can no longer be whipped round by a vanishing mass)."""
    N, chi = 200, 0.3
    uni = run(Problem.catenary(chi, links=Links.uniform(N, lumping="shared")), **FAST).dataset.attrs
    whip = run(Problem.catenary(chi, links=Links.taper(N, 0.1)), **FAST).dataset.attrs
    tip = run(Problem.catenary(chi, links=Links.uniform(N, tip_mass=0.5, lumping="shared")), **FAST).dataset.attrs
    assert whip["v_peak"] > 1.1 * uni["v_peak"]
    assert tip["v_peak"] < 0.8 * uni["v_peak"]
    for a in (uni, whip, tip):
        assert a["energy_drift"] < 1e-8 and a["link_drift"] < 1e-14


# ---------------------------------------------------------------- the run file
def test_general_run_file_reproduces_and_resumes(tmp_path):
    p = Problem.supports(0.4, 0.2, links=Links.taper(30, 0.25, tip_mass=0.05), pin=PinMotion.flick((0.5, 0.0), 0.3))
    out = tmp_path / "g.nc"
    r = run(p, output=str(out), **FAST)
    ds = load_run(str(out))
    assert ds.attrs["initial"] == "problem" and ds.attrs["pin_motion"] == "flick"
    assert np.array_equal(ds.link_length.values, p.links.h) and np.array_equal(ds.node_mass.values[:-1], p.links.m)
    again = rerun(ds).dataset
    for k, v in r.dataset.attrs.items():  # (n_rhs: a rerun is given dt0, so it skips the first-step probe)
        if k not in ("wall_time", "n_rhs", "integrity_sha256"):
            assert np.array_equal(np.asarray(again.attrs[k]), np.asarray(v), equal_nan=isinstance(v, float)), k
    assert np.array_equal(again.v_max.values, r.dataset.v_max.values)
    assert np.array_equal(again.pin_work.values, r.dataset.pin_work.values)
    # interrupted at a step boundary and resumed: the same Dataset
    from snapping.simulate import driver as stepper

    calls = {"n": 0}

    def hook(eng):
        calls["n"] += 1
        return 2 if calls["n"] == 2 else 0

    out2 = tmp_path / "i.nc"
    stepper._chunk_hook = hook
    try:
        import snapping.simulate.methods.dop853 as HO

        old = HO.NODE_EVALS_PER_CALL
        HO.NODE_EVALS_PER_CALL = 2000
        with pytest.raises(KeyboardInterrupt):
            run(p, output=str(out2), **FAST)
    finally:
        stepper._chunk_hook = None
        HO.NODE_EVALS_PER_CALL = old
    done = resume(str(out2)).dataset
    ref = run(p, **FAST).dataset
    for k in ("v_max", "pin_work", "energy", "tension", "x"):
        assert np.array_equal(done[k].values, ref[k].values), k
    assert done.attrs["v_peak"] == ref.attrs["v_peak"]


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize("make, name", [
    (lambda: Links.explicit([0.5, -0.1], [1.0, 1.0]), "h[1]"),
    (lambda: Links.explicit([0.5, 0.5], [1.0, np.nan]), "m[1]"),
    (lambda: Links.explicit([0.5, 0.5], [1.0]), "m has 1"),
    (lambda: Links.uniform(10, tip_mass=-1.0), "tip_mass"),
    (lambda: Links.taper(10, 0.0), "ratio"),
    (lambda: Links.taper(10, 0.5, lumping="nodes"), "lumping"),
    (lambda: PinMotion.flick((1.0, math.inf), 0.2), "accel"),
    (lambda: PinMotion.flick((1.0, 0.0), 0.0), "period"),
    (lambda: PinMotion.from_function(lambda t: (1.0 + t, 0.0), 1.0), "origin"),
    (lambda: PinMotion.from_function(lambda t: (math.nan, 0.0), 1.0), "not finite"),
    (lambda: Problem.catenary(0.3, 10, links=Links.uniform(12)), "N=10"),
    (lambda: Problem.catenary(0.3, 10, gravity=-1.0), "gravity"),
    (lambda: Problem.nodes([0.0, 0.0, 0.0], [1.0, 0.4, 0.0]), "link 0"),
    (lambda: Problem.nodes([0.0, 0.0], [1.0, 0.0], vx=[0.0, 0.0], vy=[1.0, 0.0]), "stretch link 0"),
    (lambda: Problem.nodes([0.0, 0.0, 0.0], [1.0, 0.5]), "same length"),
    (lambda: Links.taper(5, 1e300), "ratio"),
    (lambda: Links.taper(5, 0.5, power=1e300), "power"),
    (lambda: Links.explicit([[0.5, 0.5]], [[1.0, 1.0]]), "one-dimensional"),
    (lambda: Problem.catenary(0.5, links="x"), "links='x'"),
    (lambda: Problem.nodes([0.0, 0.0], [1.0, 0.0], links="x"), "links='x'"),
    (lambda: Links.from_density([0.5, 0.5], lambda s: "x"), "density"),
    (lambda: PinMotion.from_function(lambda t: "ab", 1.0), "r\\(t\\)"),
    (lambda: PinMotion.from_function(lambda t: (0.0, 0.0), 1.0, samples=10**9), "samples"),
    (lambda: Problem.curve(lambda s: 1 / 0, 5), "curve function failed"),
    (lambda: Problem.catenary(0.3, links=Links.explicit(np.full(4, 0.25), np.full(4, 1e-25))), "m\\[0\\]"),
    (lambda: PinMotion.flick((1.0, 0.0), 1e-300), "period"),
])
def test_bad_problem_input_names_the_parameter(make, name):
    pattern = name if "\\" in name else name.replace("[", r"\[").replace("]", r"\]")
    with pytest.raises(SnappingInputError, match=pattern):
        make()


def test_euler_richardson_refuses_what_it_cannot_take():
    p = Problem.catenary(0.3, 10, links=Links.uniform(10, tip_mass=0.5))
    with pytest.raises(SnappingInputError, match="tip mass"):
        run(p, method="euler-richardson")
    q = Problem.catenary(0.3, 10, pin=PinMotion.pull((0.0, 1.0)))
    with pytest.raises(SnappingInputError, match="moving held end"):
        run(q, method="euler-richardson")
    with pytest.raises(SnappingInputError, match="chi=0.3 given with a Problem"):
        run(0.3, problem=q)


@pytest.mark.parametrize("name", ["problem", "links", "pin", "general", "shapes", "errors", "driver"])
def test_docstring_examples_run(name):
    import doctest
    import importlib

    module = importlib.import_module(f"snapping.simulate.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0


def test_tapered_chain_available_energy_against_quadrature():
    """P of a tapered chain on the catenary (masses lumped consistently) converges to the
    quadrature of lambda(s) (s - y(s)) at second order; the paper's lumping is first order."""
    from scipy.integrate import quad

    from snapping import estimates

    chi, ratio, power = 0.3, 0.2, 1.5
    c = 1.0 - ratio ** (1.0 / power)
    norm = (1.0 - (1.0 - c) ** (power + 1.0)) / (c * (power + 1.0))
    lam = lambda s: (1.0 - c * s) ** power / norm  # noqa: E731
    exact = quad(lambda s: lam(s) * (s - float(estimates.catenary_shape(s, chi)[1])), 0.0, 1.0,
                 epsabs=1e-14, epsrel=1e-13, limit=200)[0]
    errs = {}
    for lumping in ("shared", "paper"):
        errs[lumping] = []
        for N in (100, 200, 400):
            p = Problem.catenary(chi, links=Links.taper(N, ratio, power=power, lumping=lumping),
                                 chords="arclength")  # nodes at their arclength: a trapezoid rule
            errs[lumping].append(abs(p.estimate()["P"] - exact))
    order = lambda e: math.log2(e[1] / e[2])  # noqa: E731
    assert 1.9 < order(errs["shared"]) < 2.1 and errs["shared"][-1] < 1e-6
    assert 0.9 < order(errs["paper"]) < 1.1


def test_steps_land_on_the_held_ends_breakpoints():
    """A pull from t = 0.1 to 0.4 (its acceleration jumps there): steps end exactly on both
    times, the held end's velocity is the closed form, and before the pull the chain
    falls with a fixed end (energy conserved to round-off)."""
    p = Problem.catenary(0.5, 60, pin=PinMotion.pull((0.0, -2.0), duration=0.3, t0=0.1))
    ds = run(p, t_end=0.6, tol=1e-8, **FAST).dataset  # (the balance below is at this tolerance)
    t = ds.t.values
    assert 0.1 in t and 0.3 + 0.1 in t
    bal = np.abs((ds.energy - ds.pin_work).values - float(ds.energy[0]))
    assert bal[t <= 0.1].max() < 1e-13 and bal.max() < 1e-8
    assert float(ds.pin_vy[-1]) == pytest.approx(-0.6, rel=1e-14)


def test_checkpoint_of_an_older_layout_is_refused_clearly(tmp_path):
    """Checkpoints of layout version 1 (37 control entries, no integrity digest) are
    refused with a message that names the version, not resumed wrongly or half-read."""
    import xarray as xr

    from snapping import schema
    from snapping.simulate import driver
    from snapping.simulate import rk as R

    calls = {"n": 0}

    def hook(eng):
        calls["n"] += 1
        return 2 if calls["n"] == 3 else 0

    out = tmp_path / "new.nc"
    driver._chunk_hook = hook
    try:
        with pytest.raises(KeyboardInterrupt):
            run(0.4, 40, output=str(out), **FAST)
    finally:
        driver._chunk_hook = None
    with xr.open_dataset(out) as f:
        ds = f.load()
    ctl = ds["checkpoint_ctl"].values
    assert ctl.size == R.NQ and ctl[R.Q_TBRK] == np.inf and ds.attrs["checkpoint_version"] == 3
    old = ds.drop_vars("checkpoint_ctl").assign(checkpoint_ctl=(("checkpoint_ctl",), ctl[:37]))
    old.attrs["checkpoint_version"] = 1
    del old.attrs[schema.DIGEST_ATTR]
    old.to_netcdf(tmp_path / "older.nc")
    with pytest.raises(SnappingInputError, match="checkpoint version 1 .* start the run again"):
        resume(str(tmp_path / "older.nc"))
    done = resume(str(out)).dataset  # the current layout resumes to the uninterrupted run
    ref = run(0.4, 40, **FAST).dataset
    assert np.array_equal(done.v_max.values, ref.v_max.values) and done.attrs["v_peak"] == ref.attrs["v_peak"]


def test_cli_runs_the_general_problems(tmp_path, capsys):
    import json

    from snapping.cli import main

    csv = tmp_path / "start.csv"
    s = np.linspace(0.0, 1.0, 201)
    csv.write_text("x,y\n" + "\n".join(f"{0.5 * math.sin(v)},{0.5 * (1 - math.cos(v))}" for v in 2.0 * s))
    out = tmp_path / "shape.nc"
    assert main(["simulate", "--shape", str(csv), "--N", "30", "--method", "fast", "--json", "-o", str(out)]) == 0
    summ = json.loads(capsys.readouterr().out)
    assert summ["start"] == "curve" and summ["status"] == "completed"
    ds = load_run(str(out))
    assert np.allclose(np.hypot(np.diff(ds.start_x), np.diff(ds.start_y)), 1 / 30, rtol=1e-12)
    r = math.hypot(float(ds.start_x[0]), float(ds.start_y[0]) - 0.5)  # the nodes lie on the circle of radius 1/2
    assert r == pytest.approx(0.5, abs=1e-6)  # (a cubic spline through 201 samples of the circle)
    argv = ["simulate", "--supports", "0.4,0.2", "--N", "20", "--method", "fast", "--taper", "0.2:2", "--tip-mass",
            "0.05", "--pin-motion", "flick:2,0,0.3", "--json"]
    assert main(argv) == 0
    summ = json.loads(capsys.readouterr().out)
    assert (summ["start"], summ["pin_motion"], summ["tip_mass"]) == ("supports", "flick", 0.05)
    p = Problem.supports(0.4, 0.2, links=Links.taper(20, 0.2, power=2.0, tip_mass=0.05),
                         pin=PinMotion.flick((2.0, 0.0), 0.3))
    assert summ["v_peak"] == run(p, **FAST).dataset.attrs["v_peak"]


def test_pull_that_starts_and_stops_against_a_piecewise_lagrange_reference():
    """A double pendulum whose held end is at rest until t = 0.3, accelerates with A until
    0.5 and then moves at constant velocity: the symbolic Lagrange equations integrated
    piecewise (fixed pin; uniformly accelerated pin; fixed pin again, by Galilean
    invariance) against the run, whose steps start each piece with the acceleration after
    the jump: at tol 1e-8 the angles are good to 1e-10 (3e-8, with 47 rejected steps, when a
    step from a jump began with the derivative before it)."""
    h, m, g = np.array([0.6, 0.4]), np.array([0.7, 1.2]), 1.0
    th0, om0 = np.array([-0.4, 0.8]), np.array([0.3, -0.2])
    A = (1.5, -2.0)
    x, y, vx, vy = _nodes_from_angles(th0, om0, h)
    p = Problem.nodes(x, y, vx=vx, vy=vy, links=Links.explicit(h, m), gravity=g,
                      pin=PinMotion.pull(A, duration=0.2, t0=0.3))
    ds = run(p, tol=1e-8, t_end=1.0, **FAST).dataset
    assert ds.attrs["n_rejected"] < 20
    s1 = RC.double_pendulum_solution(h, m, g, th0, om0, (0.0, 0.3))
    s2 = RC.double_pendulum_solution(h, m, g, s1.y[:2, -1], s1.y[2:, -1], (0.0, 0.2), pin=A)
    s3 = RC.double_pendulum_solution(h, m, g, s2.y[:2, -1], s2.y[2:, -1], (0.0, 0.5))
    fin = ds.isel(snapshot=-1)
    th = np.arctan2(np.diff(fin.y.values), np.diff(fin.x.values))
    err = np.abs(np.angle(np.exp(1j * (th - s3.y[:2, -1]))))
    assert err.max() < 1e-9
    assert float(fin.x[-1]) == pytest.approx(0.5 * A[0] * 0.2**2 + A[0] * 0.2 * 0.5, rel=1e-13)
