"""The stiff method (:mod:`snapping.simulate.stiff`): the banded stage matrix and its
derivatives against finite differences and a dense construction, RODAS4's order, peaks
against dop853, the energy balance."""

import math

import numpy as np
import pytest

from snapping.simulate import Body, PinMotion, Problem, run
from snapping.simulate import stiff as ST


def _setup(N=9, seed=1, **body):
    kw = dict(bending=1e-2, damping=1e-3)
    kw.update(body)
    p = Problem.catenary(0.25, N, body=Body(**kw), pin=PinMotion.pull((0.3, -0.2)))
    mdl, y0 = ST.body_model(p)
    res = ST.Residual(mdl)
    rng = np.random.default_rng(seed)
    y = y0.copy()
    y[:N] += 0.2 * rng.standard_normal(N)
    y[N:2 * N] = rng.standard_normal(N)
    f = np.empty_like(y)
    t = 0.3
    res.rhs(t, y, f)
    return res, t, y, f


def _band_full(res, D, v):
    N = res.N
    A = np.zeros((2 * N, N))
    for k in range(ST.NCOL):
        r, lk = res.cidx[k][0], res.cidx[k][1]
        A[r, lk] = D[v, k, r]
    return A


@pytest.mark.parametrize("clamp", [None, 1.2])
def test_rows_vanish_at_the_kernels_solution(clamp):
    """The numpy rows R are zero at the accelerations and tensions of forced_rhs."""
    res, t, y, f = _setup(clamp=clamp)
    N = res.N
    r = res.R(t, y[:N], y[N:2 * N], f[N:2 * N], res.sig.copy())
    assert np.abs(r).max() < 1e-12 * max(1.0, np.abs(res.sig).max())


@pytest.mark.parametrize("clamp", [None, 1.2])
def test_banded_derivatives_against_finite_differences(clamp):
    """The coloured complex-step columns are the full derivatives (nothing outside the band)."""
    res, t, y, f = _setup(clamp=clamp)
    N = res.N
    D = res.jacobian(t, y, f)
    base = [y[:N].copy(), y[N:2 * N].copy(), f[N:2 * N].copy(), res.sig.copy()]
    eps = 1e-6
    for v in range(4):
        full = np.zeros((2 * N, N))
        for k in range(N):
            a = [b.copy() for b in base]
            m = [b.copy() for b in base]
            a[v][k] += eps
            m[v][k] -= eps
            full[:, k] = (res.R(t, *a) - res.R(t, *m)) / (2 * eps)
        assert np.abs(full - _band_full(res, D, v)).max() < 1e-6 * max(1.0, np.abs(full).max())
    # the compiled colours are the numpy ones
    Dn = res.jacobian(t, y, f, compiled=False)
    assert np.allclose(D, Dn, rtol=1e-13, atol=1e-13 * np.abs(Dn).max())
    x = np.random.default_rng(5).standard_normal(N)
    for v in (0, 1):
        assert np.allclose(res.matvec(D, v, x), res.matvec_numpy(D, v, x), rtol=1e-14, atol=1e-14)


def test_ode_jacobian_against_finite_differences_of_the_rhs():
    """-P M^{-1} R_theta (from the banded pieces) is the derivative of the compiled theta''
    (no drag: the Jacobian is exact)."""
    res, t, y, f = _setup()
    N = res.N
    D = res.jacobian(t, y, f)
    J = ST.dense_ode_jacobian(res, t, y, D)
    eps = 1e-6
    Jfd = np.zeros((2 * N, 2 * N))
    for k in range(2 * N):
        yp, ym = y.copy(), y.copy()
        yp[k] += eps
        ym[k] -= eps
        fp, fm = np.empty_like(y), np.empty_like(y)
        res.rhs(t, yp, fp)
        res.rhs(t, ym, fm)
        Jfd[:, k] = (fp - fm)[:2 * N] / (2 * eps)
    assert np.abs(J - Jfd).max() < 1e-6 * np.abs(J).max()
    # the ODE's Jacobian is dense (the inverse of the tension matrix), the stage matrix banded
    assert np.count_nonzero(np.abs(J[N:, :N]) > 1e-12 * np.abs(J).max()) > 0.9 * N * N


def test_stage_matrix_banded_against_dense():
    res, t, y, f = _setup(N=11)
    N = res.N
    D = res.jacobian(t, y, f)
    gh = 0.013
    sm = ST.StageMatrix(res, D, gh)
    # dense construction: M (interleaved) + ((gh)^2 R_theta + gh R_omega) P
    M = np.zeros((2 * N, 2 * N))
    M[:, 0::2] = _band_full(res, D, 2) + gh * gh * _band_full(res, D, 0) + gh * _band_full(res, D, 1)
    M[:, 1::2] = _band_full(res, D, 3)
    A = sm.dense()
    assert np.array_equal(A, M)
    lo = max(i - j for i in range(2 * N) for j in range(2 * N) if M[i, j] != 0.0)
    up = max(j - i for i in range(2 * N) for j in range(2 * N) if M[i, j] != 0.0)
    assert lo <= ST.KL and up <= ST.KU
    # the stage solve is the solve with I/(gamma h) - J
    J = ST.dense_ode_jacobian(res, t, y, D)
    b = np.random.default_rng(3).standard_normal(2 * N)
    Uth, Uom = sm.solve(b[:N], b[N:])
    U = np.linalg.solve(np.eye(2 * N) / gh - J, b)
    assert np.allclose(np.concatenate([Uth, Uom]), U, rtol=1e-10, atol=1e-12 * np.abs(U).max())


@pytest.mark.parametrize("pin", [PinMotion.pull((0.3, -0.2)), None])
def test_fourth_order_at_fixed_steps(pin):
    """RODAS4 with the exact Jacobian: order 4 on the whole state (angles, rates, the held
    end's work W and the dissipated D; a moving held end: f_t and the W/D rows by
    differences; a fixed one: the analytic D row)."""
    p = Problem.catenary(0.25, 6, body=Body(bending=1e-2, damping=2e-3), pin=pin)
    T = 0.24
    ref = ST.solve(p, T, dt_fixed=T / 96, refine=False, records=False)["y"]
    errs = []
    for n in (6, 12, 24):
        y = ST.solve(p, T, dt_fixed=T / n, refine=False, records=False)["y"]
        errs.append(np.abs(y - ref).max())
    orders = [math.log2(errs[i] / errs[i + 1]) for i in range(2)]
    assert min(orders) > 3.6, (errs, orders)
    assert errs[-1] < 1e-7


def test_peaks_agree_with_dop853():
    """Peaks of v, a, sigma at B = 1e-4, N = 30 agree with dop853 to the tolerance asked."""
    p = Problem.catenary(0.25, 30, body=Body(bending=1e-4))
    ds = run(problem=p, method="fast", tol=1e-10).dataset
    o = ST.solve(p, None, 1e-6, records=False)
    assert o["stop"] == "snap"
    for q in ("v", "a", "sigma"):
        ref = ds.attrs[f"{q}_peak"]
        assert abs(o[f"{q}_peak"] - ref) < 1e-5 * ref, (q, o[f"{q}_peak"], ref)
    assert abs(o["t_snap_v"] - ds.attrs["t_snap_v"]) < 1e-5


@pytest.mark.parametrize("pin", [PinMotion.pull((0.2, -0.1)), None])
def test_energy_balance(pin):
    """kinetic + gravity + bending - W + D is constant to the method's accuracy (damping,
    a moving held end: W and D rows by differences; a fixed one: the analytic D row)."""
    p = Problem.catenary(0.25, 10, body=Body(bending=1e-3, damping=1e-3), pin=pin)
    errs = []
    for tol in (1e-6, 1e-8):
        rec = ST.solve(p, 0.8, tol, refine=False)["rec"]
        bal = rec[:, 4] - rec[:, 5] + rec[:, 6]
        assert rec[-1, 6] > 1e-4  # (something was dissipated)
        errs.append(np.abs(bal - bal[0]).max())
    assert errs[1] < 1e-6 and errs[1] < errs[0]


def test_chain_without_a_body():
    """A problem without a body (the paper's chain) runs through the same rows (empty body block)."""
    p = Problem.catenary(0.25, 12)
    o = ST.solve(p, None, 1e-7, records=False)
    ds = run(problem=p, method="fast", tol=1e-10).dataset
    for q in ("v", "a", "sigma"):
        assert abs(o[f"{q}_peak"] - ds.attrs[f"{q}_peak"]) < 1e-6 * ds.attrs[f"{q}_peak"]
