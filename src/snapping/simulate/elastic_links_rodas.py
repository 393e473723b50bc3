"""RODAS4 on the extensible line in link coordinates (``elastic.solve(..., method="rodas4-links")``).

The method, tableau, dense output and step rule are :mod:`snapping.simulate.elastic_rodas`'s;
the state it steps is :mod:`snapping.simulate.elastic_links`' ``(l_j, theta_j, l_j', theta_j')``
per link (then W and D), where a turning link does not stretch: at large wave speed c its steps
are set by the motion, not by a longitudinal ringing of the integration (the elastic guide,
"Link coordinates").

What differs from the node version:

* the stage matrix ``I - g^2 K - g C`` (the same reduced, block-tridiagonal system of
  :mod:`snapping.simulate.elastic_stage`) is always factored with partial pivoting (band LU):
  in link coordinates it is not symmetric positive definite once scaled (the rows of
  ``theta''`` carry ``1/l``), and the pivot-free block LU's guard fails;
* the error ``U_6`` is mapped to the nodes' positions and velocities (to first order) and
  measured there with the node states' scale (:func:`elastic_links.node_error`), so ``tol``
  means what it means for ``"rodas4"``;
* a step that would leave a link shorter than :data:`elastic_links.SHORT_LINK` of its rest
  length is rejected (its angle would be undefined), as a non-finite one is (0.1 the step).

:class:`LinksStepper` has :class:`~snapping.simulate.elastic_rodas.RodasStepper`'s interface:
its ``y`` and its dense output are node states, so :func:`elastic_solve.solve`'s Python loop,
snapshots, peaks and ``restep`` use it unchanged.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from . import elastic_links as EL
from . import elastic_stage as ES
from .elastic_jacobian import gradient_span
from .elastic_rodas import (C_AUTO, C_H, C_HACC, C_HFAIL, C_NFEV, C_NJEV, C_NLU, C_NPIV, C_STATUS, C_T, C_TB,
                            C_TOL, C_TOLD, FINISHED, NCTL, RodasDense, RodasStepper, _comb, attempt_step, control_step,
                            pin_model)
from .rosenbrock import A_ST, C_NODE, C_ST, D2, D3, D_TIME, GAMMA

__all__ = ["LinksStepper", "links_step", "links_accept"]


@njit(cache=True, error_model="numpy")
def links_step(N, hs, z0, zn0, ft, auto, pins, h, invm, ea, damp, tabe, tabt, g, B, gW, gD, dlo, dhi, ab, piv,
               St, ytmp, btmp, w, z1, zn1, c23, tol, T, E, ED, FV, gx, gy, ctl):
    """One RODAS4 step of size ``hs`` from the link state ``z0`` (node state ``zn0``) with
    ``St[0] = f`` and the Jacobian (``B, gW, gD``) there; ``pins[s]`` the held end's (x, y,
    vx, vy, ax, ay) at the stage times, ``pins[5]`` at the step's end. The new link state into
    ``z1``, its node state into ``zn1``, the dense output's ``c2, c3`` into ``c23``. Returns
    the error in node values (:func:`elastic_links.node_error`), inf when the stage matrix is
    singular, a value is not finite or a link would be shorter than ``SHORT_LINK`` h."""
    n = z0.shape[0]
    gh = GAMMA * hs
    ES.assemble_band(N, B, gh, ab)
    ctl[C_NPIV] += 1.0
    if ES.band_lu(ab, 2 * N, ES.KLE, ES.KUE, piv) != 0:
        return np.inf
    cc = np.empty(5)
    F = np.zeros((1, ES.NF))
    for st in range(6):
        if st == 0:
            for i in range(n):
                btmp[i] = St[0, i]
        else:
            _comb(ytmp, z0, St, A_ST[st], st, n)
            EL.rhs(N, ytmp, pins[st], h, invm, ea, damp, tabe, tabt, g, btmp, T, E, ED, FV, gx, gy)
            for j in range(st):
                cc[j] = C_ST[st, j] / hs
            _comb(btmp, btmp, St, cc, st, n)
        if not auto and D_TIME[st] != 0.0:
            dth = D_TIME[st] * hs
            for i in range(n):
                btmp[i] += dth * ft[i]
        ES.solve(N, B, gW, gD, dlo, dhi, gh, ES.PATH_PIVOTED, F, ab, piv, btmp, St[1 + st], w)
    _comb(z1, z0, St, A_ST[5], 5, n)
    S0, S1, S2, S3, S4, S6 = St[1], St[2], St[3], St[4], St[5], St[6]
    a0, a1, a2, a3, a4 = D2[0], D2[1], D2[2], D2[3], D2[4]
    b0, b1, b2, b3, b4 = D3[0], D3[1], D3[2], D3[3], D3[4]
    c2 = c23[0]
    c3 = c23[1]
    for i in range(n):
        c2[i] = ((((0.0 + a0 * S0[i]) + a1 * S1[i]) + a2 * S2[i]) + a3 * S3[i]) + a4 * S4[i]
        c3[i] = ((((0.0 + b0 * S0[i]) + b1 * S1[i]) + b2 * S2[i]) + b3 * S3[i]) + b4 * S4[i]
    for i in range(n):
        z1[i] += S6[i]
    for j in range(N):
        if not (z1[4 * j] >= EL.SHORT_LINK * h[j]):
            return np.inf
    EL.to_nodes(N, z1, pins[5], zn1)
    return EL.node_error(N, z1, S6, zn0, zn1, tol)


@njit(cache=True, error_model="numpy")
def f_and_jacobian(N, t, z, pinpar, pintab, pin, h, invm, ea, damp, tabe, tabt, g, f, B, gW, gD, dsp, T, E, ED, FV,
                   gx, gy, cw):
    """``f(t, z)`` and the exact Jacobian there (``dsp``: the D row's span)."""
    EL.pin6_at(t, pinpar, pintab, pin)
    EL.rhs(N, z, pin, h, invm, ea, damp, tabe, tabt, g, f, T, E, ED, FV, gx, gy)
    EL.jacobian(N, z, pin, h, invm, ea, damp, tabe, tabt, g, T, E, ED, FV, gx, gy, B, gW, gD, cw)
    lo, hi = gradient_span(N, gD)
    dsp[0] = lo
    dsp[1] = hi


@njit(cache=True, error_model="numpy")
def links_accept(N, y, yn, St, B, gW, gD, dsp, ab, piv, pins, pinpar, pintab, h, invm, ea, damp, tabe, tabt, g,
                 ytmp, btmp, w, ft, z1, zn1, y0d, yn0d, c23, ctl, T, E, ED, FV, gx, gy, cw):
    """:func:`elastic_rodas.rodas_accept` for the link state ``y`` (node state ``yn``): attempt
    steps, shrinking until one is accepted; then ``y0d``, ``yn0d`` hold the old states, ``y``,
    ``yn`` the new. Returns 0, or 1 when the step fell below 1e-14 |t| (FAILED)."""
    n = y.shape[0]
    t = ctl[C_T]
    tb = ctl[C_TB]
    auto = ctl[C_AUTO] != 0.0
    tol = ctl[C_TOL]
    reject = False
    while True:
        hs, last, failed = attempt_step(ctl, t, tb)
        if failed:
            return 1
        for s in range(6):
            EL.pin6_at(t + C_NODE[s] * hs if not auto else t, pinpar, pintab, pins[s])
        EL.pin6_at(t + hs if not auto else t, pinpar, pintab, pins[5])
        if not auto:
            dt = 1e-7 * max(1.0, abs(t))
            EL.pin6_at(t + dt, pinpar, pintab, pins[6])
            EL.rhs(N, y, pins[6], h, invm, ea, damp, tabe, tabt, g, ft, T, E, ED, FV, gx, gy)
            ctl[C_NFEV] += 1.0
            for i in range(n):
                ft[i] = (ft[i] - St[0, i]) / dt
        ctl[C_NLU] += 1.0
        ctl[C_NFEV] += 5.0
        err = links_step(N, hs, y, yn, ft, auto, pins, h, invm, ea, damp, tabe, tabt, g, B, gW, gD, int(dsp[0]),
                         int(dsp[1]), ab, piv, St, ytmp, btmp, w, z1, zn1, c23, tol, T, E, ED, FV, gx, gy, ctl)
        if not control_step(ctl, hs, err, reject):
            reject = True
            continue
        tn = tb if last else t + hs
        for i in range(n):
            y0d[i] = y[i]
            y[i] = z1[i]
            yn0d[i] = yn[i]
            yn[i] = zn1[i]
        ctl[C_TOLD] = t
        ctl[C_T] = tn
        f_and_jacobian(N, tn, y, pinpar, pintab, pins[6], h, invm, ea, damp, tabe, tabt, g, St[0], B, gW, gD,
                       dsp, T, E, ED, FV, gx, gy, cw)
        ctl[C_NFEV] += 1.0
        ctl[C_NJEV] += 1.0
        if last:
            ctl[C_STATUS] = FINISHED
        return 0


class LinksDense:
    """The step's continuous extension in link coordinates, returned as a node state."""

    def __init__(self, links, t_old, t, y0, y1, c23):
        self.links, self.t_old, self.t = links, t_old, t
        self.dense = RodasDense(t_old, t, y0, y1, c23)

    def __call__(self, tt):
        return self.links.to_nodes(tt, self.dense(tt))


class LinksStepper(RodasStepper):
    """RODAS4 in link coordinates on an :class:`ElasticLine`, with :class:`RodasStepper`'s
    interface (``step()``, ``t``, ``t_old``, ``y``, ``status``, ``dense_output()``, ``h``,
    ``nfev``, ``njev``, ``nlu``, ``nrej``, ``npiv``); ``y0`` and ``y`` are node states (the
    link state is ``zl``). A start with a link shorter than ``SHORT_LINK`` of its rest length
    is bad input."""

    def __init__(self, line, t0, z0, t_bound, tol, h0=None):
        self.line = line
        self.links = EL.LinkLine(line)
        self.yn = np.array(z0, dtype=float)
        self.zl = self.links.from_nodes(t0, self.yn)
        N = self.N = line.N
        n = self.zl.size
        self.ctl = np.zeros(NCTL)
        c = self.ctl
        c[C_T], c[C_TOLD], c[C_TB], c[C_TOL], c[C_HACC] = float(t0), np.nan, float(t_bound), float(tol), -1.0
        c[C_AUTO] = float(line.pin.kind == "fixed")
        self.pinpar, self.pintab = pin_model(line)
        self.St = np.zeros((7, n))
        self.B = np.zeros((N, 3, 8))
        self.gW, self.gD = np.zeros(4), np.zeros(4 * N)
        self.dsp = np.zeros(2)
        self.ab = np.zeros((2 * N, ES.WIDTH))
        self.piv = np.zeros(2 * N, dtype=np.int64)
        self.ytmp, self.btmp, self.z1, self.zn1, self.ft, self.y0d, self.yn0d = (np.zeros(n) for _ in range(7))
        self.w = np.zeros(2 * N)
        self.c23 = np.zeros((2, n))
        self.work = tuple(np.zeros(N) for _ in range(6))
        self.cw = np.zeros((4, N))
        self.pins = np.zeros((7, 6))
        self._dense = None
        self.f_and_jacobian()
        c[C_NFEV] += 1.0
        c[C_NJEV] += 1.0
        c[C_H] = h0 if h0 is not None else self._initial_step()

    y = property(lambda self: self.yn)

    def f_and_jacobian(self):
        f_and_jacobian(self.N, self.ctl[C_T], self.zl, self.pinpar, self.pintab, self.pins[6], *self.args(),
                       self.St[0], self.B, self.gW, self.gD, self.dsp, *self.work, self.cw)

    def _initial_step(self):
        """:meth:`RodasStepper._initial_step` on the node model (the same first step as
        ``"rodas4"``; its two evaluations counted)."""
        d0 = self._norm(self.yn)
        f0 = self.line.rhs(self.t, self.yn)
        d1 = self._norm(f0)
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        h0 = min(h0, self.t_bound - self.t)
        f1 = self.line.rhs(self.t + h0, self.yn + h0 * f0)
        self.ctl[C_NFEV] += 2.0
        d2 = self._norm(f1 - f0) / h0
        h1 = max(1e-6, h0 * 1e-3) if max(d1, d2) <= 1e-15 else (0.01 / max(d1, d2)) ** 0.2
        return min(100.0 * h0, h1, self.t_bound - self.t)

    def step(self):
        """One accepted step; returns None or a message when the step fails."""
        if self.status != "running":
            raise RuntimeError("the stepper is not running")
        t = self.t
        if links_accept(self.N, self.zl, self.yn, self.St, self.B, self.gW, self.gD, self.dsp, self.ab, self.piv,
                        self.pins, self.pinpar, self.pintab, *self.args(), self.ytmp, self.btmp, self.w, self.ft,
                        self.z1, self.zn1, self.y0d, self.yn0d, self.c23, self.ctl, *self.work, self.cw) != 0:
            return f"step size {self.ctl[C_HFAIL]:.3g} too small at t = {t:.9g}"
        self._dense = LinksDense(self.links, self.t_old, self.t, self.y0d.copy(), self.zl.copy(), self.c23)
        self.yn = self.yn.copy()  # (a new array per step, as scipy's solvers give)
        return None
