"""The compiled RODAS4 with a body (:mod:`snapping.simulate.elastic_rodas_body`, branch rodasbody).

Independent checks: the compiled rhs against :meth:`LineBody.rhs` (the Radau path's, tested against
independently written forces in test_elastic_body.py); the Jacobian (node blocks, W and D rows) against
central differences of the rhs; whole runs against scipy's Radau with the same body at tight
tolerances (a different method: peaks, state, energy balance); the error against a tight Radau
reference falling with tol; the plain line's rodas4 (no body) equal, bit for bit, to the numbers main
gave before this branch (literal values)."""

import numpy as np
import pytest

from snapping.simulate import Body, PinMotion
from snapping.simulate import elastic_rodas as ER
from snapping.simulate import elastic_rodas_body as RB
from snapping.simulate.banded_body import band_lu55
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.elastic_model import ElasticLine
from snapping.simulate.elastic_rodas_body import RodasBodyStepper
from snapping.simulate.problem import Links, Problem


def _random_line(N=9, clamp="table", seed=2):
    """A line with every part of the body (per-node bending, natural curvature, bending damping,
    quadratic and linear drag, tip drag, wind, a clamp) on a pulled held end, and a state with links
    stretched, compressed (the rod's push) and moving."""
    rng = np.random.default_rng(seed)
    body = Body(2e-3 * (1.0 + rng.random(N + 1)), curvature=0.5 * rng.standard_normal(N + 1),
                damping=1e-3 * (1.0 + rng.random(N + 1)), drag_normal=1.0 + rng.random(N + 1),
                drag_tangential=0.1, drag_linear_normal=0.3, drag_linear_tangential=0.05, tip_drag=0.05,
                wind=(0.3, -0.2), clamp={"table": (np.array([0.0, 0.2, 0.5]), np.array([1.3, 1.1, 0.9])),
                                         "angle": 1.2, "none": None}[clamp])
    s = np.linspace(1.0, 0.0, N + 1)
    p = Problem.nodes(-s * np.cos(1.2), -s * np.sin(1.2), links=Links.uniform(N, lumping="shared"),
                      pin=PinMotion.pull((0.4, -0.7)), body=body)
    line = ElasticLine(p, Elastic(ea=900.0, damping=0.02))
    z = line.start("unstretched")
    z[:4 * N] += np.tile([0.01, 0.01, 0.5, 0.5], N) * rng.standard_normal(4 * N)
    return line, z


@pytest.mark.parametrize("clamp", ["table", "angle", "none"])
def test_rhs_and_jacobian(clamp):
    line, z = _random_line(clamp=clamp)
    N, t = line.N, 0.13
    X, Y, _, _ = line.unpack(z, t)
    ln = np.hypot(np.diff(X), np.diff(Y))
    assert np.any(ln < line.h) and np.any(ln > line.h) and line.body.push  # (springs and the rod's push)
    assert np.abs(ln / line.h - 1.0).min() > 1e-2  # (no link within the differences' step of its rest length)
    st = RodasBodyStepper(line, t, z, 1.0, 1e-6)
    ref = line.rhs(t, z)
    np.testing.assert_allclose(st.St[0], ref, rtol=0, atol=1e-12 * np.abs(ref).max())
    J = st.jacobian_dense()
    n4 = 4 * N
    # the node rows against the Radau path's sparse Jacobian (its body part by differences too)
    Jr = line.jac(t, z).toarray()
    assert np.abs(J[:n4] - Jr[:n4]).max() < 1e-8 * np.abs(Jr).max()
    # every row (W and D included) against central differences of the rhs
    Jd = np.zeros((n4 + 2, n4))
    for k in range(n4):
        e = 1e-6 * (1.0 + abs(z[k]))
        zp, zm = z.copy(), z.copy()
        zp[k] += e
        zm[k] -= e
        Jd[:, k] = (line.rhs(t, zp) - line.rhs(t, zm)) / (2.0 * e)
    assert np.abs(J[:n4, :n4] - Jd[:n4]).max() < 1e-8 * np.abs(Jd[:n4]).max()
    for row in (n4, n4 + 1):  # (W: the held end's power with the clamp's torque; D: the dissipation)
        assert np.abs(Jd[row]).max() > 1.0
        assert np.abs(J[row, :n4] - Jd[row]).max() < 1e-8 * np.abs(Jd[row]).max(), row
    assert not np.any(J[:, n4:])  # (nothing depends on W and D)
    assert st.ctl[ER.C_AUTO] == 0.0  # (a pulled held end)


@pytest.mark.parametrize("gh", [1e-4, 1e-2])
def test_stage_solve_against_dense(gh):
    """The stage system ``(I/g - J) U = b`` (the reduced velocity band, pivoted, then positions, W, D)
    against numpy's dense solve with the whole Jacobian the method uses."""
    line, z = _random_line(N=11, clamp="table")
    N, n = line.N, 4 * line.N + 2
    st = RodasBodyStepper(line, 0.13, z, 1.0, 1e-6)
    J = st.jacobian_dense()
    RB.assemble_band5(N, st.B5, gh, st.ab5)
    assert band_lu55(st.ab5, 2 * N, st.piv5) == 0
    b = np.random.default_rng(5).standard_normal(n)
    U = np.zeros(n)
    RB.solve5(N, st.B5, st.gW12, st.gDb, gh, st.ab5, st.piv5, b, U, np.zeros(2 * N))
    want = np.linalg.solve(np.eye(n) / gh - J, b)
    np.testing.assert_allclose(U, want, rtol=0, atol=1e-10 * np.abs(want).max())


def test_compressed_link_near_its_rest_length():
    """A link compressed by 1e-9 of its length (the bottom of a stiff catenary sits this close): its
    push's derivative is exact (differences with the usual 1e-6 step cross the rest length and give
    about half of EA/h). Checked against differences of the rhs with a step 1e-12, inside the kink."""
    line, z = _random_line(clamp="none")
    N, t = line.N, 0.0
    X, Y, VX, VY = line.unpack(z, t)
    j = 4  # link 4 (nodes 4, 5) 1e-9 short, no relative velocity: it pushes with EA e
    d = np.array([X[5] - X[4], Y[5] - Y[4]])
    d *= line.h[j] * (1.0 - 1e-9) / np.hypot(*d)
    z[16], z[17], z[18], z[19] = X[5] - d[0], Y[5] - d[1], VX[5], VY[5]
    st = RodasBodyStepper(line, t, z, 1.0, 1e-6)
    J = st.jacobian_dense()
    e = 1e-12
    for q in (0, 1):  # node 5's x, y: the rows of nodes 4 and 5
        zp, zm = z.copy(), z.copy()
        zp[20 + q] += e
        zm[20 + q] -= e
        col = (line.rhs(t, zp) - line.rhs(t, zm)) / (2.0 * e)
        for r in (18, 19, 22, 23):
            assert abs(J[r, 20 + q] - col[r]) < 1e-4 * line.ea[j] / line.h[j] / line.m[5], (r, q, J[r, 20 + q], col[r])


def _pair(p, tol, el=None, **kw):
    el = el or Elastic.from_wave_speed(30.0)
    a = solve(p, el, tol=tol, method="rodas4", start="matched", **kw)
    b = solve(p, el, tol=tol, method="radau", start="matched", **kw)
    return a, b


@pytest.mark.parametrize("kind", ["free", "clamp", "pull"])
def test_against_radau(kind):
    """chi 0.3, N 10, bending 1e-3, drag 1, matched start, to the snap: rodas4 and Radau at tol 1e-9
    agree on the peaks to 1e-6 and conserve KE + V + V_b - W + D to ~tol."""
    body = Body(1e-3, drag_normal=1.0, **({"clamp": ([0.0, 0.3, 1.0], [0.9, 1.3, 1.3])} if kind == "clamp" else {}))
    pin = {"pin": PinMotion.pull((0.4, -0.7))} if kind == "pull" else {}
    p = Problem.catenary(0.3, links=Links.uniform(10, lumping="shared"), body=body, **pin)
    a, b = _pair(p, 1e-9)
    A, B = a.dataset.attrs, b.dataset.attrs
    assert A["status"] == B["status"] == "completed" and A["stop_reason"] == B["stop_reason"] == "snap"
    for k in ("v_peak", "a_peak", "sigma_peak", "kappa_peak_approach"):
        assert abs(A[k] / B[k] - 1.0) < 1e-6, (k, A[k], B[k])
    assert abs(A["t_snap_v"] - B["t_snap_v"]) < 1e-4
    assert A["energy_drift"] < 2e-8 and A["n_lu_pivoted"] == A["n_lu"]
    if kind == "clamp":
        assert a.line.body.clamped and A["pin_motion"] == "fixed"


def test_error_falls_with_tol():
    """The state at t = 0.4 against Radau at tol 1e-12: the error falls about tenfold per decade of tol."""
    p = Problem.catenary(0.3, links=Links.uniform(8, lumping="shared"), body=Body(1e-3, drag_normal=1.0))
    el = Elastic.from_wave_speed(30.0)
    ref = solve(p, el, tol=1e-12, method="radau", start="matched", t_end=0.4).state
    err = [np.abs(solve(p, el, tol=tol, method="rodas4", start="matched", t_end=0.4).state - ref)[:-2].max()
           for tol in (1e-5, 1e-6, 1e-7, 1e-8)]
    r = np.array(err[:-1]) / np.array(err[1:])
    assert np.all(r > 3.0) and np.all(r < 40.0), (err, r)
    assert err[-1] < 1e-6


# the plain line's rodas4 (no body): main's numbers before branch rodasbody (74f2794), N 12, c 30,
# tol 1e-6, t_end 0.6: (start, pulled, v_peak, a_peak, sigma_peak, n_rhs, n_steps)
PLAIN = [("stretched", False, 0.6675038484368907, 12.175725053498107, 0.9339171901805221, 7400, 924),
         ("matched", False, 0.654598742121549, 2.4668331210572543, 0.7496072145255717, 1864, 304),
         ("matched", True, 0.7563126530885467, 5.7768502908648705, 1.2694104524687333, 3079, 431)]


@pytest.mark.parametrize("start, pulled, v, a, s, nrhs, nsteps", PLAIN)
def test_plain_line_bit_for_bit(start, pulled, v, a, s, nrhs, nsteps):
    kw = {"pin": PinMotion.pull((0.4, -0.7))} if pulled else {}
    for body in (None, Body()):  # (an inactive body is no body)
        p = Problem.catenary(0.3, links=Links.uniform(12, lumping="shared"), body=body, **kw)
        A = solve(p, Elastic.from_wave_speed(30.0), tol=1e-6, method="rodas4", start=start, t_end=0.6).dataset.attrs
        assert (A["v_peak"], A["a_peak"], A["sigma_peak"], A["n_rhs"], A["n_steps"]) == (v, a, s, nrhs, nsteps)
        assert A["n_lu_pivoted"] == 0

