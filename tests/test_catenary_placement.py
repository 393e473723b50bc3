"""The catenary start placed every node at once (``simulate.placement``) and a taper's profiles
read at every node in one call (``on_array``), against the node-by-node originals."""

import numpy as np
import pytest

from snapping import estimates, lines
from snapping.simulate import Links, Problem, placement, shapes
from snapping.simulate.chain import _catenary_xy


def _walk(chi, L, h):
    """The node-by-node walk (brentq per node) on the same catenary: the independent reference."""
    a = estimates.catenary_parameter(chi)

    def cat(s):
        cx, cy = _catenary_xy(np.asarray(s, dtype=float) / L, chi, a)
        return L * cx, L * cy

    return shapes.place_on_curve(cat, h)


def _links(kind, N, L, seed=0):
    rng = np.random.default_rng(seed)
    if kind == "uniform":
        h = np.full(N, 1.0)
    elif kind == "random":
        h = rng.uniform(0.3, 1.0, N)
    else:  # graded: fine at the free end, coarse at the pin (as a fold-following grading)
        h = np.geomspace(0.02, 1.0, N)
    return h * (L / h.sum())


@pytest.mark.parametrize("chi", [0.05, 0.1, 0.25, 0.9])
@pytest.mark.parametrize("kind,N,L", [("uniform", 200, 1.0), ("random", 400, 3.7), ("graded", 600, 1.0)])
def test_newton_placement_is_the_walk_to_roundoff(chi, kind, N, L):
    h = _links(kind, N, L)
    a = estimates.catenary_parameter(chi)
    got = placement.place_on_catenary(chi, a, L, h)
    assert got is not None
    x, y = got
    xw, yw = _walk(chi, L, h)
    assert np.max(np.abs(x - xw)) <= 1e-12 * L and np.max(np.abs(y - yw)) <= 1e-12 * L
    assert np.max(np.abs(np.hypot(np.diff(x), np.diff(y)) - h)) <= 1e-14 * L  # chords exact
    assert x[-1] == 0.0 and y[-1] == 0.0
    # on the curve: y as the catenary's graph of x (independent of the arclengths)
    u = np.sinh((x / L - 0.5 * chi) / a) * a
    assert np.max(np.abs(y / L - (np.sqrt(a * a + 0.25) - np.sqrt(a * a + u * u)))) <= 1e-12


def test_problem_catenary_uses_it_and_keeps_the_walk_start(monkeypatch):
    h = _links("graded", 400, 1.0)
    calls = []
    newton = placement.place_on_catenary

    def counted(*a, **k):
        out = newton(*a, **k)
        calls.append(out is not None)
        return out

    monkeypatch.setattr(placement, "place_on_catenary", counted)
    p = Problem.catenary(0.1, links=Links.graded(h))
    assert calls == [True]  # placed by Newton, not by the walk
    xw, yw = _walk(0.1, p.links.length, p.links.h)
    x, y = np.asarray(p.x), np.asarray(p.y)
    assert np.max(np.abs(x - xw)) <= 1e-12 and np.max(np.abs(y - yw)) <= 1e-12


@pytest.mark.parametrize("chi,N", [(0.05, 10), (0.1, 4), (0.25, 6)])
def test_coarse_links_fall_back_to_the_walk_bit_for_bit(chi, N):
    # a deep U on few unequal links: the chord from a node need not grow along the curve, Newton may
    # reach another root; those placements are left to the walk (the very same floats)
    h = _links("random", N, 1.0, seed=1)
    assert placement.place_on_catenary(chi, estimates.catenary_parameter(chi), 1.0, h) is None
    p = Problem.catenary(chi, links=Links.graded(h))
    xw, yw = _walk(chi, p.links.length, p.links.h)
    assert np.array_equal(np.asarray(p.x), xw) and np.array_equal(np.asarray(p.y), yw)


def test_paper_links_unchanged():
    p = Problem.catenary(0.25, 50)
    from snapping.simulate.chain import initial_state

    st = initial_state(0.25, 50, "exact")
    assert np.array_equal(np.asarray(p.x), st.x) and np.array_equal(np.asarray(p.y), st.y)


@pytest.mark.parametrize("name", ["fly-line", "bullwhip"])
def test_taper_profiles_on_array_are_the_per_node_calls(name):
    ln = lines.get(name)
    body = ln.body()
    h = _links("graded", 700, 1.0)
    snode = np.zeros(h.size + 1)
    snode[:-1] = np.cumsum(h[::-1])[::-1]
    n_tapered = 0
    for k in ("bending", "drag_normal", "drag_tangential"):
        v = getattr(body, k)
        if not callable(v):
            continue
        n_tapered += 1
        assert callable(getattr(v, "on_array", None))
        per_node = np.asarray([float(v(float(x))) for x in snode])  # one call per node, as before
        assert np.array_equal(body.node_values(k, h), per_node)  # the same floats, bit for bit
    assert n_tapered == 3


def _peaks(p, method="fast"):
    from snapping.simulate import run

    a = run(p, method=method, tol=1e-6, progress=False).dataset.attrs
    return [float(a[q]) for q in ("v_peak", "a_peak", "sigma_peak", "kappa_peak")] + [int(a["n_rhs"])]


@pytest.mark.parametrize("body", [False, True])
def test_compiled_peak_refinement_is_z_at_bit_for_bit(monkeypatch, body):
    # DOP853's refinement by one compiled call (meas_at) against the old path through Z_at: the same peaks
    # and the same count of evaluations, bit for bit, on the paper's chain and on a body (drag, bending)
    from snapping.simulate import Body
    from snapping.simulate.methods import dop853

    b = Body(1e-4, drag_normal=0.5) if body else None
    p = Problem.catenary(0.3, 40, body=b)
    new = _peaks(p)
    monkeypatch.setattr(dop853.Engine, "meas_at", lambda self, t: self.Z_at(t)[1])
    assert new == _peaks(p)
