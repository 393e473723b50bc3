"""The line's body on the extensible line in sweeps and convergence studies (snapping.sweep_elastic,
snapping.continuum): a grid point's or a level's run is exactly elastic.solve of the problem built here
by hand (catenary, uniform shared-lumped links, the body), a level run with another body is not reused,
and a method that steps no body is refused by name before any run."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from snapping import continuum, sweep
from snapping._validate import SnappingInputError
from snapping.simulate import Body, Links, Problem
from snapping.simulate.elastic import Elastic, solve
from snapping.sweep_elastic import level_row

EL = Elastic.from_wave_speed(30.0, grid_damping=1.0)
BODY = Body(1e-3, drag_normal=0.5)


def _direct(chi, N, body, **kw):
    return solve(Problem.catenary(chi, links=Links.uniform(N, lumping="shared"), body=body), EL, **kw).dataset


def test_one_cell_sweep_with_a_body_is_the_direct_solve(tmp_path):
    grid = sweep.Grid(chi=[0.4], N=[6], options={"elastic": EL, "body": BODY, "tol": 1e-6, "t_end": 0.3})
    paths = sweep.run_sweep(grid, tmp_path / "sw", progress=False, workers=1)
    direct = _direct(0.4, 6, BODY, tol=1e-6, t_end=0.3)
    with xr.open_dataset(paths[0]) as ds:
        assert json.loads(ds.attrs["problem"])["body"]["bending"] == 1e-3
        for v in ("t", "v_max", "energy", "elastic_energy"):
            np.testing.assert_array_equal(ds[v].values, direct[v].values)
        assert ds.attrs["v_peak"] == direct.attrs["v_peak"]
    # the body matters: the bare line's run differs
    assert _direct(0.4, 6, None, tol=1e-6, t_end=0.3).attrs["v_peak"] != direct.attrs["v_peak"]


def test_converge_with_a_body_runs_each_level_directly_and_records_both():
    c = continuum.converge(0.4, levels=2, n0=4, tol=1e-6, body=BODY, elastic=EL)
    ds = c.dataset
    assert ds.n_links.values.tolist() == [4, 8]
    assert json.loads(ds.attrs["body"])["bending"] == 1e-3 and json.loads(ds.attrs["elastic"]) == EL.describe()
    for k, N in enumerate((4, 8)):
        a = _direct(0.4, N, BODY, tol=1e-6).attrs
        for q in ("v_peak", "a_peak", "sigma_peak"):
            assert float(ds[f"{q}_level"].values[k] if f"{q}_level" in ds else ds[q].values[k]) == a[q], (N, q)


def test_a_level_run_with_another_body_is_not_reused(tmp_path):
    path = str(tmp_path / "level.nc")
    h = np.full(4, 0.25)
    first = level_row(0.4, h, "shared", None, 1e-6, path, EL.describe(), "stretched", body_d=BODY.describe())
    other = Body(2e-3, drag_normal=0.5)
    again = level_row(0.4, h, "shared", None, 1e-6, path, EL.describe(), "stretched", body_d=other.describe())
    assert again["v_peak"] == _direct(0.4, 4, other, tol=1e-6).attrs["v_peak"] != first["v_peak"]
    assert np.isfinite(again["cpu_time"])  # (run again, not read back)
    same = level_row(0.4, h, "shared", None, 1e-6, path, EL.describe(), "stretched", body_d=other.describe())
    assert same["v_peak"] == again["v_peak"] and np.isnan(same["cpu_time"])  # (read back)


def test_a_method_without_a_body_is_refused_by_name():
    with pytest.raises(SnappingInputError, match=r"method='rodas4-links' steps no body.*'radau', 'dop853', 'rodas4'"):
        sweep.Grid(chi=[0.4], N=[6], options={"elastic": EL, "body": BODY, "method": "rodas4-links"})


def test_cli_converge_carries_the_body_on_the_extensible_line(capsys):
    """`snapping converge --stretching 30 --grid-damping 1 --bending 1e-3 --drag-normal 0.5`: each level is the
    direct solve of the line with that body (the CLI once kept the extensible line and dropped the body)."""
    from snapping.cli import main

    assert main(["converge", "--chi", "0.4", "--stretching", "30", "--grid-damping", "1", "--bending", "1e-3",
                 "--drag-normal", "0.5", "--levels", "2", "--n0", "4", "--tol", "1e-6", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for k, N in enumerate((4, 8)):
        assert out["levels"]["v_peak"][k] == _direct(0.4, N, BODY, tol=1e-6).attrs["v_peak"], N
