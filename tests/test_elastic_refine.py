"""The compiled peak refinement of RODAS4 runs (elastic_refine) and the directly assembled run
Dataset: the same numbers, bit for bit, as the Python references they replace
(``_Peaks.refine``, xarray's public constructor), on runs with a slack start, damping, a moving
held end and requested snapshots."""

import math

import numpy as np
import pytest
import xarray as xr

from snapping.simulate import elastic_dataset as ED
from snapping.simulate import elastic_refine as ERF
from snapping.simulate import elastic_solve as ES
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.pin import PinMotion
from snapping.simulate.problem import Links, Problem

CASES = {
    # (problem, elastic, solve keywords)
    "stretched-stop": (lambda: Problem.catenary(0.25, links=Links.uniform(16, lumping="shared")),
                       lambda: Elastic.from_wave_speed(20.0), dict(tol=1e-4, t_end_max=2.0)),
    "damped-snapshots": (lambda: Problem.catenary(0.3, links=Links.uniform(12, tip_mass=0.2)),
                         lambda: Elastic(ea=400.0, damping=0.05), dict(tol=1e-5, t_end=0.8, snapshot_times=(0.2, 0.5))),
    "pulled-unstretched": (lambda: Problem.catenary(0.25, links=Links.uniform(10),
                                                    pin=PinMotion.pull((0.0, -2.0), duration=0.3)),
                           lambda: Elastic.from_wave_speed(15.0), dict(tol=3e-5, t_end=0.6, start="unstretched")),
}


def _run(case, *, compiled_refine=True, direct=True, monkeypatch):
    mk_p, mk_e, kw = CASES[case]
    monkeypatch.setattr(ES, "COMPILED_REFINE", compiled_refine)
    monkeypatch.setattr(ED, "DIRECT_DATASET", direct)
    return solve(mk_p(), mk_e(), method="rodas4", **kw)


def _same_attrs(a, b):
    a, b = dict(a), dict(b)
    a.pop("wall_time"), b.pop("wall_time")
    assert a.keys() == b.keys()
    for k in a:
        same = a[k] == b[k] or (isinstance(a[k], float) and math.isnan(a[k]) and math.isnan(b[k]))
        assert same and type(a[k]) is type(b[k]), (k, a[k], b[k])


@pytest.mark.parametrize("case", list(CASES))
def test_compiled_refine_equals_python(case, monkeypatch):
    py = _run(case, compiled_refine=False, direct=False, monkeypatch=monkeypatch)
    cc = _run(case, monkeypatch=monkeypatch)
    assert cc.peaks == py.peaks  # values and times, bit for bit
    _same_attrs(cc.dataset.attrs, py.dataset.attrs)  # n_rhs counts the integrations again
    assert cc.dataset.drop_attrs().identical(py.dataset.drop_attrs())
    # the refinement did something: some peak moved off the step ends' running maximum
    ds = py.dataset
    ends = {"v": float(ds.v_max.max()), "a": float(ds.a_max.max()), "sigma": float(ds.sigma_max.max())}
    assert all(py.peaks[k]["value"] >= ends[k] for k in ends)
    assert any(py.peaks[k]["value"] > ends[k] for k in ends)


def test_refine_is_called_and_counted(monkeypatch):
    """The compiled path is taken (the flag switches it) and its integrations count in n_rhs."""
    calls = []
    orig = ERF.refine
    monkeypatch.setattr(ERF, "refine", lambda *a: calls.append(1) or orig(*a))
    r = _run("stretched-stop", monkeypatch=monkeypatch)
    assert calls == [1]
    ds = r.dataset
    assert ds.attrs["n_rhs"] > int(ds.attrs["n_steps"]) * 6  # (steps' evaluations + the refinement's)


def test_dataset_direct_equals_public(monkeypatch):
    pub = _run("damped-snapshots", direct=False, monkeypatch=monkeypatch)
    dd = _run("damped-snapshots", monkeypatch=monkeypatch)
    a, b = dd.dataset, pub.dataset
    assert a.drop_attrs().identical(b.drop_attrs())
    assert list(a.variables) == list(b.variables) and dict(a.sizes) == dict(b.sizes)
    assert set(a.coords) == set(b.coords) and list(a.data_vars) == list(b.data_vars)
    _same_attrs(a.attrs, b.attrs)
    for name in a.variables:
        assert a[name].attrs == b[name].attrs and a[name].dtype == b[name].dtype
    assert a.sizes["snapshot"] == 5  # (initial, two requested, peak, final)


def test_assemble_falls_back_to_public(monkeypatch):
    """Without xarray's private constructor (absent, or raising), the public one."""
    data = {"v": (("step",), np.arange(3.0), {"units": "x"})}
    coords = {"t": (("step",), np.arange(3.0) * 0.5, {})}
    good = ED._public(data, coords, {"a": 1})
    seen = []

    class Absent:  # an xarray whose Dataset has no _construct_direct
        def __new__(cls, *a, **kw):
            seen.append("public")
            return xr.Dataset(*a, **kw)

    class Raising(Absent):
        @staticmethod
        def _construct_direct(*a, **kw):
            seen.append("direct")
            raise TypeError("another signature")

    for fake in (Absent, Raising):
        monkeypatch.setattr(ED, "xr", type("xr", (), {"Dataset": fake, "Variable": xr.Variable}))
        fb = ED._assemble(data, coords, {"a": 1})
        monkeypatch.undo()
        assert fb.identical(good) and fb.attrs == {"a": 1} and set(fb.coords) == {"t"}
    assert seen == ["public", "direct", "public"]


@pytest.mark.parametrize("t0,t1", [(0.0, 1.0), (0.1234567, 0.1234571), (1.0, 1.0), (3.3, 7.9), (1e-9, 2e-9)])
def test_grid_is_linspace(t0, t1):
    out = np.empty(ES.PEAK_SAMPLES + 1)
    ERF.grid(t0, t1, ES.PEAK_SAMPLES, out)
    assert np.array_equal(out, np.linspace(t0, t1, ES.PEAK_SAMPLES + 1))
