"""The extensible line in sweeps and convergence studies (snapping.sweep_elastic): a grid point's
run is exactly a direct elastic.solve of the same line, and a stiff line's levels approach the
inextensible chain's (chi = 0.5, N = 4 and 8: chains that carry no compression, so the
tension-only line and the rigid links are the same model as c -> infinity)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from snapping import continuum, sweep
from snapping._validate import SnappingInputError
from snapping.cli import main
from snapping.simulate import Links, Problem, run
from snapping.simulate.elastic import Elastic, solve

EL = Elastic.from_wave_speed(30.0, grid_damping=1.0)


def test_one_cell_elastic_sweep_is_the_direct_solve(tmp_path):
    grid = sweep.Grid(chi=[0.5], N=[4], options={"elastic": EL, "tol": 1e-6, "t_end": 0.3})
    paths = sweep.run_sweep(grid, tmp_path / "sw", progress=False, workers=1)
    direct = solve(Problem.catenary(0.5, links=Links.uniform(4, lumping="shared")), EL, tol=1e-6, t_end=0.3).dataset
    with xr.open_dataset(paths[0]) as ds:
        assert ds.attrs["model"] == "elastic" and json.loads(ds.attrs["elastic"]) == EL.describe()
        for v in ("t", "v_max", "energy", "elastic_energy", "strain"):
            np.testing.assert_array_equal(ds[v].values, direct[v].values)
        assert ds.attrs["v_peak"] == direct.attrs["v_peak"]
    comb = sweep.combine(paths)
    assert float(comb["strain_peak"].sel(chi=0.5, N=4)) == direct.attrs["strain_peak"]
    assert json.loads(comb.attrs["elastic"]) == EL.describe()


def test_elastic_sweep_refuses_what_it_cannot_run():
    with pytest.raises(SnappingInputError, match="method='euler-richardson'"):
        sweep.Grid(chi=[0.5], N=[4], options={"elastic": EL, "method": "euler-richardson"})
    with pytest.raises(SnappingInputError, match="record_thin"):
        sweep.Grid(chi=[0.5], N=[4], options={"elastic": EL, "record_thin": 0.1})
    with pytest.raises(SnappingInputError, match="one value per link"):
        sweep.Grid(chi=[0.5], N=[4], options={"elastic": Elastic(ea=[1e3] * 4)})
    with pytest.raises(SnappingInputError, match="ensemble"):
        sweep.run_sweep(sweep.Grid(chi=[0.5, 0.6], N=[4], options={"elastic": EL}), "unused", ensemble=2)


def test_converge_stiff_line_approaches_the_inextensible_chain():
    """c = 300: every level's peak speed within 5e-4 of the rigid chain's (measured: 1.3e-4 at N = 4,
    2.1e-4 at N = 8; a softer c = 30 is 3e-4 and 1.9e-3 off), and each level is the direct solve.
    Its curvature peak (branch stretchk) within 2% (measured -1.4e-2, -3.0e-3: both runs' largest
    curvature is their last step's, still rising when the stop rule ends them a step apart)."""
    el = Elastic.from_wave_speed(300.0, grid_damping=1.0)
    c = continuum.converge(0.5, levels=2, n0=4, elastic=el, tol=1e-7)
    ds = c.dataset
    assert ds.n_links.values.tolist() == [4, 8] and np.all(np.isfinite(ds.kappa_peak.values))
    assert json.loads(ds.attrs["elastic"]) == el.describe() and "extensible" in c.table()
    for k, N in enumerate((4, 8)):
        p = Problem.catenary(0.5, links=Links.uniform(N, lumping="shared"))
        rigid = run(p, method="fast", tol=1e-9, progress=False).dataset.attrs
        assert float(ds.v_peak[k]) == pytest.approx(rigid["v_peak"], rel=5e-4)
        assert float(ds.kappa_peak[k]) == pytest.approx(rigid["kappa_peak"], rel=2e-2)
    assert float(ds.v_peak[0]) == solve(Problem.catenary(0.5, links=Links.uniform(4, lumping="shared")), el,
                                         tol=1e-7).dataset.attrs["v_peak"]


@pytest.mark.parametrize("argv, needle", [
    (["sweep", "--chi", "0.5", "--N", "4", "--stretching", "0"], "--stretching=0.0"),
    (["sweep", "--chi", "0.5", "--N", "4", "--stretching", "30", "--method", "euler-richardson"],
     "--method euler-richardson"),
    (["sweep", "--chi", "0.5", "--N", "4", "--ea", "30"], "--ea is in SI"),
    (["converge", "--chi", "0.5", "--stretching", "30", "--axial-damping", "-1"], "--axial-damping=-1.0"),
    (["converge", "--chi", "0.5", "--stretching", "nan"], "--stretching=nan"),
])
def test_elastic_sweep_and_converge_bad_options_exit_2_one_line(argv, needle, tmp_path, capsys):
    if argv[0] == "sweep":
        argv = argv + ["-o", str(tmp_path / "out")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and "\n" not in err
    assert not (tmp_path / "out").exists()
