"""The compiled step loop and peak refinement of ``method="rodas4-links"``
(elastic_advance.advance_links / LinksRun, elastic_refine.refine_segments / restep_links): the
same Dataset, peaks and attributes, bit for bit, as the Python step loop and ``_Peaks.refine``
they replace (``COMPILED_LOOP = False``, ``COMPILED_REFINE = False``), on runs with a matched
start, a stretched start that goes slack, damping, a moving held end with snapshots, a small
record buffer and the failures; and the peaks agree with a different method (node RODAS4)."""

import math

import numpy as np
import pytest

from snapping.simulate import elastic_advance as EA
from snapping.simulate import elastic_solve as ES
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.pin import PinMotion
from snapping.simulate.problem import Links, Problem


def _cat(n, chi=0.25, **kw):
    return Problem.catenary(chi, links=Links.uniform(n, lumping="shared"), **kw)


CASES = {
    # (problem, elastic, solve keywords)
    "matched-snap": (lambda: _cat(16), lambda: Elastic.from_wave_speed(30.0), dict(start="matched", tol=3e-4)),
    "stretched-slack": (lambda: _cat(12), lambda: Elastic.from_wave_speed(10.0),
                        dict(start="unstretched", tol=1e-5, t_end=0.5, snapshot_times=(0.05, 0.2, 0.2))),
    "damped": (lambda: _cat(12), lambda: Elastic.from_wave_speed(15.0, damping=0.05),
               dict(start="stretched", tol=1e-5, t_end_max=1.6)),
    "pulled-snapshots": (lambda: _cat(10, 0.3, pin=PinMotion.pull((0.7, -1.3))), lambda: Elastic.from_wave_speed(10.0),
                         dict(start="stretched", tol=1e-6, t_end=0.4, snapshot_times=(0.1, 0.25))),
}


def _run(case, loop, refine, monkeypatch, **extra):
    mk_p, mk_e, kw = CASES[case]
    monkeypatch.setattr(ES, "COMPILED_LOOP", loop)
    monkeypatch.setattr(ES, "COMPILED_REFINE", refine)
    return solve(mk_p(), mk_e(), method="rodas4-links", **{**kw, **extra})


def _same(a, b):
    assert a.peaks == b.peaks  # values and times, bit for bit
    x, y = dict(a.dataset.attrs), dict(b.dataset.attrs)
    x.pop("wall_time"), y.pop("wall_time")
    assert x.keys() == y.keys()
    for k in x:
        same = x[k] == y[k] or (isinstance(x[k], float) and math.isnan(x[k]) and math.isnan(y[k]))
        assert same and type(x[k]) is type(y[k]), (k, x[k], y[k])
    assert a.dataset.drop_attrs().identical(b.dataset.drop_attrs())
    assert np.array_equal(a.state, b.state)


@pytest.mark.parametrize("case", list(CASES))
def test_compiled_loop_and_refine_equal_python(case, monkeypatch):
    py = _run(case, False, False, monkeypatch)
    _same(_run(case, True, True, monkeypatch), py)
    _same(_run(case, False, True, monkeypatch), py)  # the compiled refinement on the Python loop's steps
    _same(_run(case, True, False, monkeypatch), py)  # the compiled loop's kept steps, refined in Python
    s = py.summary()
    if case == "stretched-slack":
        assert s["n_slack_steps"] > 0 and list(py.dataset.snapshot_kind.values).count("requested") == 3
    if case == "matched-snap":
        assert s["stop_reason"] == "snap"
    # the refinement did something: some peak moved off the step ends' running maximum
    ds = py.dataset
    ends = {"v": float(ds.v_max.max()), "a": float(ds.a_max.max()), "sigma": float(ds.sigma_max.max())}
    assert all(py.peaks[k]["value"] >= ends[k] for k in ends)
    assert any(py.peaks[k]["value"] > ends[k] for k in ends)


def test_small_record_buffer_and_max_rhs(monkeypatch):
    """A 5-row record buffer (drained many times) gives the same run; a max_rhs stop the
    same failure at the same step."""
    py = _run("pulled-snapshots", False, False, monkeypatch)
    monkeypatch.setattr(EA, "ROWS", 5)
    _same(_run("pulled-snapshots", True, True, monkeypatch), py)
    py = _run("damped", False, False, monkeypatch, max_rhs=300)
    cc = _run("damped", True, True, monkeypatch, max_rhs=300)
    assert cc.summary()["stop_reason"] == "more than max_rhs=300 right-hand-side evaluations"
    _same(cc, py)


def test_collapsing_link_fails_alike(monkeypatch):
    """The step-size failure (a link collapsing to SHORT_LINK, as in test_elastic_links) ends
    the compiled loop with the Python loop's status, message and record."""
    p = _cat(20)
    x, y = p.x.copy(), p.y.copy()
    vx, vy = np.zeros(21), np.zeros(21)
    d = np.array([x[1] - x[0], y[1] - y[0]])
    x[0], y[0] = x[1] - 0.5 * d[0], y[1] - 0.5 * d[1]
    vx[0], vy[0] = 20.0 * d / np.hypot(*d)
    runs = []
    for loop in (False, True):
        monkeypatch.setattr(ES, "COMPILED_LOOP", loop)
        runs.append(solve(p, Elastic.from_wave_speed(30.0), method="rodas4-links", tol=1e-6, t_end=0.01,
                          initial=(x, y, vx, vy)))
    assert runs[1].summary()["status"] == "failed" and "too small" in runs[1].summary()["stop_reason"]
    _same(runs[1], runs[0])


def test_compiled_peaks_agree_with_node_rodas4():
    """chi 0.25, N = 16, c = 30, matched start, to the snap, both methods at tol 1e-8 (compiled
    paths): the refined v peak and its time agree (different coordinates, different steps)."""
    a = solve(_cat(16), Elastic.from_wave_speed(30.0), start="matched", tol=1e-8, method="rodas4-links").summary()
    b = solve(_cat(16), Elastic.from_wave_speed(30.0), start="matched", tol=1e-8, method="rodas4").summary()
    assert a["stop_reason"] == b["stop_reason"] == "snap"
    assert a["v_peak"] == pytest.approx(b["v_peak"], rel=1e-6)
    assert a["t_snap_v"] == pytest.approx(b["t_snap_v"], abs=1e-4)
