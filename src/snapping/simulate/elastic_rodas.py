"""A compiled RODAS4 for the extensible line (``elastic.solve(..., method="rodas4")``): error
controlled, linearly implicit, O(N) per step.

The method is that of :mod:`snapping.simulate.rosenbrock` (RODAS4, Hairer and Wanner, *Solving
ODEs II*, sec. VI.4, ``rodas.f``: the tableau :data:`snapping.simulate.stiff.RODAS4`, order 4,
stiffly accurate and L-stable, the embedded order-3 estimate ``U_6``, the continuous extension
of order 3 with ``rosenbrock.D2, D3``); here it steps the elastic line's first-order state
(:mod:`snapping.simulate.elastic_kernels`: node positions and velocities, then W and D).

Each stage solves ``(I/(gamma h) - J) U = b``. The Jacobian ``J`` is exact: the node part from
:func:`elastic_kernels.jac_blocks` (block tridiagonal, ``dr/dt = v`` above, ``K = da/dr`` and
``C = da/dv`` below), the W and D rows (the held end's power, the dissipation rate) from
:func:`wd_gradients` (they are left out of ``jac_blocks``; a Rosenbrock method needs them, or
the two integrals lose order). The second-order structure reduces the stage system to the
velocities: with ``g = gamma h``,

    (I - g^2 K - g C) U_v = g b_v + g^2 K b_r,   U_r = g (b_r + U_v),

a 2N x 2N system of 2 x 2 blocks, block tridiagonal, factored once per step without pivoting
(:mod:`snapping.simulate.elastic_stage`: scaled by the masses it is symmetric positive
definite, and nearly so with damping; a guard falls back to the pivoted band LU); W's and D's
stages follow as ``U_w = g (b_w + grad_w . U)``. A step costs five evaluations of the
right-hand side, one more at the accepted end (the next step's first stage, whose tensions
the Jacobian there reuses), one Jacobian and one factorisation; a moving held end one more
evaluation for ``df/dt`` (a forward difference).

The attempts of a step (:func:`rodas_accept`) are compiled; :class:`RodasStepper` takes one
accepted step per call (scipy's ``OdeSolver`` interface), and
:func:`snapping.simulate.elastic_advance.advance` takes many, with the run's bookkeeping,
between two returns to Python.

Slack-taut transitions are met by the error control, not by events: the tension's derivative
jumps there (with damping, the tension itself), the estimate ``U_6`` sees it and the step
shrinks for that step only. Events would stop at every crossing of every link, and the
release's unloading wave makes hundreds of links near the free end cross many times; where
it matters, the error control resolves them (see the elastic guide).

Error norm: the max norm of ``U_6/(tol (1 + max(|y_n|, |y_n+1|)))`` (that of the chain's
compiled methods); the step rule of ``rodas.f`` with Gustafsson's predictive controller
(``h_new = h min(6, max(1/5, 0.9 err^-1/4))``, the predictive factor after two accepted
steps).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import elastic_kernels as EK
from . import elastic_stage as ES
from .elastic_jacobian import full_jacobian, gradient_span, jacobian, wd_gradients  # noqa: F401 (re-exported)
from . import general as G
from .rosenbrock import A_ST, C_NODE, C_ST, D2, D3, D_TIME, GAMMA

__all__ = ["RodasStepper", "RodasDense", "wd_gradients", "rodas_step", "rodas_accept", "f_and_jacobian",
           "full_jacobian", "pin_model", "NCTL"]

SAFE, FAC_MIN, FAC_MAX = 0.9, 0.2, 6.0
#: the stepper's controls and counts (``ctl``): time, the last step's start, the next step,
#: the end, tol, the predictive controller's last step and error (none while <= 0), counts
#: of evaluations, Jacobians, factorisations, rejected steps and pivoted factorisations,
#: status, the step that failed, "always pivot" and "autonomous" (a fixed held end)
(C_T, C_TOLD, C_H, C_TB, C_TOL, C_HACC, C_ERRACC, C_NFEV, C_NJEV, C_NLU, C_NREJ, C_NPIV, C_STATUS, C_HFAIL,
 C_PIVOTED, C_AUTO) = range(16)
NCTL = 16
RUNNING, FINISHED, FAILED = 0.0, 1.0, 2.0


@njit(cache=True, error_model="numpy", boundscheck=False)
def _comb(out, base, St, c, m, n):
    """``out = base + c_0 St[1] + ... + c_{m-1} St[m]`` (1 <= m <= 5), the terms of each
    element added in this order (as a loop over the stages adds them), in one pass."""
    S0 = St[1]
    c0 = c[0]
    if m == 1:
        for i in range(n):
            out[i] = base[i] + c0 * S0[i]
        return
    S1 = St[2]
    c1 = c[1]
    if m == 2:
        for i in range(n):
            out[i] = (base[i] + c0 * S0[i]) + c1 * S1[i]
        return
    S2 = St[3]
    c2 = c[2]
    if m == 3:
        for i in range(n):
            out[i] = ((base[i] + c0 * S0[i]) + c1 * S1[i]) + c2 * S2[i]
        return
    S3 = St[4]
    c3 = c[3]
    if m == 4:
        for i in range(n):
            out[i] = (((base[i] + c0 * S0[i]) + c1 * S1[i]) + c2 * S2[i]) + c3 * S3[i]
        return
    S4 = St[5]
    c4 = c[4]
    for i in range(n):
        out[i] = ((((base[i] + c0 * S0[i]) + c1 * S1[i]) + c2 * S2[i]) + c3 * S3[i]) + c4 * S4[i]


@njit(cache=True, error_model="numpy")
def rodas_step(N, t, hs, z0, ft, auto, pins, h, invm, ea, damp, tabe, tabt, g, B, gW, gD, dlo, dhi, F, ab, piv,
               pivoted, St, ytmp, btmp, w, z1, c23, tol, T, E, ED, FV, ctl):
    """One RODAS4 step of size ``hs`` from (t, z0) with ``St[0] = f(t, z0)`` and the Jacobian
    (``B, gW, gD``; ``gD`` zero outside ``[dlo, dhi)``) there; ``pins[s]`` the held end's
    state at the stage times ``t + c_s hs``, ``ft`` df/dt (used unless ``auto``). The stage
    matrix is factored by :func:`elastic_stage.factor` (pivot-free unless its guard fails or
    ``pivoted``; a pivoted factorisation counts in ``ctl[C_NPIV]``). Stages into ``St[1:7]``,
    the new state into ``z1``, the dense output's ``c2, c3`` into ``c23``. Returns the scaled
    error (max norm; inf when the stage matrix is singular or a value not finite)."""
    n = z0.shape[0]
    gh = GAMMA * hs
    path = ES.factor(N, B, gh, F, ab, piv, pivoted)
    if path == ES.PATH_SINGULAR:
        ctl[C_NPIV] += 1.0
        return np.inf
    if path == ES.PATH_PIVOTED:
        ctl[C_NPIV] += 1.0
    cc = np.empty(5)
    for st in range(6):
        if st == 0:
            for i in range(n):
                btmp[i] = St[0, i]
        else:
            _comb(ytmp, z0, St, A_ST[st], st, n)
            EK.rhs(N, ytmp, pins[st], h, invm, ea, damp, tabe, tabt, g, btmp, T, E, ED, FV)
            for j in range(st):
                cc[j] = C_ST[st, j] / hs
            _comb(btmp, btmp, St, cc, st, n)
        if not auto and D_TIME[st] != 0.0:
            dth = D_TIME[st] * hs
            for i in range(n):
                btmp[i] += dth * ft[i]
        ES.solve(N, B, gW, gD, dlo, dhi, gh, path, F, ab, piv, btmp, St[1 + st], w)
    _comb(z1, z0, St, A_ST[5], 5, n)
    return finish_step(z0, z1, St, c23, tol, n)


@njit(cache=True, error_model="numpy")
def finish_step(z0, z1, St, c23, tol, n):
    """The end of a RODAS4 step (the plain line's and :mod:`elastic_rodas_body`'s): the dense output's
    ``c2, c3`` into ``c23``, ``z1 += U_6`` (the stiffly accurate solution) and the scaled error (max
    norm of ``U_6/(tol (1 + max(|z0|, |z1|)))``; inf when a value is not finite)."""
    S0, S1, S2, S3, S4, S6 = St[1], St[2], St[3], St[4], St[5], St[6]
    a0, a1, a2, a3, a4 = D2[0], D2[1], D2[2], D2[3], D2[4]
    b0, b1, b2, b3, b4 = D3[0], D3[1], D3[2], D3[3], D3[4]
    c2 = c23[0]
    c3 = c23[1]
    for i in range(n):
        c2[i] = ((((0.0 + a0 * S0[i]) + a1 * S1[i]) + a2 * S2[i]) + a3 * S3[i]) + a4 * S4[i]
        c3[i] = ((((0.0 + b0 * S0[i]) + b1 * S1[i]) + b2 * S2[i]) + b3 * S3[i]) + b4 * S4[i]
    err = 0.0
    for i in range(n):
        z1[i] += S6[i]
        e = abs(S6[i]) / (tol * (1.0 + max(abs(z0[i]), abs(z1[i]))))
        if not (e - e == 0.0):
            return np.inf
        if e > err:
            err = e
    return err


@njit(cache=True, error_model="numpy")
def pin_at(t, pinpar, pintab, out):
    """The held end's (x, y, vx, vy) at ``t`` into ``out`` (:func:`general.pin_kinematics`,
    which :meth:`PinMotion.kinematics` evaluates; position and velocity are continuous)."""
    x, y, vx, vy, _, _ = G.pin_kinematics(t, pinpar, pintab)
    out[0] = x
    out[1] = y
    out[2] = vx
    out[3] = vy


@njit(cache=True, error_model="numpy")
def f_and_jacobian(N, t, z, pinpar, pintab, pin, h, invm, ea, damp, tabe, tabt, g, f, B, gW, gD, dsp, T, E, ED, FV):
    """``f(t, z)`` and the Jacobian there (:func:`jacobian`, from the same tensions; ``B`` its
    compact node blocks, ``dsp`` the D row's span): what a step needs at its start."""
    pin_at(t, pinpar, pintab, pin)
    EK.rhs(N, z, pin, h, invm, ea, damp, tabe, tabt, g, f, T, E, ED, FV)
    jacobian(N, z, pin, h, invm, ea, damp, tabe, tabt, T, E, ED, B, gW, gD)
    lo, hi = gradient_span(N, gD)
    dsp[0] = lo
    dsp[1] = hi


@njit(cache=True, error_model="numpy")
def attempt_step(ctl, t, tb):
    """``(hs, last, failed)`` of the next attempt from ``t``: the step ``ctl[C_H]``, cut to reach
    ``tb`` exactly when it (nearly) passes it (``last``); ``failed`` (and ``ctl[C_STATUS] = FAILED``,
    the step in ``ctl[C_HFAIL]``) when it fell below 1e-14 |t|. Shared by RODAS4's loops in node
    and link coordinates."""
    hs = ctl[C_H]
    last = t + hs >= tb or t + 1.01 * hs >= tb
    if last:
        hs = tb - t
    if hs <= 1e-14 * max(1.0, abs(t)):
        ctl[C_STATUS] = FAILED
        ctl[C_HFAIL] = hs
        return hs, last, True
    return hs, last, False


@njit(cache=True, error_model="numpy")
def control_step(ctl, hs, err, reject):
    """The step rule of ``rodas.f`` with Gustafsson's predictive controller, after an attempt of
    step ``hs`` with scaled error ``err``: True when accepted (err <= 1; ``ctl[C_H]`` the next
    step, ``C_HACC``, ``C_ERRACC`` updated), False when rejected (``C_NREJ`` counted, ``ctl[C_H]``
    the retry's step: a tenth of ``hs`` for a non-finite error). ``reject``: an attempt of this
    step was rejected before (the next step then does not grow)."""
    if not (err - err == 0.0):
        ctl[C_NREJ] += 1.0
        ctl[C_H] = 0.1 * hs
        return False
    fac = min(1.0 / FAC_MIN, max(1.0 / FAC_MAX, err ** 0.25 / SAFE))
    hnew = hs / fac
    if err <= 1.0:
        if ctl[C_HACC] > 0.0:  # Gustafsson's predictive controller (rodas.f, PRED)
            facg = (ctl[C_HACC] / hs) * (err * err / ctl[C_ERRACC]) ** 0.25 / SAFE
            facg = min(1.0 / FAC_MIN, max(1.0 / FAC_MAX, facg))
            hnew = hs / max(fac, facg)
        ctl[C_HACC] = hs
        ctl[C_ERRACC] = max(1e-2, err)
        if reject:
            hnew = min(hnew, hs)
        ctl[C_H] = hnew
        return True
    ctl[C_NREJ] += 1.0
    ctl[C_H] = hnew
    return False


@njit(cache=True, error_model="numpy")
def rodas_accept(N, y, St, B, gW, gD, dsp, F, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g,
                 ytmp, btmp, w, ft, z1, y0d, c23, ctl, T, E, ED, FV):
    """Attempt RODAS4 steps from ``(ctl[C_T], y)`` (``St[0] = f`` and the Jacobian there) with
    the step ``ctl[C_H]`` and shrink it until one is accepted: then ``y0d`` holds the old
    state, ``y`` (and ``z1``) the new, ``c23`` its dense output, ``St[0]`` and the Jacobian
    are those of the new state, ``ctl`` the new time, the next step and the counts. Returns 0,
    or 1 when the step fell below 1e-14 |t| (``ctl[C_STATUS] = FAILED``, the step in
    ``ctl[C_HFAIL]``). The step rule of ``rodas.f`` with Gustafsson's predictive controller."""
    n = y.shape[0]
    t = ctl[C_T]
    tb = ctl[C_TB]
    auto = ctl[C_AUTO] != 0.0
    pivoted = ctl[C_PIVOTED] != 0.0
    tol = ctl[C_TOL]
    reject = False
    while True:
        hs, last, failed = attempt_step(ctl, t, tb)
        if failed:
            return 1
        if auto:
            for s in range(6):
                pin_at(t, pinpar, pintab, pins[s])
        else:
            for s in range(6):
                pin_at(t + C_NODE[s] * hs, pinpar, pintab, pins[s])
            dt = 1e-7 * max(1.0, abs(t))
            pin_at(t + dt, pinpar, pintab, pins[6])
            EK.rhs(N, y, pins[6], h, invm, ea, damp, tabe, tabt, g, ft, T, E, ED, FV)
            ctl[C_NFEV] += 1.0
            for i in range(n):
                ft[i] = (ft[i] - St[0, i]) / dt
        ctl[C_NLU] += 1.0
        ctl[C_NFEV] += 5.0
        err = rodas_step(N, t, hs, y, ft, auto, pins, h, invm, ea, damp, tabe, tabt, g, B, gW, gD, int(dsp[0]),
                         int(dsp[1]), F, ab, piv, pivoted, St, ytmp, btmp, w, z1, c23, tol, T, E, ED, FV, ctl)
        if not control_step(ctl, hs, err, reject):
            reject = True
            continue
        tn = tb if last else t + hs
        for i in range(n):
            y0d[i] = y[i]
            y[i] = z1[i]
        ctl[C_TOLD] = t
        ctl[C_T] = tn
        f_and_jacobian(N, tn, y, pinpar, pintab, pins[6], h, invm, ea, damp, tabe, tabt, g, St[0], B, gW, gD,
                       dsp, T, E, ED, FV)
        ctl[C_NFEV] += 1.0
        ctl[C_NJEV] += 1.0
        if last:
            ctl[C_STATUS] = FINISHED
        return 0


class RodasDense:
    """The continuous extension of one step (order 3): ``y(t_old + x hs) = (1 - x) y0 + x (y1 +
    (1 - x)(c2 + x c3))``; called with a time in [t_old, t]."""

    def __init__(self, t_old, t, y0, y1, c23):
        self.t_old, self.t = t_old, t
        self.y0, self.y1, self.c2, self.c3 = y0, y1, c23[0].copy(), c23[1].copy()

    def __call__(self, tt):
        x = (float(tt) - self.t_old) / (self.t - self.t_old)
        return self.y0 * (1.0 - x) + x * (self.y1 + (1.0 - x) * (self.c2 + x * self.c3))


def pin_model(line):
    """The compiled held end of ``line``: ``(par, tab)`` of :func:`general.pin_kinematics`."""
    mdl = G.make_model(np.ones(1), np.ones(1), **line.pin.model_args())
    return mdl[0], mdl[-1]


class RodasStepper:
    """RODAS4 on an :class:`ElasticLine` with the interface of scipy's ``OdeSolver`` that
    :func:`elastic_solve.solve` uses: ``step()``, ``t``, ``t_old``, ``y``, ``status``,
    ``dense_output()``, ``h`` (the next step, settable), ``nfev``, ``njev``, ``nlu`` (and
    ``nrej``, rejected steps, ``npiv``, pivoted factorisations). ``pivoted=True`` factors
    every stage matrix with partial pivoting (the reference of the pivot-free path)."""

    def __init__(self, line, t0, z0, t_bound, tol, h0=None, *, pivoted=False):
        self.line = line
        self.y = np.array(z0, dtype=float)
        N = self.N = line.N
        n = self.y.size
        self.ctl = np.zeros(NCTL)
        c = self.ctl
        c[C_T], c[C_TOLD], c[C_TB], c[C_TOL], c[C_HACC] = float(t0), np.nan, float(t_bound), float(tol), -1.0
        c[C_AUTO] = float(line.pin.kind == "fixed")
        c[C_PIVOTED] = float(bool(pivoted))
        self.pinpar, self.pintab = pin_model(line)
        self.St = np.zeros((7, n))
        self.B = np.zeros((N, 3, 8))
        self.gW, self.gD = np.zeros(4), np.zeros(4 * N)
        self.dsp = np.zeros(2)
        self.F = np.zeros((N, ES.NF))
        self.ab = np.zeros((2 * N, ES.WIDTH))
        self.piv = np.zeros(2 * N, dtype=np.int64)
        self.ytmp, self.btmp, self.z1, self.ft, self.y0d = (np.zeros(n) for _ in range(5))
        self.w = np.zeros(2 * N)
        self.c23 = np.zeros((2, n))
        self.work = tuple(np.zeros(N) for _ in range(4))
        self.pins = np.zeros((7, 4))
        self._dense = None
        self.f_and_jacobian()
        c[C_NFEV] += 1.0
        c[C_NJEV] += 1.0
        c[C_H] = h0 if h0 is not None else self._initial_step()

    def args(self):
        """The line's arrays, as the compiled functions take them."""
        ln = self.line
        return ln.h, ln._invm, ln.ea, ln.damp, ln.tabe, ln.tabt, ln.g

    def f_and_jacobian(self):
        """f and the Jacobian at the current (t, y) (not counted)."""
        f_and_jacobian(self.N, self.ctl[C_T], self.y, self.pinpar, self.pintab, self.pins[6], *self.args(), self.St[0],
                       self.B, self.gW, self.gD, self.dsp, *self.work)

    # the state and counts
    t = property(lambda self: float(self.ctl[C_T]))
    t_old = property(lambda self: None if np.isnan(self.ctl[C_TOLD]) else float(self.ctl[C_TOLD]))
    t_bound = property(lambda self: float(self.ctl[C_TB]))
    tol = property(lambda self: float(self.ctl[C_TOL]))
    nfev = property(lambda self: int(self.ctl[C_NFEV]))
    njev = property(lambda self: int(self.ctl[C_NJEV]))
    nlu = property(lambda self: int(self.ctl[C_NLU]))
    nrej = property(lambda self: int(self.ctl[C_NREJ]))
    npiv = property(lambda self: int(self.ctl[C_NPIV]))
    status = property(lambda self: {RUNNING: "running", FINISHED: "finished", FAILED: "failed"}[self.ctl[C_STATUS]])

    @property
    def h(self):
        return float(self.ctl[C_H])

    @h.setter
    def h(self, value):
        self.ctl[C_H] = float(value)

    def _f(self, t, z, out):
        self.ctl[C_NFEV] += 1.0
        pin = np.zeros(4)
        pin_at(float(t), self.pinpar, self.pintab, pin)
        EK.rhs(self.N, z, pin, *self.args(), out, *self.work)

    def _norm(self, v):
        return float(np.max(np.abs(v) / (self.tol * (1.0 + np.abs(self.y)))))

    def _initial_step(self):
        """Hairer and Wanner's starting step (I, sec. II.4) for an order-4 method."""
        d0, d1 = self._norm(self.y), self._norm(self.St[0])
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        h0 = min(h0, self.t_bound - self.t)
        f1 = np.empty_like(self.y)
        self._f(self.t + h0, self.y + h0 * self.St[0], f1)
        d2 = self._norm(f1 - self.St[0]) / h0
        h1 = max(1e-6, h0 * 1e-3) if max(d1, d2) <= 1e-15 else (0.01 / max(d1, d2)) ** 0.2
        return min(100.0 * h0, h1, self.t_bound - self.t)

    def dense_output(self):
        return self._dense

    def step(self):
        """One accepted step (retrying with smaller ones after rejections); returns None or a
        message when the step fails."""
        if self.status != "running":
            raise RuntimeError("the stepper is not running")
        t = self.t
        if rodas_accept(self.N, self.y, self.St, self.B, self.gW, self.gD, self.dsp, self.F, self.ab, self.piv,
                        self.pins, self.pinpar, self.pintab, *self.args(), self.ytmp, self.btmp, self.w, self.ft,
                        self.z1, self.y0d, self.c23, self.ctl, *self.work) != 0:
            return f"step size {self.ctl[C_HFAIL]:.3g} too small at t = {t:.9g}"
        self._dense = RodasDense(self.t_old, self.t, self.y0d.copy(), self.y.copy(), self.c23)
        self.y = self.y.copy()  # (a new array per step, as scipy's solvers give)
        return None
