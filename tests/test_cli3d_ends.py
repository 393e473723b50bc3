"""The ends of a 3D run: its CLI options (a held end along a curve in space, gravity along
any direction, the whirl spun up), its bad input refused before any work, its names in SI,
and its rerun from the file (``snapping animate --frames``)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from snapping import units
from snapping.cli import main
from snapping.simulate.dataset import load_run
from snapping.spatial import Problem3D
from snapping.spatial import dataset3d as D
from snapping.spatial.held3d import Pin3D

L, M, G = 2.0, 0.5, 9.81


@pytest.fixture(scope="module")
def table_run(tmp_path_factory):
    """A 3D run whose held end follows samples in space (written and read back)."""
    t = np.linspace(0.0, 0.4, 9)
    pin = Pin3D.from_table(t, 0.2 * t * t, -0.1 * t, 0.3 * np.sin(t))
    p = Problem3D.catenary(0.3, 8).perturbed(1e-2).with_pin(pin)
    path = tmp_path_factory.mktemp("t3") / "table.nc"
    D.run3d_dataset(p, tol=1e-9, t_end=0.6, snapshot_times=[0.3], output=str(path))
    return p, load_run(path)


def test_rerun_from_the_file_repeats_the_run(table_run):
    p, ds = table_run
    q = D.problem3d_from_dataset(ds)
    for t in (0.0, 0.15, 0.4, 0.9):
        assert q.pin.kinematics(t) == p.pin.kinematics(t)
    np.testing.assert_array_equal(q.r, p.r)
    np.testing.assert_array_equal(q.v, p.v)
    again = D.rerun3d(ds, snapshot_times=[0.1, 0.2])
    np.testing.assert_array_equal(again["v_max"].values, ds["v_max"].values)  # (the same steps)
    assert list(again["t_snapshot"].values) == [0.0, 0.1, 0.2, 0.6]


def test_3d_dataset_converts_to_si_as_by_hand(table_run):
    _, ds = table_run
    si = units.to_si(ds, L, M, G)  # (every name has a kind: an unknown one raises)
    v, a, w = math.sqrt(G * L), G, math.sqrt(G / L)
    for name, unit, f in (("z", "m", L), ("vz", "m s-1", v), ("az", "m s-2", a), ("start_z", "m", L),
                          ("z_amp", "m", L), ("vz_amp", "m s-1", v), ("pin_table_z", "m", L),
                          ("angular_momentum_g", "kg m2 s-1", M * L * v)):
        assert si[name].attrs["units"] == unit, name
        np.testing.assert_allclose(si[name].values, ds[name].values * f, rtol=1e-15, atol=0, err_msg=name)
    vals = units.values_to_si({"whirl": 2.5, "z_amp_snap": 0.01, "angular_momentum_drift": 1e-9}, units.Scales(L, M, G))
    assert vals["whirl"] == {"value": pytest.approx(2.5 * w, rel=1e-15), "units": "s-1"}
    assert vals["z_amp_snap"]["value"] == pytest.approx(0.01 * L, rel=1e-15)
    assert vals["angular_momentum_drift"]["value"] == pytest.approx(1e-9 * M * L * v, rel=1e-15)


def test_cli_spun_up_whirl_with_si(capsys):
    assert main(["simulate", "--whirl", "2.5", "--spin-up", "0.3,0.05", "--N", "6", "--t-end", "0.4", "--json",
                 "--length", str(L), "--mass", str(M)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "completed" and out["z_amp_max"] > 0.0
    assert out["si"]["values"]["v_peak"]["value"] == pytest.approx(out["v_peak"] * math.sqrt(G * L), rel=1e-14)
    assert out["si"]["values"]["t_final"]["value"] == pytest.approx(0.4 * math.sqrt(L / G), rel=1e-14)


def test_cli_circle_about_an_axis_and_tilted_gravity(tmp_path, capsys):
    out = tmp_path / "c.nc"
    assert main(["simulate", "--chi", "0.3", "--N", "6", "--pin-motion", "circle:0.1,3,0.2", "--pin-axis", "0,0,1",
                 "--g-dir", "0.6,0.8,0", "--t-end", "0.5", "-o", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["dims"] == 3
    ds = load_run(out)
    q = D.problem3d_from_dataset(ds)
    assert q.pin.kind == "circle" and q.pin.axis == (0.0, 0.0, 1.0) and q.pin.duration == 0.2
    assert q.g_dir == (0.6, 0.8, 0.0)
    fin = ds.isel(snapshot=-1)
    np.testing.assert_allclose([float(fin[c][-1]) for c in "xyz"], q.pin.position(0.5), rtol=0, atol=1e-15)


@pytest.mark.parametrize("argv, word", [
    (["--dims", "3", "--chi", "0.3", "--g-dir", "0,0,0"], "--g-dir=(0.0, 0.0, 0.0) has length 0"),
    (["--dims", "3", "--chi", "0.3", "--g-dir", "0,2,0"], "--g-dir=(0.0, 2.0, 0.0) has length 2"),
    (["--chi", "0.3", "--g-dir", "0,1"], "--g-dir"),
    (["--chi", "0.3", "--perturb", "nan"], "eps=nan"),
    (["--chi", "0.3", "--perturb", "-inf", "--perturb-kind", "shape"], "eps=-inf"),
    (["--whirl", "0.9"], "omega=0.9 has no steady whirling shape"),
    (["--whirl", "0.9", "--spin-up", "1,0"], "radius=0.0"),
    (["--chi", "0.3", "--spin-up", "1"], "needs --whirl"),
    (["--chi", "0.3", "--pin-motion", "circle:0.1,2", "--pin-axis", "0,0,0"], "axis=(0.0, 0.0, 0.0)"),
    (["--chi", "0.3", "--pin-motion", "circle:0.1,2,0,0.5"], "ramp=0 with --pin-motion t0=0.5"),
    (["--chi", "0.3", "--pin-motion", "pull3d:1,2"], "pull3d:AX,AY,AZ"),
    (["--chi", "0.3", "--pin-motion", "flick:1,0,0.3", "--pin-axis", "0,1,0"], "--pin-axis=(0.0, 1.0, 0.0) is only for a circle"),
    (["--chi", "0.3", "--pin-motion", "table:/nonexistent/pin.csv"], "pin.csv"),
    (["--whirl", "2.5", "--g-dir", "1,0,0"], "--whirl is about the vertical"),
])
def test_bad_3d_input_is_one_line_exit_2_before_any_run(argv, word, capsys, monkeypatch):
    def no_run(*a, **k):  # pragma: no cover - reached only when a check is missing
        raise AssertionError("a run started before the input was checked")

    monkeypatch.setattr(D, "run3d", no_run)
    assert main(["simulate", "--N", "6", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert word in err and len(err.splitlines()) == 1, err
