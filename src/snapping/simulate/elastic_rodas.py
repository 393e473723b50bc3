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

a 2N x 2N system of 2 x 2 blocks, bandwidth 3 each side, factored once per step by the banded
LU with partial pivoting of :mod:`snapping.simulate.banded` (O(N)); W's and D's stages follow
as ``U_w = g (b_w + grad_w . U)``. A step costs five evaluations of the right-hand side, one
more at the accepted end (the next step's first stage), one Jacobian and one factorisation;
a moving held end one more evaluation for ``df/dt`` (a forward difference).

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

import math

import numpy as np
from numba import njit

from . import elastic_kernels as EK
from .banded import band_lu, band_solve
from .rosenbrock import A_ST, C_NODE, C_ST, D2, D3, D_TIME, GAMMA

__all__ = ["RodasStepper", "wd_gradients", "stage_system", "stage_solve", "rodas_step", "full_jacobian"]

#: the reduced stage matrix's bandwidths (2 x 2 blocks, interleaved x, y)
KLE = KUE = 3
WIDTH = 2 * KLE + KUE + 1
SAFE, FAC_MIN, FAC_MAX = 0.9, 0.2, 6.0


@njit(cache=True)
def wd_gradients(N, z, pin, h, ea, damp, tabe, tabt, T, E, ED, FV, gW, gD):
    """The gradients of the W row (the held end's power ``T u . v_pin`` of link N-1) and of
    the D row (``sum_j h_j (T_j - f_j) edot_j``) by the node state (x, y, vx, vy per node):
    ``gW`` (4 entries, node N-1's), ``gD`` (4N). ``T, E, ED, FV`` are those of ``z``
    (:func:`elastic_kernels.tensions`)."""
    for i in range(4 * N):
        gD[i] = 0.0
    for k in range(4):
        gW[k] = 0.0
    for j in range(N):
        if E[j] <= 0.0:
            continue
        ln = h[j] * (1.0 + E[j])
        if j + 1 < N:
            x1, y1, vx1, vy1 = z[4 * j + 4], z[4 * j + 5], z[4 * j + 6], z[4 * j + 7]
        else:
            x1, y1, vx1, vy1 = pin[0], pin[1], pin[2], pin[3]
        ux = (x1 - z[4 * j]) / ln
        uy = (y1 - z[4 * j + 1]) / ln
        dvx = vx1 - z[4 * j + 2]
        dvy = vy1 - z[4 * j + 3]
        udv = ux * dvx + uy * dvy
        # d(edot)/dd = (dv - (u.dv) u)/(l h), d(edot)/d(dv) = u/h
        px = (dvx - udv * ux) / ln
        py = (dvy - udv * uy) / ln
        ed = ED[j]
        c = damp[j]
        if T[j] > 0.0:  # rate h c edot^2
            gdx, gdy = 2.0 * c * ed * px, 2.0 * c * ed * py
            gvx, gvy = 2.0 * c * ed * ux, 2.0 * c * ed * uy
        else:  # the damping cancels the tension: rate -h f edot
            f, fp = EK.law(E[j], ea[j], tabe, tabt)
            gdx, gdy = -(fp * ed * ux + f * px), -(fp * ed * uy + f * py)
            gvx, gvy = -f * ux, -f * uy
        # by node j (d = r_{j+1} - r_j: minus) and node j+1 (plus)
        gD[4 * j] -= gdx
        gD[4 * j + 1] -= gdy
        gD[4 * j + 2] -= gvx
        gD[4 * j + 3] -= gvy
        if j + 1 < N:
            gD[4 * j + 4] += gdx
            gD[4 * j + 5] += gdy
            gD[4 * j + 6] += gvx
            gD[4 * j + 7] += gvy
        if j == N - 1 and T[j] > 0.0:
            # W' = G . v_pin with G = T u: dG/dd = T/l (I - u u^T) + u (dT/dd)^T, dG/d(dv) = u (dT/d(dv))^T
            _, fp = EK.law(E[j], ea[j], tabe, tabt)
            tdx = fp * ux / h[j] + c * px / h[j]
            tdy = fp * uy / h[j] + c * py / h[j]
            uvp = ux * pin[2] + uy * pin[3]
            q = T[j] / ln
            gW[0] = -(q * (pin[2] - uvp * ux) + tdx * uvp)
            gW[1] = -(q * (pin[3] - uvp * uy) + tdy * uvp)
            gW[2] = -(c * ux / h[j]) * uvp
            gW[3] = -(c * uy / h[j]) * uvp


@njit(cache=True)
def stage_system(N, B, gh, ab):
    """The reduced stage matrix ``I - g^2 K - g C`` (``g = gh``) from the Jacobian's blocks
    ``B`` (:func:`elastic_kernels.jac_blocks`) in the band storage of :func:`banded.band_lu`
    (row i, column j at ``ab[i, j - i + KLE]``)."""
    ab[:, :] = 0.0
    g2 = gh * gh
    for i in range(N):
        for k in range(3):
            jn = i - 1 + k
            if jn < 0 or jn >= N:
                continue
            for r in range(2):
                row = 2 * i + r
                for c in range(2):
                    v = -g2 * B[i, k, 2 + r, c] - gh * B[i, k, 2 + r, 2 + c]
                    if k == 1 and r == c:
                        v += 1.0
                    ab[row, 2 * jn + c - row + KLE] = v


@njit(cache=True)
def stage_solve(N, B, gW, gD, gh, ab, piv, b, U, w):
    """``U = (I/gh - J)^{-1} b`` with the factored reduced matrix ``ab``: the velocities
    from the banded solve, the positions ``gh (b_r + U_v)``, then W and D."""
    g2 = gh * gh
    for i in range(N):
        for r in range(2):
            acc = gh * b[4 * i + 2 + r]
            for k in range(3):
                jn = i - 1 + k
                if jn < 0 or jn >= N:
                    continue
                acc += g2 * (B[i, k, 2 + r, 0] * b[4 * jn] + B[i, k, 2 + r, 1] * b[4 * jn + 1])
            w[2 * i + r] = acc
    band_solve(ab, 2 * N, KLE, KUE, piv, w)
    for i in range(N):
        for r in range(2):
            uv = w[2 * i + r]
            U[4 * i + 2 + r] = uv
            U[4 * i + r] = gh * (b[4 * i + r] + uv)
    accd = 0.0
    for i in range(4 * N):
        accd += gD[i] * U[i]
    accw = 0.0
    for k in range(4):
        accw += gW[k] * U[4 * (N - 1) + k]
    U[4 * N] = gh * (b[4 * N] + accw)
    U[4 * N + 1] = gh * (b[4 * N + 1] + accd)


@njit(cache=True)
def rodas_step(N, t, hs, z0, ft, auto, pins, h, invm, ea, damp, tabe, tabt, g, B, gW, gD, ab, piv, St, ytmp,
               btmp, w, z1, c23, tol, T, E, ED, FV):
    """One RODAS4 step of size ``hs`` from (t, z0) with ``St[0] = f(t, z0)`` and the Jacobian
    (``B, gW, gD``) there; ``pins[s]`` the held end's state at the stage times ``t + c_s hs``,
    ``ft`` df/dt (used unless ``auto``). Stages into ``St[1:7]``, the new state into ``z1``,
    the dense output's ``c2, c3`` into ``c23``. Returns the scaled error (max norm; inf when
    the stage matrix is singular or a value not finite)."""
    n = z0.shape[0]
    gh = GAMMA * hs
    stage_system(N, B, gh, ab)
    if band_lu(ab, 2 * N, KLE, KUE, piv) != 0:
        return np.inf
    for st in range(6):
        if st == 0:
            for i in range(n):
                btmp[i] = St[0, i]
        else:
            for i in range(n):
                acc = z0[i]
                for j in range(st):
                    acc += A_ST[st, j] * St[1 + j, i]
                ytmp[i] = acc
            EK.rhs(N, ytmp, pins[st], h, invm, ea, damp, tabe, tabt, g, btmp, T, E, ED, FV)
            for i in range(n):
                acc = btmp[i]
                for j in range(st):
                    acc += C_ST[st, j] / hs * St[1 + j, i]
                btmp[i] = acc
        if not auto and D_TIME[st] != 0.0:
            for i in range(n):
                btmp[i] += D_TIME[st] * hs * ft[i]
        stage_solve(N, B, gW, gD, gh, ab, piv, btmp, St[1 + st], w)
    err = 0.0
    for i in range(n):
        acc = z0[i]
        for j in range(5):
            acc += A_ST[5, j] * St[1 + j, i]
        z1[i] = acc + St[6, i]
        e = abs(St[6, i]) / (tol * (1.0 + max(abs(z0[i]), abs(z1[i]))))
        if not (e - e == 0.0):
            return np.inf
        if e > err:
            err = e
        c2 = 0.0
        c3 = 0.0
        for j in range(5):
            c2 += D2[j] * St[1 + j, i]
            c3 += D3[j] * St[1 + j, i]
        c23[0, i] = c2
        c23[1, i] = c3
    return err


class RodasDense:
    """The continuous extension of one step (order 3): ``y(t_old + x hs) = (1 - x) y0 + x (y1 +
    (1 - x)(c2 + x c3))``; called with a time in [t_old, t]."""

    def __init__(self, t_old, t, y0, y1, c23):
        self.t_old, self.t = t_old, t
        self.y0, self.y1, self.c2, self.c3 = y0, y1, c23[0].copy(), c23[1].copy()

    def __call__(self, tt):
        x = (float(tt) - self.t_old) / (self.t - self.t_old)
        return self.y0 * (1.0 - x) + x * (self.y1 + (1.0 - x) * (self.c2 + x * self.c3))


def full_jacobian(line, t, z):
    """The dense Jacobian the method uses at (t, z): ``jac_blocks``'s node part with the W and
    D rows of :func:`wd_gradients` (for tests against differences)."""
    J = line.jac(t, z).toarray()
    N = line.N
    gW, gD = np.zeros(4), np.zeros(4 * N)
    T, E, ED, FV = (np.zeros(N) for _ in range(4))
    EK.tensions(N, z, line.pin_state(t), line.h, line.ea, line.damp, line.tabe, line.tabt, T, E, ED, FV)
    wd_gradients(N, z, line.pin_state(t), line.h, line.ea, line.damp, line.tabe, line.tabt, T, E, ED, FV, gW, gD)
    J[4 * N, 4 * (N - 1):4 * N] = gW
    J[4 * N + 1, :4 * N] = gD
    return J


class RodasStepper:
    """RODAS4 on an :class:`ElasticLine` with the interface of scipy's ``OdeSolver`` that
    :func:`elastic_solve.solve` uses: ``step()``, ``t``, ``t_old``, ``y``, ``status``,
    ``dense_output()``, ``nfev``, ``njev``, ``nlu`` (and ``nrej``, rejected steps)."""

    def __init__(self, line, t0, z0, t_bound, tol, h0=None):
        self.line, self.t, self.t_old, self.t_bound, self.tol = line, float(t0), None, float(t_bound), float(tol)
        self.y = np.array(z0, dtype=float)
        N = self.N = line.N
        n = self.y.size
        self.auto = line.pin.kind == "fixed"
        self.St = np.zeros((7, n))
        self.B = np.zeros((N, 3, 4, 4))
        self.gW, self.gD = np.zeros(4), np.zeros(4 * N)
        self.ab = np.zeros((2 * N, WIDTH))
        self.piv = np.zeros(2 * N, dtype=np.int64)
        self.ytmp, self.btmp, self.z1, self.ft = (np.zeros(n) for _ in range(4))
        self.w = np.zeros(2 * N)
        self.c23 = np.zeros((2, n))
        self.work = tuple(np.zeros(N) for _ in range(4))
        self.pins = np.zeros((6, 4))
        self.nfev = self.njev = self.nlu = self.nrej = 0
        self.status = "running"
        self._dense = None
        self._hacc = self._erracc = None
        self._f(self.t, self.y, self.St[0])
        self._jac(self.t, self.y)
        self.h = h0 if h0 is not None else self._initial_step()

    def _args(self):
        ln = self.line
        return ln.h, ln._invm, ln.ea, ln.damp, ln.tabe, ln.tabt, ln.g

    def _f(self, t, z, out):
        self.nfev += 1
        h, invm, ea, damp, tabe, tabt, g = self._args()
        EK.rhs(self.N, z, self.line.pin_state(t), h, invm, ea, damp, tabe, tabt, g, out, *self.work)

    def _jac(self, t, z):
        self.njev += 1
        ln, pin = self.line, self.line.pin_state(t)
        EK.jac_blocks(self.N, z, pin, ln.h, ln._invm, ln.ea, ln.damp, ln.tabe, ln.tabt, self.B, *self.work)
        wd_gradients(self.N, z, pin, ln.h, ln.ea, ln.damp, ln.tabe, ln.tabt, *self.work, self.gW, self.gD)

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
        t, y = self.t, self.y
        h, invm, ea, damp, tabe, tabt, g = self._args()
        reject = False
        while True:
            hs = self.h
            last = t + hs >= self.t_bound or t + 1.01 * hs >= self.t_bound
            if last:
                hs = self.t_bound - t
            if hs <= 1e-14 * max(1.0, abs(t)):
                self.status = "failed"
                return f"step size {hs:.3g} too small at t = {t:.9g}"
            if self.auto:
                self.pins[:] = self.line.pin_state(t)
            else:
                for s in range(6):
                    self.pins[s] = self.line.pin_state(t + C_NODE[s] * hs)
                dt = 1e-7 * max(1.0, abs(t))
                self._f(t + dt, y, self.ft)
                self.ft -= self.St[0]
                self.ft /= dt
            self.nlu += 1
            self.nfev += 5
            err = rodas_step(self.N, t, hs, y, self.ft, self.auto, self.pins, h, invm, ea, damp, tabe, tabt, g,
                             self.B, self.gW, self.gD, self.ab, self.piv, self.St, self.ytmp, self.btmp, self.w,
                             self.z1, self.c23, self.tol, *self.work)
            if not np.isfinite(err):
                self.nrej += 1
                self.h = 0.1 * hs
                reject = True
                continue
            fac = min(1.0 / FAC_MIN, max(1.0 / FAC_MAX, err ** 0.25 / SAFE))
            hnew = hs / fac
            if err <= 1.0:
                if self._hacc is not None:  # Gustafsson's predictive controller (rodas.f, PRED)
                    facg = (self._hacc / hs) * (err * err / self._erracc) ** 0.25 / SAFE
                    facg = min(1.0 / FAC_MIN, max(1.0 / FAC_MAX, facg))
                    hnew = hs / max(fac, facg)
                self._hacc, self._erracc = hs, max(1e-2, err)
                if reject:
                    hnew = min(hnew, hs)
                tn = self.t_bound if last else t + hs
                y1 = self.z1.copy()
                self._dense = RodasDense(t, tn, y.copy(), y1, self.c23)
                self.t_old, self.t, self.y = t, tn, y1
                self._f(tn, y1, self.St[0])
                self._jac(tn, y1)
                self.h = hnew
                if last:
                    self.status = "finished"
                return None
            self.nrej += 1
            reject = True
            self.h = hnew
