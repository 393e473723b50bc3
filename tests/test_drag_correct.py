"""The stiff method's drag correction (branch ``dragcorr``, issue 24): ``drag_jacobian="correct"``
corrects each stage of RODAS4 once for what the banded Jacobian leaves out (drag): ``J U`` by one
forward difference of the right side along U, the residual of the exact stage equation, one more
banded solve.

* the compiled step with the correction against the Python reference's (``stiff._Stepper``) from
  a moving state with drag;
* the compiled step with and without the correction against a RODAS4 step written here with dense
  stage solves whose Jacobian is the central differences of the right side in every angle and
  angular velocity (drag included): the corrected step is far closer;
* the option: validated, off by default (the step unchanged), stored in the run file and read back.
"""

from __future__ import annotations

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.simulate import Body, Problem, run
from snapping.simulate import models as MD
from snapping.simulate import rosenbrock as RB
from snapping.simulate import stiff as ST
from snapping.simulate.methods import rodas4 as RO

RNG = np.random.default_rng(2024)
BODY = Body(bending=1e-3, damping=1e-4, drag_normal=2.0, drag_tangential=0.2, drag_linear_normal=0.3, tip_drag=0.3)


def _problem(N=12):
    return Problem.catenary(0.3, N, body=BODY)


def _engine(p):
    return RO.Engine(p.initial_angles(), 0.0, mdl=p.model(), tol=1e-6, dt0=None, t_end=1.0, stop_fraction=0.0,
                     thin=0.0, max_link_error=0.5, snapshot_times=())


def _moving(eng, seed=3):
    N = eng.N
    y0 = eng.Y1[0].copy()
    y0[N:2 * N] = 1.5 * np.random.default_rng(seed).standard_normal(N)  # (moving: the drag acts)
    return y0


def _compiled_step(eng, y0, h, correct):
    N, n = eng.N, y0.size
    rp = eng.rp.copy()
    rp[RB.RP_DCORR] = 1.0 if correct else 0.0
    St = np.zeros((RB.NSTG, n))
    w = eng.w
    MD.model_rhs(N, 0.0, y0, St[RB.S_F0], w.c, w.s, w.S, w.cp, w.dp, w.sig, eng.mdl)
    RB.jacobian_at(N, 0.0, y0, St[RB.S_F0], w.sig, eng.Dj, eng.mdl, eng.barr, rp)
    y1 = np.zeros(n)
    cnt = np.zeros(RB.NCNT)
    err, nev = RB.rodas_step(N, 0.0, h, y0.copy(), y1, St, eng.ft, eng.Dj, eng.ab, eng.piv, eng.ytmp, eng.btmp,
                             eng.rhs, eng.tmp, w.c, w.s, w.S, w.cp, w.dp, w.sig, 1e-6, eng.mdl, eng.barr, rp, cnt)
    return y1, err, nev, cnt


def _f(eng, y):
    w = eng.w
    out = np.empty_like(y)
    MD.model_rhs(eng.N, 0.0, y, out, w.c, w.s, w.S, w.cp, w.dp, w.sig, eng.mdl)
    return out


def _dense_step(eng, y0, h):
    """RODAS4 (the tableau of ``stiff.RODAS4``) on the angles and angular velocities with dense stage
    solves ``(I/(gamma h) - J) U = b``, J the central differences of the right side (drag included)."""
    N = eng.N
    n2 = 2 * N
    J = np.empty((n2, n2))
    for k in range(n2):
        d = 1e-6 * max(1.0, abs(y0[k]))
        yp, ym = y0.copy(), y0.copy()
        yp[k] += d
        ym[k] -= d
        J[:, k] = (_f(eng, yp)[:n2] - _f(eng, ym)[:n2]) / (2 * d)
    tab = ST.RODAS4
    gh = tab["gamma"] * h
    M = np.eye(n2) / gh - J
    U = []
    for i in range(6):
        Y = y0.copy()
        for j, a in enumerate(tab["a"][i]):
            Y[:n2] += a * U[j]
        b = _f(eng, Y)[:n2]
        for j, cc in enumerate(tab["C"][i]):
            b = b + (cc / h) * U[j]
        U.append(np.linalg.solve(M, b))
    y1 = y0[:n2].copy()
    for j, a in enumerate(tab["a"][5]):
        y1 += a * U[j]
    return y1 + U[5]


def test_compiled_corrected_step_is_the_python_reference_step():
    p = _problem()
    eng = _engine(p)
    N = eng.N
    assert eng.rp[RB.RP_DRAG] == 1.0 and eng.rp[RB.RP_DCORR] == 0.0
    y0 = _moving(eng)
    h = 3e-3
    y1, _, nev, cnt = _compiled_step(eng, y0, h, True)
    assert nev == 5 + 6 and cnt[RB.CN_EXTRA] == 6.0  # (one evaluation more per stage)
    mdl, _ = ST.body_model(p)
    res = ST.Residual(mdl)
    f = np.empty_like(y0)
    res.rhs(0.0, y0, f)
    D = res.jacobian(0.0, y0, f)
    st = ST._Stepper(res, 1e-6, drag_correct=True)
    ynew, _ = st.step(0.0, y0, f, D, h, None)
    assert st.nrhs_q == 6 and st.nsolve == 12
    np.testing.assert_allclose(y1, ynew, rtol=1e-12, atol=1e-13)
    y1b, _ = ST._Stepper(res, 1e-6).step(0.0, y0, f, D, h, None)
    assert np.max(np.abs(y1b[:2 * N] - ynew[:2 * N])) > 1e-6  # (the correction matters here)


@pytest.mark.parametrize("h", [2e-3, 1e-2])
def test_corrected_step_is_close_to_the_dense_exact_jacobian_step(h):
    p = _problem(14)
    eng = _engine(p)
    N = eng.N
    y0 = _moving(eng, 5)
    ref = _dense_step(eng, y0, h)
    banded, _, nevb, _ = _compiled_step(eng, y0, h, False)
    corr, _, nevc, _ = _compiled_step(eng, y0, h, True)
    assert (nevb, nevc) == (5, 11)
    eb = np.max(np.abs(banded[:2 * N] - ref))
    ec = np.max(np.abs(corr[:2 * N] - ref))
    print(h, eb, ec)
    assert eb > 1e-6  # (the banded step misses the drag's Jacobian)
    assert ec < 0.02 * eb  # (measured: 5e-4 and 4e-3 of it)


def test_off_by_default_and_flag_off_is_the_step_unchanged():
    p = _problem()
    eng = _engine(p)
    y0 = _moving(eng)
    a = _compiled_step(eng, y0, 3e-3, False)
    r = run(p, method="rodas4", tol=1e-4, t_end=0.02, progress=False)
    assert "drag_jacobian" not in r.dataset.attrs
    np.testing.assert_array_equal(a[0], _compiled_step(_engine(p), y0, 3e-3, False)[0])


def test_option_validated_stored_and_read_back(tmp_path):
    p = _problem(8)
    for bad in ("exact", 1, None):
        with pytest.raises(SnappingInputError, match=r"drag_jacobian=.*banded.*correct"):
            run(p, method="rodas4", t_end=0.01, drag_jacobian=bad)
    with pytest.raises(SnappingInputError, match="drag_jacobian='correct' is an option of method='rodas4'"):
        run(0.3, 8, method="fast", t_end=0.01, drag_jacobian="correct")
    from snapping.simulate import inputs_from_attrs, rerun

    a = run(p, method="rodas4", tol=1e-4, t_end=0.05, drag_jacobian="correct", progress=False).dataset
    b = run(p, method="rodas4", tol=1e-4, t_end=0.05, progress=False).dataset
    assert a.attrs["drag_jacobian"] == "correct" and inputs_from_attrs(a)["drag_jacobian"] == "correct"
    for d, per in ((a, 11), (b, 5)):  # (per attempted step; the corrections' evaluations counted)
        att = int(d.attrs["n_steps"]) + int(d.attrs["n_rejected"])
        assert per * att + int(d.attrs["n_steps"]) <= int(d.attrs["n_rhs"]) <= per * att + int(d.attrs["n_steps"]) + 5
    assert a.attrs["n_steps"] < b.attrs["n_steps"]  # (the drag's Jacobian in the stages: fewer steps)
    c = rerun(a).dataset
    np.testing.assert_array_equal(a.v_max.values, c.v_max.values)


def test_correct_refused_where_nothing_to_correct_or_no_stage_solves():
    """(review) 'correct' on a line without drag would double the work for nothing: refused, naming what is 0;
    'fast' that steps the problem with dop853 is named as such (not as 'this run's method is fast')."""
    for body in (Body(bending=1e-3), Body(bending=1e-3, damping=1e-4)):
        with pytest.raises(SnappingInputError, match="has none .*drag_normal.*tip_drag all 0.*banded"):
            run(Problem.catenary(0.3, 10, body=body), method="rodas4", t_end=0.01, drag_jacobian="correct")
    for p in (Problem.catenary(0.3, 10, body=Body(drag_normal=1.0)), None):
        args = (p,) if p is not None else (0.3, 8)
        with pytest.raises(SnappingInputError, match="method='fast' steps this problem with 'dop853': give "
                                                     "method='rodas4'"):
            run(*args, method="fast", t_end=0.01, drag_jacobian="correct")
    with pytest.raises(SnappingInputError, match="this run's method is 'dop853'"):
        run(0.3, 8, method="dop853", t_end=0.01, drag_jacobian="correct")
    for body in (Body(drag_normal=1.0), Body(tip_drag=0.5, bending=1e-4)):  # drag of either kind: accepted
        r = run(Problem.catenary(0.3, 10, body=body), method="rodas4", t_end=0.01, drag_jacobian="correct",
                progress=False)
        assert r.dataset.attrs["drag_jacobian"] == "correct"
