"""Independent reference solutions for a general planar chain (tests only; slow, dense, simple).

The system (nondimensional)
---------------------------
A planar chain of N rigid massless links with point masses at the nodes. Node ``i = 0``
is the free end, node ``i = N`` the held end (the pin). Link ``j`` (``j = 0 .. N-1``)
joins node ``j`` and node ``j + 1`` and has length ``h[j] > 0``; nodes ``0 .. N-1`` carry
masses ``m[i] > 0``; the pin has no mass, its motion is prescribed. Gravity is ``g e2``
with ``y`` pointing DOWN (any ``g >= 0``). Every array here is indexed by node / link
number in that order (free end first, pin last).

Conventions
-----------
* Link vector ``d_j = r_{j+1} - r_j`` (from node j towards node j + 1, i.e. towards the
  pin), ``|d_j| = h_j``.
* Link angle ``theta_j``: ``d_j = h_j (cos theta_j, sin theta_j)`` (the same definition as
  :mod:`snapping.simulate.angles`). With y down, a chain hanging straight down from the
  pin has ``theta_j = -pi/2`` for every link.
* Tension ``T_j`` of link j: positive when the link pulls its two nodes together. The
  force of link j on node j is ``+T_j d_j / h_j`` and on node j + 1 it is ``-T_j d_j / h_j``.

Relation to :mod:`snapping.simulate.angles` (uniform chain, ``h_j = 1/N``, ``m_i = 1/N``,
``g = 1``, fixed pin): its momentum balance ``r_k'' = N^2 [sig_k d_k - sig_{k-1} d_{k-1}] + e2``
with ``m = 1/N``, ``|d| = 1/N`` reads ``m r'' = sig_k t_k - sig_{k-1} t_{k-1} + m e2``: its
``sig`` is exactly the link tension ``T`` of this module (same sign, scale 1; the hanging
uniform chain has ``sig_j = T_j = (j + 1)/N``). The test file checks this numerically.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import ellipk

__all__ = [
    "dense_accelerations", "double_pendulum_reference", "double_pendulum_solution",
    "double_pendulum_rhs", "double_pendulum_energy", "double_pendulum_positions",
    "pendulum_period", "hanging_tension",
]


# ---------------------------------------------------------------- 1. dense KKT solve
def dense_accelerations(x, y, vx, vy, h, m, g, pin_acc=(0.0, 0.0), check=True):
    """Accelerations of the free nodes and the link tensions by a dense KKT solve.

    Parameters
    ----------
    x, y, vx, vy : arrays of length N + 1
        Positions and velocities of nodes 0 .. N (node N is the pin; its velocity is the
        prescribed pin velocity). They must satisfy the constraints
        ``|r_{j+1} - r_j| = h_j`` and ``(r_{j+1} - r_j).(v_{j+1} - v_j) = 0`` (checked to a
        relative 1e-6; a ``ValueError`` otherwise).
    h : array of length N, link lengths.   m : array of length N, masses of nodes 0 .. N-1.
    g : gravity along +e2 (y down).        pin_acc : prescribed pin acceleration (Ax, Ay).
    check : whether to check the constraints (off inside an ODE integration, whose trial
        stages drift from them by the integration error).

    Returns
    -------
    (ax, ay, T) : arrays of length N: accelerations of nodes 0 .. N-1 and link tensions.

    Derivation
    ----------
    Cartesian unknowns ``q = (x_0, y_0, ..., x_{N-1}, y_{N-1})``, constraints
    ``phi_j = (|d_j|^2 - h_j^2)/2``, ``d_j = r_{j+1} - r_j``. Their Jacobian G (N x 2N) has
    row j equal to ``-d_j`` in the columns of node j and ``+d_j`` in those of node j + 1
    (absent when j + 1 = N, the pin). Lagrange's equations with multipliers::

        M a = f_gravity + G^T lambda,      f_gravity = g (0, m_i) per node,

    and the constraints differentiated twice, ``phi_j'' = |v_{j+1} - v_j|^2 + d_j.(a_{j+1} - a_j) = 0``::

        G a = -|v_{j+1} - v_j|^2  (- d_{N-1}.A for the last link, whose node N moves with A).

    The saddle-point system ``[[M, -G^T], [G, 0]] [a; lambda] = [f; rhs]`` is solved densely.
    Tension: the constraint force on node j from link j is ``lambda_j * (-d_j)``, while a
    tension T_j pulls node j towards node j + 1 with ``T_j d_j / h_j``; hence

        T_j = -lambda_j * h_j      (sign: lambda_j < 0 in tension; scale: one factor h_j).

    Check (hanging chain at rest): node 0 has ``0 = m_0 g e2 + T_0 d_0/h_0`` with
    ``d_0/h_0 = -e2``, so ``T_0 = g m_0``; inductively ``T_j = g sum_{i<=j} m_i``
    (:func:`hanging_tension`; tested).
    """
    x, y, vx, vy = (np.asarray(a, dtype=float) for a in (x, y, vx, vy))
    h = np.asarray(h, dtype=float)
    m = np.asarray(m, dtype=float)
    N = h.size
    if N < 1 or m.size != N or any(a.size != N + 1 for a in (x, y, vx, vy)):
        raise ValueError(f"need N >= 1 links, N masses and N + 1 node coordinates (N = {N})")
    if np.any(h <= 0) or np.any(m <= 0):
        raise ValueError("link lengths and masses must be positive")
    Ax, Ay = (float(a) for a in pin_acc)
    dx, dy = np.diff(x), np.diff(y)
    dvx, dvy = np.diff(vx), np.diff(vy)
    length = np.hypot(dx, dy)
    if check and np.any(abs(length - h) > 1e-6 * h):
        raise ValueError(f"positions violate the link lengths by up to {np.max(abs(length - h) / h):.3g} (relative)")
    rate = dx * dvx + dy * dvy
    if check and np.any(abs(rate) > 1e-6 * h * (np.hypot(dvx, dvy) + 1e-300)):
        raise ValueError("velocities violate the differentiated constraints (r_{j+1}-r_j).(v_{j+1}-v_j) = 0")

    n = 2 * N
    G = np.zeros((N, n))
    for j in range(N):
        G[j, 2 * j] = -dx[j]
        G[j, 2 * j + 1] = -dy[j]
        if j + 1 < N:
            G[j, 2 * j + 2] = dx[j]
            G[j, 2 * j + 3] = dy[j]
    rhs = -(dvx**2 + dvy**2)
    rhs[N - 1] -= dx[N - 1] * Ax + dy[N - 1] * Ay

    K = np.zeros((n + N, n + N))
    K[:n, :n] = np.diag(np.repeat(m, 2))
    K[:n, n:] = -G.T
    K[n:, :n] = G
    b = np.zeros(n + N)
    b[1:n:2] = g * m
    b[n:] = rhs
    sol = np.linalg.solve(K, b)
    a = sol[:n]
    lam = sol[n:]
    return a[0::2].copy(), a[1::2].copy(), -lam * h


# ---------------------------------------------------------------- 2. symbolic double pendulum
@functools.lru_cache(maxsize=None)
def _double_pendulum_equations():
    """Lagrange's equations of the N = 2 chain, derived with sympy and lambdified.

    Returns ``f(t, th0, th1, w0, w1, h0, h1, m0, m1, g, Ax, Ay) -> (th0'', th1'')``.
    """
    import sympy as sp

    t = sp.symbols("t", real=True)
    h0, h1, m0, m1, g, Ax, Ay = sp.symbols("h0 h1 m0 m1 g Ax Ay", real=True)
    th0 = sp.Function("th0", real=True)(t)
    th1 = sp.Function("th1", real=True)(t)
    # pin at the origin at t = 0, at rest, constant acceleration (Ax, Ay)
    px, py = Ax * t**2 / 2, Ay * t**2 / 2
    x1 = px - h1 * sp.cos(th1)
    y1 = py - h1 * sp.sin(th1)
    x0 = x1 - h0 * sp.cos(th0)
    y0 = y1 - h0 * sp.sin(th0)
    T = (m0 * (sp.diff(x0, t) ** 2 + sp.diff(y0, t) ** 2)
         + m1 * (sp.diff(x1, t) ** 2 + sp.diff(y1, t) ** 2)) / 2
    V = -g * (m0 * y0 + m1 * y1)  # y down: potential energy decreases downwards
    L = T - V
    qs = (th0, th1)
    eqs = [sp.diff(sp.diff(L, sp.diff(q, t)), t) - sp.diff(L, q) for q in qs]
    a0, a1, w0, w1, s0, s1 = sp.symbols("a0 a1 w0 w1 s0 s1", real=True)
    subs = {sp.diff(th0, t, 2): a0, sp.diff(th1, t, 2): a1}
    subs2 = {sp.diff(th0, t): w0, sp.diff(th1, t): w1}
    subs3 = {th0: s0, th1: s1}
    eqs = [sp.expand(e.subs(subs).subs(subs2).subs(subs3)) for e in eqs]
    Mat, rhs = sp.linear_eq_to_matrix(eqs, [a0, a1])
    Mat = Mat.applyfunc(lambda e: sp.factor(sp.trigsimp(e)))  # (small entries: cheap)
    rhs = rhs.applyfunc(lambda e: sp.trigsimp(e))
    # Cramer's rule on the 2 x 2 mass matrix (no simplification: it is slow and not needed)
    det = Mat[0, 0] * Mat[1, 1] - Mat[0, 1] * Mat[1, 0]
    acc = [(rhs[0] * Mat[1, 1] - Mat[0, 1] * rhs[1]) / det,
           (Mat[0, 0] * rhs[1] - Mat[1, 0] * rhs[0]) / det]
    if any(t in e.free_symbols for e in acc):  # the pin velocity A t must drop out
        acc = [sp.expand(e) for e in acc]
        assert not any(t in e.free_symbols for e in acc), acc
    f = sp.lambdify((t, s0, s1, w0, w1, h0, h1, m0, m1, g, Ax, Ay), acc, modules="math")
    return f


def double_pendulum_rhs(t, state, h, m, g, pin=None):
    """``[th0', th1', th0'', th1'']`` of the state ``[th0, th1, th0', th1']`` (sympy-derived).

    Angles as in :func:`double_pendulum_reference`; ``pin`` None (fixed at the origin) or
    a constant pin acceleration ``(Ax, Ay)`` with ``r_pin(t) = A t^2 / 2``.
    """
    f = _double_pendulum_equations()
    Ax, Ay = (0.0, 0.0) if pin is None else (float(pin[0]), float(pin[1]))
    th0, th1, w0, w1 = (float(v) for v in state)
    a0, a1 = f(float(t), th0, th1, w0, w1, float(h[0]), float(h[1]), float(m[0]), float(m[1]),
               float(g), Ax, Ay)
    return np.array([w0, w1, float(a0), float(a1)])


def double_pendulum_solution(h, m, g, phi0, omega0, t_span, pin=None, t_eval=None, events=None,
                             method="DOP853", rtol=1e-12, atol=1e-12):
    """The ``scipy.integrate.solve_ivp`` result (dense output on) for the angle state
    ``[th0, th1, th0', th1']`` of :func:`double_pendulum_reference`."""
    _check2(h, m)
    y0 = np.array([phi0[0], phi0[1], omega0[0], omega0[1]], dtype=float)
    return solve_ivp(lambda t, s: double_pendulum_rhs(t, s, h, m, g, pin), t_span, y0,
                     method=method, rtol=rtol, atol=atol, t_eval=t_eval, events=events,
                     dense_output=True)


def double_pendulum_positions(t, theta, h, pin=None):
    """Node positions ``(x0, y0, x1, y1)`` of angles ``theta = (th0, th1)`` (arrays) at times t."""
    t = np.asarray(t, dtype=float)
    Ax, Ay = (0.0, 0.0) if pin is None else (float(pin[0]), float(pin[1]))
    th0, th1 = np.asarray(theta[0]), np.asarray(theta[1])
    x1 = Ax * t**2 / 2 - h[1] * np.cos(th1)
    y1 = Ay * t**2 / 2 - h[1] * np.sin(th1)
    return x1 - h[0] * np.cos(th0), y1 - h[0] * np.sin(th0), x1, y1


def double_pendulum_energy(h, m, g, theta, omega):
    """Kinetic + potential energy (``V = -g sum m_i y_i``, y down) for a FIXED pin at the origin."""
    th0, th1 = np.asarray(theta[0]), np.asarray(theta[1])
    w0, w1 = np.asarray(omega[0]), np.asarray(omega[1])
    h0, h1 = float(h[0]), float(h[1])
    m0, m1 = float(m[0]), float(m[1])
    # v1 = h1 w1 (sin th1, -cos th1);  v0 = v1 + h0 w0 (sin th0, -cos th0)
    v1sq = (h1 * w1) ** 2
    v0sq = v1sq + (h0 * w0) ** 2 + 2 * h0 * h1 * w0 * w1 * np.cos(th0 - th1)
    y1 = -h1 * np.sin(th1)
    y0 = y1 - h0 * np.sin(th0)
    return 0.5 * (m0 * v0sq + m1 * v1sq) - g * (m0 * y0 + m1 * y1)


def double_pendulum_reference(h, m, g, phi0, omega0, t_eval, pin=None):
    """Node positions ``(x0(t), y0(t), x1(t), y1(t))`` at ``t_eval`` of the two-link chain.

    Generalised coordinates: the absolute link angles ``theta = (theta_0, theta_1)`` with
    the convention of this module: link j points from node j to node j + 1 along
    ``(cos theta_j, sin theta_j)``, so (y down)::

        node 1 = pin - h1 (cos theta_1, sin theta_1)
        node 0 = node 1 - h0 (cos theta_0, sin theta_0)

    (hanging straight down: ``theta_0 = theta_1 = -pi/2``). ``phi0 = (theta_0, theta_1)``
    and ``omega0 = (theta_0', theta_1')`` at t = 0. ``h = (h0, h1)``, ``m = (m0, m1)``
    (m0 at the free end, node 0; m1 at node 1). The equations are Lagrange's equations of
    ``L = T - V`` (``V = -g (m0 y0 + m1 y1)``) derived symbolically with sympy, solved
    for the second derivatives and lambdified; integrated by DOP853 with
    ``rtol = atol = 1e-12`` from ``t = 0`` to ``max(t_eval)``.

    ``pin``: None (fixed at the origin) or a constant acceleration ``(Ax, Ay)``: the pin
    starts at the origin at rest, ``r_pin(t) = (Ax, Ay) t^2 / 2``, and the positions
    returned include that motion.
    """
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or t_eval.size == 0 or t_eval.min() < 0:
        raise ValueError("t_eval must be a non-empty 1-d array of times >= 0")
    T1 = float(t_eval.max())
    if T1 == 0.0:
        th = np.array([[phi0[0]], [phi0[1]]], dtype=float) * np.ones(t_eval.size)
    else:
        sol = double_pendulum_solution(h, m, g, phi0, omega0, (0.0, T1), pin=pin)
        if not sol.success:
            raise RuntimeError(sol.message)
        th = sol.sol(t_eval)[:2]
    return double_pendulum_positions(t_eval, th, h, pin)


def _check2(h, m):
    if len(h) != 2 or len(m) != 2 or min(h) <= 0 or min(m) <= 0:
        raise ValueError("the double pendulum needs two positive lengths and two positive masses")


# ---------------------------------------------------------------- 3. simple pendulum period
def pendulum_period(h, m_bob, amplitude, g=1.0):
    """Exact period of a rigid massless rod of length h with a point mass (N = 1), released
    from rest at angle ``amplitude`` (radians, |amplitude| < pi) from the downward vertical:
    ``4 sqrt(h/g) K(k^2)``, ``k = sin(amplitude/2)``, with K the complete elliptic integral of
    the first kind in scipy's parameter convention (``ellipk(m)``, m = k^2). The period is
    independent of the mass: ``m_bob`` is accepted (and checked > 0) only for symmetry.
    """
    if h <= 0 or m_bob <= 0 or g <= 0:
        raise ValueError("need h > 0, m_bob > 0 and g > 0")
    if not abs(amplitude) < math.pi:
        raise ValueError("amplitude must be below pi in magnitude")
    return 4.0 * math.sqrt(h / g) * float(ellipk(math.sin(amplitude / 2.0) ** 2))


# ---------------------------------------------------------------- 4. hanging chain
def hanging_tension(m, g):
    """Tension of each link of a chain hanging straight down at rest: ``T_j = g sum_{i<=j} m_i``
    (link j carries the weight of nodes 0 .. j below it)."""
    return float(g) * np.cumsum(np.asarray(m, dtype=float))
