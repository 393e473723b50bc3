"""The stretching study's and the design answer's elastic method can be chosen (issue 24:
``regimes(method=)``, ``cap(stretch_method=)``, ``stretch_factor(method=)``): a study run with
``"rodas4-links"`` holds the peaks of a direct ``solve(..., method="rodas4-links")`` of the same cell
(which differ from the node method's, so the check discriminates), the default stays ``"rodas4"``,
and the choice is in the study's key. About 3 s after compilation."""

from __future__ import annotations

import math

import pytest

from snapping import caps, caps_runs
from snapping import regimes as R
from snapping import regimes_spec as S
from snapping._validate import SnappingInputError
from snapping.continuum import level_parameters
from snapping.simulate import Links, Problem, run
from snapping.simulate.elastic import Elastic, solve

CHI, C, TOL = 0.5, 10.0, 1e-5


def _direct(level, method):
    p = R.cell_problem(CHI, "stretching", 1.0 / C, level)
    return solve(p, Elastic.from_wave_speed(C, grid_damping=S.STRETCH_DAMPING), tol=S.stretch_tol(TOL, C),
                 method=method, stop_floor=S.STRETCH_STOP_FLOOR, start="matched").dataset.attrs


def test_study_runs_its_cells_by_the_chosen_method():
    levels = level_parameters(2, 0.5, first=-4)
    ds = R.regimes("stretching", [CHI], [1.0 / C], levels=2, first=-4, tol=TOL, method="rodas4-links",
                   progress=False)
    assert ds.attrs["elastic_method"] == "rodas4-links"
    for k, lv in enumerate(levels):
        links, node = _direct(lv, "rodas4-links"), _direct(lv, "rodas4")
        assert abs(float(node["v_peak"]) / float(links["v_peak"]) - 1) > 1e-9  # the two methods differ here
        got = float(ds.v_peak_level.sel(chi=CHI, number=1.0 / C).values[k])
        assert got == float(links["v_peak"])  # the study's run is the links run, bit for bit
        assert int(ds.n_rhs_level.sel(chi=CHI, number=1.0 / C).values[k]) == int(links["n_rhs"])


def test_cell_passes_the_node_method_when_asked(monkeypatch):
    """The default is the links method (branch shipstretch): a cell asked for the node method runs it."""
    import snapping.simulate.elastic as E

    seen = []

    class Stop(Exception):
        pass

    def spy(problem, elastic, **kw):
        seen.append(kw["method"])
        raise Stop

    monkeypatch.setattr(E, "solve", spy)
    for method in ("rodas4", "rodas4-links"):
        with pytest.raises(Stop):
            R._run_task(CHI, "stretching", 1.0 / C, {"n_links": 4, "frac": 0.25}, TOL, method=method)
    assert seen == ["rodas4", "rodas4-links"]


def test_default_method_and_the_study_key():
    # the regime study's default is the links method (the shipped study, branch shipstretch); the
    # caps' stretch factor keeps its own default, the node method (the design answers unchanged)
    assert S.STRETCH_METHOD == "rodas4-links" and "rodas4" in S.STRETCH_METHODS and caps.STRETCH_METHOD == "rodas4"
    seen = []

    def fake(chi, mech, number, level, tol, damping=None, start=None, method=None):
        seen.append(method)
        from snapping.continuum import QUANTITIES
        return {**{q: 1.0 for q in QUANTITIES}, "n_links": 1, "n_rhs": 1, "cpu_time": 0.0}

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(R, "_run_task", fake)
        lk = R.regimes("stretching", [CHI], [0.1], levels=2, first=-4, progress=False)
        assert set(m for m in seen if m is not None) == {"rodas4-links"} and lk.attrs["elastic_method"] == "rodas4-links"
        seen.clear()
        d = R.regimes("stretching", [CHI], [0.1], levels=2, first=-4, method="rodas4", progress=False)
        assert set(m for m in seen if m is not None) == {"rodas4"} and d.attrs["elastic_method"] == "rodas4"
    assert d.attrs["regimes_study"] != lk.attrs["regimes_study"]  # a file of one method is not resumed by the other
    for bad in ("radau", "links", 4):
        with pytest.raises(SnappingInputError, match="method"):
            R.regimes("stretching", [CHI], [0.1], levels=2, first=-4, method=bad, progress=False)
    with pytest.raises(SnappingInputError, match="stretching"):
        R.regimes("end-mass", [CHI], [0.1], levels=2, first=-4, method="rodas4-links", progress=False)


def test_stretch_factor_and_cap_take_the_method(monkeypatch):
    g, length, mass = 9.81, 2.0, 0.1
    sp = caps.spec(None, length=length, mass=mass, ea=40.0)
    p = Problem.catenary(0.3, links=Links.uniform(20, lumping="shared"))
    rigid = run(p, method="fast", tol=1e-6, progress=False).dataset.attrs
    el = solve(p, Elastic.from_wave_speed(math.sqrt(40.0 / (mass / length)) / math.sqrt(g * length), grid_damping=1.0),
               tol=1e-6, method="rodas4-links", start="matched").dataset.attrs
    f = caps_runs.stretch_factor(sp, 0.3, 1e-6, 20, method="rodas4-links")
    assert f["v_peak"] == pytest.approx(float(el["v_peak"]) / float(rigid["v_peak"]), rel=1e-12)
    assert f["n_rhs"] == int(el["n_rhs"]) + int(rigid["n_rhs"])
    seen = []

    def fake(sp, chi, tol=1e-6, N=caps.STRETCH_N, start=caps.STRETCH_START, method=caps.STRETCH_METHOD):
        seen.append(method)
        return {**dict.fromkeys(("v_peak", "a_peak", "sigma_peak", "kappa_peak", "t_snap_v"), 0.9), "N": N,
                "n_rhs": 1, "wall": 0.0, "cpu": 0.0, "strain_peak": 0.01, "s_sigma": 0.5, "t_sigma": 1.2,
                "t_snap": 1.19}

    monkeypatch.setattr(caps, "stretch_factor", fake)
    r = caps.cap(None, 0.3, N=16, check=False, length=length, mass=mass, ea=40.0, stretch_method="rodas4-links")
    assert seen == ["rodas4-links"] * 2 and all(x["method"] == "elastic rodas4-links" for x in r["runs"]
                                               if x["run"] == "stretching")
    seen.clear()
    caps.cap(None, 0.3, N=16, check=False, length=length, mass=mass, ea=40.0)
    assert seen == ["rodas4"] * 2
    with pytest.raises(SnappingInputError, match="stretch_method"):
        caps.cap(None, 0.3, N=16, check=False, length=length, mass=mass, ea=40.0, stretch_method="radau")
