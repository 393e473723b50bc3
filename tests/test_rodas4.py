"""The stiff method as a method of ``run`` (``method="rodas4"``, alias ``"stiff"``): its
compiled pieces against independent references (a dense LU, the Python RODAS4 step of
:mod:`snapping.simulate.stiff`, a tight dop853 solve), agreement with dop853 on the snap,
checkpoints and resume bit for bit, and what it refuses."""

from __future__ import annotations

import numpy as np
import pytest

from snapping import schema
from snapping._validate import SnappingInputError
from snapping.simulate import Body, PinMotion, Problem, RunInterrupted, load_run, resume, run
from snapping.simulate import driver as stepper
from snapping.simulate import rk as R
from snapping.simulate import rosenbrock as RB
from snapping.simulate import stiff as ST
from snapping.simulate.methods import rodas4 as RO
from test_checkpoint import _StopAt, assert_same_run


@pytest.mark.parametrize("kl, ku", [(5, 5), (RB.KL, RB.KU)])
def test_band_lu_solves_a_banded_system_that_needs_pivoting(kl, ku):
    """The general loops (5, 5) and those of the stage matrix's bandwidths (constants)."""
    rng = np.random.default_rng(3)
    n = 40
    A = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - kl), min(n, i + ku + 1)):
            A[i, j] = rng.normal()
    A[np.arange(n), np.arange(n)] *= 1e-3  # small diagonal: partial pivoting must swap rows
    w = RB.WROW if (kl, ku) == (RB.KL, RB.KU) else 2 * kl + ku + 1  # (+1: the reciprocal pivots)
    ab = np.zeros((n, w))  # (stored by rows: A[i, j] at ab[i, j - i + kl])
    for i in range(n):
        for j in range(max(0, i - kl), min(n, i + ku + 1)):
            ab[i, j - i + kl] = A[i, j]
    piv = np.zeros(n, dtype=np.int64)
    assert RB.band_lu(ab, n, kl, ku, piv) == 0
    assert np.any(piv != np.arange(n))
    b = rng.normal(size=n)
    x = b.copy()
    RB.band_solve(ab, n, kl, ku, piv, x)
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-9, atol=1e-11)
    sing = np.zeros_like(ab)
    assert RB.band_lu(sing, n, kl, ku, piv) == 1


@pytest.mark.parametrize("case", ["clamp", "pull"])
def test_jacobian_is_the_complex_step_one(case):
    """rosenbrock.jacobian_at (d/da and d/dT in closed form) against Residual.jacobian (complex
    steps in every variable) at a perturbed state, with a moving clamp or held end."""
    kw = {"clamp": dict(body=Body(bending=1e-3, damping=1e-4, clamp=0.3)),
          "pull": dict(body=Body(bending=1e-3, drag_normal=0.3), pin=PinMotion.pull((0.3, -0.2)))}[case]
    p = Problem.catenary(0.3, 13, **kw)
    eng = _engine(p)
    res = ST.Residual(ST.body_model(p)[0])
    y = p.initial_angles() + 0.01 * np.random.default_rng(1).normal(size=eng.Y0.shape[1])
    f = np.empty_like(y)
    res.rhs(0.1, y, f)
    D = res.jacobian(0.1, y, f)
    mine = np.zeros_like(D)
    RB.jacobian_at(eng.N, 0.1, y, f, res.sig, mine, eng.mdl, eng.barr, eng.rp)
    np.testing.assert_allclose(mine, D, rtol=0, atol=1e-13 * np.max(np.abs(D)))
    assert np.count_nonzero(D[3]) == np.count_nonzero(mine[3]) > 0


def test_assembled_stage_matrix_is_the_lapack_one():
    """rosenbrock.assemble (rows) holds the entries of stiff_system.StageMatrix (LAPACK bands)."""
    p = Problem.catenary(0.3, 11, body=Body(bending=1e-3, damping=1e-4))
    eng = _engine(p)
    res = ST.Residual(ST.body_model(p)[0])
    dense = ST.StageMatrix(res, eng.Dj, 0.01).dense()
    n = dense.shape[0]
    RB.assemble(eng.N, eng.Dj, 0.01, eng.ab)
    mine = np.zeros_like(dense)
    for i in range(n):
        for j in range(max(0, i - RB.KL), min(n, i + RB.KU + 1)):
            mine[i, j] = eng.ab[i, j - i + RB.KL]
    np.testing.assert_array_equal(mine, dense)
    assert np.count_nonzero(eng.ab) == np.count_nonzero(dense)


def _engine(p, tol=1e-6):
    return RO.Engine(p.initial_angles(), 0.0, mdl=p.model(), tol=tol, dt0=None, t_end=1.0, stop_fraction=0.0,
                     thin=0.0, max_link_error=0.5, snapshot_times=())


CASES = {
    "damping": dict(body=Body(bending=1e-3, damping=2e-4)),                    # W/D rows exact
    "drag": dict(body=Body(bending=1e-3, drag_normal=0.5, drag_tangential=0.05)),  # D row: drag power gradient
    "pull": dict(body=Body(bending=1e-3, damping=1e-4), pin=PinMotion.pull((0.3, -0.2))),  # f_t too
    "clamp": dict(body=Body(bending=1e-3, damping=1e-4, clamp=0.3)),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_compiled_step_is_the_python_rodas4_step(case):
    """One compiled step (rosenbrock.rodas_step) against stiff._Stepper.step (numpy, LAPACK
    banded LU) from the same state: the same new state and error (up to the error norm:
    max here, rms there)."""
    p = Problem.catenary(0.3, 12, **CASES[case])
    eng = _engine(p)
    N, n = eng.N, eng.Y0.shape[1]
    y0 = eng.Y1[0].copy()
    t = float(np.nextafter(0.0, 1.0)) if eng.rp[RB.RP_AUTO] == 0.0 else 0.0
    h = 3e-3
    St = np.zeros((RB.NSTG, n))
    St[RB.S_F0] = eng.KK[0, RB.S_F1]
    if eng.rp[RB.RP_AUTO] == 0.0:
        RB.time_derivative(N, t, y0, St[0], eng.ft, eng.ytmp, eng.w.c, eng.w.s, eng.w.S, eng.w.cp, eng.w.dp,
                           eng.w.sig, eng.mdl)
    y1 = np.zeros(n)
    err, nev = RB.rodas_step(N, t, h, y0, y1, St, eng.ft, eng.Dj, eng.ab, eng.piv, eng.ytmp, eng.btmp, eng.rhs,
                             eng.tmp, eng.w.c, eng.w.s, eng.w.S, eng.w.cp, eng.w.dp, eng.w.sig, 1e-6, eng.mdl,
                             eng.barr, eng.rp, eng.cnt)
    mdl, yref = ST.body_model(p)
    res = ST.Residual(mdl)
    np.testing.assert_array_equal(yref, y0)
    f = np.empty_like(yref)
    res.rhs(t, yref, f)
    D = res.jacobian(t, yref, f)
    st = ST._Stepper(res, 1e-6)
    ynew, err_rms = st.step(t, yref, f, D, h, st.time_derivative(t, yref, f))
    np.testing.assert_allclose(y1, ynew, rtol=1e-11, atol=1e-13)
    assert abs(y1[2 * N + 1] - yref[2 * N + 1]) > 0  # (D moves: its rows are exercised)
    assert err_rms <= err * (1 + 1e-9) and err > 0
    assert nev == 5 + (6 if eng.rp[RB.RP_QFD] else 0)


def test_continuous_extension_is_third_order():
    """The state between steps (rodas.f's CONTRO) against the exact flow (dop853 at tol
    1e-13 from the step's start): the error at the step's middle falls ~2^4 per halving."""
    from scipy.integrate import solve_ivp

    from snapping.simulate import forced as FR

    p = Problem.catenary(0.3, 8, body=Body(bending=1e-3, damping=1e-4))
    eng = _engine(p)
    N, n = eng.N, eng.Y0.shape[1]
    y0 = eng.Y1[0].copy()
    errs = []
    for h in (0.04, 0.02, 0.01):
        St = np.zeros((RB.NSTG, n))
        St[RB.S_F0] = eng.KK[0, RB.S_F1]
        y1 = np.zeros(n)
        RB.rodas_step(N, 0.0, h, y0, y1, St, eng.ft, eng.Dj, eng.ab, eng.piv, eng.ytmp, eng.btmp, eng.rhs, eng.tmp,
                      eng.w.c, eng.w.s, eng.w.S, eng.w.cp, eng.w.dp, eng.w.sig, 1e-6, eng.mdl, eng.barr, eng.rp,
                      eng.cnt)
        mid = np.zeros(n)
        RB.dense_eval(0.5, y0, y1, St, mid)
        end = np.zeros(n)
        RB.dense_eval(1.0, y0, y1, St, end)
        np.testing.assert_array_equal(end, y1)
        ref = solve_ivp(lambda t, y: FR.evaluate_rhs(t, y, eng.mdl), (0.0, h / 2), y0, method="DOP853", rtol=1e-13,
                        atol=1e-13).y[:, -1]
        errs.append(np.max(np.abs(mid[:2 * N] - ref[:2 * N])))
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(rates > 3.5), (errs, rates)


def _dop(p, **kw):
    return run(p, method="dop853", tol=1e-10, **kw).dataset.attrs


@pytest.mark.parametrize("pin", [None, PinMotion.pull((0.3, -0.2))])
def test_rodas4_and_dop853_agree_on_the_snap(pin):
    """Peaks and snap times of a body problem (damped bending; with a moving held end its
    stop rule) against dop853 at tol 1e-10."""
    N, beta = 30, 1e-3
    p = Problem.catenary(0.25, N, body=Body(bending=beta, damping=np.sqrt(beta) / (2 * N ** 2)), pin=pin)
    ref = _dop(p)
    ds = run(p, method="stiff", tol=1e-8).dataset
    a = ds.attrs
    assert a["method"] == "rodas4" and a["status"] == "completed" and a["stop_reason"] == ref["stop_reason"]
    assert a["stop_reason"].startswith("snap detected")
    for q in ("v", "a", "sigma"):
        assert a[f"{q}_peak"] == pytest.approx(ref[f"{q}_peak"], rel=2e-6), q
        assert a[f"t_snap_{q}"] == pytest.approx(ref[f"t_snap_{q}"], abs=2e-6), q
    assert a["n_jacobians"] == a["n_steps"] + 1  # (the pull's one breakpoint is the start)
    assert a["n_factorizations"] == a["n_steps"] + a["n_rejected"]
    # the same columns as dop853's, energy balance to the tolerance's order
    assert set(ds.data_vars) == set(run(p, method="fast", t_end=0.01).dataset.data_vars)
    bal = ds["energy"] - ds["pin_work"] + ds["dissipated"]
    assert float(abs(bal - bal[0]).max()) < 1e-5


CASE_P = Problem.catenary(0.3, 24, body=Body(bending=1e-3, damping=1e-4, drag_normal=0.2))
CASE = dict(problem=CASE_P, snapshot_times=[0.2, 0.9], tol=1e-7, method="stiff")


def test_rodas4_resume_is_bit_for_bit(tmp_path, monkeypatch):
    """Interrupted at several returns of the compiled loop (small calls), each resumed run is
    the uninterrupted one, bit for bit (the Jacobian, the stages and the counters travel in
    the file)."""
    monkeypatch.setattr(RO, "NODE_EVALS_PER_CALL", 40 * 24 * 7)
    real = RO.Engine.__init__

    def init(self, *a, **k):
        real(self, *a, **k)
        self.ctl[R.Q_STEPS_PER_CALL] = 7.0

    monkeypatch.setattr(RO.Engine, "__init__", init)
    n_ret = []
    monkeypatch.setattr(stepper, "_chunk_hook", lambda eng: n_ret.append(eng.t) and None)
    reference = run(**CASE).dataset
    monkeypatch.setattr(stepper, "_chunk_hook", None)
    assert len(n_ret) > 10
    path = tmp_path / "run.nc"
    for k in (1, len(n_ret) // 2, len(n_ret) - 1):
        monkeypatch.setattr(stepper, "_chunk_hook", _StopAt(k))
        with pytest.raises(RunInterrupted):
            run(**CASE, output=path, checkpoint_every=None, overwrite=True)
        monkeypatch.setattr(stepper, "_chunk_hook", None)
        ck = load_run(path)
        assert ck.attrs["status"] == "interrupted" and ck.attrs["method"] == "rodas4"
        assert all(v in ck.variables for v in schema.CHECKPOINT_VARS_RODAS4)
        assert_same_run(resume(path).dataset, reference)


@pytest.mark.parametrize("make", [lambda: dict(chi=0.25, N=10), lambda: dict(problem=Problem.catenary(0.25, 10)),
                                  lambda: dict(problem=Problem.catenary(0.25, 10, pin=PinMotion.pull((0.2, 0.0))))])
def test_rodas4_refuses_problems_without_a_body(make):
    with pytest.raises(SnappingInputError, match="method='rodas4' \\(stiff\\) solves chains with a body.*use "
                                                 "method='fast'"):
        run(**make(), method="stiff")
