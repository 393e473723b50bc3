"""Bad inputs to the extensible line with a body (:mod:`snapping.simulate.elastic_body`): every
refusal a SnappingInputError naming the parameter, the value and what is valid, raised before any
integration or file access (branch ``bodyreview``: an outside tester's classes of inputs)."""

import os

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.simulate import Body
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.elastic_model import ElasticLine
from snapping.simulate.problem import Links, Problem

EL = Elastic.from_wave_speed(30.0)


def _p(body, N=6, links=None):
    return Problem.catenary(0.3, links=links or Links.uniform(N, lumping="shared"), body=body)


# bodies with no bending (no stiffness, no bending damping, no clamp): tension-only lines
NO_BENDING = [Body(0.0, drag_normal=1.0), Body(0.0, tip_drag=0.5), Body(0.0, drag_linear_tangential=0.2),
              Body(0.0, wind=(0.3, 0.0), drag_normal=0.1)]


@pytest.mark.parametrize("body", NO_BENDING)
def test_compression_true_needs_bending(body):
    with pytest.raises(SnappingInputError, match=r"compression=True with a body without bending.*None or False"):
        ElasticLine(_p(body), EL, compression=True)
    with pytest.raises(SnappingInputError, match=r"compression=True"):
        solve(_p(body), EL, t_end=0.01, compression=True)
    for c in (None, False):  # (the tension-only line: allowed)
        assert ElasticLine(_p(body), EL, compression=c).body.push is False


@pytest.mark.parametrize("body", [Body(1e-3), Body(0.0, damping=1e-4), Body(1e-3, clamp=0.5)])
def test_compression_with_bending_is_a_choice(body):
    assert ElasticLine(_p(body), EL).body.push is True
    assert ElasticLine(_p(body), EL, compression=True).body.push is True
    assert ElasticLine(_p(body), EL, compression=False).body.push is False


@pytest.mark.parametrize("bad", ["yes", 1, 0, 1.0, "True"])
def test_compression_of_the_wrong_type(bad):
    with pytest.raises(SnappingInputError, match=r"compression=.*True, False or None"):
        solve(_p(Body(1e-3)), EL, t_end=0.01, compression=bad)


@pytest.mark.parametrize("method", ["radau", "dop853", "RADAU", "Dop853", "rodas4", "Rodas4"])
@pytest.mark.parametrize("option", ["checkpoint", "resume", "checkpoint_every"])
def test_checkpoint_options_with_a_body(tmp_path, method, option):
    """Only rodas4/rodas4-links keep checkpoints and they take no body: the refusal names the
    option and the body, before any file is looked at (a missing resume file is not the reason)."""
    path = str(tmp_path / "line.nc")
    kw = {"checkpoint": {"checkpoint": path}, "resume": {"resume": path},
          "checkpoint_every": {"checkpoint": path, "checkpoint_every": 1.0}}[option]
    with pytest.raises(SnappingInputError, match=rf"{option if option != 'checkpoint_every' else 'checkpoint'}=.*"
                                                 r"with a body.*'rodas4'.*no body.*\('radau', 'dop853', 'rodas4'\)"):
        solve(_p(Body(1e-3, drag_normal=0.5)), EL, method=method, t_end=0.01, **kw)
    assert not os.path.exists(path)


@pytest.mark.parametrize("method", ["rodas4-links", "Rodas4-Links"])
@pytest.mark.parametrize("option", [None, "checkpoint", "resume"])
def test_rodas_with_a_body_names_the_method(tmp_path, method, option):
    """rodas4 takes a body (branch rodasbody); rodas4-links refuses it by name."""
    path = str(tmp_path / "missing.nc")  # (never written: the method is refused first)
    kw = {} if option is None else {option: path}
    with pytest.raises(SnappingInputError, match=rf"method='{method.lower()}' with a body.*use one of "
                                                 r"\('radau', 'dop853', 'rodas4'\)"):
        solve(_p(Body(1e-3)), EL, method=method, t_end=0.01, **kw)
    assert not os.path.exists(path)


def test_plain_line_keeps_its_checkpoint_refusals(tmp_path):
    """Without a body the old messages stand (radau keeps no checkpoint; rodas4 does)."""
    with pytest.raises(SnappingInputError, match=r"checkpoint=.*method='radau': only the methods"):
        solve(_p(None), EL, method="radau", t_end=0.01, checkpoint=str(tmp_path / "a.nc"))


@pytest.mark.parametrize("kw, match", [
    ({"bending": np.full(4, 1e-3)}, r"bending has 4 entries; the chain has 7 nodes"),
    ({"bending": np.full(6, 1e-3)}, r"bending has 6 entries; the chain has 7 nodes"),
    ({"drag_normal": np.ones(8)}, r"drag_normal has 8 entries; the chain has 7 nodes"),
    ({"bending": np.array([1e-3, np.nan, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3])}, r"bending\[1\]=nan is out of range"),
    ({"drag_normal": lambda s: np.inf + 0.0 * s}, r"drag_normal\[0\]=inf is out of range"),
    ({"bending": 1e-3, "curvature": lambda s: np.nan * s}, r"curvature\[0\]=nan is out of range"),
])
def test_body_arrays_against_the_links(kw, match):
    """Per-node arrays of the wrong length, NaN or inf in them, reach no compiled code."""
    b = kw.pop("bending", 0.0)
    with pytest.raises(SnappingInputError, match=match):
        solve(_p(Body(b, **kw)), EL, t_end=0.01)


def test_graded_links_arrays_and_planar_wind():
    h = np.linspace(1.0, 3.0, 8)  # (graded links: a body's arrays count the nodes, N + 1)
    links = Links.graded(h / h.sum())
    with pytest.raises(SnappingInputError, match=r"bending has 8 entries; the chain has 9 nodes"):
        solve(_p(Body(np.full(8, 1e-3)), links=links), EL, t_end=0.01)
    r = solve(_p(Body(np.full(9, 1e-3), drag_normal=0.5), links=links), EL, t_end=0.05, tol=1e-6, start="matched")
    assert r.dataset.attrs["status"] == "completed" and r.dataset.attrs["energy_drift"] < 1e-7
    with pytest.raises(SnappingInputError, match=r"wind=.*out of the plane"):
        solve(_p(Body(1e-3, wind=(0.1, 0.0, 0.2))), EL, t_end=0.01)
    with pytest.raises(SnappingInputError, match=r"clamp=1.0 needs bending stiffness"):
        Body(0.0, drag_normal=1.0, clamp=1.0)


def test_other_entry_points_take_the_body_and_refuse_a_method_without_one():
    """The studies and sweeps take a body with the extensible line (tests/test_elastic_body_studies.py);
    a method that steps no body is refused by name before any run, in a grid and in a study alike."""
    from snapping.continuum import converge
    from snapping.sweep_grid import Grid

    with pytest.raises(SnappingInputError, match=r"method='rodas4-links' steps no body"):
        Grid(chi=[0.3], N=[8], options={"elastic": {"ea": 900.0}, "body": {"bending": 1e-3},
                                        "method": "rodas4-links"})
    c = converge(0.3, levels=2, n0=4, tol=1e-4, body={"bending": 1e-3}, elastic={"ea": 900.0})
    assert "body" in c.dataset.attrs and "elastic" in c.dataset.attrs


@pytest.mark.parametrize("body", [None, Body(1e-3, drag_normal=0.5)])
@pytest.mark.parametrize("j", [0, 3, 5])
def test_initial_with_a_zero_length_link(body, j):
    """An ``initial`` state whose link j has (next to) no length: refused naming the link, not a
    ZeroDivisionError from the compiled Jacobian (plain line and body alike)."""
    p = _p(body)
    x, y = p.x.copy(), p.y.copy()
    if j < p.N - 1:
        x[j], y[j] = x[j + 1], y[j + 1]
    else:  # (the held link: node N - 1 onto the held end)
        x[j] = x[j + 1] + 1e-12
        y[j] = y[j + 1]
    v = np.zeros(p.N + 1)
    with pytest.raises(SnappingInputError, match=rf"initial x, y: link {j} has length .*longer than 1e-09 of its rest"):
        solve(p, EL, t_end=0.01, initial=(x, y, v, v))
    x[j] = x[j + 1] + 1e-6 * p.links.h[j]  # (short but not degenerate: runs)
    y[j] = y[j + 1]
    assert np.isfinite(solve(p, EL, t_end=1e-3, tol=1e-4, initial=(x, y, v, v)).dataset.attrs["v_peak"])


@pytest.mark.parametrize("body", [None, Body(1e-3, drag_normal=0.5)])
def test_stretched_start_of_a_moving_problem(body):
    """A moving start (a rigid rotation about the held end) has no static equilibrium to start
    from: refused naming the start, its speed and the starts that take it; 'matched' runs."""
    p0 = _p(None)
    w = 0.5  # (the rotation's rate: speeds w r, the largest at the free end)
    vx, vy = -w * p0.y, w * p0.x
    p = Problem.nodes(p0.x, p0.y, vx=vx, vy=vy, links=p0.links, body=body)
    r0 = float(np.hypot(p0.x, p0.y).max())
    with pytest.raises(SnappingInputError, match=rf"start='stretched' needs a start at rest.*speed up to "
                                                 rf"{w * r0:.6g}\).*'matched'.*'unstretched'"):
        solve(p, EL, t_end=0.01, start="stretched")
    assert solve(p, EL, t_end=0.01, tol=1e-5, start="matched").dataset.attrs["status"] == "completed"
