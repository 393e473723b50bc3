"""The static equilibrium of the extensible line (:class:`~snapping.simulate.elastic_model.ElasticLine`):
the ``"stretched"`` start, and the hanging line's stretch; and the ``"matched"`` start
(:func:`matched`: the rigid chain's tensions the instant after release).

The equilibrium minimises the potential energy (elastic + gravity), convex for tension-only
links. Newton on the stiffness alone stalls on a long, stiff line started from its
unstretched shape (links at rest length carry no tension, so the geometric stiffness
``T/l`` that holds the nodes sideways is zero, and a step's sideways part ``d`` overstretches
a link by ``d^2/(2 h)``, a force ``EA d^2/(2 h^2)``): N = 1000, c = 30 took 2,000 damped
steps. So :func:`statics` first takes the start as a rigid chain (:func:`rigid_tensions`)
and solves for the small stretch in mixed form (:func:`mixed`: positions and tensions, a
Newton matrix that stays well conditioned as EA -> infinity), a few O(N) steps at any N
and stiffness; a few Newton steps on the stiffness then reach the force's round-off.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg  # noqa: F401  (so that sp.linalg is there)

__all__ = ["statics", "mixed", "rigid_tensions", "strain_of", "matched"]


def _solve(A, b) -> np.ndarray:
    """``spsolve``, with NaNs (no warning) where ``A`` is singular: the callers fall back."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sp.linalg.MatrixRankWarning)
        return sp.linalg.spsolve(A, b)


def strain_of(line, T: np.ndarray) -> np.ndarray:
    """The strain at which each link's law gives the tension ``T`` (>= 0): ``T/EA`` or the
    table's inverse (extended with its last slope)."""
    if line.tabe.size == 0:
        return T / line.ea
    e, t = line.tabe, line.tabt
    out = np.interp(T, t, e)
    far = T > t[-1]
    out[far] = e[-1] + (T[far] - t[-1]) * (e[-1] - e[-2]) / (t[-1] - t[-2])
    return out


def mixed(line, z: np.ndarray, free: np.ndarray, max_iter: int):
    """The statics in mixed form, from ``z``'s shape taken as a rigid chain: unknowns the
    node positions and the link tensions, equations the force balance of the free nodes
    and each link's length ``l_j = h_j (1 + e_j(T_j))``; its Newton matrix stays well
    conditioned however stiff the links (EA -> infinity is the rigid chain), so a few steps
    (O(N) each: sparse, banded) take the rigid shape to the stretched one. Returns
    (positions z, Newton steps), or (None, steps) where it does not converge or some
    tension comes out negative (a slack equilibrium: the caller's damped iteration
    takes over)."""
    N = line.N
    pin = line.pin_state(0.0)
    X = np.empty(3 * N)
    X[0:2 * N:2], X[1:2 * N:2] = z[0:4 * N:4], z[1:4 * N:4]
    X[2 * N:] = 0.0
    held0 = X[0:2].copy()
    e0 = line.ea if line.tabe.size == 0 else np.full(N, (line.tabt[1] - line.tabt[0]) / (line.tabe[1] - line.tabe[0]))
    j = np.arange(N)
    px, py = 2 * j, 2 * j + 1  # position unknowns of node j
    tj = 2 * N + j  # tension unknowns
    nxt = j + 1 < N

    def residual_jac(X):
        x, y = np.append(X[0:2 * N:2], pin[0]), np.append(X[1:2 * N:2], pin[1])
        T = X[2 * N:]
        dx, dy = np.diff(x), np.diff(y)
        ln = np.hypot(dx, dy)
        ux, uy = dx / ln, dy / ln
        e = np.where(T > 0.0, strain_of(line, np.maximum(T, 0.0)), T / e0)
        if line.tabe.size == 0:
            slope = line.ea
        else:  # (the segment's slope, as the law's)
            k = np.clip(np.searchsorted(line.tabe, e) - 1, 0, line.tabe.size - 2)
            slope = np.maximum(np.diff(line.tabt)[k] / np.diff(line.tabe)[k], 1e-300)
        de = 1.0 / np.where(T > 0.0, slope, e0)
        # force balance: node i gets +T_i u_i and -T_{i-1} u_{i-1}, gravity g e_y
        Fx, Fy = T * ux, T * uy + line.m * line.g
        Fx[1:] -= (T * ux)[:-1]
        Fy[1:] -= (T * uy)[:-1]
        G = ln / line.h - 1.0 - e
        R = np.concatenate([np.column_stack([Fx, Fy]).ravel(), G])
        q = T / ln
        Pxx, Pxy, Pyy = q * (1 - ux * ux), -q * ux * uy, q * (1 - uy * uy)
        rows, cols, vals = [], [], []

        def add(r, c, v):
            rows.append(r), cols.append(c), vals.append(v)

        # link j between node j and node j+1 (the pin beyond N-1): dF_j/dr_j = -P_j, dF_j/dr_{j+1} = P_j
        for (ra, ca, v) in ((px, px, Pxx), (px, py, Pxy), (py, px, Pxy), (py, py, Pyy)):
            add(ra, ca, -v)
            add(ra[nxt], ca[nxt] + 2, v[nxt])  # node j, by node j+1
            add(ra[nxt] + 2, ca[nxt], v[nxt])  # node j+1, by node j
            add(ra[nxt] + 2, ca[nxt] + 2, -v[nxt])  # node j+1, by itself
        add(px, tj, ux)
        add(py, tj, uy)
        add(px[nxt] + 2, tj[nxt], -ux[nxt])
        add(py[nxt] + 2, tj[nxt], -uy[nxt])
        add(tj, px, -ux / line.h)
        add(tj, py, -uy / line.h)
        add(tj[nxt], px[nxt] + 2, ux[nxt] / line.h[nxt])
        add(tj[nxt], py[nxt] + 2, uy[nxt] / line.h[nxt])
        add(tj, tj, -de)
        r, c, v = (np.concatenate(a) for a in (rows, cols, vals))
        if not free[0]:  # node 0 held: its rows say X[0:2] = held0
            keep = r >= 2
            r, c, v = np.concatenate([r[keep], [0, 1]]), np.concatenate([c[keep], [0, 1]]), \
                np.concatenate([v[keep], [1.0, 1.0]])
            R[0:2] = X[0:2] - held0
        return R, sp.csc_matrix((v, (r, c)), shape=(3 * N, 3 * N)), T

    X[2 * N:] = rigid_tensions(line, z, free)
    rprev = np.inf
    for it in range(1, max_iter + 1):
        R, J, T = residual_jac(X)
        rn = float(np.abs(R).max())
        dX = _solve(J, -R)
        if not np.all(np.isfinite(dX)):
            return None, it
        X = X + dX
        # (converged: the step at the positions' round-off, or the residual no longer falls)
        if np.abs(dX[:2 * N]).max() <= 1e-13 * max(1.0, float(np.abs(X[:2 * N]).max())) or rn >= rprev:
            if X[2 * N:].min() < 0.0:
                return None, it
            zz = z.copy()
            zz[0:4 * N:4], zz[1:4 * N:4] = X[0:2 * N:2], X[1:2 * N:2]
            return zz, it
        rprev = rn
    return None, max_iter


def rigid_tensions(line, z: np.ndarray, free: np.ndarray) -> np.ndarray:
    """The link tensions (>= 0) that balance gravity on ``z``'s shape held as a rigid chain:
    least squares over the free nodes' force balance (banded normal equations; exact when
    the shape is the rigid chain's equilibrium, as the catenary start)."""
    N = line.N
    x, y = np.append(z[0:4 * N:4], line.pin_state(0.0)[0]), np.append(z[1:4 * N:4], line.pin_state(0.0)[1])
    dx, dy = np.diff(x), np.diff(y)
    ln = np.hypot(dx, dy)
    ux, uy = dx / ln, dy / ln
    # node i (free): T_i u_i - T_{i-1} u_{i-1} = -m_i g e_y
    nodes = np.flatnonzero(free)
    rows, cols, vals = [], [], []
    for comp, u in ((0, ux), (1, uy)):
        r = 2 * np.arange(nodes.size) + comp
        rows += [r, r[nodes > 0]]
        cols += [nodes, nodes[nodes > 0] - 1]
        vals += [u[nodes], -u[nodes[nodes > 0] - 1]]
    A = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(2 * nodes.size, N))
    b = np.zeros(2 * nodes.size)
    b[1::2] = -line.m[nodes] * line.g
    AtA = (A.T @ A).tocsc()
    # (a link no free node touches has no equation: its tension stays zero; a shape that
    # does not fix its tensions, a straight line across gravity, gets the smallest ones)
    d = AtA.diagonal()
    AtA = AtA + sp.diags(np.where(d > 0.0, 1e-12 * d, 1.0))
    return np.maximum(_solve(AtA, A.T @ b), 0.0)


def statics(line, z0: np.ndarray, *, hold_free_end: bool = False, tol: float = 1e-12,
            max_iter: int = 200) -> np.ndarray:
    """The static equilibrium nearest ``z0`` (velocities zero; the held end at its t = 0
    position; with ``hold_free_end`` node 0 held too): the minimum of the potential energy
    (elastic + gravity), convex for tension-only links. First :func:`mixed` (Newton in
    positions and tensions from ``z0``'s shape as a rigid chain: a few steps at any N and
    stiffness), then at most a few Newton steps on the banded stiffness (O(N) each) to the
    force's round-off, with a backtracking line search on the force norm. Where that fails
    (a slack equilibrium, a shape far from any rigid equilibrium such as a straight line
    across gravity), a Levenberg-damped Newton iteration on the stiffness. (That one alone
    stalls on a long stiff line from the unstretched shape: the geometric stiffness T/l is
    zero there, and a step's transverse part d overstretches the links by d^2/(2 h).)
    ``line.statics_iterations`` records the Newton steps taken."""
    N = line.N
    z = z0.copy()
    z[2:4 * N:4] = z[3:4 * N:4] = 0.0
    z[4 * N:] = 0.0
    free = np.ones(N, bool)
    if hold_free_end:
        free[0] = False
    if not free.any():  # one link held at both ends: nothing is free, the start is the equilibrium
        line.statics_iterations = 0
        return z
    idx = np.sort(np.concatenate([4 * np.flatnonzero(free), 4 * np.flatnonzero(free) + 1]))
    mrow = np.repeat(line.m[free], 2)
    mdiag = sp.diags(np.concatenate([np.repeat(line.m, 4), [1.0, 1.0]]))

    def grad_hess(zz):
        dz = line.rhs(0.0, zz)
        J = line.jac(0.0, zz)
        # forces (mass x acceleration) and the stiffness -dF/dr, on the free position unknowns
        f = (dz[idx + 2] * mrow)
        K = -(mdiag @ J).tocsr()[idx + 2][:, idx].tocsc()
        return f, K

    scale = float(line.m.sum()) * max(line.g, 1e-300)
    # the force's round-off: a position's last bit times the stiffest link's EA/h
    floor = 16.0 * np.finfo(float).eps * float((line.ea / line.h).max()) * max(1.0, float(np.abs(z).max()))
    kscale = float(line.ea.max() / line.h.min())
    D = sp.diags(mrow / line.m.mean())

    def potential(zz):
        mm = line.measure(0.0, zz)
        return float(mm[13] + mm[14])

    def finish(z, f, K, it):
        for _ in range(3):  # polish: plain Newton steps while the force still falls
            zt = z.copy()
            zt[idx] += _solve(K, f)
            ft, Kt = grad_hess(zt)
            if not np.abs(ft).max() < np.abs(f).max():
                break
            z, f, K = zt, ft, Kt
        line.statics_iterations = it  # (mixed, stiffness and damped Newton steps together)
        return z

    zm, it = mixed(line, z, free, min(max_iter, 30))
    if zm is not None:  # Newton on the stiffness, a backtracking line search on the force norm
        z = zm
        f, K = grad_hess(z)
        fn = float(np.linalg.norm(f))
        for _ in range(10):
            if np.abs(f).max() <= tol * scale + floor:
                return finish(z, f, K, it)
            step = _solve(K, f)
            alpha, ok = 1.0, False
            while np.all(np.isfinite(step)) and alpha > 1e-6:
                zt = z.copy()
                zt[idx] += alpha * step
                ft, Kt = grad_hess(zt)
                ftn = float(np.linalg.norm(ft))
                if ftn <= (1.0 - 1e-4 * alpha) * fn:
                    ok = True
                    break
                alpha *= 0.5
            if not ok:
                break
            z, f, K, fn = zt, ft, Kt, ftn
            it += 1
    # the damped iteration (where the mixed form fails: slack or a shape far from any rigid
    # equilibrium, a straight line across gravity), Levenberg on the stiffness
    mu = 1e-3 * kscale
    P = potential(z)
    for it in range(it, max_iter):
        f, K = grad_hess(z)
        if np.abs(f).max() <= tol * scale + floor:
            return finish(z, f, K, it)
        A = (K + mu * D).tocsc()
        step = _solve(A, f)
        zt = z.copy()
        zt[idx] += step
        Pt = potential(zt)
        # (near the minimum the potential's change drowns in round-off: the force decides)
        if Pt < P - 1e-12 * (abs(P) + scale) or np.abs(grad_hess(zt)[0]).max() < np.abs(f).max():
            z, P = zt, Pt
            mu *= 0.1
        else:
            mu = max(mu * 10.0, 1e-12)
    from .errors import SimulationError

    raise SimulationError(f"statics: no equilibrium within {max_iter} Newton steps (largest force "
                          f"{np.abs(grad_hess(z)[0]).max():.3g})")


def matched(line, *, tol: float = 1e-15, max_iter: int = 50):
    """The ``"matched"`` start: the line at the problem's start shape and velocities, each
    link stretched to the tension the rigid chain carries the instant after release, so that
    no release wave is launched (as EA -> infinity it is the inextensible chain's release).

    A taut link's length obeys ``l_j'' = (a_{j+1} - a_j).u_j + |w_j|^2/l_j`` with ``w_j``
    the part of the nodes' relative velocity across the link (``l_j' = 0`` where the start's
    velocities are a rigid chain's). Asking ``l_j'' = 0`` of every link with the elastic
    accelerations ``a_i = F_i/m_i`` is the rigid chain's tension system
    (:func:`snapping.simulate.general.general_rhs`, its held end's acceleration included) on
    the stretched lengths ``l_j = h_j (1 + e_j)``, with ``T_j = f_j(e_j)``: solved for T_j on
    the start's link directions and angular velocities, ``e_j = f_j^{-1}(T_j)``
    (:func:`strain_of`), repeated until the lengths stop changing. A link the rigid chain
    would compress (T_j <= 0, a coarse chain's free arm) is left at its rest length, slack,
    with every link beyond it: the piece it frees falls as a whole (at rest: no tension in
    it, every link's l'' = 0), and the rest is solved again as a chain whose free end is the
    node inside the slack link nearest the held end (:func:`_rigid_release_tensions`). At rest the tension system
    does not involve the lengths (only ``h_j theta_j'^2`` does), so it ends after one
    solve; with angular velocities each pass shrinks the change by O(T/EA).
    Node positions are laid from the held end along the start's directions, velocities
    ``v_j = v_{j+1} - l_j theta_j' n_j``. Returns (state vector, tensions, passes);
    ``line.matched_iterations`` records the passes."""
    from . import general as G

    N = line.N
    th, om = start_angles(line)
    invm = 1.0 / line.m
    pin_args = line.pin.model_args()
    t0 = 0.0
    if 0.0 in G.breakpoints(G.make_model(line.h, invm, g=line.g, **pin_args)):
        t0 = float(np.nextafter(0.0, 1.0))  # (the held end's acceleration from t = 0 on: the right limit)

    def tensions(lengths, z):
        T = _rigid_release_tensions(N, t0, th, om, lengths, invm, line.g, pin_args)
        return T, np.where(T > 0.0, strain_of(line, np.maximum(T, 0.0)), 0.0)

    return matched_lengths(line, th, om, tensions, tol, max_iter, lay_positions=False)


def start_angles(line) -> tuple:
    """The start's link angles (unwrapped) and angular velocities ``theta_j'`` (from the
    problem's node positions and velocities, over the rest lengths)."""
    p = line.problem
    th = np.unwrap(np.arctan2(np.diff(p.y), np.diff(p.x)))
    om = (-np.sin(th) * np.diff(p.vx) + np.cos(th) * np.diff(p.vy)) / line.h
    return th, om


def lay(line, th, om, lengths) -> np.ndarray:
    """The state vector of links of ``lengths`` at angles ``th`` turning at ``om``, laid from
    the held end: node j = node j+1 - l_j t_j, ``v_j = v_{j+1} - l_j theta_j' n_j``."""
    c, s = np.cos(th), np.sin(th)
    px, py, pvx, pvy = line.pin_state(0.0)
    x = px - np.concatenate([np.cumsum((lengths * c)[::-1])[::-1], [0.0]])
    yy = py - np.concatenate([np.cumsum((lengths * s)[::-1])[::-1], [0.0]])
    vx = pvx - np.concatenate([np.cumsum((-lengths * om * s)[::-1])[::-1], [0.0]])
    vy = pvy - np.concatenate([np.cumsum((lengths * om * c)[::-1])[::-1], [0.0]])
    return line.pack(x, yy, vx, vy)


def matched_lengths(line, th, om, tensions, tol: float, max_iter: int, lay_positions: bool = True):
    """The matched start's fixed point, shared by :func:`matched` and
    :func:`snapping.simulate.elastic_body.matched_body`: from the rest lengths, ``T, e =
    tensions(lengths, z)`` (``z`` the state laid on those lengths when ``lay_positions``, else
    None) and lengths ``h (1 + e)``, until they change by at most ``tol`` times the longest
    rest link. Returns (state vector, tensions clipped at 0, passes); records the passes as
    ``line.matched_iterations``."""
    from .errors import SimulationError

    lengths = line.h.copy()
    for it in range(1, max_iter + 1):
        T, e = tensions(lengths, lay(line, th, om, lengths) if lay_positions else None)
        new = line.h * (1.0 + e)
        change = float(np.abs(new - lengths).max())
        lengths = new
        if change <= tol * float(line.h.max()):
            break
    else:
        raise SimulationError(f"matched start: the link lengths still change by {change:.3g} after {max_iter} passes")
    if not np.all(np.isfinite(lengths)):
        raise SimulationError("matched start: the rigid chain's tension system has no finite solution")
    line.matched_iterations = it
    return lay(line, th, om, lengths), np.where(T > 0.0, T, 0.0), it


def _rigid_release_tensions(N, t, th, om, lengths, invm, g, pin_args) -> np.ndarray:
    """The rigid chain's tensions (:func:`snapping.simulate.general.general_rhs`) on links of
    directions ``th``, angular velocities ``om`` and ``lengths``, with the tension-only links'
    active set: while some tension is <= 0, the links from the free end to the last such one
    are dropped (zero tension: the piece they join falls freely) and the rest is solved again
    as a chain whose free end is the first node kept."""
    from . import general as G

    T = np.zeros(N)
    lo = 0
    while lo < N:
        n = N - lo
        w = G.Work(n)
        y = np.concatenate([th[lo:], om[lo:], [0.0]])
        G.general_rhs(n, t, y, np.zeros_like(y), w.c, w.s, w.S, w.cp, w.dp, w.sig,
                      *G.make_model(lengths[lo:], invm[lo:], g=g, **pin_args))
        bad = np.flatnonzero(w.sig <= 0.0)
        if bad.size == 0:
            T[lo:] = w.sig
            break
        lo += int(bad[-1]) + 1
    return T
