"""SI units (snapping.units and the CLI's --length/--mass/--g): the scales against hand values
and pint's dimensions, a run Dataset converted exactly and back, and the options of the CLI."""

import json
import math

import numpy as np
import pytest
import xarray as xr

from snapping import schema, units
from snapping._validate import SnappingInputError
from snapping.cli import main
from snapping.estimates import CHAIN_RANGE, Chain
from snapping.simulate import run
from snapping.simulate.problem import from_options

L, M, G = 1.022, 0.0208, 9.81  # the paper's chain

#: the SI value of each unit for the paper's chain, computed by hand
HAND = {
    "length": 1.022,
    "mass": 0.0208,
    "time": 0.32276835155659966,  # sqrt(1.022 / 9.81)
    "speed": 3.1663575287702432,  # sqrt(9.81 * 1.022)
    "acceleration": 9.81,
    "force": 0.204048,  # 0.0208 * 9.81
    "energy": 0.208537056,  # 0.0208 * 9.81 * 1.022
    "curvature": 0.9784735812133072,  # 1 / 1.022
    "dimensionless": 1.0,
}

#: CF units each kind must carry, and the pint unit names (not CF strings) of the same dimension
CF = {"length": "m", "mass": "kg", "time": "s", "speed": "m s-1", "acceleration": "m s-2", "force": "N",
      "energy": "J", "curvature": "m-1", "dimensionless": "1"}
PINT_NAMES = {"length": "meter", "mass": "kilogram", "time": "second", "speed": "meter / second",
              "acceleration": "meter / second ** 2", "force": "newton", "energy": "joule",
              "curvature": "1 / meter", "dimensionless": "dimensionless"}


# -------------------------------------------------------------------------- scales
def test_scales_against_hand_values():
    s = units.Scales(L, M, G)
    for kind, value in HAND.items():
        assert s.factor(kind) == pytest.approx(value, rel=1e-14), kind
        assert s.units(kind) == CF[kind]
    assert round(s.time, 5) == 0.32277 and round(s.force, 6) == 0.204048
    assert (s.time, s.speed, s.acceleration, s.force, s.energy, s.curvature) == tuple(
        s.factor(k) for k in ("time", "speed", "acceleration", "force", "energy", "curvature"))
    assert units.Scales(L, M).g == 9.81 == units.G_STANDARD


def test_scales_follow_dimensional_analysis():
    s = units.Scales(2.5, 0.3, 7.0)  # no special numbers: a wrong exponent shows
    f = s.factor
    assert f("time") == pytest.approx(math.sqrt(2.5 / 7.0), rel=1e-14)
    assert f("speed") == pytest.approx(f("length") / f("time"), rel=1e-14)
    assert f("acceleration") == pytest.approx(f("speed") / f("time"), rel=1e-14)
    assert f("acceleration") == pytest.approx(7.0, rel=1e-14)
    assert f("force") == pytest.approx(f("mass") * f("acceleration"), rel=1e-14)
    assert f("energy") == pytest.approx(f("force") * f("length"), rel=1e-14)
    assert f("curvature") == pytest.approx(1.0 / f("length"), rel=1e-14)


def test_scales_pass_pints_dimension_checks():
    import pint

    ureg = units.registry()
    s = units.Scales(2.5, 0.3, 7.0)
    for kind, name in PINT_NAMES.items():
        q = s.quantity(kind)
        assert q.dimensionality == ureg.Quantity(1.0, name).dimensionality, kind
        assert q.to(name).magnitude == pytest.approx(s.factor(kind), rel=1e-14)
    # the products of units are the units of the products, as pint computes them
    assert (s.quantity("length") / s.quantity("time")).to("m/s").magnitude == pytest.approx(s.speed, rel=1e-14)
    assert (s.quantity("mass") * s.quantity("speed") ** 2).to("J").magnitude == pytest.approx(
        s.energy * s.factor("mass") * s.speed**2 / s.energy, rel=1e-14)
    assert (s.quantity("force") * s.quantity("length")).to("J").magnitude == pytest.approx(s.energy, rel=1e-14)
    with pytest.raises(pint.DimensionalityError):
        s.quantity("force").to("J")


def test_scales_agree_with_estimates_chain():
    c, s = Chain(L, M, G), units.Scales(L, M, G)
    assert units.SCALE_RANGE == CHAIN_RANGE
    assert c.time(1.0) == pytest.approx(s.time, rel=1e-14)
    assert c.velocity(1.0) == pytest.approx(s.speed, rel=1e-14)
    assert c.force(1.0) == pytest.approx(s.force, rel=1e-14)
    assert c.energy(1.0) == pytest.approx(s.energy, rel=1e-14)
    assert c.distance(1.0) == s.length and c.acceleration(1.0) == s.acceleration


@pytest.mark.parametrize("name", ["length", "mass", "g"])
@pytest.mark.parametrize("bad", [-1.0, 0.0, float("nan"), float("inf"), "abc", True, 1e31, None])
def test_bad_scales_are_named_errors(name, bad):
    kw = {"length": L, "mass": M, "g": G, name: bad}
    with pytest.raises(SnappingInputError, match=rf"^{name}="):
        units.Scales(**kw)


def test_unknown_kind_is_named():
    with pytest.raises(SnappingInputError, match="kind='volume'"):
        units.Scales(L, M).factor("volume")


# ------------------------------------------------------------------ the kind tables
def test_every_schema_variable_has_a_kind():
    names = set(schema.ALL_VARS) | set(schema.COORDS) - {"snapshot_kind"}
    assert names <= set(units.VARIABLE_KINDS), sorted(names - set(units.VARIABLE_KINDS))
    strings = {"method", "chords", "initial", "status", "stop_reason", "failure", "snap_note", "snapping_version",
               "wall_time", "problem", "pin_motion", "start", "body", "start_rest"}
    numeric = (set(schema.INPUT_ATTRS) | set(schema.RESULT_ATTRS) | set(schema.PROBLEM_ATTRS)) - strings
    assert numeric <= set(units.VALUE_KINDS), sorted(numeric - set(units.VALUE_KINDS))
    assert set(units.VARIABLE_KINDS.values()) | set(units.VALUE_KINDS.values()) <= set(units.KIND_UNITS)


# ---------------------------------------------------------------------- the Dataset
@pytest.fixture(scope="module")
def tiny():
    return run(0.5, 4, t_end=0.01, progress=False).dataset


@pytest.fixture(scope="module")
def general():
    """A general run: a tip mass and a pulled held end (pin and problem variables)."""
    p = from_options(chi=0.5, N=4, chords="arclength", supports=None, shape=None, tip_mass=0.2, taper=None,
                     lumping=None, pin_motion="pull:1,0", gravity=1.0)
    return run(p, None, method="fast", t_end=0.01, progress=False).dataset


@pytest.mark.parametrize("which", ["tiny", "general"])
def test_dataset_to_si_scales_each_variable_exactly(which, request):
    ds = request.getfixturevalue(which)
    s = units.Scales(L, M, G)
    si = units.to_si(ds, L, M, G)
    expected = {"t": "s", "dt": "s", "v_max": "m s-1", "a_max": "m s-2", "sigma_max": "N", "kappa_max": "m-1",
                "energy": "J", "x": "m", "vy": "m s-1", "ax": "m s-2", "tension": "N", "curvature": "m-1",
                "s_node": "m", "link_error": "1", "error_estimate": "1", "pin_force_y": "N"}
    if which == "general":
        expected.update(pin_x="m", pin_vx="m s-1", pin_work="J", node_mass="kg", link_length="m", start_vx="m s-1")
    for name, u in expected.items():
        assert si[name].attrs["units"] == u, name
    assert set(si.variables) == set(ds.variables)
    for name in ds.variables:
        kind = units.VARIABLE_KINDS.get(str(name))
        if kind is None:
            assert str(name) == "snapshot_kind"
            continue
        assert si[name].attrs["units"] == units.KIND_UNITS[kind]
        assert si[name].attrs["long_name"] == ds[name].attrs["long_name"]
        assert si[name].dims == ds[name].dims
        np.testing.assert_array_equal(si[name].values, ds[name].values * s.factor(kind), err_msg=str(name))
    # by hand: the last time and the peak speed in SI
    assert float(si["t"][-1]) == pytest.approx(float(ds["t"][-1]) * HAND["time"], rel=1e-14)
    assert float(si["v_max"].max()) == pytest.approx(float(ds["v_max"].max()) * HAND["speed"], rel=1e-14)
    assert si.attrs["units_system"] == "SI" and si.attrs["si_length"] == L and si.attrs["si_g"] == G
    assert ds.attrs.get("units_system") is None and ds["v_max"].attrs["units"] == "1"  # the input is untouched


def test_round_trip_si_back_to_nondimensional(general):
    ds = general.copy()
    ds.attrs[schema.DIGEST_ATTR] = "x"  # a stale digest is not carried into SI
    si = units.to_si(ds, 2.5, 0.3, g=7.0)
    assert schema.DIGEST_ATTR not in si.attrs
    back = units.from_si(si)
    xr.testing.assert_allclose(back, general, rtol=1e-15, atol=0)
    want = {k: v for k, v in general.attrs.items() if k != schema.DIGEST_ATTR}
    assert set(back.attrs) == set(want)
    for k, v in want.items():
        a, b = np.asarray(back.attrs[k]), np.asarray(v)
        assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), k
    for name in general.variables:
        assert back[name].attrs == general[name].attrs, name
    with pytest.raises(SnappingInputError, match="already in SI"):
        units.to_si(si, L, M)
    with pytest.raises(SnappingInputError, match="not a Dataset from snapping.units.to_si"):
        units.from_si(general)


def test_to_si_refuses_unknown_nondimensional_variables_and_keeps_si_ones(tiny):
    ds = tiny.assign(mystery=("step", np.ones(tiny.sizes["step"]), {"units": "1"}))
    with pytest.raises(SnappingInputError, match="mystery"):
        units.to_si(ds, L, M)
    ds = tiny.assign(wall_time=((), 1.5, {"units": "s"}))
    assert float(units.to_si(ds, L, M)["wall_time"]) == 1.5
    with pytest.raises(SnappingInputError, match="length"):
        units.to_si(tiny)


def test_si_dataset_writes_as_netcdf(tiny, tmp_path):
    units.to_si(tiny, L, M).to_netcdf(tmp_path / "si.nc")
    with xr.open_dataset(tmp_path / "si.nc") as f:
        assert f["tension"].attrs["units"] == "N" and f.attrs["units_system"] == "SI"


def test_summary_to_si(tiny):
    from snapping.simulate import summary

    summ = summary(tiny)
    si = units.summary_to_si(summ, L, M, G)
    vals = si["values"]
    assert vals["v_peak"] == {"value": pytest.approx(summ["v_peak"] * HAND["speed"], rel=1e-14), "units": "m s-1"}
    assert vals["sigma_peak"]["units"] == "N"
    assert vals["sigma_peak"]["value"] == pytest.approx(summ["sigma_peak"] * HAND["force"], rel=1e-14)
    assert vals["t_final"]["value"] == pytest.approx(summ["t_final"] * HAND["time"], rel=1e-14)
    assert vals["energy_drift"]["units"] == "J"
    assert summ["t_snap_v"] is None and vals["t_snap_v"] == {"value": None, "units": "s"}  # no snap: absent
    for k in ("chi", "N", "tol", "n_steps", "wall_time", "status"):
        assert k not in vals
    assert si["scales"]["time"]["value"] == pytest.approx(HAND["time"], rel=1e-14)
    general = units.summary_to_si({"tip_mass": 0.2, "gravity": 1.0}, scales=units.Scales(L, M))["values"]
    assert general["tip_mass"]["value"] == pytest.approx(0.2 * M) and general["gravity"]["units"] == "m s-2"


# --------------------------------------------------------------------------- the CLI
SIM = ["simulate", "--chi", "0.5", "--N", "20", "--method", "fast", "--no-progress"]
SI = ["--length", "1.022", "--mass", "0.0208"]


def _cli(argv, capsys):
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def _si_line(out, name):
    """(nondimensional, SI, units) of row ``name`` of the SI table."""
    block = out.split("In SI", 1)[1]
    for line in block.splitlines():
        parts = line.split()
        if parts and parts[0] == name:
            return float(parts[1]), float(parts[2]), " ".join(parts[3:])
    raise AssertionError(f"no SI row {name!r} in {block!r}")


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("si") / "run.nc"
    assert main(SIM + ["-o", str(path)]) == 0
    return str(path)


def test_cli_simulate_prints_both_unit_systems(capsys):
    code, out, _ = _cli(SIM + SI, capsys)
    assert code == 0
    v, v_si, u = _si_line(out, "v_peak")
    assert u == "m s-1" and v_si == pytest.approx(v * HAND["speed"], rel=1e-5)
    t, t_si, u = _si_line(out, "t_snap_v")
    assert u == "s" and t_si == pytest.approx(t * HAND["time"], rel=1e-5)
    assert _si_line(out, "sigma_peak")[2] == "N"
    assert "chain length 1.022 m, mass 0.0208 kg, g = 9.81" in out
    code, out, _ = _cli(SIM, capsys)
    assert code == 0 and "In SI" not in out
    assert "units: nondimensional" in out and "--length METERS --mass KG" in out


def test_cli_simulate_json_si_part(capsys):
    code, out, _ = _cli(SIM + SI + ["--g", "9.8", "--json"], capsys)
    assert code == 0
    d = json.loads(out)
    si = d["si"]
    assert si["system"] == "SI" and si["scales"]["g"] == {"value": 9.8, "units": "m s-2"}
    assert si["values"]["v_peak"]["units"] == "m s-1"
    assert si["values"]["v_peak"]["value"] == pytest.approx(d["v_peak"] * math.sqrt(9.8 * 1.022), rel=1e-14)
    assert si["values"]["a_peak"]["value"] == pytest.approx(d["a_peak"] * 9.8, rel=1e-14)
    assert si["values"]["sigma_peak"]["value"] == pytest.approx(d["sigma_peak"] * 0.0208 * 9.8, rel=1e-14)
    assert d["v_peak"] < 10  # the nondimensional summary itself is unchanged
    code, out, _ = _cli(SIM + ["--json"], capsys)
    d = json.loads(out)
    assert "si" not in d and d["units_note"].startswith("units: nondimensional")


def test_cli_fit_si(run_file, capsys):
    code, out, _ = _cli(["fit", run_file, "--no-joint", "--json"] + SI, capsys)
    assert code == 0
    d = json.loads(out)
    vals = d["si"]["values"]
    assert vals["t_star"]["units"] == "s"
    assert vals["t_star"]["value"] == pytest.approx(d["snap"]["t_star"] * HAND["time"], rel=1e-14)
    assert vals["peak_sigma_max"]["value"] == pytest.approx(d["snap"]["peaks"]["sigma_max"]["value"] * HAND["force"])
    assert vals["delta_c"]["units"] == "m"
    code, out, _ = _cli(["fit", run_file, "--no-joint"] + SI, capsys)
    assert code == 0
    t, t_si, u = _si_line(out, "t_star")
    assert u == "s" and t_si == pytest.approx(t * HAND["time"], rel=1e-5)
    code, out, _ = _cli(["fit", run_file, run_file, "--no-joint"], capsys)
    assert code == 0 and "units: nondimensional" in out
    code, out, _ = _cli(["fit", run_file, run_file, "--no-joint", "--json"] + SI, capsys)
    assert len(json.loads(out)["si"]["runs"]) == 2


def test_cli_sweep_si(tmp_path, capsys):
    argv = ["sweep", "--chi", "0.5", "--N", "10", "--method", "fast", "--workers", "1", "-o", str(tmp_path)]
    code, out, _ = _cli(argv + SI + ["--json"], capsys)
    assert code == 0
    d = json.loads(out)
    r, si = d["runs"][0], d["si"]["runs"][0]
    assert (si["chi"], si["N"]) == (0.5, 10)
    assert si["v_peak"]["value"] == pytest.approx(r["v_peak"] * HAND["speed"], rel=1e-14)
    assert si["t_snap_v"] == {"value": pytest.approx(r["t_snap_v"] * HAND["time"], rel=1e-14), "units": "s"}
    code, out, _ = _cli(argv + SI, capsys)
    assert code == 0
    v, v_si, u = _si_line(out.replace("chi=0.5 N=10 ", ""), "v_peak")
    assert u == "m s-1" and v_si == pytest.approx(v * HAND["speed"], rel=1e-5)
    code, out, _ = _cli(argv, capsys)
    assert "units: nondimensional" in out


@pytest.mark.slow
def test_cli_converge_si(capsys):
    code, out, _ = _cli(["converge", "--chi", "0.5", "--levels", "2", "--first", "-3", "--json"] + SI, capsys)
    assert code == 0
    d = json.loads(out)
    vals = d["si"]["values"]
    assert vals["v_peak_limit"]["value"] == pytest.approx(d["v_peak_limit"] * HAND["speed"], rel=1e-14)
    assert vals["t_snap_v_error"]["units"] == "s"
    assert d["si"]["levels"]["sigma_peak"]["value"][0] == pytest.approx(d["levels"]["sigma_peak"][0] * HAND["force"])


BAD = [
    (["--length", "-1", "--mass", "0.02"], "--length"),
    (["--length", "0", "--mass", "0.02"], "--length"),
    (["--length", "nan", "--mass", "0.02"], "--length"),
    (["--length", "1", "--mass", "0"], "--mass"),
    (["--length", "1", "--mass", "-0.5"], "--mass"),
    (["--length", "1", "--mass", "inf"], "--mass"),
    (["--length", "1", "--mass", "0.02", "--g", "0"], "--g"),
    (["--length", "1", "--mass", "0.02", "--g", "nan"], "--g"),
    (["--length", "1"], "--mass"),
    (["--mass", "0.02"], "--length"),
    (["--g", "9.8"], "--g"),
    (["--length", "abc", "--mass", "0.02"], "--length"),
]
COMMANDS = {
    "simulate": SIM,
    "fit": ["fit", "{run}"],
    "sweep": ["sweep", "--chi", "0.5", "--N", "10", "-o", "{tmp}"],
    "converge": ["converge", "--chi", "0.5", "-o", "{tmp}"],
}


@pytest.mark.parametrize("command", list(COMMANDS))
@pytest.mark.parametrize("extra, option", BAD)
def test_cli_bad_si_input_exits_2_naming_the_option(command, extra, option, run_file, tmp_path, capsys):
    argv = [a.format(run=run_file, tmp=tmp_path / "out") for a in COMMANDS[command]] + extra
    code, out, err = _cli(argv, capsys)
    assert code == 2, (argv, out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "error" in lines[0] and "Traceback" not in err, err
    assert option in lines[0], lines[0]
    assert not (tmp_path / "out").exists()  # refused before any work


def test_cli_estimate_g_is_the_shared_option(capsys):
    code, out, _ = _cli(["estimate", "--chi", "0.25", "--g", "9.8", "--json"], capsys)
    assert code == 0 and json.loads(out)["chain"]["g_m_per_s2"] == 9.8
    code, out, _ = _cli(["estimate", "--chi", "0.25", "--json"], capsys)
    assert json.loads(out)["chain"]["g_m_per_s2"] == 9.81
    code, _, err = _cli(["estimate", "--chi", "0.25", "--g", "-1"], capsys)
    assert code == 2 and "--g" in err
    code, out, _ = _cli(["estimate", "--help"], capsys)
    assert "--g M_PER_S2" in out and "default 9.81" in out
    for command in COMMANDS:
        _, out, _ = _cli([command, "--help"], capsys)
        assert "--length METERS" in out and "--mass KG" in out and "--g M_PER_S2" in out, command
