"""A line's body given in SI (snapping.units.body_numbers, Body.from_si, the CLI's --ei,
--diameter, ...): the conversions against hand-computed numbers and pint's dimensions, the
nondimensional numbers in the run's summary, bad input named, and the body in sweeps and in
``converge`` (issue 21)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from snapping import units
from snapping._validate import SnappingInputError
from snapping.cli import main
from snapping.simulate import Body, Problem, run
from snapping.simulate.body import summarize

# a line of 2.5 m and 25 g (10 g/m), EI = 2e-3 N m^2, 1.5 mm diameter, g = 9.81
L, M, G = 2.5, 0.025, 9.81
LAM = M / L  # 0.01 kg/m


def test_body_numbers_against_hand_computed_values():
    n = units.body_numbers(L, M, G, ei=2e-3, bending_damping=1e-4, curvature=0.4, diameter=1.5e-3, air_density=1.2,
                           cd_normal=1.1, cd_tangential=0.015, tip_drag_area=2e-5, wind=(3.0, -1.0))
    # beta = EI/(lambda g L^3) = 2e-3/(0.01 * 9.81 * 15.625)
    assert n["bending"] == pytest.approx(2e-3 / 1.5328125, rel=1e-14)
    # eta / (lambda g L^3 sqrt(L/g))
    assert n["damping"] == pytest.approx(1e-4 / (1.5328125 * math.sqrt(2.5 / 9.81)), rel=1e-14)
    assert n["curvature"] == pytest.approx(1.0, rel=1e-14)  # 0.4 /m over 2.5 m
    # c_n = 0.5 rho C_n d L / lambda = 0.5 * 1.2 * 1.1 * 1.5e-3 * 2.5 / 0.01 = 0.2475
    assert n["drag_normal"] == pytest.approx(0.2475, rel=1e-14)
    # c_t = 0.5 rho C_t pi d L / lambda = 0.5 * 1.2 * 0.015 * pi * 1.5e-3 * 2.5 / 0.01
    assert n["drag_tangential"] == pytest.approx(0.003375 * math.pi, rel=1e-14)
    # c_d = 0.5 rho (C_d A) L / M = 0.5 * 1.2 * 2e-5 * 2.5 / 0.025 = 1.2e-3
    assert n["tip_drag"] == pytest.approx(1.2e-3, rel=1e-14)
    u = math.sqrt(9.81 * 2.5)
    assert n["wind"] == pytest.approx((3.0 / u, -1.0 / u), rel=1e-14)


def test_defaults_air_density_and_coefficients():
    n = units.body_numbers(L, M, diameter=1e-3)
    assert n["drag_normal"] == pytest.approx(0.5 * units.AIR_DENSITY * units.CD_NORMAL * 1e-3 * L / LAM)
    ct = 0.5 * units.AIR_DENSITY * units.CD_TANGENTIAL * math.pi * 1e-3 * L / LAM
    assert n["drag_tangential"] == pytest.approx(ct)
    assert units.AIR_DENSITY == 1.2 and units.CD_NORMAL == 1.2 and units.CD_TANGENTIAL == 0.01
    assert "drag_normal" not in units.body_numbers(L, M, ei=1.0)  # no diameter: no drag


def test_dimensional_analysis_with_pint():
    """The nondimensional numbers give back SI results that pint computes independently: the
    broadside terminal speed sqrt(lambda g / (0.5 rho C_n d)), the small-deflection cantilever
    tip lambda g L^4 / (8 EI), the tip body's terminal speed sqrt(M_tip g / (0.5 rho C_d A))."""
    ureg = units.registry()
    Q = ureg.Quantity
    rho, cn, d, ei, cda = Q(1.2, "kg/m**3"), 1.2, Q(1.5e-3, "m"), Q(2e-3, "N m**2"), Q(2e-5, "m**2")
    lam, g, Lq = Q(LAM, "kg/m"), Q(G, "m/s**2"), Q(L, "m")
    n = units.body_numbers(L, M, G, ei=2e-3, diameter=1.5e-3, cd_normal=cn, tip_drag_area=2e-5)
    s = units.Scales(L, M, G)
    v_si = ((lam * g / (0.5 * rho * cn * d)) ** 0.5).to("m/s").magnitude
    assert s.to_si(1.0 / math.sqrt(n["drag_normal"]), "speed") == pytest.approx(v_si, rel=1e-13)
    tip_si = (lam * g * Lq ** 4 / (8 * ei)).to("m").magnitude
    assert s.to_si(1.0 / (8.0 * n["bending"]), "length") == pytest.approx(tip_si, rel=1e-13)
    # a tip body of mass m_tip (ratio mu = m_tip/M) falls at sqrt(mu / c_d) in units of sqrt(g L)
    mu = 0.3
    v_tip = ((Q(mu * M, "kg") * g / (0.5 * rho * cda)) ** 0.5).to("m/s").magnitude
    assert s.to_si(math.sqrt(mu / n["tip_drag"]), "speed") == pytest.approx(v_tip, rel=1e-13)
    # every SI input's declared unit is what the formula consumes: a wrong one fails in pint
    for k, (unit, _) in units.BODY_SI_INPUTS.items():
        assert unit == "" or Q(1.0, unit).dimensionality


def test_profiles_in_si_arrays_and_functions_of_s_in_meters():
    ei = lambda s: 1e-3 * (1.0 - 0.3 * s / L)  # noqa: E731  (s in m from the held end)
    b = Body.from_si(L, M, ei=ei, diameter=np.linspace(1e-3, 2e-3, 11))
    p = Problem.catenary(0.3, 10, body=b)
    beta = b.node_values("bending", p.links.h)
    s = np.zeros(11)
    s[:10] = np.cumsum(p.links.h[::-1])[::-1]  # nondimensional s of each node (index 0 the free end)
    assert beta == pytest.approx(1e-3 * (1.0 - 0.3 * s) / (LAM * G * L ** 3), rel=1e-13)
    assert b.node_values("drag_normal", p.links.h)[-1] == pytest.approx(0.5 * 1.2 * 1.2 * 2e-3 * L / LAM)
    assert p.describe()["body"]["nodes"]["bending"][0] == pytest.approx(beta[0])


def test_from_si_is_the_body_of_its_numbers():
    n = units.body_numbers(L, M, ei=1e-3, diameter=1e-3, wind=(1.0, 0.0))
    a, b = Body.from_si(L, M, ei=1e-3, diameter=1e-3, wind=(1.0, 0.0), clamp=0.2), Body(**n, clamp=0.2)
    assert a.describe() == b.describe()


@pytest.mark.parametrize("kw, name", [
    ({"ei": -1.0}, "ei="), ({"ei": float("nan")}, "ei"), ({"diameter": -1e-3}, "diameter="),
    ({"diameter": 1e-3, "cd_normal": -1.0}, "cd_normal="), ({"diameter": 1e-3, "cd_tangential": float("inf")},
                                                             "cd_tangential="),
    ({"diameter": 1e-3, "air_density": -1.2}, "air_density="), ({"tip_drag_area": -1.0}, "tip_drag_area="),
    ({"wind": (1.0, 2.0, 3.0)}, "wind="), ({"cd_normal": 1.0}, "cd_normal"), ({"bending_damping": -1.0},
                                                                             "bending_damping="),
    ({"ei": "abc"}, "ei"),
])
def test_bad_si_body_is_refused_naming_it(kw, name):
    with pytest.raises(SnappingInputError, match=name):
        Body.from_si(L, M, **kw)


def test_bad_scales_of_a_body_are_refused():
    with pytest.raises(SnappingInputError, match="length="):
        Body.from_si(-1.0, M, ei=1.0)


CLI_SI_BAD = [
    (["--ei", "1e-3"], "--ei"),  # no --length/--mass
    (["--length", "2", "--mass", "0.02", "--ei=-1e-3"], "--ei"),
    (["--length", "2", "--mass", "0.02", "--ei", "nan"], "--ei"),
    (["--length", "2", "--mass", "0.02", "--ei", "1e-3", "--bending", "1e-3"], "--ei"),
    (["--length", "2", "--mass", "0.02", "--diameter=-1"], "--diameter"),
    (["--length", "2", "--mass", "0.02", "--diameter", "1e-3", "--drag-normal", "1"], "--diameter"),
    (["--length", "2", "--mass", "0.02", "--cd-normal", "1"], "--cd-normal"),
    (["--length", "2", "--mass", "0.02", "--diameter", "1e-3", "--cd-normal=-1"], "--cd-normal"),
    (["--length", "2", "--mass", "0.02", "--diameter", "1e-3", "--cd-tangential", "inf"], "--cd-tangential"),
    (["--length", "2", "--mass", "0.02", "--diameter", "1e-3", "--air-density=-1"], "--air-density"),
    (["--length", "2", "--mass", "0.02", "--air-density", "1.2"], "--air-density"),
    (["--length", "2", "--mass", "0.02", "--tip-drag-area=-1"], "--tip-drag-area"),
    (["--length", "2", "--mass", "0.02", "--wind-si", "1"], "--wind-si"),
    (["--length", "2", "--mass", "0.02", "--wind-si", "1,nan"], "--wind"),
    (["--length", "2", "--mass", "0.02", "--wind-si", "1,0", "--wind", "1,0"], "--wind-si"),
    (["--length=-2", "--mass", "0.02", "--ei", "1"], "--length"),
]


@pytest.mark.parametrize("extra, opt", CLI_SI_BAD)
def test_cli_bad_si_body_option_is_one_line_exit_2(extra, opt, capsys):
    argv = ["simulate", "--chi", "0.3", "--N", "10", "--t-end", "1e-3", "--json", "--no-progress", *extra]
    try:
        status = main(argv)
    except SystemExit as exc:
        status = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and opt in err[0] and "error" in err[0], err


def test_cli_si_body_runs_the_same_as_its_numbers_and_prints_them(capsys):
    base = ["simulate", "--chi", "0.3", "--N", "16", "--t-end", "0.3", "--no-progress"]
    si = ["--length", str(L), "--mass", str(M), "--ei", "2e-3", "--diameter", "1.5e-3", "--tip-drag-area", "2e-5",
          "--wind-si", "1,0"]
    assert main(base + si + ["--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    n = units.body_numbers(L, M, ei=2e-3, diameter=1.5e-3, tip_drag_area=2e-5, wind=(1.0, 0.0))
    assert out["body"]["beta"] == n["bending"] and out["body"]["drag_normal"] == n["drag_normal"]
    assert out["body"]["drag_tangential"] == n["drag_tangential"] and out["body"]["tip_drag"] == n["tip_drag"]
    assert out["body"]["wind"] == list(n["wind"])
    assert out["body_si"]["ei"] == {"value": 2e-3, "units": "N m2"}
    assert out["body_si"]["cd_normal"]["value"] == units.CD_NORMAL and out["body_si"]["air_density"]["value"] == 1.2
    ref = run(Problem.catenary(0.3, 16, body=Body(**n)), t_end=0.3).summary()
    assert out["v_peak"] == ref["v_peak"] and out["energy_drift"] == ref["energy_drift"]  # bit for bit
    assert ref["body"] == out["body"]  # the API's summary has the numbers too
    assert main(base + si) == 0
    text = capsys.readouterr().out
    assert "body: beta" in text and "bending number B/(lambda g L^3)" in text and "from SI: ei" in text


def test_summarize_compacts_profiles():
    b = Body(Body.taper_profile(1e-3, 0.1), drag_normal=0.5, tip_drag=0.1, clamp=0.0)
    p = Problem.catenary(0.3, 20, body=b)
    d = summarize(json.dumps(p.body.describe(p.links.h)))
    assert d["beta"][1] == pytest.approx(1e-3) and d["beta"][0] < 2e-4
    assert d["drag_normal"] == 0.5 and d["tip_drag"] == 0.1 and d["clamp"] == 0.0 and "wind" not in d
    assert summarize(Body().describe()) == {}


# ----------------------------------------------------------------------- sweeps
def test_sweep_with_a_body_and_combine_keeps_it(tmp_path):
    from snapping import sweep

    body = Body(1e-3, drag_normal=0.5)
    grid = sweep.Grid(chi=[0.3, 0.4], N=[16], options={"tol": 1e-7, "body": body})
    assert grid.options["body"] == body.describe()
    paths = sweep.run_sweep(grid, tmp_path / "s", workers=1, progress=False)
    ds = sweep.combine(paths)
    assert json.loads(ds.attrs["body"]) == body.describe()
    ref = run(Problem.catenary(0.4, 16, body=body), tol=1e-7).dataset.attrs
    assert float(ds.v_peak.sel(chi=0.4, N=16)) == ref["v_peak"]
    other = run(Problem.catenary(0.5, 16, body=Body(2e-3)), tol=1e-7, output=tmp_path / "other.nc").path
    with pytest.raises(SnappingInputError, match="different body"):
        sweep.combine([*paths, other])
    plain = run(0.5, 16, tol=1e-7, output=tmp_path / "plain.nc").path
    with pytest.raises(SnappingInputError, match="different initial"):  # (a run without a body)
        sweep.combine([*paths, plain])
    with pytest.raises(SnappingInputError, match="body"):
        sweep.Grid(chi=[0.3], N=[16, 20], options={"body": Body(np.ones(17) * 1e-3)})
    with pytest.raises(SnappingInputError, match="ensemble"):
        sweep.run_sweep(sweep.Grid(chi=[0.3, 0.4], N=[16], options={"body": body}), tmp_path / "e", ensemble=2,
                        progress=False)


def test_cli_sweep_with_an_si_body(tmp_path, capsys):
    status = main(["sweep", "--chi", "0.3", "--N", "12", "-o", str(tmp_path / "s"), "--workers", "1", "--json",
                   "--length", "2", "--mass", "0.02", "--ei", "1e-3", "--diameter", "1e-3"])
    out = json.loads(capsys.readouterr().out)
    assert status == 0 and out["body"]["beta"] == pytest.approx(1e-3 / (0.01 * 9.81 * 8))
    assert out["body"]["drag_normal"] == pytest.approx(0.144)


# ------------------------------------------------------------------- converge
def test_converge_with_bending_converges_to_the_rod_at_second_order():
    """Uniform chains of 50..400 links with beta = 1e-4 at chi = 0.25, released from the line's
    rest shape (the heavy elastica, the default start with bending): the peak speed and
    acceleration and the snapping time converge with an observed order near 2 (measured:
    2.02, 2.12, 2.23; consistent lumping; from the catenary 1.89, 2.01, 2.07 to a limit of
    5.909). The peak tension and curvature do not yet: the fold's radius sqrt(B/T) is ~3e-3
    there, about one link of the finest level."""
    from snapping import continuum

    c = continuum.converge(0.25, levels=4, n0=50, body=Body(1e-4))
    a = c.dataset.attrs
    assert a["grading"] == "uniform" and c.dataset.n_links.values.tolist() == [50, 100, 200, 400]
    assert c.summary()["body"] == {"beta": 1e-4}
    for q in ("v_peak", "a_peak", "t_snap_v"):
        assert 1.6 < a[f"{q}_order"] < 2.5, (q, a[f"{q}_order"])
    assert a["v_peak_limit"] == pytest.approx(5.788, abs=0.01)
    with pytest.raises(SnappingInputError, match="n0"):
        continuum.converge(0.25, levels=3, n0=50, ratio=0.3, body=Body(1e-4))


def test_clamp_at_the_start_keeps_profiles_given_as_functions():
    b = Body.from_si(L, M, ei=lambda s: 1e-3 * (1.0 - 0.5 * s / L), diameter=lambda s: 1e-3, clamp="start")
    p = Problem.catenary(0.3, 12, body=b)
    assert isinstance(p.body.clamp, float) and callable(p.body.bending)
    beta = p.body.node_values("bending", p.links.h)
    assert beta[-1] == pytest.approx(1e-3 / (LAM * G * L ** 3)) and beta[0] == pytest.approx(beta[-1] / 2)
    assert p.body.numbers(p.links.h)["beta"] == pytest.approx([beta[0], beta[-1]])


def test_cli_converge_with_a_body(capsys):
    status = main(["converge", "--chi", "0.3", "--levels", "3", "--bending", "1e-3", "--drag-normal", "0.5", "--n0",
                   "10", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert status == 0 and out["body"] == {"beta": 1e-3, "drag_normal": 0.5} and out["grading"] == "uniform"
    assert out["levels"]["n_links"] == [10, 20, 40]


@pytest.mark.parametrize("argv, opt", [
    (["converge", "--chi", "0.3", "--n0", "10"], "--n0"),  # no body: fold-following levels
    (["converge", "--chi", "0.3", "--bending", "1e-3", "--n0", "0"], "n0"),
    (["converge", "--chi", "0.3", "--bending=-1"], "--bending"),
    (["converge", "--chi", "0.3", "--ei", "1"], "--ei"),
    (["sweep", "--chi", "0.3", "--N", "10", "-o", "unused_dir", "--drag-normal", "nan"], "--drag-normal"),
    (["sweep", "--chi", "0.3", "--N", "10", "-o", "unused_dir", "--length", "1", "--mass", "0.01", "--diameter=-1"],
     "--diameter"),
])
def test_cli_sweep_and_converge_bad_body_option(argv, opt, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    try:
        status = main(argv)
    except SystemExit as exc:
        status = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and opt in err[0], err
    assert not (tmp_path / "unused_dir").exists() or not any((tmp_path / "unused_dir").glob("*.nc"))


def test_api_bad_body_of_sweep_and_converge_is_refused_by_name():
    from snapping import continuum, sweep

    with pytest.raises(SnappingInputError, match=r"^body=str"):
        continuum.converge(0.3, body="x")
    with pytest.raises(SnappingInputError, match="numbers"):
        continuum.converge(0.3, body=Body(np.full(11, 1e-3)))
    with pytest.raises(SnappingInputError, match=r"options\['body'\]=int"):
        sweep.Grid(chi=[0.3], N=[10], options={"body": 3})
    c = continuum.converge(0.5, levels=3, first=-2, body=Body())  # a body that changes nothing: the string's study
    assert c.dataset.attrs["grading"] == "fold" and "body" not in c.dataset.attrs


def test_wind_without_drag_is_refused_not_ignored(capsys):
    """The wind acts on a line only through its drag: asked for on the command line without any,
    it is refused by name (it used to run as if it had not been given, and leave no trace in
    the file)."""
    assert not Body(wind=(0.5, 0.0)).active  # (the API: an inactive body, documented)
    base = ["simulate", "--chi", "0.25", "--N", "16", "--t-end", "0.1", "--no-progress"]
    for extra in (["--wind", "0.5,0"], ["--length", "2", "--mass", "0.02", "--wind-si", "3,0"]):
        assert main(base + extra) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "needs drag" in err[0] and "--drag-normal" in err[0], err


@pytest.mark.parametrize("opt, value, needle", [
    ("--bending", "-1e-4", "--bending=-0.0001 is out of range"),
    ("--bending", "-inf", "--bending=-inf"),
    ("--ei", "-1e-3", "--ei=-0.001 is out of range"),
])
def test_negative_numbers_in_any_form_reach_the_check_of_their_option(opt, value, needle, capsys):
    """argparse alone takes only -1 and -.5 for numbers; -1e-4 or -inf read as unknown options
    ("expected one argument"): the option's own check names the value instead."""
    si = ["--length", "2", "--mass", "0.02"] if opt == "--ei" else []
    assert main(["simulate", "--chi", "0.25", "--N", "16", "--t-end", "0.1", *si, opt, value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err


def test_a_negative_wind_component_is_a_value(capsys):
    """--wind -0.5,0 (a wind towards -x) is a valid value, not an option."""
    assert main(["simulate", "--chi", "0.25", "--N", "16", "--t-end", "0.1", "--no-progress", "--json",
                 "--wind", "-0.5,0", "--drag-normal", "1"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["body"]["wind"] == [-0.5, 0.0]
