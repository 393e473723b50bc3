"""The catalogue of real lines (snapping.lines): values in their physical ranges, the bodies it
makes equal to the explicit SI bodies, --line on the command line, and the energy balance of a
real line's drag run, with the recorded dissipation checked against a quadrature of the drag
power computed here from the recorded states."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from snapping import lines
from snapping._validate import SnappingInputError
from snapping.cli import main
from snapping.simulate import Body, Problem, run

GRAIN = 64.79891e-6  # kg (exact by definition)
FT = 0.3048


def _I(d):
    return math.pi * d ** 4 / 64


def _A(d):
    return math.pi * d ** 2 / 4


@pytest.mark.parametrize("name", lines.names())
def test_catalogue_values_are_in_their_physical_ranges(name):
    ln = lines.get(name)
    assert ln.name == name and ln.sources and ln.title
    assert 1e-5 <= ln.mass_per_length <= 1.0  # kg/m: a thin nylon line to a thick rope
    assert 1e-4 <= ln.diameter <= 0.05  # m
    density = ln.mass_per_length / _A(ln.diameter)  # kg/m^3 of the solid section
    assert 300 <= density <= 8000, density
    if ln.ei > 0:  # the modulus EI implies: rubber (1e5) to steel (2e11); polymers and leather below 1e10
        assert 1e5 <= ln.ei / _I(ln.diameter) <= 1e10
    if ln.ea is not None:
        assert 1e5 <= ln.ea / _A(ln.diameter) <= 1e10
    assert 0.1 <= ln.cd_normal <= 2.0 and 1e-3 <= ln.cd_tangential <= 0.2
    assert set(ln.estimates) <= {"mass_per_length", "diameter", "ei", "ea", "cd_normal", "cd_tangential", "taper",
                                 "tip_mass", "tip_drag_area", "length"}
    assert all(len(v) > 20 for v in ln.estimates.values())  # each estimate says how it was derived


def test_published_values():
    # the paper's chain (Tomaszewski et al.): 1.022 m, 20.8 g
    bc = lines.get("ball-chain")
    assert bc.mass() == pytest.approx(0.0208, rel=1e-12) and bc.length == 1.022 and bc.ei == 0.0
    # AFFTA: a 5-weight's 30 ft after its level tip weigh 140 grains (a trapezoid sum of lambda0 r^2 here)
    fly = lines.get("fly-line")
    x = np.linspace(0.1524, 0.1524 + 30 * FT, 200001)
    lam = fly.mass_per_length * np.interp(x, *zip(*fly.taper)) ** 2
    grains = float(np.sum(0.5 * (lam[1:] + lam[:-1]) * np.diff(x))) / GRAIN
    assert grains == pytest.approx(140.0, abs=1e-4)
    # the bullwhip's cone: 1000 kg/m^3 over pi L (d0^2 + d0 d1 + d1^2)/12
    wh = lines.get("bullwhip")
    d0, d1 = 0.015, 0.003
    assert wh.mass() == pytest.approx(1000 * math.pi * wh.length * (d0 ** 2 + d0 * d1 + d1 ** 2) / 12, rel=1e-12)
    assert wh.profile("ei")(wh.length) == pytest.approx(wh.ei / 625, rel=1e-12)  # EI ~ d^4: (15/3)^4
    # EN 892: a static elongation under 10 % for 75 kg over the preload
    rope = lines.get("climbing-rope")
    assert 75 * 9.81 / rope.ea <= 0.10 and 0.060 <= rope.mass_per_length <= 0.085


def _h(N):
    return np.full(N, 1.0 / N)


@pytest.mark.parametrize("name", lines.names())
def test_the_line_body_equals_the_explicit_si_body(name):
    ln = lines.get(name)
    L = 0.8 * ln.length
    N = 24
    h = _h(N)
    dist = np.arange(N + 1) / N * L  # node j's distance from the free end, m
    if ln.taper is None:
        r = np.ones(N + 1)
        M = ln.mass_per_length * L
    else:
        xs, rs = (np.asarray(c, dtype=float) for c in zip(*ln.taper))
        if ln.taper_units == "fraction":
            xs = xs * L
        r = np.interp(dist, xs, rs)
        xx = np.linspace(0.0, L, 400001)
        lam = ln.mass_per_length * np.interp(xx, xs, rs) ** 2
        M = float(np.sum(0.5 * (lam[1:] + lam[:-1]) * np.diff(xx)))
    assert ln.mass(L) == pytest.approx(M, rel=1e-9)
    explicit = Body.from_si(L, ln.mass(L), ei=ln.ei * r ** 4, diameter=ln.diameter * r, cd_normal=ln.cd_normal,
                            cd_tangential=ln.cd_tangential, tip_drag_area=ln.tip_drag_area)
    for made in (ln.body(L), Body.from_line(name, L)):
        for k in ("bending", "drag_normal", "drag_tangential", "damping", "curvature"):
            np.testing.assert_allclose(made.node_values(k, h), explicit.node_values(k, h), rtol=1e-12, atol=0)
        assert made.tip_drag == explicit.tip_drag and made.clamp is None
    # by hand, at the held end (r there: the last node): beta = EI/(lambda g L^3), lambda = M/L
    lam = M / L
    assert ln.body(L).node_values("bending", h)[-1] == pytest.approx(ln.ei * r[-1] ** 4 / (lam * 9.81 * L ** 3),
                                                                     rel=1e-8)
    assert ln.body(L).node_values("drag_normal", h)[0] == pytest.approx(
        0.5 * 1.2 * ln.cd_normal * ln.diameter * r[0] * L / lam, rel=1e-8)


def test_overrides_and_bad_names():
    fly = lines.get("fly-line")
    assert fly.body(ei=0.0).node_values("bending", _h(4)).max() == 0.0
    assert fly.body(cd_normal=0.6).node_values("drag_normal", _h(4))[0] == pytest.approx(
        0.5 * fly.body().node_values("drag_normal", _h(4))[0], rel=1e-12)
    assert fly.replace(ea=1e3).ea == 1e3
    with pytest.raises(SnappingInputError, match=r"line='fly' is not in the catalogue; valid names: ball-chain, "
                                                 r"nylon-monofilament, fly-line, bullwhip, climbing-rope, bungee-cord"):
        Body.from_line("fly")
    with pytest.raises(SnappingInputError, match="eii= is not a body override"):
        fly.body(eii=1.0)


def test_tapered_links_carry_the_line_masses():
    wh = lines.get("bullwhip")
    N = 50
    links = wh.links(N)
    M = wh.mass()
    # link k (index 0 at the free end) spans distances [k, k+1] L/N from the tip; lambda = lambda0 r^2, r linear
    a, b = np.arange(N) / N, np.arange(1, N + 1) / N
    ra, rb = 0.2 + 0.8 * a, 0.2 + 0.8 * b
    link_mass = wh.mass_per_length * wh.length * (b - a) * (ra ** 2 + ra * rb + rb ** 2) / 3 / M
    np.testing.assert_allclose(links.link_mass, link_mass, rtol=1e-12)
    assert links.tip_mass == pytest.approx(1e-3 / M, rel=1e-12)
    assert links.m.sum() == pytest.approx(1.0 - link_mass[-1] / 2 + links.tip_mass, rel=1e-12)


def _cli_json(argv, capsys):
    assert main(argv + ["--json", "--no-progress"]) == 0
    return json.loads(capsys.readouterr().out)


def test_cli_line_runs_the_catalogue_problem_and_options_override(capsys):
    s = _cli_json(["simulate", "--chi", "0.3", "--N", "30", "--line", "bullwhip"], capsys)
    wh = lines.get("bullwhip")
    ref = run(wh.problem(0.3, 30), progress=False).summary()
    assert s["v_peak"] == ref["v_peak"] and s["n_rhs"] == ref["n_rhs"]  # bit for bit: masses, taper, tip body
    assert s["line"] == "bullwhip" and s["body_si"]["ei"]["value"] == "profile: bullwhip ei"
    s2 = _cli_json(["simulate", "--chi", "0.3", "--N", "30", "--line", "nylon-monofilament", "--length", "2",
                    "--ei", "0"], capsys)
    ny = lines.get("nylon-monofilament")
    ref2 = run(Problem.catenary(0.3, 30, body=ny.body(2.0, ei=0.0)), progress=False).summary()
    assert s2["v_peak"] == ref2["v_peak"] and "beta" not in s2["body"]
    s3 = _cli_json(["simulate", "--chi", "0.3", "--N", "30", "--line", "nylon-monofilament", "--length", "2",
                    "--drag-normal", "3"], capsys)  # a nondimensional twin replaces the line's diameter
    assert s3["body"]["drag_normal"] == 3.0 and "drag_tangential" not in s3["body"]


@pytest.mark.parametrize("argv, needle", [
    (["simulate", "--chi", "0.3", "--N", "10", "--line", "whip"], "--line='whip' is not in the catalogue; valid "
                                                                   "names: ball-chain,"),
    (["sweep", "--chi", "0.3", "--N", "10", "--line", "fly-line", "-o", "SWEEP"], "--line fly-line has tapered"),
])
def test_cli_bad_line_is_one_line_exit_2(argv, needle, capsys, tmp_path):
    argv = [str(tmp_path / "s") if a == "SWEEP" else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and len(err.splitlines()) == 1


def _drag_power(ds, line, L, N):
    """The drag power sum_j F_j . v_j of every snapshot, from its positions and velocities: the
    force per length of snapping.units.body_numbers' conventions, written out here."""
    lam = line.mass(L) / L
    dist = np.arange(N + 1) / N * L  # node j's distance from the free end (equal links)
    xs, rs = (np.asarray(c, dtype=float) for c in zip(*line.taper))
    d = line.diameter * np.interp(dist, xs, rs)
    cn = 0.5 * 1.2 * line.cd_normal * d * L / lam
    ct = 0.5 * 1.2 * line.cd_tangential * math.pi * d * L / lam
    l = np.full(N + 1, 1.0 / N)
    l[0] = 0.5 / N
    cd = 0.5 * 1.2 * line.tip_drag_area * L / line.mass(L)
    P = []
    for k in range(ds.sizes["snapshot"]):
        sn = ds.isel(snapshot=k)
        x, y, vx, vy = (np.asarray(sn[v].values, dtype=float) for v in ("x", "y", "vx", "vy"))
        tx, ty = np.diff(x), np.diff(y)  # link j from node j to node j + 1
        n = np.hypot(tx, ty)
        tx, ty = tx / n, ty / n
        bx, by = tx.copy(), ty.copy()  # node tangents: the links' bisector inside, link 0's at the free end
        bx[1:] += tx[:-1]
        by[1:] += ty[:-1]
        nb = np.hypot(bx, by)
        bx, by = bx / nb, by / nb
        u = np.stack([vx[:N], vy[:N]])
        ut = u[0] * bx + u[1] * by
        un = u - ut * np.stack([bx, by])
        f = -cn[:N] * l[:N] * np.hypot(*un) * un - ct[:N] * l[:N] * np.abs(ut) * ut * np.stack([bx, by])
        f[:, 0] -= cd * np.hypot(*u[:, 0]) * u[:, 0]
        P.append(float(np.sum(f * u)))
    return np.array(P)


def test_energy_balance_of_a_real_line_closes_and_the_dissipation_is_the_drag_work():
    fly = lines.get("fly-line")
    N, L = 40, fly.length
    p = fly.problem(0.25, N)
    t_end = 1.0  # before the snap: the power is smooth for the quadrature
    times = np.linspace(0.0, t_end, 801)
    res = {}
    for tol in (1e-6, 1e-8, 1e-10):
        ds = run(p, tol=tol, t_end=t_end, snapshot_times=list(times[1:]), progress=False).dataset
        b = np.asarray(ds["energy"] - ds["pin_work"] + ds["dissipated"], dtype=float)
        res[tol] = (float(np.abs(b - b[0]).max() / abs(b[0])), ds)
    assert res[1e-6][0] < 1e-7 and res[1e-10][0] < 1e-11
    assert res[1e-6][0] > res[1e-8][0] > res[1e-10][0]  # it shrinks with the tolerance
    assert res[1e-6][0] > 1e3 * res[1e-10][0]
    ds = res[1e-10][1]
    ts = np.asarray(ds["t_snapshot"].values)
    t_snap, first = np.unique(ts, return_index=True)  # (t_end is requested and final: once)
    sel = ds.isel(snapshot=first)
    np.testing.assert_array_equal(t_snap, times)
    P = _drag_power(sel, fly, L, N)
    assert np.all(P <= 0.0)
    from scipy.integrate import simpson

    work = -simpson(P, x=t_snap)
    assert float(ds["t"][-1]) == t_end
    D = float(ds["dissipated"][-1])
    assert D > 0.1 * float(ds["energy"][0])  # the air takes a good part of the energy by t = 1
    assert work == pytest.approx(D, rel=1e-10)  # (measured 9e-13; 200 intervals instead of 800: 3e-8)


def test_the_showcase_compares_like_with_like():
    """examples/real_lines.py: the ideal chain has the real line's links, held ends and held-end
    motion, and no body; each starts at rest (the ideal chain on its catenary, the real line in
    its static equilibrium with bending, the default; the whip's clamped at the stroke's starting
    angle); the whip's handle turns by the stroke's angle and is at rest after it."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "examples" / "real_lines.py"
    spec = importlib.util.spec_from_file_location("real_lines", path)
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    for name in ("bullwhip", "fly-line"):
        real, ideal = ex.problems(name, 20)
        assert ideal.body is None and real.body.active
        np.testing.assert_array_equal(real.links.m, ideal.links.m)
        for k in (0, -1):  # the same held end and the same free end: both let go from the same points
            assert (real.x[k], real.y[k]) == pytest.approx((ideal.x[k], ideal.y[k]), abs=1e-12)
        assert real.start["rest"] == "equilibrium"
        assert real.pin.describe() == ideal.pin.describe()
    real, _ = ex.problems("bullwhip", 20)
    t, a = real.body.clamp
    assert a[-1] - a[0] == pytest.approx(2.0, rel=1e-12) and t[-1] == 0.3
    assert real.pin.kind == "flick" and real.pin.accel == (-10.0, 0.0)
