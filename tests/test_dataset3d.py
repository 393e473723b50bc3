"""The 3D run Dataset (snapping.spatial.dataset3d), the CLI's 3D runs and the 3D figures.

Checks against independent references: the planar run (snapping.simulate, method fast) of
the same planar problem gives the snapshots x, y, vx, vy and the tensions (its own solve, in
link angles), and its energy zero; the z of a planar problem is exactly 0.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from snapping import schema
from snapping.cli import main
from snapping.simulate import run
from snapping.simulate.dataset import load_run
from snapping.simulate.problem import Problem
from snapping.spatial import Problem3D
from snapping.spatial.dataset3d import run3d_dataset

TIMES = [0.5, 1.0]


@pytest.fixture(scope="module")
def pair():
    planar = run(Problem.catenary(0.25, 30), method="fast", tol=1e-11, snapshot_times=TIMES, progress=False).dataset
    spatial = run3d_dataset(Problem3D.catenary(0.25, 30), tol=1e-11, snapshot_times=TIMES)
    return planar, spatial


def _requested(ds):
    return ds.isel(snapshot=np.flatnonzero(ds["snapshot_kind"].values == "requested"))


def test_planar_problem_in_3d_has_the_planar_snapshots(pair):
    planar, spatial = pair
    p, s = _requested(planar), _requested(spatial)
    np.testing.assert_array_equal(s["t_snapshot"].values, TIMES)
    np.testing.assert_array_equal(p["t_snapshot"].values, TIMES)
    for name, tol in (("x", 1e-12), ("y", 1e-12), ("vx", 1e-11), ("vy", 1e-11), ("tension", 1e-11)):
        np.testing.assert_allclose(s[name].values, p[name].values, rtol=0, atol=tol, err_msg=name)
    assert np.all(spatial["z"].values == 0.0) and np.all(spatial["vz"].values == 0.0)
    assert np.all(spatial["z_amp"].values == 0.0)
    # the energy has the planar zero (hanging straight at rest), and the same start
    assert spatial.attrs["energy_initial"] == pytest.approx(planar.attrs["energy_initial"], abs=1e-14)
    assert spatial.attrs["v_peak"] == pytest.approx(planar.attrs["v_peak"], rel=1e-10)
    assert spatial.attrs["t_snap_v"] == pytest.approx(planar.attrs["t_snap_v"], abs=1e-8)


def test_snapshots_do_not_change_the_steps():
    from snapping.spatial.solve3d import run3d

    p = Problem3D.catenary(0.3, 15).perturbed(1e-3)
    a = run3d(p, tol=1e-9)
    b = run3d(p, tol=1e-9, snapshot_times=[0.0, 0.2, 0.7, 1.0, 50.0])
    np.testing.assert_array_equal(a["record"], b["record"])
    assert a["v_peak"] == b["v_peak"] and [s[0] for s in b["snapshots"]] == [0.0, 0.2, 0.7, 1.0]
    # a snapshot is the state at its time: the dense output agrees with a run stopped there
    c = run3d(p, tol=1e-12, t_end=0.7)
    np.testing.assert_allclose(b["snapshots"][2][2], c["state"], rtol=0, atol=3e-9)


def test_names_are_in_the_schema_and_a_planar_run_has_no_3d_name(pair):
    planar, spatial = pair
    known = {**schema.ALL_VARS, **schema.SPATIAL_VARS}
    for name, var in spatial.data_vars.items():
        assert name in known, name
        assert var.attrs["units"] and var.attrs["long_name"], name
    for name in spatial.coords:
        assert name in schema.COORDS, name
    attrs_known = (set(schema.INPUT_ATTRS) | set(schema.RESULT_ATTRS) | set(schema.PROBLEM_ATTRS)
                   | set(schema.SPATIAL_ATTRS) | {"title", "Conventions", "units"})
    assert set(spatial.attrs) <= attrs_known, set(spatial.attrs) - attrs_known
    new = set(schema.SPATIAL_VARS) | set(schema.SPATIAL_ATTRS)
    assert not new & (set(schema.ALL_VARS) | set(schema.RESULT_ATTRS) | set(schema.INPUT_ATTRS))
    assert not new & (set(planar.data_vars) | set(planar.attrs))
    assert {"z", "vz", "z_amp", "vz_amp", "start_z", "start_vz"} <= set(spatial.data_vars)


def test_perturbed_run_dataset_records_the_out_of_plane_motion(tmp_path):
    eps = 1e-4
    p = Problem3D.catenary(0.25, 20).perturbed(eps)
    path = tmp_path / "run3d.nc"
    ds = run3d_dataset(p, tol=1e-9, snapshot_times=[0.3], output=path)
    back = load_run(path)
    assert int(back.attrs["dims"]) == 3 and json.loads(back.attrs["perturbation"])["eps"] == eps
    np.testing.assert_array_equal(back["z"].values, ds["z"].values)
    # the initial snapshot is the start; the record's z_amp is the snapshots' largest |z| (plane z = 0)
    np.testing.assert_allclose(ds["vz"].isel(snapshot=0).values, p.v[:, 2], rtol=0, atol=1e-16)
    for i, t in enumerate(ds["t_snapshot"].values):
        k = int(np.argmin(abs(ds["t"].values - t)))
        if ds["t"].values[k] == t:
            assert ds["z_amp"].values[k] == pytest.approx(float(abs(ds["z"].isel(snapshot=i)).max()), rel=1e-12)
    pk = ds.isel(snapshot=int(np.flatnonzero(ds["snapshot_kind"].values == "peak")[0]))
    assert float(abs(pk["z"]).max()) == pytest.approx(ds.attrs["z_amp_snap"], rel=1e-9)
    assert float(pk["speed"].max()) == pytest.approx(ds.attrs["v_peak"], rel=1e-9)
    # links exactly their length in every snapshot
    r = np.stack([ds[c].values for c in "xyz"], axis=-1)
    np.testing.assert_allclose(np.linalg.norm(np.diff(r, axis=1), axis=-1), 1 / 20, rtol=1e-12)


# ---------------------------------------------------------------- the CLI
def test_cli_dims3_writes_the_3d_run_file(tmp_path, capsys):
    path = tmp_path / "r.nc"
    assert main(["simulate", "--chi", "0.25", "--N", "12", "--perturb", "1e-4", "--tol", "1e-9", "--json",
                 "--snapshot-times", "0.5", "-o", str(path)]) == 0
    out = json.loads(capsys.readouterr().out)
    ds = load_run(path)
    ref = run3d_dataset(Problem3D.catenary(0.25, 12).perturbed(1e-4), tol=1e-9, snapshot_times=[0.5])
    assert out["dims"] == 3 and out["v_peak"] == ref.attrs["v_peak"] and out["z_amp_snap"] == ref.attrs["z_amp_snap"]
    np.testing.assert_array_equal(ds["z"].values, ref["z"].values)
    assert main(["simulate", "--dims", "3", "--chi", "0.25", "--N", "12", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["z_amp_max"] == 0.0


def test_cli_whirl_runs_the_steady_shape(tmp_path, capsys):
    path = tmp_path / "w.nc"
    assert main(["simulate", "--whirl", "2.5", "--N", "12", "--t-end", "1", "--tol", "1e-10", "--json",
                 "-o", str(path)]) == 0
    assert json.loads(capsys.readouterr().out)["stop_reason"] == "t_end"
    p = Problem3D.whirling(2.5, 12)
    ds = load_run(path)
    # a steady whirl: the start shape turned rigidly about the vertical (velocity -omega x e_z at t = 0)
    fin = ds.isel(snapshot=-1)
    t = float(fin["t_snapshot"])
    assert t == 1.0
    c, s = math.cos(2.5 * t), math.sin(2.5 * t)
    np.testing.assert_allclose(fin["x"].values, c * p.r[:, 0], rtol=0, atol=1e-8)
    np.testing.assert_allclose(fin["z"].values, -s * p.r[:, 0], rtol=0, atol=1e-8)
    np.testing.assert_allclose(fin["y"].values, p.r[:, 1], rtol=0, atol=1e-8)


@pytest.mark.parametrize("argv, word", [
    (["--chi", "0.25", "--N", "10", "--perturb", "nan"], "eps=nan"),
    (["--chi", "0.25", "--N", "10", "--perturb", "inf", "--perturb-mode", "random", "--seed", "1"], "eps=inf"),
    (["--whirl", "0.5", "--N", "10"], "omega=0.5 has no steady whirling shape"),
    (["--chi", "0.25", "--N", "10", "--perturb", "1e-3", "--bending", "1e-3", "--clamped"], "no 3D form"),
    (["--chi", "0.25", "--N", "10", "--perturb", "1e-3", "--dims", "2"], "--dims 2"),
    (["--whirl", "2.5", "--N", "10", "--chi", "0.3"], "--whirl"),
    (["--dims", "3", "--chi", "0.25", "--N", "10", "--method", "euler-richardson"], "--method"),
])
def test_cli_3d_bad_input_is_one_line_exit_2(argv, word, capsys):
    assert main(["simulate", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert word in err and len(err.splitlines()) == 1


# ---------------------------------------------------------------- figures
def test_figures_draw_from_a_small_run(tmp_path):
    from snapping.figures import save
    from snapping.spatial.figures3d import amplitude_vs_eps, chain_views, growth

    g = growth(0.5, 8, [1e-6, 1e-5, 1e-4], tol=1e-9)
    # linear growth: z/eps the same at every eps (independent of the figure: the runs themselves)
    ratio = g["z_amp_snap"] / g["eps"]
    assert np.ptp(ratio) < 1e-3 * ratio.mean() and ratio.mean() > 0
    fig = amplitude_vs_eps(g)
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    # the dotted linear-growth line through the smallest eps has slope 1 on the log-log axes
    dotted = [ln for ln in ax.get_lines() if ln.get_linestyle() == ":"]
    x, y = dotted[0].get_data()
    assert np.log(y[1] / y[0]) / np.log(x[1] / x[0]) == pytest.approx(1.0, abs=1e-12)
    ds = run3d_dataset(Problem3D.catenary(0.5, 8).perturbed(1e-2), tol=1e-8, snapshot_times=[0.4, 0.8])
    fig2 = chain_views(ds, n=3)
    assert len(fig2.axes[1].get_lines()) == 3
    z_drawn = fig2.axes[2].get_lines()[-1].get_ydata()
    pk = int(np.flatnonzero(ds["snapshot_kind"].values == "peak")[0])
    np.testing.assert_array_equal(z_drawn, ds["z"].isel(snapshot=pk).values)
    paths = save(fig2, tmp_path / "views")
    assert all(p.stat().st_size > 0 for p in paths)
