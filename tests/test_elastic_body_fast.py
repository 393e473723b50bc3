"""Branch fastbody: the compiled RODAS4 with a body made faster (:mod:`snapping.simulate.elastic_body_jacobian`,
:mod:`snapping.simulate.elastic_body_advance`).

Independent checks: the body's exact Jacobian against central differences of the body's forces as the Radau
path computes them (:meth:`LineBody.forces`) and against the coloured differences it replaced; the compiled run
loop against the Python loop it replaced (``elastic_solve.COMPILED_LOOP = False``), bit for bit; the runs'
peaks against the numbers main gave before the branch (the coloured-difference Jacobian, literal values, tol
1e-6), to a fraction of the tolerance. The runs against Radau are tests/test_elastic_rodas_body.py's."""

import numpy as np
import pytest

from snapping.simulate import Body, PinMotion
from snapping.simulate import elastic_rodas_body as RB
from snapping.simulate import elastic_solve as ES
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.elastic_rodas_body import RodasBodyStepper
from snapping.simulate.problem import Links, Problem
from test_elastic_rodas_body import _random_line


def _body_part(st, jac):
    """The body's part (bending, drag: without the springs and the compressed links' push) of ``jac``
    (:func:`RB.body_jacobian` or :func:`RB.body_jacobian_fd`) at the stepper's state: ``(B5, gW, gD)``."""
    N = st.N
    args = (N, st.t, st.y, st.pins[6], *st.bargs()[:6], *st.work[:3], st.J3, st.gW4, st.bd)
    tail = (st.bs, st.zz, st.GX, st.GY, st.QP, st.Q, st.hmin)
    S = (np.zeros((N, 5, 8)), np.zeros(RB.NGW), np.zeros(4 * N))
    RB._springs_part(N, *args[2:], *S)
    out = (np.zeros((N, 5, 8)), np.zeros(RB.NGW), np.zeros(4 * N))
    jac(*args, *out, *tail)
    return tuple(a - s for a, s in zip(out, S))


@pytest.mark.parametrize("clamp", ["table", "angle", "none"])
@pytest.mark.parametrize("seed", [2, 7])
def test_exact_body_jacobian(clamp, seed):
    """Branch fastbody: the body's exact Jacobian (:mod:`elastic_body_jacobian`) against central differences
    of the body's own forces (:meth:`LineBody.forces`, the Radau path's Python-called kernel, push off),
    node by node, and against the coloured differences it replaced (:func:`RB.body_jacobian_fd`) for the W
    and D rows; each part (K, C, W, D) to 1e-8 of its own size (the differences' error is ~3e-10)."""
    line, z = _random_line(N=12, clamp=clamp, seed=seed)
    N, t = line.N, 0.13
    st = RodasBodyStepper(line, t, z, 1.0, 1e-6)
    # the stepper's Jacobian (body_f_and_jacobian: the moments and geometry its evaluation left) is body_jacobian's
    st.f_and_jacobian()  # (again: the starting step's trial evaluation left other tensions in st.work)
    full = (np.zeros((N, 5, 8)), np.zeros(RB.NGW), np.zeros(4 * N))
    RB.body_jacobian(N, t, st.y, st.pins[6], *st.bargs()[:6], *st.work[:3], st.J3, st.gW4, st.bd, *full, st.bs,
                     st.zz, st.GX, st.GY, st.QP, st.Q, st.hmin)
    for a, b in zip(full, (st.B5, st.gW12, st.gDb)):
        assert np.array_equal(a, b)
    B5, gW, gD = _body_part(st, RB.body_jacobian)
    J = np.zeros((2 * N, 4 * N))  # the body's accelerations by the node states
    for i in range(N):
        for k in range(5):
            jn = i - 2 + k
            if 0 <= jn < N:
                for r in range(2):
                    J[2 * i + r, 4 * jn:4 * jn + 2] = B5[i, k, 2 * r:2 * r + 2]
                    J[2 * i + r, 4 * jn + 2:4 * jn + 4] = B5[i, k, 4 + 2 * r:6 + 2 * r]
    Jd = np.zeros_like(J)
    for c in range(4 * N):
        e = 1e-6 * (1.0 + abs(z[c]))
        zp, zm = z.copy(), z.copy()
        zp[c] += e
        zm[c] -= e
        fp, fm = line.body.forces(t, zp, push=False)[:2], line.body.forces(t, zm, push=False)[:2]
        Jd[0::2, c] = (fp[0][:N] - fm[0][:N]) / (2.0 * e) / line.m
        Jd[1::2, c] = (fp[1][:N] - fm[1][:N]) / (2.0 * e) / line.m
    pos = np.tile([True, True, False, False], N)
    for part in (pos, ~pos):  # K (positions) and C (velocities)
        assert np.abs(Jd[:, part]).max() > 10.0
        assert np.abs(J[:, part] - Jd[:, part]).max() < 1e-8 * np.abs(Jd[:, part]).max()
    Bf, gWf, gDf = _body_part(st, RB.body_jacobian_fd)
    assert np.abs(B5 - Bf).max() < 1e-8 * np.abs(Bf).max()
    for a, b in ((gW, gWf), (gD, gDf)):
        assert np.abs(b).max() > 0.1
        assert np.abs(a - b).max() < 1e-8 * np.abs(b).max()


def _problem(kind, N=10):
    body = Body(1e-3, drag_normal=1.0, **({"clamp": ([0.0, 0.3, 1.0], [0.9, 1.3, 1.3])} if kind == "clamp" else
                                           {"clamp": 1.2} if kind == "angle" else {}))
    pin = {"pin": PinMotion.pull((0.4, -0.7))} if kind == "pull" else {}
    return Problem.catenary(0.3, links=Links.uniform(N, lumping="shared"), body=body, **pin)


@pytest.mark.parametrize("kind", ["angle", "pull"])
def test_compiled_loop_is_the_python_loop(kind, monkeypatch):
    """The compiled loop (:func:`elastic_body_advance.advance_body`: steps, measures, records, peaks, stop
    rule, snapshots) against the Python loop it replaced, bit for bit: every attribute but the wall time
    and every variable of the Dataset (a clamp given as a constant: a table's spline is evaluated by scipy
    in the Python loop's measures, compiled in the stepper)."""
    p = _problem(kind, N=8)
    out = []
    for loop in (False, True):
        monkeypatch.setattr(ES, "COMPILED_LOOP", loop)
        out.append(solve(p, Elastic.from_wave_speed(30.0), tol=1e-5, method="rodas4", start="matched",
                         snapshot_times=(0.1, 0.25)).dataset)
    A, B = out[0].attrs, out[1].attrs
    assert A["stop_reason"] == "snap" and A["n_steps"] > 100
    for k in A:
        if k != "wall_time":
            assert A[k] == B[k] or (isinstance(A[k], float) and np.isnan(A[k]) and np.isnan(B[k])), k
    for v in out[0].data_vars:
        assert np.array_equal(out[0][v].values, out[1][v].values, equal_nan=True), v


# the pre-fastbody numbers (main 8bce05c: the body's Jacobian by coloured differences, the Python loop), chi 0.3,
# N 10, c 30, tol 1e-6, matched start, to the snap: (kind, v_peak, a_peak, sigma_peak, kappa_peak_approach)
BEFORE = [("free", 2.5051349560524363, 37.5939180801631, 3.620068758717454, 0.8107027377173109),
          ("clamp", 2.537212162765708, 39.43028002175002, 3.2183794880562777, 1.259858159742411),
          ("pull", 3.4521136999392215, 108.26612137896107, 8.93025123705291, 1.2168049535823273)]


@pytest.mark.parametrize("kind, v, a, s, k", BEFORE)
def test_peaks_as_before(kind, v, a, s, k):
    """The exact Jacobian and the compiled loop leave the peaks where the differences' Jacobian put them, to a
    fraction of tol 1e-6 (RODAS4 needs the exact Jacobian for its order: differences of relative error ~1e-10
    move the steps, not the answer)."""
    A = solve(_problem(kind), Elastic.from_wave_speed(30.0), tol=1e-6, method="rodas4", start="matched").dataset.attrs
    for name, want in (("v_peak", v), ("a_peak", a), ("sigma_peak", s), ("kappa_peak_approach", k)):
        assert abs(A[name] / want - 1.0) < 1e-6, (name, A[name], want)
