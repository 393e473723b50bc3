"""The line at rest, held at both ends: the discrete static equilibrium with bending.

The physical experiment: the line hangs at rest held at both ends (the held end, node N at
the origin, and a second support at the free end's start position, node 0), then the
free end is released. Without bending the rest shape is the catenary; with bending
stiffness it is the *heavy elastica* with hinged ends (a clamped held end when the body
has a clamp). Releasing a catenary that is not in bending equilibrium launches grid-scale
bending waves (the nodes near the ends and the fold are out of moment balance), which no
damping removes in an undamped run; this module gives the start without them.

The discrete problem (the chain of :mod:`snapping.simulate.forced`: links ``h_k`` at angles
``theta_k``, ``d_k = r_{k+1} - r_k = h_k (cos theta_k, sin theta_k)``, node masses
``m_j`` (tip mass in ``m_0``), index 0 the free end, y downward): minimise the energy::

    V(theta) = g sum_k h_k sin(theta_k) Mc_k + V_b(theta),   Mc_k = m_0 + ... + m_k,

(gravity: ``-g sum_j m_j y_j`` with ``y_j = -sum_{k>=j} h_k sin theta_k``) and ``V_b`` the
bending energy of :mod:`snapping.simulate.force_bending` (stiffness, natural curvature,
the clamp's term at node N), subject to the free end at the support,
``c(theta) = sum_k d_k + r_0^* = 0``. With the Lagrangian ``V + mu . c`` the conditions are::

    G_k = g Mc_k h_k cos theta_k + Bl_k D_k - Bl_{k+1} D_{k+1} + h_k (-mu_x sin theta_k + mu_y cos theta_k) = 0,
    D_i = theta_i - theta_{i-1} - K0L_i  (D_N = phi - theta_{N-1} - K0L_N at a clamp),

and ``c = 0``. Since ``mu . c = -mu . r_0 + const``, ``mu`` is the force the support exerts
on node 0 (the free end's reaction); the held end exerts ``-(mu + g sum_j m_j e2)``.

Newton on ``(theta, mu)``: the Hessian of the Lagrangian is tridiagonal (bending couples
neighbouring links; gravity and the constraint are diagonal), bordered by the two
constraint gradients ``C = dc/dtheta``; each Newton step solves ``H z = [G, C^T]`` with a
banded LU (:func:`scipy.linalg.solve_banded`, O(N)) and a 2 x 2 Schur complement for
``mu``, with backtracking on the residual. The start is the given shape (the catenary);
the result must be stable, a local minimum of the energy along the constraints (counted in
O(N) by the inertia of the bordered Hessian: :func:`unstable_directions`; Newton alone may
find an arch standing up). When Newton does not converge from the catenary to a stable
shape, the bending is switched on by continuation, ``B -> s B`` with ``s`` stepped from 0
to 1, every stage stable. Air drag and
wind play no part (the line is held at rest in still air); damping none (at rest).

Examples
--------
>>> import numpy as np
>>> from snapping.simulate import Body, Links, Problem
>>> from snapping.simulate.equilibrium import hanging_equilibrium
>>> p = Problem.catenary(0.25, 40, links=Links.uniform(40, lumping="shared"), start="catenary")
>>> e = hanging_equilibrium(p.links, Body(bending=1e-3), p.x, p.y)
>>> e.converged, bool(e.residual < 1e-12), e.reaction_free.round(3)   # the support carries half the weight
(True, True, array([-0.001, -0.501]))
>>> bool(np.allclose(np.hypot(np.diff(e.x), np.diff(e.y)), p.links.h, rtol=0, atol=1e-14))
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import LinAlgError, solve_banded

from .. import _validate as V

__all__ = ["Equilibrium", "hanging_equilibrium", "discrete_residual", "unstable_directions", "EQUILIBRIUM_TOL"]

#: relative residual at which Newton stops: each gradient row against the size of its terms (the line's
#: weight times h_k, and (Bl_k + Bl_{k+1}) max|theta|, whose differences round at that size), the
#: constraint against the length L
EQUILIBRIUM_TOL = 1e-12
#: Newton iterations per continuation stage, and continuation stages at most
MAX_NEWTON = 60
MAX_STAGES = 200


@dataclass(frozen=True)
class Equilibrium:
    """The line at rest held at both ends: node positions ``x, y`` (N + 1, index N the held
    end at the origin, node 0 at the support), link angles ``theta``, the forces the support
    exerts on the free end (``reaction_free``) and the held end on the line
    (``reaction_held``), the relative ``residual`` reached, Newton ``iterations`` in all and
    continuation ``stages`` (1: Newton converged from the start shape)."""

    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    reaction_free: np.ndarray
    reaction_held: np.ndarray
    residual: float
    iterations: int
    stages: int
    converged: bool


def _arrays(links, body, theta0):
    """(h, Mc, Bl, K0L, phi, clamped) of the chain and its body, from the compiled body model
    (the same arrays the dynamics uses)."""
    from . import forced as FR
    from . import general as G

    h = np.asarray(links.h, dtype=float)
    N = h.size
    Mc = np.cumsum(np.asarray(links.m, dtype=float))
    Bl = np.zeros(N + 1)
    K0L = np.zeros(N + 1)
    phi, clamped = 0.0, False
    if body is not None:
        par, _, _, _, _, tab = body.model(G.make_model(h, 1.0 / links.m), h, float(theta0[N - 1]))
        o, n1 = int(par[FR.P_BOFF]), N + 1
        Bl = tab[o + FR.B_BL * n1:o + (FR.B_BL + 1) * n1].copy()
        K0L = tab[o + FR.B_K0L * n1:o + (FR.B_K0L + 1) * n1].copy()
        clamped = par[FR.P_CLAMP] != 0.0
        if clamped:
            phi = float(FR.clamp_angle(0.0, par, tab)[0])
    return h, Mc, Bl, K0L, phi, clamped


def _gradient(th, mu, h, Mc, g, Bl, K0L, phi, clamped):
    """(G, D): the Lagrangian's gradient in theta and the turning defects D (N + 1)."""
    N = th.size
    D = np.zeros(N + 1)
    D[1:N] = np.diff(th) - K0L[1:N]
    if clamped:
        D[N] = phi - th[N - 1] - K0L[N]
    c, s = np.cos(th), np.sin(th)
    Gr = g * Mc * h * c + Bl[:N] * D[:N] - Bl[1:] * D[1:] + h * (-mu[0] * s + mu[1] * c)
    return Gr, D


def discrete_residual(theta, mu, links, body=None, target=(0.0, 0.0), gravity=1.0):
    """The equilibrium conditions at link angles ``theta`` and support force ``mu``: the
    gradient ``G`` (N) and the constraint ``c = sum_k d_k + r_0^*`` (2), as defined in the
    module's text (for checks)."""
    th = np.asarray(theta, dtype=float)
    h, Mc, Bl, K0L, phi, clamped = _arrays(links, body, th)
    Gr, _ = _gradient(th, np.asarray(mu, dtype=float), h, Mc, gravity, Bl, K0L, phi, clamped)
    con = np.array([np.sum(h * np.cos(th)) + target[0], np.sum(h * np.sin(th)) + target[1]])
    return Gr, con


def _hessian(th, mu, h, Mc, g, Bl):
    """The Lagrangian's Hessian in theta (tridiagonal: diagonal ``a``, off-diagonal ``b``) and
    the constraint gradients ``C`` (N, 2)."""
    N = th.size
    c, s = np.cos(th), np.sin(th)
    a = -g * Mc * h * s - h * (mu[0] * c + mu[1] * s) + Bl[:N] + Bl[1:]
    return a, -Bl[1:N], np.stack([-h * s, h * c], axis=1)


def unstable_directions(th, mu, h, Mc, g, Bl) -> int:
    """How many independent directions along the constraints lower the energy (0: a stable
    rest shape, a local minimum): the negative eigenvalues of the bordered (KKT) matrix less
    2, counted in O(N) as those of H (the pivots of its LDL^T, Sylvester) plus those of the
    Schur complement ``-C^T H^-1 C`` (Haynsworth)."""
    a, b, C = _hessian(th, mu, h, Mc, g, Bl)
    N = th.size
    d = np.empty(N)
    d[0] = a[0]
    for k in range(1, N):  # (a plain loop: O(N), called once per solve)
        d[k] = a[k] - b[k - 1] ** 2 / d[k - 1] if d[k - 1] != 0.0 else a[k] - b[k - 1] ** 2 / 1e-300
    neg = int(np.sum(d < 0.0))
    ab = np.zeros((3, N))
    ab[0, 1:], ab[1], ab[2, :-1] = b, a, b
    try:
        S = -C.T @ solve_banded((1, 1), ab, C)
    except (LinAlgError, ValueError):
        return N
    neg += int(np.sum(np.linalg.eigvalsh(0.5 * (S + S.T)) < 0.0))
    return neg - 2


def _newton(th, mu, h, Mc, g, Bl, K0L, phi, clamped, target, fscale, tol, max_iter):
    """Newton with backtracking; returns (theta, mu, residual, iterations, converged)."""
    N = th.size
    L = float(h.sum())

    def resid(th, mu):
        Gr, _ = _gradient(th, mu, h, Mc, g, Bl, K0L, phi, clamped)
        con = np.array([np.sum(h * np.cos(th)) + target[0], np.sum(h * np.sin(th)) + target[1]])
        # the test: each row against the size of its terms (the bending terms round at eps (Bl_k + Bl_k+1) |theta|)
        size = h * fscale + (Bl[:N] + Bl[1:]) * max(1.0, float(np.max(np.abs(th))))
        r = max(float(np.max(np.abs(Gr) / size)), float(np.max(np.abs(con))) / L)
        # the merit: a fixed weighting of the whole residual (Newton's step descends on it)
        merit = float(np.sum((Gr / (h * fscale)) ** 2 * h)) + float(np.sum(con ** 2)) / L ** 2
        return Gr, con, r, merit

    Gr, con, r, merit = resid(th, mu)
    it = 0
    while r > tol and it < max_iter:
        it += 1
        a, b, C = _hessian(th, mu, h, Mc, g, Bl)  # C: dc/dtheta, transposed (N, 2)
        ab = np.zeros((3, N))  # the tridiagonal Hessian, banded (upper, diagonal, lower)
        ab[0, 1:], ab[1], ab[2, :-1] = b, a, b
        try:
            Z = solve_banded((1, 1), ab, np.column_stack([Gr, C]))
        except (LinAlgError, ValueError):
            break
        if not np.all(np.isfinite(Z)):
            break
        zg, zc = Z[:, 0], Z[:, 1:]
        S = C.T @ zc  # Schur complement of the bordered system
        try:
            dmu = np.linalg.solve(S, con - C.T @ zg)
        except LinAlgError:
            break
        dth = -zg - zc @ dmu
        lam = 1.0
        while True:  # backtracking (Armijo) on the merit
            th1, mu1 = th + lam * dth, mu + lam * dmu
            G1, c1, r1, m1 = resid(th1, mu1)
            if m1 <= (1.0 - 1e-4 * lam) * merit or r1 <= tol or lam < 1e-6:
                break
            lam *= 0.5
        if not (m1 < merit or r1 <= tol):
            break
        th, mu, Gr, con, r, merit = th1, mu1, G1, c1, r1, m1
    return th, mu, r, it, bool(r <= tol)


def hanging_equilibrium(links, body, x, y, *, gravity: float = 1.0, support=None, tol: float = EQUILIBRIUM_TOL,
                        max_iter: int | None = None) -> Equilibrium:
    """The line of ``links`` with ``body`` (a :class:`snapping.simulate.body.Body` or None)
    at rest, held at the origin (node N) and at ``(x[0], y[0])`` (node 0), under gravity
    ``gravity`` along +y: Newton from the shape ``x, y`` (the catenary), continuation in the
    bending stiffness when needed (see the module's text). A clamp ``"start"`` must be
    resolved first (:meth:`snapping.simulate.body.Body.resolved`). Raises
    :class:`snapping._validate.SnappingInputError` when no equilibrium is found, with the
    residual reached."""
    max_iter = MAX_NEWTON if max_iter is None else int(max_iter)
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    N = links.N
    th0 = np.unwrap(np.arctan2(np.diff(y), np.diff(x)))
    h, Mc, Bl, K0L, phi, clamped = _arrays(links, body, th0)
    g = float(gravity)
    target = (float(x[0]), float(y[0])) if support is None else (float(support[0]), float(support[1]))
    L = float(h.sum())
    fscale = max(g * float(Mc[-1]), float(np.max(Bl * np.r_[h, h[-1]])) / L ** 2, 1e-300)
    if not math.isfinite(fscale):
        raise V.SnappingInputError("start='equilibrium': the line's weight or stiffness is not finite")

    def initial_mu(th, scale):
        Gr, _ = _gradient(th, np.zeros(2), h, Mc, g, scale * Bl, scale * K0L, phi, clamped)
        C = np.stack([-np.sin(th), np.cos(th)], axis=1)
        return np.linalg.lstsq(C, -Gr / h, rcond=None)[0]

    def stable(th, mu, scale):
        return unstable_directions(th, mu, h, Mc, g, scale * Bl) == 0

    total = 0
    th, mu = th0.copy(), initial_mu(th0, 1.0)
    if N <= 2:  # held at both ends, one or two links are a rigid frame: the start shape, its reactions
        e = _result(h, th0, mu, g, Mc, 0.0, 0, 0)
        return Equilibrium(x.copy(), y.copy(), *(getattr(e, k) for k in ("theta", "reaction_free", "reaction_held",
                                                                         "residual", "iterations", "stages",
                                                                         "converged")))
    th1, mu1, r, it, ok = _newton(th, mu, h, Mc, g, Bl, K0L, phi, clamped, target, fscale, tol, max_iter)
    ok = ok and stable(th1, mu1, 1.0)  # (Newton may find an unstable shape: an arch standing up)
    total += it
    stages = 1
    if not ok:  # continuation: the stiffness (and natural curvature) switched on by s = 0 -> 1, stable all along
        s, ds = 0.0, 1.0
        th, mu = th0.copy(), initial_mu(th0, 0.0)
        th, mu, r, it, ok = _newton(th, mu, h, Mc, g, 0.0 * Bl, 0.0 * K0L, phi, False, target,
                                    max(g * float(Mc[-1]), 1e-300), tol, max_iter)
        total += it
        while ok and s < 1.0 and stages < MAX_STAGES:
            stages += 1
            s1 = min(1.0, s + ds)
            # the clamp's angle moves from the free direction of the last link to phi with s
            ph = th[N - 1] + s1 * (phi - th[N - 1]) if clamped else phi
            t2, m2, r2, it, ok2 = _newton(th.copy(), mu.copy(), h, Mc, g, s1 * Bl, s1 * K0L, ph, clamped,
                                          target, max(g * float(Mc[-1]), float(np.max(s1 * Bl * np.r_[h, h[-1]]))
                                                      / L ** 2, 1e-300), tol, max_iter)
            total += it
            if ok2 and stable(t2, m2, s1):
                s, th, mu, r = s1, t2, m2, r2
                ds = min(2.0 * ds, 1.0)
            else:
                ds *= 0.5
                if ds < 1e-6:
                    ok, r = False, r2
                    break
        ok = ok and s >= 1.0
        if ok:
            th1, mu1, r, it, ok = _newton(th, mu, h, Mc, g, Bl, K0L, phi, clamped, target, fscale, tol, max_iter)
            total += it
            ok = ok and stable(th1, mu1, 1.0)
    if not ok:
        raise V.SnappingInputError(
            f"start='equilibrium': no stable static equilibrium found for the line held at both ends (Newton from "
            f"the catenary and {stages} continuation stages in the bending stiffness, {total} iterations): relative "
            f"residual {r:.3g} (at most {tol:g}, and a local minimum of the energy, wanted); use start='catenary'")
    return _result(h, th1, mu1, g, Mc, r, total, stages)


def _result(h, th, mu, g, Mc, r, total, stages) -> Equilibrium:
    N = h.size
    xs = np.zeros(N + 1)
    ys = np.zeros(N + 1)
    xs[:N] = -np.cumsum((h * np.cos(th))[::-1])[::-1]
    ys[:N] = -np.cumsum((h * np.sin(th))[::-1])[::-1]
    held = -(mu + np.array([0.0, g * float(Mc[-1])]))
    return Equilibrium(xs, ys, th, mu.copy(), held, float(r), int(total), int(stages), True)
