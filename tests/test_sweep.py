"""Sweeps: parallel, resumable, atomic, combined over (chi, N), on local processes and on Dask."""

import os
from pathlib import Path

import numpy as np
import pytest

from snapping import SnappingInputError, simulate
from snapping import sweep as S

OPTS = {"tol": 1e-7}


def test_sweep_runs_combines_and_skips_finished(tmp_path):
    grid = S.Grid(chi=[0.4, 0.7], N=[8, 12], options=OPTS)
    paths = S.run_sweep(grid, tmp_path, workers=2, progress=False)
    assert len(paths) == 4 and all(S.is_complete_run(p) for p in paths)
    # each file is the same run as a direct call (runs are deterministic)
    direct = simulate.run(0.7, 12, **OPTS).dataset
    ds = simulate.load_run(grid.path(tmp_path, 0.7, 12))
    assert ds.attrs["v_peak"] == direct.attrs["v_peak"]
    np.testing.assert_array_equal(ds["v_max"].values, direct["v_max"].values)
    # combined over chi and N, with the per-run results as (chi, N) variables
    comb = S.combine(paths)
    assert dict(comb.sizes)["chi"] == 2 and dict(comb.sizes)["N"] == 2
    assert float(comb["v_peak"].sel(chi=0.7, N=12)) == direct.attrs["v_peak"]
    n = int(direct.sizes["step"])
    np.testing.assert_array_equal(comb["v_max"].sel(chi=0.7, N=12).values[:n], direct["v_max"].values)
    assert comb["v_max"].attrs["units"] == "1"
    assert comb["wall_time"].attrs["units"] == "s" and comb["v_peak"].attrs["units"] == "1"
    # a rerun does nothing to finished runs; a removed run is redone
    mtimes = {p: os.stat(p).st_mtime_ns for p in paths}
    os.remove(paths[0])
    S.run_sweep(grid, tmp_path, workers=1, progress=False)
    assert S.is_complete_run(paths[0])
    assert all(os.stat(p).st_mtime_ns == mtimes[p] for p in paths[1:])


def test_a_failed_write_leaves_no_file(tmp_path, monkeypatch):
    ds = simulate.run(0.5, 4, t_end=0.01).dataset
    target = tmp_path / "run.nc"

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr("snapping.simulate.dataset.save", boom)
    with pytest.raises(OSError):
        S.atomic_to_netcdf(ds, target)
    assert not target.exists() and list(tmp_path.iterdir()) == []


def test_a_truncated_file_is_not_complete_and_is_redone(tmp_path):
    grid = S.Grid(chi=[0.5], N=[5], options=OPTS)
    path = grid.path(tmp_path, 0.5, 5)
    path.write_bytes(b"CDF\x01 truncated")
    assert not S.is_complete_run(path)
    S.run_sweep(grid, tmp_path, workers=1, progress=False)
    assert S.is_complete_run(path)


def test_sweep_on_a_local_dask_cluster(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cl:
        with distributed.Client(cl) as client:
            grid = S.Grid(chi=[0.4, 0.7], N=[5], options=OPTS)
            paths = S.run_sweep(grid, tmp_path, scheduler=client, progress=False)
    assert all(S.is_complete_run(p) for p in paths)
    comb = S.combine(paths)
    assert list(comb["chi"].values) == [0.4, 0.7]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(chi=[], N=[5]), "chi grid is empty"),
        (dict(chi=[0.2], N=[]), "N grid is empty"),
        (dict(chi=[0.2, 0.2], N=[5]), r"chi grid has duplicate values \[0.2\]"),
        (dict(chi=[0.2], N=[5, 5]), r"N grid has duplicate values \[5\]"),
        (dict(chi=[1.2], N=[5]), r"chi=1.2"),
        (dict(chi=[0.2], N=[0]), r"N=0"),
    ],
)
def test_bad_grids(kwargs, match):
    with pytest.raises(SnappingInputError, match=match):
        S.Grid(**kwargs)


def test_unwritable_directory_and_unreachable_scheduler(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    grid = S.Grid(chi=[0.5], N=[4], options=OPTS)
    with pytest.raises(SnappingInputError, match="cannot be written"):
        S.run_sweep(grid, blocker / "sub", progress=False)
    pytest.importorskip("dask.distributed")
    with pytest.raises(SnappingInputError, match="cannot be reached"):
        S.run_sweep(grid, tmp_path / "ok", scheduler="tcp://127.0.0.1:1", progress=False)
    assert not any(Path(tmp_path / "ok").glob("*.nc"))


def test_cli_sweep(tmp_path, capsys):
    import json

    from snapping.cli import main

    assert main(["sweep", "--chi", "0.5", "--N", "6,9", "--tol", "1e-7", "-o", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [r["N"] for r in out["runs"]] == [6, 9]
    assert (tmp_path / "sweep.nc").is_file()
    assert main(["sweep", "--chi", "0.5,0.5", "--N", "6", "-o", str(tmp_path)]) == 2
    assert "duplicate" in capsys.readouterr().err


def test_sweep_in_ensembles_matches_single_runs(tmp_path):
    """--ensemble K: several chi of one N in one kernel; each member's peaks as its single run's."""
    opts = {"method": "fast", "chords": "exact", "tol": 1e-8}
    grid = S.Grid(chi=[0.3, 0.4, 0.5], N=[20, 30], options=opts)
    paths = S.run_sweep(grid, tmp_path / "ens", workers=2, progress=False, ensemble=2)
    assert all(S.is_complete_run(p) for p in paths)
    for chi in grid.chi:
        for N in grid.N:
            ens = simulate.load_run(grid.path(tmp_path / "ens", chi, N)).attrs
            single = simulate.run(chi, N, **opts).dataset.attrs
            for q in ("v_peak", "a_peak", "sigma_peak", "t_snap_v"):
                assert ens[q] == pytest.approx(single[q], rel=1e-8), (chi, N, q)
            assert ens["link_drift"] < 1e-14
    # a rerun redoes only the missing member, alone
    os.remove(paths[1])
    mtimes = {p: os.stat(p).st_mtime_ns for p in paths if p != paths[1]}
    S.run_sweep(grid, tmp_path / "ens", workers=1, progress=False, ensemble=2)
    assert S.is_complete_run(paths[1]) and all(os.stat(p).st_mtime_ns == m for p, m in mtimes.items())
    # groups hold one N each, at most K members
    todo = [({"chi": c, "N": n}, "") for c in (0.3, 0.4, 0.5) for n in (20, 30)]
    assert [len(t) for t in S._groups(todo, 2)] == [2, 1, 2, 1]
    assert all(len({p["N"] for p, _ in t}) == 1 for t in S._groups(todo, 2))


def test_ensemble_sweep_bad_options(tmp_path):
    grid = S.Grid(chi=[0.3, 0.4], N=[10], options={"tol": 1e-6})
    with pytest.raises(SnappingInputError, match="ensemble=2 needs an angle-form method"):
        S.run_sweep(grid, tmp_path, ensemble=2, progress=False)
    grid = S.Grid(chi=[0.3, 0.4], N=[10], options={"method": "fast", "checkpoint_every": 10.0})
    with pytest.raises(SnappingInputError, match=r"options \['checkpoint_every'\] are not supported"):
        S.run_sweep(grid, tmp_path, ensemble=2, progress=False)
    with pytest.raises(SnappingInputError, match="ensemble"):
        S.run_sweep(grid, tmp_path, ensemble=0, progress=False)


def test_ensemble_sweep_with_a_failing_member_keeps_the_other(tmp_path):
    # chi = 0.1 needs steps below dt_min = 3e-4 at N = 40, chi = 0.5 does not
    grid = S.Grid(chi=[0.1, 0.5], N=[40], options={"method": "fast", "dt_min": 3e-4})
    with pytest.raises(RuntimeError, match=r"1 of 2 runs failed \(chi=0.1,0.5 N=40: ensemble members failed: chi=0.1"):
        S.run_sweep(grid, tmp_path, workers=1, ensemble=2, progress=False)
    assert S.is_complete_run(grid.path(tmp_path, 0.5, 40)) and not S.is_complete_run(grid.path(tmp_path, 0.1, 40))
