"""The drag power's exact gradient (branch ``dragexact``, issue 24): the stiff method's dissipation
row ``D' = 2R - p`` takes its stage terms from :func:`snapping.simulate.forced.drag_power_gradient`
instead of one forward difference (a full right side) per stage.

* the gradient against the complex step of an independent numpy transcription of the drag power
  (node velocities summed from the held end, the tangent the links' bisector), at random states,
  with every drag term (quadratic and linear, normal and tangential, a tip body, wind, a moving
  held end), to within rounding; the transcription's power is tied to the compiled one's;
* one compiled RODAS4 step with the exact rows against the same step with the rows by forward
  differences: the angles bit for bit, the dissipation to the difference's accuracy, and 5
  evaluations instead of 11;
* the compiled step against the Python reference's (``stiff._Stepper``) from a moving state;
* a drag run (graded links, the nylon answer's settings) with the exact rows against the same run
  by differences: the same steps and peaks; a graded design answer against direct runs by differences.
"""

from __future__ import annotations

import numpy as np
import pytest

from snapping.simulate import Body, Links, PinMotion, Problem, run
from snapping.simulate import forced as FR
from snapping.simulate import general as G
from snapping.simulate import rosenbrock as RB
from snapping.simulate.methods import rodas4 as RO

RNG = np.random.default_rng(24)


def _cabs(x):
    """|x| for a complex step (the real part's sign)."""
    return x if x.real >= 0.0 else -x


def _power(th, om, h, pv, wind, CN, CT, KN, KT, cd):
    """``sum_j F_j.v_j`` (j < N) of the drag written from its definition (complex-safe)."""
    N = th.size
    t = np.stack([np.cos(th), np.sin(th)], axis=1)
    nrm = np.stack([-np.sin(th), np.cos(th)], axis=1)
    v = [None] * (N + 1)
    v[N] = np.asarray(pv, dtype=complex)
    for j in range(N - 1, -1, -1):
        v[j] = v[j + 1] - h[j] * om[j] * nrm[j]
    p = 0.0
    for j in range(N):
        tau = t[j]
        if j > 0:
            b = t[j - 1] + t[j]
            tau = b / np.sqrt(b[0] * b[0] + b[1] * b[1])
        u = v[j] - wind
        ut = (u @ tau) * tau
        un = u - ut
        F = -(CN[j] * np.sqrt(un @ un) + KN[j]) * un - (CT[j] * _cabs(u @ tau) + KT[j]) * ut
        if j == 0:
            F = F - cd * np.sqrt(u @ u) * u
        p += F @ v[j]
    return p


BODIES = {
    "quadratic": dict(body=Body(drag_normal=0.5, drag_tangential=0.05)),
    "all": dict(body=Body(bending=1e-3, drag_normal=0.4, drag_tangential=0.07, drag_linear_normal=0.2,
                          drag_linear_tangential=0.1, tip_drag=0.3, wind=(0.3, -0.1))),
    "moving": dict(body=Body(drag_normal=0.3, drag_linear_tangential=0.2, tip_drag=0.1),
                   pin=PinMotion.pull((0.3, -0.2))),
}


@pytest.mark.parametrize("case", sorted(BODIES))
def test_gradient_is_the_complex_step_of_the_drag_power(case):
    N = 9
    kw = dict(BODIES[case])
    p = Problem.catenary(0.3, links=Links.graded(np.linspace(1.5, 0.5, N) / np.linspace(1.5, 0.5, N).sum()), **kw)
    mdl = p.model()
    par, h, invm, invh, snode, tab = mdl
    o, n1 = int(par[FR.P_BOFF]), N + 1
    CN, CT, KN, KT = (tab[o + b * n1:o + (b + 1) * n1] for b in (FR.B_CN, FR.B_CT, FR.B_KN, FR.B_KT))
    wind = np.array([par[FR.P_WX], par[FR.P_WY]])
    t = 0.13
    pv = G.pin_kinematics(t, par, tab)[2:4]
    El = tab[o + FR.B_EL * n1:o + (FR.B_EL + 1) * n1]
    assert not np.any(El)  # (no damping: D' is the drag's alone)
    for _ in range(3):
        y = np.zeros(2 * N + 2)
        y[:N] = p.initial_angles()[:N] + 0.4 * RNG.standard_normal(N)
        y[N:2 * N] = 2.0 * RNG.standard_normal(N)
        g = np.zeros(2 * N)
        FR.drag_power_gradient(N, t, y, np.zeros(N), np.zeros(N), par, h, tab.copy(), g)
        th, om = y[:N], y[N:2 * N]
        p0 = _power(th.astype(complex), om.astype(complex), h, pv, wind, CN, CT, KN, KT, par[FR.P_TIPCD]).real
        dprime = FR.evaluate_rhs(t, y, mdl)[2 * N + 1]
        assert p0 == pytest.approx(-dprime, rel=1e-13, abs=1e-15)  # (the transcription is the compiled power)
        cs = np.zeros(2 * N)
        for i in range(2 * N):
            z = y[:2 * N].astype(complex)
            z[i] += 1e-30j
            cs[i] = _power(z[:N], z[N:], h, pv, wind, CN, CT, KN, KT, par[FR.P_TIPCD]).imag / 1e-30
        np.testing.assert_allclose(g, cs, rtol=1e-12, atol=1e-13 * np.max(np.abs(cs)))
        assert np.max(np.abs(cs[:N])) > 0.0 and np.max(np.abs(cs[N:])) > 0.0


def _engine(p, tol=1e-6):
    return RO.Engine(p.initial_angles(), 0.0, mdl=p.model(), tol=tol, dt0=None, t_end=1.0, stop_fraction=0.0,
                     thin=0.0, max_link_error=0.5, snapshot_times=())


def _step(eng, h, fd):
    N, n = eng.N, eng.Y0.shape[1]
    rp = eng.rp.copy()
    if fd:
        rp[RB.RP_QFD] = 1.0
    St = np.zeros((RB.NSTG, n))
    St[RB.S_F0] = eng.KK[0, RB.S_F1]
    y0 = eng.Y1[0].copy()
    y0[N:2 * N] = 0.5 * RNG.standard_normal(N)  # (moving: the drag acts)
    w = eng.w
    from snapping.simulate import models as MD
    MD.model_rhs(N, 0.0, y0, St[RB.S_F0], w.c, w.s, w.S, w.cp, w.dp, w.sig, eng.mdl)
    RB.jacobian_at(N, 0.0, y0, St[RB.S_F0], w.sig, eng.Dj, eng.mdl, eng.barr, rp)
    y1 = np.zeros(n)
    err, nev = RB.rodas_step(N, 0.0, h, y0, y1, St, eng.ft, eng.Dj, eng.ab, eng.piv, eng.ytmp, eng.btmp, eng.rhs,
                             eng.tmp, w.c, w.s, w.S, w.cp, w.dp, w.sig, 1e-6, eng.mdl, eng.barr, rp, eng.cnt)
    return y0, y1, St.copy(), nev


def test_compiled_step_exact_rows_against_forward_differences():
    p = Problem.catenary(0.3, 14, body=Body(bending=1e-3, damping=1e-4, drag_normal=0.5, drag_tangential=0.05,
                                            tip_drag=0.2))
    eng = _engine(p)
    assert eng.rp[RB.RP_QFD] == 0.0 and eng.rp[RB.RP_DRAG] == 1.0
    N = eng.N
    state = RNG.bit_generator.state
    y0, y1, St, nev = _step(eng, 2e-3, fd=False)
    RNG.bit_generator.state = state
    y0f, y1f, Stf, nevf = _step(_engine(p), 2e-3, fd=True)
    np.testing.assert_array_equal(y0, y0f)
    assert (nev, nevf) == (5, 11)
    np.testing.assert_array_equal(y1[:2 * N], y1f[:2 * N])  # (the dynamics do not see the W/D rows)
    dD, dDf = y1[2 * N + 1] - y0[2 * N + 1], y1f[2 * N + 1] - y0f[2 * N + 1]
    assert dD > 0.0 and abs(dD - dDf) <= 1e-6 * abs(dD)
    stage = St[1:7, 2 * N + 1]
    np.testing.assert_allclose(stage, Stf[1:7, 2 * N + 1], rtol=1e-5, atol=1e-6 * np.max(np.abs(stage)))


def test_graded_drag_run_keeps_its_steps_and_peaks(monkeypatch):
    """A run as the nylon answer's graded ones (drag, bending, grid damping, tol 1e-3) with the exact
    rows and by differences: the dynamics do not see the W/D rows and here their error is never the
    largest, so the steps and peaks are the same; the evaluations about half."""
    hs = np.concatenate([np.full(20, 0.01), np.full(16, 0.05)])
    links = Links.graded(hs / hs.sum())
    body = Body(bending=2e-5, damping=1e-6, drag_normal=0.3, drag_tangential=0.02, tip_drag=0.05)
    p = Problem.catenary(0.2, links=links, body=body)
    exact = run(p, method="rodas4", tol=1e-3, progress=False).dataset.attrs
    orig = RO.Engine.__init__

    def init(self, *a, **kw):
        orig(self, *a, **kw)
        self.rp[RB.RP_QFD] = 1.0

    monkeypatch.setattr(RO.Engine, "__init__", init)
    fd = run(p, method="rodas4", tol=1e-3, progress=False).dataset.attrs
    assert exact["n_steps"] == fd["n_steps"] and exact["n_rejected"] == fd["n_rejected"]  # (370, 17)
    assert exact["n_rhs"] < 0.6 * fd["n_rhs"]  # (2484 against 4806)
    for q in ("v_peak", "a_peak", "sigma_peak"):
        assert float(exact[q]) == pytest.approx(float(fd[q]), rel=1e-9)


def test_graded_answer_agrees_with_direct_runs_by_differences(monkeypatch):
    """A graded design answer (a thin line whose bending length is 0.03 L, with drag: the nylon
    answer's route on few links) against direct runs of its two levels with the W/D rows by forward
    differences (the route before): the same peaks, and the answer's extrapolation of them."""
    import math

    from snapping import caps, caps_runs, estimates
    from snapping.simulate import grading
    from snapping.simulate.stiffness import grid_damping

    g0 = 9.81
    Lc, Mc, chi, lb = 1.0, 0.1, 0.5, 0.03
    kw = {"ei": lb ** 2 * (Mc / Lc) * g0 * Lc ** 3, "diameter": 2e-3, "cd_normal": 1.2}
    r = caps.cap(None, chi, N=12, check=False, alone=False, graded=True, length=Lc, mass=Mc, **kw)
    g = r["graded"]
    assert g["used"] and g["pair"] == (0, 1)
    orig = RO.Engine.__init__

    def init(self, *a, **k):
        orig(self, *a, **k)
        assert self.rp[RB.RP_QFD] == 0.0 and self.rp[RB.RP_DRAG] == 1.0
        self.rp[RB.RP_QFD] = 1.0

    monkeypatch.setattr(RO.Engine, "__init__", init)
    a = estimates.catenary_parameter(chi)
    peaks = []
    for k in (0, 1):
        s = 0.5 ** k
        h = grading.fold_following(chi, frac=1.5 * lb * s / a, h_min=0.4 * lb * s, h_max=min(0.5, 20 * lb * s))
        links = Links.graded(h)
        eta = grid_damping(h, links.m, np.full(h.size + 1, lb ** 2), 0.01)
        body = Body.from_si(Lc, Mc, g0, **kw)
        body = Body(body.bending, damping=eta, drag_normal=body.drag_normal, drag_tangential=body.drag_tangential)
        at = run(Problem.catenary(chi, links=links, body=body), method="rodas4", tol=1e-3, progress=False,
                 drag_jacobian=caps_runs.GRADED_DRAG_JACOBIAN).dataset.attrs
        peaks.append({"v_peak": float(at["v_peak"]) * math.sqrt(g0 * Lc), "a_peak": float(at["a_peak"]) * g0,
                      "sigma_peak": float(at["sigma_peak"]) * Mc * g0})
    for q in caps.QUANTITIES:
        for k in (0, 1):
            assert g["levels_peaks"][k][q] == pytest.approx(peaks[k][q], rel=1e-6)
        assert r["real"][q] == pytest.approx(peaks[1][q] + (peaks[1][q] - peaks[0][q]) / 3.0, rel=1e-6)


def test_compiled_step_is_the_python_reference_step_in_motion():
    """The compiled step and the Python reference's (``stiff._Stepper``, its own LAPACK banded solves)
    from a moving state with drag (at rest the drag's gradient vanishes): the same new state, the
    dissipation included."""
    from snapping.simulate import stiff as ST

    p = Problem.catenary(0.3, 12, body=Body(bending=1e-3, drag_normal=0.5, drag_tangential=0.05,
                                            drag_linear_normal=0.1))
    eng = _engine(p)
    N = eng.N
    y0, y1, _, nev = _step(eng, 3e-3, fd=False)
    assert nev == 5
    mdl, _ = ST.body_model(p)
    res = ST.Residual(mdl)
    f = np.empty_like(y0)
    res.rhs(0.0, y0, f)
    D = res.jacobian(0.0, y0, f)
    ynew, _ = ST._Stepper(res, 1e-6).step(0.0, y0, f, D, 3e-3, None)
    np.testing.assert_allclose(y1, ynew, rtol=1e-11, atol=1e-13)
    assert y1[2 * N + 1] - y0[2 * N + 1] > 1e-8
