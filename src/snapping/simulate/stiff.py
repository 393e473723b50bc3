"""A stiff (linearly implicit) integrator for chains with bending: RODAS4 with O(N) banded stage solves.

Why. The explicit method (``method="fast"``, DOP853) is stable only for steps below the
period of the fastest bending wave, ``dt ~ h^2 sqrt(lambda/B)``: bending stiffness makes
fine chains expensive exactly where the snap needs them fine. A linearly implicit
(Rosenbrock) method is L-stable: bending waves are resolved where the error control asks
for it and damped where it does not, and its step is set by accuracy only.

The structure: :mod:`snapping.simulate.stiff_system` (the rows, their banded derivatives,
the stage matrix).

The method. RODAS4 (Hairer and Wanner, *Solving ODEs II*, sec. VI.4; the coefficients of
``rodas.f``): 6 stages (6 evaluations per step), order 4 with an embedded order 3 error
estimate, stiffly accurate and L-stable, the standard error control
``h_new = h min(6, max(0.2, 0.9 err^{-1/4}))`` with the error norm
``rms(U_6/(tol (1 + max(|y_n|, |y_{n+1}|))))`` (relative and absolute ``tol``; the scale of an
angular velocity floored at the roundoff of its estimate, :func:`omega_floor`: issue 24's
links of 1e-7, whose estimate no step size brings below tol 1e-7).
Peaks (v, a, sigma): the global maxima over accepted steps, then located between the
neighbouring steps by Brent's bounded search on the state at time t, obtained by one
RODAS4 step from the accepted step before (an interpolant as accurate as the steps).

Measured (``benchmarks/bench_stiff.py``, ``bench_stiff_single.py``; chi = 0.25, peaks to
1e-6; counts are right-hand-side evaluations, all included): the step is not set by the
bending stiffness, but by the bending waves the release excites. The catenary is not a
bending equilibrium (the free end and the hinge carry no moment), so releasing it
launches grid-scale bending waves; without bending damping they never decay, and an
error-controlled method must follow them. Undamped, this method needs more evaluations
than dop853 (N = 100, beta = 1e-6, 1e-4, 1e-2: 0.34, 0.55, 0.48 times dop853's
efficiency). With a little bending damping (``eta = sqrt(beta)/(2 N^2)``: damping ratio
about 1 for the shortest wave, negligible for the fall) the waves decay and the L-stable
steps pass over them: dop853/stiff evaluations 0.6-1.3 (N = 100), 2.8-2.9 (N = 300),
1.5 (N = 1000, beta = 1e-6), 11.3 (N = 1000, beta = 1e-4) and 17 (N = 1000, beta = 1e-2,
to t = 1.3, stiff at tol 2e-7: at tol 1e-6 its peaks are 1.8e-6 off).
Each step also costs a Jacobian (20 complex evaluations of the compiled rows) and a
banded LU, and the step loop is Python: per evaluation the method is 5-50x slower in
wall time than dop853's compiled loop (N = 1000, beta = 1e-2: 66 s against 86 s).

Integration status: this module is the Python reference of the method (:func:`solve`:
peaks, counts, records; the rms error norm). The method of :func:`snapping.simulate.run`
is ``method="rodas4"`` (alias ``"stiff"``; :mod:`snapping.simulate.methods.rodas4`), its
step loop compiled (:mod:`snapping.simulate.rosenbrock`, the max norm of DOP853, tested
step for step against :class:`_Stepper`), with records, peaks on the continuous
extension, the stop rules, snapshots, checkpoints and resume; ``method="fast"`` chooses
it where the explicit stability limit would cost more (:mod:`snapping.simulate.stiffness`).
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.optimize import minimize_scalar

from . import forced as FR
from . import general as G
from . import kernels as K
from .stiff_system import (KL, KU, NCOL, Residual, StageMatrix, body_model,  # noqa: F401 (re-exported)
                           dense_ode_jacobian)

__all__ = ["Residual", "StageMatrix", "solve", "RODAS4", "ROUND", "omega_floor"]

#: RODAS4 (Hairer-Wanner, rodas.f): gamma, nodes c_i, d_i (time-derivative weights), the
#: stage sums a_ij (Y_i = y + sum a_ij U_j) and c_ij (b_i = f(Y_i) + sum c_ij/h U_j + d_i h f_t);
#: y_new = y + sum a_6j U_j + U_6, error estimate U_6
RODAS4 = {
    "gamma": 0.25,
    "c": (0.0, 0.386, 0.21, 0.63, 1.0, 1.0),
    "d": (0.25, -0.1043, 0.1035, -0.0362, 0.0, 0.0),
    "a": ((), (1.544,), (0.9466785280815826, 0.2557011698983284),
          (3.314825187068521, 2.896124015972201, 0.9986419139977817),
          (1.221224509226641, 6.019134481288629, 12.53708332932087, -0.687886036105895),
          (1.221224509226641, 6.019134481288629, 12.53708332932087, -0.687886036105895, 1.0)),
    "C": ((), (-5.6688,), (-2.430093356833875, -0.2063599157091915),
          (-0.1073529058151375, -9.594562251023355, -20.47028614809616),
          (7.496443313967647, -10.24680431464352, -33.99990352819905, 11.7089089320616),
          (8.083246795921522, -7.981132988064893, -31.52159432874371, 16.31930543123136, -6.058818238834054)),
}

#: the unit roundoff of the error norm's floor (twice the double's eps: the measured noise of the
#: estimate reached 1.3 times the model at the free end's links, ``tests/test_tiplinks.py``)
ROUND = 2.0 * float(np.finfo(np.float64).eps)


def omega_floor(res: Residual, D, y) -> np.ndarray:
    """The roundoff floor of the error estimate of each link's angular velocity (N values; the
    error norm's scale of that component is ``max(tol (1 + |omega_j|), floor_j)``): the
    accelerations move by ``eps S_j`` when the state is rounded to doubles, ``S_j = sum_l
    |da_j/dtheta_l| |theta_l| + |da_j/domega_l| |omega_l|``, and a stage solve passes at most
    ``1/(c_j + 2 sqrt(k_j))`` of it to omega_j (``k_j, c_j`` the row sums of ``|da_j/dtheta|``,
    ``|da_j/domega|``), with the angle rows' derivatives ``-(dR_2j/dx)/h_j`` of ``D``
    (:meth:`Residual.jacobian`; the tension coupling left out). Numpy; the compiled step's is
    :func:`snapping.simulate.rosenbrock.omega_floor`."""
    N = res.N
    kth = np.zeros(N)
    kom = np.zeros(N)
    s = np.zeros(N)
    for k in range(NCOL):
        r, lk = res.cidx[k][0], res.cidx[k][1]
        a = r % 2 == 0  # (the angle rows)
        j, lk = r[a] // 2, lk[a]
        a0 = np.abs(D[0, k, r[a]])
        a1 = np.abs(D[1, k, r[a]])
        np.add.at(kth, j, a0)
        np.add.at(kom, j, a1)
        np.add.at(s, j, a0 * np.abs(y[lk]) + a1 * np.abs(y[N + lk]))
    ih = 1.0 / res.h
    den = kom * ih + 2.0 * np.sqrt(kth * ih)
    return np.where(den > 0.0, ROUND * s * ih / np.where(den > 0.0, den, 1.0), 0.0)


class _Stepper:
    """RODAS4 steps on the chain (the state, its derivative and its Jacobian at the step's start)."""

    def __init__(self, res: Residual, tol: float, drag_correct: bool = False):
        self.res, self.tol, self.drag_correct = res, tol, bool(drag_correct)
        self.N = res.N
        self.nstep = self.nrej = self.njac = self.nlu = self.nsolve = self.nrhs_q = 0

    def step(self, t, y, f0, D, h, ft=None):
        """One RODAS4 step of size h from (t, y) with ``f0 = f(t, y)`` and the Jacobian ``D``
        there; returns ``(y_new, err)`` (err the scaled error norm)."""
        res, N = self.res, self.N
        tab = RODAS4
        g = tab["gamma"]
        gh = g * h
        sm = StageMatrix(res, D, gh)
        self.nlu += 1
        U = []
        n = y.size
        gq = None  # (the drag power's gradient at y, once per step)
        for i in range(6):
            if i == 0:
                fi = f0
            else:
                Yi = y.copy()
                for j, a in enumerate(tab["a"][i]):
                    Yi += a * U[j]
                fi = np.empty(n)
                res.rhs(t + tab["c"][i] * h, Yi, fi)
            b = fi.copy()
            for j, cc in enumerate(tab["C"][i]):
                b += (cc / h) * U[j]
            if ft is not None and tab["d"][i] != 0.0:
                b += (tab["d"][i] * h) * ft
            Uth, Uom = sm.solve(b[:N], b[N:2 * N])
            self.nsolve += 1
            if self.drag_correct:
                Uth, Uom = self._correct(t, y, f0, sm, gh, b, Uth, Uom)
            Ui = np.empty(n)
            Ui[:N] = Uth
            Ui[N:2 * N] = Uom
            # W, D: (1/(gamma h)) U_q - dq'/dx U_x = b_q, the directional derivative by a difference
            bq = b[2 * N:]
            if res.quad and not res.quad_fd:  # dD'/dx U_x, exact (W' = 0)
                El, om = res.El, y[N:2 * N]
                bq = bq.copy()
                bq[1] += 2.0 * float(np.dot(El[1:N] * (om[1:] - om[:-1]), Uom[1:] - Uom[:-1]))
                if res.clamped:
                    _, phid = FR.clamp_angle(t, res.par, res.tab)
                    bq[1] -= 2.0 * El[N] * (phid - om[N - 1]) * Uom[N - 1]
                if res.hasdrag:  # D' = 2R - p: the drag's power gradient along U_x
                    if gq is None:
                        gq = np.empty(2 * N)
                        FR.drag_power_gradient(N, t, y, np.empty(N), np.empty(N), res.par, res.h, res.tab, gq)
                    bq[1] -= float(np.dot(gq, Ui[:2 * N]))
            elif res.quad:
                ux = Ui[:2 * N]
                nu = np.sqrt(np.mean(ux * ux))
                if nu > 0.0:
                    dl = 1e-7 * (1.0 + np.sqrt(np.mean(y[:2 * N] ** 2))) / nu
                    yp = y.copy()
                    yp[:2 * N] += dl * ux
                    fp = np.empty(n)
                    res.rhs(t, yp, fp)
                    self.nrhs_q += 1
                    bq = bq + (fp[2 * N:] - f0[2 * N:]) / dl
            Ui[2 * N:] = gh * bq
            U.append(Ui)
        ynew = y.copy()
        for j, a in enumerate(tab["a"][5]):
            ynew += a * U[j]
        ynew += U[5]
        sc = self.tol * (1.0 + np.maximum(np.abs(y), np.abs(ynew)))
        sc[N:2 * N] = np.maximum(sc[N:2 * N], omega_floor(res, D, y))  # (the roundoff floor)
        err = math.sqrt(float(np.mean((U[5] / sc) ** 2)))
        return ynew, err

    def _correct(self, t, y, f0, sm, gh, b, Uth, Uom):
        """One defect correction of a stage's angle part for what the banded Jacobian leaves out
        (drag): ``J U`` by one forward difference of the right side along U, the residual of
        ``U/(gamma h) - J U = b``, one more banded solve (the compiled step's ``_stage_correct``)."""
        N = self.N
        u = np.concatenate([Uth, Uom])
        nu = np.sqrt(np.mean(u * u))
        if not nu > 0.0:
            return Uth, Uom
        dl = 1e-7 * (1.0 + np.sqrt(np.mean(y[:2 * N] ** 2))) / nu
        yp = y.copy()
        yp[:2 * N] += dl * u
        fp = np.empty_like(y)
        self.res.rhs(t, yp, fp)
        self.nrhs_q += 1
        rom = b[N:2 * N] - (Uom / gh - (fp[N:2 * N] - f0[N:2 * N]) / dl)
        rth = b[:N] - (Uth / gh - Uom)
        dth, dom = sm.solve(rth, rom)
        self.nsolve += 1
        return Uth + dth, Uom + dom

    def time_derivative(self, t, y, f0):
        if self.res.autonomous:
            return None
        dt = 1e-7 * max(1.0, abs(t))
        f1 = np.empty_like(y)
        self.res.rhs(t + dt, y, f1)
        self.nrhs_q += 1
        return (f1 - f0) / dt


def solve(problem, t_end: float | None = None, tol: float = 1e-8, *, h0: float = 1e-4, stop_fraction: float = 0.5,
          t_end_max: float = 10.0, max_steps: int = 200000, refine: bool = True, records: bool = True,
          dt_fixed: float | None = None) -> dict:
    """Integrate ``problem`` with RODAS4 and banded O(N) stage solves (see the module).

    Runs to ``t_end``, or without it to the snap by the driver's rule (``v_max`` below
    ``stop_fraction`` of its running peak after the peak; at ``t_end_max`` at the latest).
    Returns a dict: the peaks ``v_peak, a_peak, sigma_peak`` and their times ``t_snap_v,
    t_snap_a, t_snap_sigma`` (located between steps when ``refine``), ``n_steps,
    n_rejected``, ``n_rhs`` (right-hand-side evaluations of the steps: 5 per attempted
    step, 1 per accepted step (its end, which starts the next), 2 at the start),
    ``n_rhs_extra`` (W/D directional derivatives and ``f_t``), ``n_rhs_refine`` (peak
    location; all evaluations: ``n_rhs + n_rhs_extra + n_rhs_refine``), ``n_jac``
    (Jacobians: 20 complex evaluations of the rows each), ``n_lu``
    (banded factorisations), ``n_solves`` (banded solves), ``wall``, ``t``, ``y`` (final
    state) and, with ``records``, ``rec``: an array (steps + 1, 7) of ``t, v_max, a_max,
    sigma_max, energy, W, D`` at the accepted steps. ``dt_fixed``: every step of that size,
    no error control (order studies).

    >>> from snapping.simulate import Body, Problem
    >>> from snapping.simulate import stiff
    >>> o = stiff.solve(Problem.catenary(0.25, 8, body=Body(bending=1e-3)), 0.1, 1e-6)
    >>> o["stop"], o["n_rhs"] == 5 * (o["n_steps"] + o["n_rejected"]) + o["n_steps"] + 2, round(o["t"], 12)
    ('t_end', True, 0.1)
    """
    mdl, y = body_model(problem)
    res = Residual(mdl)
    st = _Stepper(res, float(tol))
    N = res.N
    w0 = time.perf_counter()
    t = 0.0
    f = np.empty_like(y)
    res.rhs(t, y, f)
    m = res.measure(t, y)
    rec = [(t, *m)]
    best = [(m[q], 0) for q in range(3)]  # (value, index into hist)
    hist = [(t, y.copy(), None)]  # accepted states (t, y, D) -- D filled when the step from it is taken
    D = res.jacobian(t, y, f)
    st.njac += 1
    hist[0] = (t, y.copy(), D)
    h = float(h0 if dt_fixed is None else dt_fixed)
    nrej_row = 0
    vpeak = m[0]
    tstop = t_end if t_end is not None else t_end_max
    stopped = "t_end"
    bps = sorted(b for b in G.breakpoints(mdl) if 0.0 <= b < tstop)
    tl = t  # (the time the next step starts from: t, or its right limit at a breakpoint)
    while t < tstop:
        if st.nstep >= max_steps:
            stopped = "max_steps"
            break
        if t + h >= tstop:
            h = tstop - t
        nb = [b for b in bps if b > t]
        if nb and t + h > nb[0]:
            h = nb[0] - t  # (land on the held end's breakpoints)
        if t in bps and tl != np.nextafter(t, np.inf):  # a step from a breakpoint: its right limit
            tl = np.nextafter(t, np.inf)
            res.rhs(tl, y, f)
            D = res.jacobian(tl, y, f)
            st.njac += 1
            hist[-1] = (tl, y.copy(), D)
        ft = st.time_derivative(tl, y, f)
        ynew, err = st.step(tl, y, f, D, h, ft)
        if dt_fixed is not None:
            err = 0.0 if np.all(np.isfinite(ynew)) else math.inf
        if not (err <= 1.0) or not np.all(np.isfinite(ynew)):
            st.nrej += 1
            nrej_row += 1
            fac = 0.2 if not math.isfinite(err) else max(0.2, 0.9 * err ** -0.25)
            h *= fac
            if h < 1e-14:
                raise RuntimeError(f"stiff.solve: step size underflow at t={t}")
            continue
        fac = min(6.0, max(0.2, 0.9 * (max(err, 1e-10)) ** -0.25))
        if nrej_row:
            fac = min(fac, 1.0)
        nrej_row = 0
        t = t + h if t + h < tstop else tstop
        if nb and abs(t - nb[0]) <= 4e-16 * max(1.0, abs(t)):
            t = nb[0]
        tl = t
        y = ynew
        st.nstep += 1
        res.rhs(t, y, f)
        par, hh, invm, invh, snode, _ = mdl
        FR.forced_measure(N, t, y, res.c, res.s, res.sig, res.Z, res.rinv0, res.meas, par, hh, invm, invh, snode,
                          res.tab)
        mm = res.meas
        m = (mm[K.M_VMAX], mm[K.M_AMAX], mm[K.M_SIGMAX], mm[K.M_ENERGY], y[2 * N], y[2 * N + 1])
        D = res.jacobian(t, y, f)
        st.njac += 1
        hist.append((t, y.copy(), D))
        if records:
            rec.append((t, *m))
        for q in range(3):
            if m[q] > best[q][0]:
                best[q] = (m[q], len(hist) - 1)
        if m[0] > vpeak:
            vpeak = m[0]
        elif t_end is None and m[0] < stop_fraction * vpeak and best[0][1] > 0:
            stopped = "snap"
            break
        # keep only what a peak search can need: the bracket around each running best
        keep = {i for b in best for i in (b[1] - 1, b[1], b[1] + 1)} | {len(hist) - 1}
        for i in range(len(hist) - 1):
            if i not in keep and hist[i] is not None:
                hist[i] = None
        h = h * fac if dt_fixed is None else float(dt_fixed)
    nrhs_steps = res.nrhs
    nq_steps = st.nrhs_q
    out = {"n_steps": st.nstep, "n_rejected": st.nrej, "n_jac": st.njac, "n_lu": st.nlu, "n_solves": st.nsolve,
           "t": t, "y": y, "stop": stopped, "tol": tol, "N": N}
    names = ("v", "a", "sigma")
    for q in range(3):
        val, i = best[q]
        tq = hist[i][0]
        if refine and 0 < i < len(hist) - 1:
            val, tq = _locate(res, st, hist, i, q)
        out[f"{names[q]}_peak"] = float(val)
        out[f"t_snap_{names[q]}"] = float(tq)
    out["n_rhs_refine"] = res.nrhs - nrhs_steps
    out["n_rhs_extra"] = nq_steps
    out["n_rhs"] = nrhs_steps - nq_steps
    out["wall"] = time.perf_counter() - w0
    if records:
        out["rec"] = np.array(rec)
    return out


def _locate(res, st, hist, i, q):
    """Maximise quantity q on [t_{i-1}, t_{i+1}]: the state at t by one RODAS4 step from the
    accepted state before t (Brent's bounded search)."""
    (ta, ya, Da), (tb, yb, Db), (tc, _, _) = hist[i - 1], hist[i], hist[i + 1]
    fa = np.empty_like(ya)
    res.rhs(ta, ya, fa)
    fb = np.empty_like(yb)
    res.rhs(tb, yb, fb)

    def state(tt):
        if tt <= ta:
            return ya
        if tt <= tb:
            ys, ts, fs, Ds = ya, ta, fa, Da
        else:
            ys, ts, fs, Ds = yb, tb, fb, Db
        if tt == ts:
            return ys
        ft = st.time_derivative(ts, ys, fs)
        yn, _ = st.step(ts, ys, fs, Ds, tt - ts, ft)
        return yn

    def negq(tt):
        return -res.measure(tt, state(tt))[q]

    best_v, best_t = -negq(tb), tb
    r = minimize_scalar(negq, bounds=(ta, tc), method="bounded", options={"xatol": 1e-10 * max(1.0, tc)})
    if -r.fun > best_v:
        best_v, best_t = -r.fun, float(r.x)
    return best_v, best_t
