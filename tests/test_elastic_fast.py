"""The elastic line's fast RODAS4 path: the pivot-free stage factorisation
(snapping.simulate.elastic_stage) against a dense LAPACK solve, its guard's fallback, the
compact Jacobian against jac_blocks, and the compiled run loop (elastic_advance) against
the Python step loop it replaces."""

from __future__ import annotations

import numpy as np
import pytest

from snapping.simulate import elastic_rodas as ER
from snapping.simulate import elastic_solve as S
from snapping.simulate import elastic_stage as ES
from snapping.simulate.elastic import Elastic, ElasticLine, solve
from snapping.simulate.pin import PinMotion
from snapping.simulate.problem import Links, Problem


def _random_state(line, rng, t, *, cancel):
    """A state near the unstretched start with taut and slack links, random velocities, the
    last link taut (the W row not zero) and, ``cancel``, link 3 stretched and closing fast
    (damping cancels its tension)."""
    N = line.N
    z = line.start("unstretched") + 2e-3 * rng.standard_normal(4 * N + 2)
    z[2:4 * N:4] += 0.3 * rng.standard_normal(N)
    z[3:4 * N:4] += 0.3 * rng.standard_normal(N)
    xs, ys = line.unpack(z, t)[:2]
    d = np.array([xs[-1] - xs[-2], ys[-1] - ys[-2]])
    z[4 * N - 4:4 * N - 2] = np.array([xs[-1], ys[-1]]) - d / np.hypot(*d) * line.h[-1] * 1.015
    if cancel:
        u = z[16:18] - z[12:14]
        z[12:14] = z[16:18] - u / np.hypot(*u) * line.h[3] * 1.002
        z[14:16] = z[18:20] + 5.0 * (z[16:18] - z[12:14])
    return z


def _compact(line, t, z):
    N = line.N
    pin = line.pin_state(t)
    T, E, ED, FV = (np.zeros(N) for _ in range(4))
    f = np.zeros_like(z)
    from snapping.simulate import elastic_kernels as EK

    EK.rhs(N, z, pin, line.h, line._invm, line.ea, line.damp, line.tabe, line.tabt, line.g, f, T, E, ED, FV)
    J, gW, gD = np.zeros((N, 3, 8)), np.zeros(4), np.zeros(4 * N)
    ER.jacobian(N, z, pin, line.h, line._invm, line.ea, line.damp, line.tabe, line.tabt, T, E, ED, J, gW, gD)
    return J, gW, gD, T, E


CASES = [(Elastic(ea=np.linspace(100.0, 900.0, 8), damping=0.3), False),
         (Elastic(table=([0.0, 0.01, 0.03], [0.0, 2.0, 9.0]), damping=0.1), False),
         (Elastic(ea=400.0, damping=2.0), True),
         (Elastic(ea=3e4), False)]


@pytest.mark.parametrize("elastic, cancel", CASES)
def test_pivot_free_stage_solve_is_the_dense_solve(elastic, cancel):
    """At random states (slack and taut links, damping, a link whose damping cancels its
    tension, a table, the held end moving) the stage solve with the pivot-free block LU
    equals numpy's dense LU solve of ``(I/g - J) U = b`` (J the full Jacobian, W and D rows
    included) to 1e-12 of |U|, for steps from tiny to stiff; the guard holds (no fallback);
    the pivoted path gives the same; the compact blocks are jac_blocks' exactly."""
    p = Problem.catenary(0.3, links=Links.uniform(8, lumping="shared"), pin=PinMotion.pull((0.7, -1.3)))
    line = ElasticLine(p, elastic)
    N, n = 8, 34
    rng = np.random.default_rng(5)
    t = 0.4
    for _ in range(3):
        z = _random_state(line, rng, t, cancel=cancel)
        J, gW, gD, T, E = _compact(line, t, z)
        assert (E > 0).any() and (E < 0).any() and T[-1] > 0
        if cancel:
            assert E[3] > 0 and T[3] == 0.0
        B = line.jac(t, z).toarray()  # (jac_blocks' node rows)
        for i in range(N):
            for k in range(3):
                c = i - 1 + k
                if 0 <= c < N:
                    np.testing.assert_array_equal(J[i, k, :4].reshape(2, 2), B[4 * i + 2:4 * i + 4, 4 * c:4 * c + 2])
                    np.testing.assert_array_equal(J[i, k, 4:].reshape(2, 2), B[4 * i + 2:4 * i + 4, 4 * c + 2:4 * c + 4])
        Jd = ER.full_jacobian(line, t, z)  # (its W and D rows: tested against differences in test_elastic_rodas)
        np.testing.assert_array_equal(Jd[4 * N, 4 * N - 4:4 * N], gW)
        np.testing.assert_array_equal(Jd[4 * N + 1, :4 * N], gD)
        lo, hi = ER.gradient_span(N, gD)
        assert np.all(gD[:lo] == 0.0) and np.all(gD[hi:] == 0.0)
        for gh in (1e-6, 1e-4, 1e-2):
            b = rng.standard_normal(n)
            ref = np.linalg.solve(np.eye(n) / gh - Jd, b)
            F, ab, piv = np.zeros((N, ES.NF)), np.zeros((2 * N, ES.WIDTH)), np.zeros(2 * N, dtype=np.int64)
            for pivoted, want in ((False, ES.PATH_BLOCK), (True, ES.PATH_PIVOTED)):
                path = ES.factor(N, J, gh, F, ab, piv, pivoted)
                assert path == want
                U = np.zeros(n)
                ES.solve(N, J, gW, gD, lo, hi, gh, path, F, ab, piv, b.copy(), U, np.zeros(2 * N))
                assert np.abs(U - ref).max() <= 1e-12 * np.abs(ref).max(), (gh, pivoted)


def test_guard_falls_back_to_pivoting():
    """A stage matrix that is no Schur-stable one (a diagonal block with a negative pivot, and
    one with a tiny pivot that the block recursion would divide by) is factored with
    pivoting, and the solve is still the dense one."""
    N = 5
    rng = np.random.default_rng(3)
    J = rng.standard_normal((N, 3, 8))
    J[0, 0] = J[-1, 2] = 0.0
    gh = 1.0
    F, ab, piv = np.zeros((N, ES.NF)), np.zeros((2 * N, ES.WIDTH)), np.zeros(2 * N, dtype=np.int64)
    J[2, 1, :4] = [3.0, 0.0, 0.0, 3.0]  # (I - K: a diagonal of -2)
    assert ES.factor(N, J, gh, F, ab, piv, False) == ES.PATH_PIVOTED
    A = np.zeros((2 * N, 2 * N))
    for i in range(N):
        for k in range(3):
            c = i - 1 + k
            if 0 <= c < N:
                A[2 * i:2 * i + 2, 2 * c:2 * c + 2] = -gh * gh * J[i, k, :4].reshape(2, 2) - gh * J[i, k, 4:].reshape(2, 2)
    A += np.eye(2 * N)
    b = rng.standard_normal(4 * N + 2)
    b[0:4 * N:4] = b[1:4 * N:4] = 0.0  # (then the right side is g b_v)
    U = np.zeros(4 * N + 2)
    ES.solve(N, J, np.zeros(4), np.zeros(4 * N), 0, 0, gh, ES.PATH_PIVOTED, F, ab, piv, b.copy(), U, np.zeros(2 * N))
    uv = np.ravel(np.c_[U[2:4 * N:4], U[3:4 * N:4]])
    ref = np.linalg.solve(A, gh * np.ravel(np.c_[b[2:4 * N:4], b[3:4 * N:4]]))
    assert np.abs(uv - ref).max() <= 1e-12 * np.abs(ref).max()
    J[2, 1, :4] = [1.0, 0.0, 0.0, 1.0 - 1e-13]  # (a tiny pivot: growth)
    J[2, 0] = J[1, 2] = 1.0
    assert ES.factor(N, J, gh, F, ab, piv, False) == ES.PATH_PIVOTED


@pytest.mark.parametrize("start, kw", [
    ("matched", {"tol": 1e-6, "snapshot_times": (0.05, 0.05, -1.0, 0.3)}),
    ("stretched", {"tol": 1e-5, "t_end": 0.4, "snapshot_times": (0.1,)}),
    ("matched", {"tol": 1e-6, "max_rhs": 900})])
def test_compiled_run_loop_is_the_python_step_loop(monkeypatch, start, kw):
    """The compiled loop (records, with a small buffer drained many times, peaks and their
    refinement, snapshots, the stop rule, the first slack link, the failure on max_rhs)
    gives the Dataset of the Python step loop over the same stepper, bit for bit."""
    from snapping.simulate import elastic_advance as EA

    p = Problem.catenary(0.25, links=Links.uniform(10, lumping="shared"))
    el = Elastic.from_wave_speed(30.0, grid_damping=0.5)
    monkeypatch.setattr(EA, "ROWS", 37)
    a = solve(p, el, method="rodas4", start=start, **kw).dataset
    monkeypatch.setattr(S, "COMPILED_LOOP", False)
    b = solve(p, el, method="rodas4", start=start, **kw).dataset
    assert a.attrs["stop_reason"] == b.attrs["stop_reason"]
    assert a.attrs["n_steps"] > 20
    for k in a.attrs:
        if k != "wall_time":
            assert a.attrs[k] == b.attrs[k] or (a.attrs[k] != a.attrs[k] and b.attrs[k] != b.attrs[k]), k
    assert set(a.variables) == set(b.variables)
    for v in a.variables:
        np.testing.assert_array_equal(a[v].values, b[v].values, err_msg=v)
