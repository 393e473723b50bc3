"""RODAS4 on chains whose free end is graded down to links of ~1e-7 (issue 24's fifth bending
level): the error estimate of a tiny link's angular velocity has a roundoff floor (the angles
rounded to doubles, through the link's bending stiffness ~B/h^4), which the error norm must
not ask to beat (:func:`snapping.simulate.rosenbrock.omega_floor`)."""

from __future__ import annotations

import numpy as np

from snapping.regimes import eta_grid
from snapping.simulate import Body, Links, Problem, grading
from snapping.simulate import rk as R
from snapping.simulate import rosenbrock as RB
from snapping.simulate import stiff as ST
from snapping.simulate.methods import rodas4 as RO

EPS = np.finfo(float).eps


def _problem():
    """chi = 0.1, beta = 7.2e-8 with the regime study's grid damping, 153 fold-graded links from
    1.7e-7 at the free end (the bending study's fifth level has 5e-7, 14,625 links)."""
    h = grading.fold_following(0.1, frac=0.5, h_min=1e-7, h_max=0.1, gamma=1.0)
    return Problem.catenary(0.1, links=Links.graded(h), chords="exact",
                            body=Body(bending=7.2e-8, damping=eta_grid(h, 7.2e-8, 1.0)))


def _engine(p, tol, t_end):
    eng = RO.Engine(p.initial_angles(), 0.0, mdl=p.model(), tol=tol, dt0=None, t_end=t_end, stop_fraction=0.0,
                    thin=0.0, max_link_error=0.5, snapshot_times=())
    eng.ctl[R.Q_STEPS_PER_CALL] = 50
    return eng


def _steps_to(p, tol, t_end, cap):
    """Accepted steps to t_end (None: more than ``cap``)."""
    eng = _engine(p, tol, t_end)
    code = eng.loop(None, poll=lambda: -7 if eng.ctl[R.Q_NSTEPS] > cap else None)
    return None if code == -7 else int(eng.ctl[R.Q_NSTEPS])


def test_the_floor_is_the_noise_of_the_estimate_through_the_dense_jacobian():
    """omega_floor from the banded rows against the same bound from the dense ODE Jacobian
    (-M^-1 R_theta by a dense solve: the tension coupling included), and against the noise it
    bounds: the estimate U_6 of a step moves, when the state is rounded differently by one ulp,
    by less than the floor (and by far more than tol 1e-7 at the free end's links)."""
    p = _problem()
    eng = _engine(p, 1e-7, 1.0)
    N, n = eng.N, eng.Y0.shape[1]
    y0 = eng.Y1[0].copy()
    mdl, _ = ST.body_model(p)
    res = ST.Residual(mdl)
    f = np.empty(n)
    res.rhs(0.0, y0, f)
    J = ST.dense_ode_jacobian(res, 0.0, y0, res.jacobian(0.0, y0, f))
    Ath, Aom = np.abs(J[N:, :N]), np.abs(J[N:, N:])
    S = Ath @ np.abs(y0[:N]) + Aom @ np.abs(y0[N:2 * N])
    expect = 2 * EPS * S / (Aom.sum(1) + 2 * np.sqrt(Ath.sum(1)))
    fl = np.array([RB.omega_floor(N, j, eng.Dj, y0, mdl[1]) for j in range(N)])
    np.testing.assert_allclose(fl[:8], expect[:8], rtol=2e-3)
    np.testing.assert_allclose(ST.omega_floor(res, res.jacobian(0.0, y0, f), y0), fl, rtol=1e-12, atol=0)
    assert fl[0] > 1e-6 and fl[1] > 1e-7  # the tip's floor: above tol 1e-7
    assert np.all(fl[50:] < 1e-12)  # links of 1e-3 and more: far below any tolerance
    rng = np.random.default_rng(5)
    U6 = []
    for trial in range(6):
        y = y0 * (1 + rng.choice([-1.0, 0.0, 1.0], n) * EPS / 2) if trial else y0.copy()
        f = np.empty(n)
        RB.MD.model_rhs(N, 0.0, y, f, eng.w.c, eng.w.s, eng.w.S, eng.w.cp, eng.w.dp, eng.w.sig, eng.mdl)
        Dj = np.zeros_like(eng.Dj)
        RB.jacobian_at(N, 0.0, y, f, eng.w.sig, Dj, eng.mdl, eng.barr, eng.rp)
        St = np.zeros((RB.NSTG, n))
        St[RB.S_F0] = f
        RB.rodas_step(N, 0.0, 1e-9, y, np.zeros(n), St, eng.ft, Dj, eng.ab, eng.piv, eng.ytmp, eng.btmp, eng.rhs,
                      eng.tmp, eng.w.c, eng.w.s, eng.w.S, eng.w.cp, eng.w.dp, eng.w.sig, 1e-7, eng.mdl, eng.barr,
                      eng.rp, eng.cnt)
        U6.append(St[6, N:N + 4].copy())
    spread = np.ptp(np.array(U6), axis=0)
    assert spread[0] > 1e-7, spread  # the noise alone exceeds tol 1e-7 at the free end
    assert np.all(spread < fl[:4]), (spread, fl[:4])


def test_tiny_tip_links_do_not_collapse_the_step_at_tol_1e_7():
    """The 153 links to t = 1e-6 (the release's transient and after): at tol 1e-7 in at most 4x
    the steps of tol 1e-6 (an order-3 estimate: 10^(1/4) = 1.8x, with a margin); before the
    floor, 69,758 steps of ~1e-11 (tol 1e-6: 304); with it 199 (tol 1e-6: 163)."""
    p = _problem()
    n6 = _steps_to(p, 1e-6, 1e-6, 5000)
    assert n6 is not None
    n7 = _steps_to(p, 1e-7, 1e-6, 4 * n6)
    assert n7 is not None, f"tol 1e-7 needs more than {4 * n6} steps to t = 1e-6 (tol 1e-6: {n6})"
