"""Bending stiffness, bending damping and air drag on the extensible line (node coordinates).

The :class:`~snapping.simulate.body.Body` of a problem on the line of
:mod:`snapping.simulate.elastic_model` (state ``z = (x_i, y_i, vx_i, vy_i)_{i<N}, W, D``, node
0 the free end, node N the held end from the pin motion; link j runs from node j to node j+1,
``d_j = r_{j+1} - r_j``). The forces are added to the springs' (:mod:`elastic_kernels`); the
inextensible chain's body (:mod:`force_bending`, :mod:`force_drag`) is their limit EA -> infinity.

Bending: the energy and Rayleigh dissipation function

    V_b = sum_{i=1}^{N-1} B_i (psi_i - kappa0_i l_i)^2/(2 l_i),   R = sum_i eta_i psi_i'^2/(2 l_i),

``psi_i = atan2(d_{i-1} x d_i, d_{i-1} . d_i)`` the turning angle at node i (from link i-1 to
link i), ``l_i = (h_{i-1} + h_i)/2`` the node's share of *rest* length (the arrays ``Bl = B/l``,
``K0L = kappa0 l``, ``El = eta/l`` of :meth:`Body.node_arrays`). A clamped held end (link angle
``phi(t)``: the clamp's direction + pi, the held link pointing at the held end) adds
``psi_N = atan2(d_{N-1} x e_phi, d_{N-1} . e_phi)`` with ``psi_N' = phi' - theta_{N-1}'``. With the
link angle ``theta_j`` of ``d_j``, ``dtheta_j/dd_j = g_j = (-d_jy, d_jx)/|d_j|^2`` and
``theta_j' = g_j . (v_{j+1} - v_j)``; with the node moment ``M_i = Bl_i (psi_i - K0L_i) + El_i psi_i'``
(``M_0 = 0``; ``M_N = 0`` at a hinge) the generalised force on link j is ``Q_j = M_{j+1} - M_j``
and the node forces are ``+Q_j g_j`` on node j+1, ``-Q_j g_j`` on node j: exactly
``-dV_b/dr - dR/dv`` (a couple: no net force). At ``|d_j| = h_j`` this is force_bending's
``Q_j/h_j n_j``. The couple on node N acts on the held end.

Drag (force_drag's law, in node velocities, which are state variables here: local): at node
j < N, tangent ``tau_j`` the unit bisector of the unit vectors of links j-1 and j (link 0's at
the free end, link j's where the two fold back exactly), ``u = v_j - wind``,
``F_j = -(CN_j |u_n| + KN_j) u_n - (CT_j |u_t| + KT_j) u_t [- c_d |u| u at j = 0]`` (the arrays
``CN = c_n l`` etc. of :meth:`Body.node_arrays`, ``l_0 = h_0/2``).

Energy: ``KE + V_grav + V_elastic + V_b - W + D`` is conserved with
``W' = -F^int_N . v_pin + M_N phi'`` (the springs' and the bending couples' force on node N,
the clamp's torque times its rate) and ``D' = KV + 2R - sum_j F^drag_j . v_j``.

The turning angle is the wrapped one, in (-pi, pi]: a joint folded past pi (a limp line's
fold) turns its moment's sign where the inextensible chain's unwrapped angles would not (``V_b``
stays continuous there without natural curvature, its force does not).

Compression: a line with bending (``Body.has_bending``) is a rod, and its links push when shorter
than their rest length, with the springs' law continued below it (:func:`compression`,
``T = min(0, EA e + c edot)``, energy ``h EA e^2/2``): without it the inextensible chain's
compression (a bending chain pushes near its free end) has no limit in the tension-only line,
which folds there, the more violently the larger EA (chi 0.3, N 10, beta 1e-2, to t 0.4: a_peak
8x, 25x, 87x the chain's at c = 100, 300, 1000). A line with drag only stays tension-only.

Jacobian: node i's force depends on nodes i-2..i+2 (five 4 x 4 blocks); the springs' blocks
are the analytic ones (:func:`elastic_kernels.jac_blocks`), the body's are central differences
over the nodes coloured mod 5 (:func:`body_jac_fd`: 40 force evaluations, O(N) each; error
about 1e-9 relative), enough for Radau's Newton iteration.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from numba import njit

from .. import _validate as V
from . import elastic_kernels as EK
from .force_drag import add_drag

__all__ = ["LineBody", "body_forces", "bending_energy", "body_jac_fd", "check_method", "BODY_METHODS"]

#: the elastic line's methods that take a body ("rodas4": :mod:`elastic_rodas_body`, branch rodasbody)
BODY_METHODS = ("radau", "dop853", "rodas4")


@njit(cache=True, error_model="numpy")
def _geometry(N, z, pin, UX, UY, LN, OM):
    """Unit vectors ``UX, UY``, lengths ``LN`` and angular velocities ``OM`` of the N links."""
    for j in range(N):
        x0 = z[4 * j]
        y0 = z[4 * j + 1]
        vx0 = z[4 * j + 2]
        vy0 = z[4 * j + 3]
        if j + 1 < N:
            x1 = z[4 * j + 4]
            y1 = z[4 * j + 5]
            vx1 = z[4 * j + 6]
            vy1 = z[4 * j + 7]
        else:
            x1 = pin[0]
            y1 = pin[1]
            vx1 = pin[2]
            vy1 = pin[3]
        dx = x1 - x0
        dy = y1 - y0
        ln = math.sqrt(dx * dx + dy * dy)
        UX[j] = dx / ln
        UY[j] = dy / ln
        LN[j] = ln
        OM[j] = (dx * (vy1 - vy0) - dy * (vx1 - vx0)) / (ln * ln)


@njit(cache=True, error_model="numpy")
def body_forces(N, z, pin, Bl, K0L, El, CN, CT, KN, KT, cd, wx, wy, clamped, ex, ey, phid,
                push, h, EA, KV, UX, UY, LN, OM, MM, FX, FY):
    """The body's node forces into ``FX, FY`` (N + 1 each, overwritten; entry N the force on the
    held end); returns ``(M_N, diss, p_drag)``: the clamp's moment, the bending damping's
    dissipation rate 2R and the drag's power ``sum_j F_j . v_j``. ``(ex, ey)`` the clamp's
    unit link direction, ``phid`` its rate. With ``push`` a link shorter than its rest length
    pushes (:func:`compression`: the rod's axial stiffness ``EA`` and damping ``KV``, rest lengths ``h``)."""
    _geometry(N, z, pin, UX, UY, LN, OM)
    for i in range(N + 1):
        FX[i] = 0.0
        FY[i] = 0.0
    diss = 0.0
    if push:
        diss += compression(N, z, pin, h, EA, KV, UX, UY, LN, FX, FY)
    MM[0] = 0.0
    for i in range(1, N):
        cr = UX[i - 1] * UY[i] - UY[i - 1] * UX[i]
        dt = UX[i - 1] * UX[i] + UY[i - 1] * UY[i]
        dom = OM[i] - OM[i - 1]
        MM[i] = Bl[i] * (math.atan2(cr, dt) - K0L[i]) + El[i] * dom
        diss += El[i] * dom * dom
    if clamped:
        j = N - 1
        cr = UX[j] * ey - UY[j] * ex
        dt = UX[j] * ex + UY[j] * ey
        dom = phid - OM[j]
        MM[N] = Bl[N] * (math.atan2(cr, dt) - K0L[N]) + El[N] * dom
        diss += El[N] * dom * dom
    else:
        MM[N] = 0.0
    for j in range(N):
        q = (MM[j + 1] - MM[j]) / LN[j]
        fx = -UY[j] * q
        fy = UX[j] * q
        FX[j + 1] += fx
        FY[j + 1] += fy
        FX[j] -= fx
        FY[j] -= fy
    # the drag: the chain's law per node (force_drag.add_drag; here the node velocities are state values)
    pd = add_drag(N, UX, UY, wx, wy, CN, CT, KN, KT, cd, z[2:4 * N:4], z[3:4 * N:4], FX, FY)
    return MM[N], diss, pd


@njit(cache=True, error_model="numpy")
def compression(N, z, pin, h, EA, KV, UX, UY, LN, FX, FY):
    """A compressed link's push (added to ``FX, FY``; returns its damping's dissipation rate): the
    springs' law continued below the rest length, ``T_j = min(0, EA_j e_j + KV_j edot_j)`` for
    ``e_j <= 0`` (the springs carry ``max(0, ...)`` above it), force ``+T_j u_j`` on node j."""
    diss = 0.0
    for j in range(N):
        e = LN[j] / h[j] - 1.0
        if e > 0.0:
            continue
        vx1 = z[4 * j + 6] if j + 1 < N else pin[2]
        vy1 = z[4 * j + 7] if j + 1 < N else pin[3]
        ed = (UX[j] * (vx1 - z[4 * j + 2]) + UY[j] * (vy1 - z[4 * j + 3])) / h[j]
        f = EA[j] * e
        t = f + KV[j] * ed
        if t > 0.0:
            t = 0.0
        diss += h[j] * (t - f) * ed
        FX[j] += t * UX[j]
        FY[j] += t * UY[j]
        FX[j + 1] -= t * UX[j]
        FY[j + 1] -= t * UY[j]
    return diss


@njit(cache=True, error_model="numpy")
def compression_energy(N, h, EA, LN):
    """``sum h_j EA_j e_j^2/2`` over the compressed links (``LN`` their lengths)."""
    v = 0.0
    for j in range(N):
        e = LN[j] / h[j] - 1.0
        if e < 0.0:
            v += 0.5 * h[j] * EA[j] * e * e
    return v


@njit(cache=True, error_model="numpy")
def bending_energy(N, z, pin, Bl, K0L, clamped, ex, ey, UX, UY, LN, OM):
    """``V_b`` of the state ``z`` (the clamp's link direction ``(ex, ey)`` when clamped)."""
    _geometry(N, z, pin, UX, UY, LN, OM)
    v = 0.0
    for i in range(1, N):
        d = math.atan2(UX[i - 1] * UY[i] - UY[i - 1] * UX[i], UX[i - 1] * UX[i] + UY[i - 1] * UY[i]) - K0L[i]
        v += Bl[i] * d * d
    if clamped:
        j = N - 1
        d = math.atan2(UX[j] * ey - UY[j] * ex, UX[j] * ex + UY[j] * ey) - K0L[N]
        v += Bl[N] * d * d
    return 0.5 * v


@njit(cache=True, error_model="numpy")
def add_body(N, z, pin, invm, Bl, K0L, El, CN, CT, KN, KT, cd, wx, wy, clamped, ex, ey, phid,
             push, h, EA, KV, UX, UY, LN, OM, MM, FX, FY, dz):
    """Add the body's accelerations, held-end power and dissipation to the springs' ``dz``."""
    mn, diss, pd = body_forces(N, z, pin, Bl, K0L, El, CN, CT, KN, KT, cd, wx, wy, clamped, ex, ey, phid,
                               push, h, EA, KV, UX, UY, LN, OM, MM, FX, FY)
    for i in range(N):
        dz[4 * i + 2] += FX[i] * invm[i]
        dz[4 * i + 3] += FY[i] * invm[i]
    dz[4 * N] += mn * phid - (FX[N] * pin[2] + FY[N] * pin[3])
    dz[4 * N + 1] += diss - pd


@njit(cache=True, error_model="numpy")
def body_jac_fd(N, z, pin, invm, hmin, Bl, K0L, El, CN, CT, KN, KT, cd, wx, wy, clamped, ex, ey, phid,
                push, h, EA, KV, UX, UY, LN, OM, MM, FX, FY, GX, GY, zz, B5):
    """Add the body's acceleration derivatives to the 5-block band ``B5[i, k]`` (node i's rows
    by node ``i - 2 + k``'s columns): central differences, the nodes perturbed together in
    colours mod 5 (a node's force reaches two nodes either side: the colours' rows never
    overlap). Steps: ``1e-6 hmin`` in position (``2e-6`` of the shortest link where a link is
    shorter than ``hmin/2``: a step as long as the link would turn it over), ``1e-6 (1 + |v|)``
    in velocity."""
    for i in range(z.size):
        zz[i] = z[i]
    _geometry(N, z, pin, UX, UY, LN, OM)
    lmin = LN[0]
    for j in range(1, N):
        lmin = min(lmin, LN[j])
    hmin = min(hmin, 2.0 * lmin)
    for col in range(5):
        for comp in range(4):
            for sgn in (1.0, -1.0):
                for i in range(col, N, 5):
                    v = z[4 * i + comp]
                    e = 1e-6 * hmin if comp < 2 else 1e-6 * (1.0 + abs(v))
                    zz[4 * i + comp] = v + sgn * e
                body_forces(N, zz, pin, Bl, K0L, El, CN, CT, KN, KT, cd, wx, wy, clamped, ex, ey, phid,
                            push, h, EA, KV, UX, UY, LN, OM, MM, FX, FY)
                if sgn > 0.0:
                    for k in range(N):
                        GX[k] = FX[k]
                        GY[k] = FY[k]
                else:
                    for k in range(N):
                        GX[k] -= FX[k]
                        GY[k] -= FY[k]
            for i in range(col, N, 5):
                v = z[4 * i + comp]
                e = 1e-6 * hmin if comp < 2 else 1e-6 * (1.0 + abs(v))
                zz[4 * i + comp] = v
                for k in range(max(0, i - 2), min(N, i + 3)):
                    B5[k, i - k + 2, 2, comp] += GX[k] * invm[k] / (2.0 * e)
                    B5[k, i - k + 2, 3, comp] += GY[k] * invm[k] / (2.0 * e)


def check_method(line, method: str, asked=()) -> None:
    """With a body: refuse a method without one, and checkpoint options (``asked``: their
    ``(name, value)`` pairs given), which only the compiled RODAS4 loops keep: SnappingInputError,
    before any file is looked at."""
    if line.body is None:
        return
    if method not in BODY_METHODS:
        raise V.SnappingInputError(f"method={method!r} with a body (bending, drag): the link-coordinate stepper does "
                                   f"not take the body's forces; use one of {BODY_METHODS}")
    if asked:
        k, v = asked[0]
        raise V.SnappingInputError(f"{k}={v!r} with a body (bending, drag): only the compiled loops of 'rodas4' and "
                                   f"'rodas4-links' keep checkpoints, and they take no body (a body's 'rodas4' steps in "
                                   f"Python's loop); run the body's methods {BODY_METHODS} without checkpoint, resume "
                                   f"and checkpoint_every")


def body_inputs(line, method: str, inputs: dict) -> None:
    """:func:`snapping.simulate.elastic_solve.solve`'s part for a body: refuse a method without
    one (SnappingInputError), record ``compression`` (1 or 0) in ``inputs``."""
    if line.body is None:
        return
    check_method(line, method)
    inputs["compression"] = int(line.body.push)


class LineBody:
    """A :class:`Body` on an :class:`ElasticLine`: its node arrays, the clamp's motion, and
    the rhs, Jacobian, measures and energy of the line with it."""

    def __init__(self, line, body, compression=None):
        if isinstance(body.clamp, str):  # ("start": the direction the problem's start leaves the held end)
            body = body.resolved(line.problem.x, line.problem.y)
        self.line, self.body = line, body
        N = line.N
        self.clamped = body.clamp is not None
        a = body.node_arrays(line.h, self.clamped)
        self.Bl, self.K0L, self.El = a["Bl"], a["K0L"], a["El"]
        self.CN, self.CT, self.KN, self.KT = a["CN"], a["CT"], a["KN"], a["KT"]
        self.cd = float(body.tip_drag)
        self.wx, self.wy = float(body.wind[0]), float(body.wind[1])
        self._spline = None
        if isinstance(body.clamp, tuple):
            from scipy.interpolate import CubicSpline

            t, ang = body.clamp
            self._spline = CubicSpline(t, ang, bc_type="clamped")
            self._tlast, self._alast = float(t[-1]), float(ang[-1])
        self._scr = tuple(np.zeros(N + 1) for _ in range(9))
        self._zz = np.zeros(4 * N + 2)
        self.hmin = float(line.h.min())
        #: a bending line's links push when shorter than their rest length (a rod: :func:`compression`)
        #: (``compression``: True or False to choose; None: a body with bending pushes)
        if compression and not body.has_bending:
            raise V.SnappingInputError(f"compression={compression!r} with a body without bending (bending = damping = 0, "
                                       f"no clamp): a line with drag only is tension-only; compression must be None or "
                                       f"False here (True needs bending > 0)")
        self.push = bool(body.has_bending) if compression is None else bool(compression)

    def clamp(self, t: float):
        """``(ex, ey, phi')``: the clamp's unit link direction (the held link pointing at the held
        end: the clamp's angle + pi) and its rate at time t; zeros without a clamp."""
        if not self.clamped:
            return 0.0, 0.0, 0.0
        if self._spline is None:
            a, ad = float(self.body.clamp), 0.0
        elif t >= self._tlast:
            a, ad = self._alast, 0.0
        else:
            a, ad = float(self._spline(t)), float(self._spline(t, 1))
        return -math.cos(a), -math.sin(a), ad

    def _args(self, t):
        ex, ey, phid = self.clamp(t)
        L = self.line
        return (self.Bl, self.K0L, self.El, self.CN, self.CT, self.KN, self.KT, self.cd, self.wx, self.wy,
                self.clamped, ex, ey, phid, self.push, L.h, L.ea, L.damp)

    def forces(self, t, z, push: bool | None = None):
        """``(FX, FY, M_N, diss, p_drag)``: copies of the body's node forces (N + 1) and
        :func:`body_forces`' returns; ``push=False``: without the compressed links' push."""
        L = self.line
        s = self._scr
        a = self._args(t)
        if push is not None:
            a = a[:14] + (bool(push) and self.push,) + a[15:]
        mn, diss, pd = body_forces(L.N, z, L.pin_state(t), *a, *s[:7])
        return s[5].copy(), s[6].copy(), mn, diss, pd

    def rhs(self, t, z, dz):
        L = self.line
        pin = L.pin_state(t)
        EK.rhs(L.N, z, pin, L.h, L._invm, L.ea, L.damp, L.tabe, L.tabt, L.g, dz, *L._work)
        add_body(L.N, z, pin, L._invm, *self._args(t), *self._scr[:7], dz)
        return dz

    def _pattern(self):
        if getattr(self, "_pat", None) is None:
            N = self.line.N
            self._pat = EK.block_band_pattern(N, 5)
            self._b3 = np.zeros((N, 3, 4, 4))
            self._b5 = np.zeros((N, 5, 4, 4))
        return self._pat

    def jac(self, t, z):
        """The Jacobian of :meth:`rhs` (W and D rows zero, as the springs'), sparse, 5-block band."""
        L = self.line
        indices, indptr, order = self._pattern()
        pin = L.pin_state(t)
        EK.jac_blocks(L.N, z, pin, L.h, L._invm, L.ea, L.damp, L.tabe, L.tabt, self._b3, *L._work)
        B5 = self._b5
        B5[:] = 0.0
        B5[:, 1:4] = self._b3
        s = self._scr
        body_jac_fd(L.N, z, pin, L._invm, self.hmin, *self._args(t), *s[:9], self._zz, B5)
        n = 4 * L.N + 2
        return sp.csc_matrix((B5.ravel()[order], indices, indptr), shape=(n, n))

    def bending_energy(self, t, z):
        L = self.line
        ex, ey, _ = self.clamp(t)
        s = self._scr
        return float(bending_energy(L.N, z, L.pin_state(t), self.Bl, self.K0L, self.clamped, ex, ey, *s[:4]))

    def measure(self, t, z):
        """The line's measures (:data:`elastic_kernels.MEASURE_NAMES`) with the body: the
        accelerations of the full rhs, the bending energy (and a pushing line's compression
        energy) in ``elastic_energy`` (index 14), the body's force on the held end in
        ``pin_force_x, _y``; a pushing line's ``n_slack`` counts the links at or above their rest
        length that carry nothing (``sigma_max``/``sigma_min`` stay the springs' tensions, >= 0)."""
        L = self.line
        pin = L.pin_state(t)
        dz = np.empty_like(z)
        self.rhs(t, z, dz)  # (leaves the springs' T, E in L._work)
        T, E = L._work[0], L._work[1]
        out = np.zeros(EK.NMEAS)
        EK.measure_given(L.N, z, pin, L.h, L.m, L.ea, L.tabe, L.tabt, L.tabw, L.g, L.snode, dz, T, E, out)
        FXN, FYN = self._scr[5][L.N], self._scr[6][L.N]
        out[10] += FXN
        out[11] += FYN
        out[14] += self.bending_energy(t, z)
        if self.push:  # (the geometry of z: bending_energy's)
            out[14] += compression_energy(L.N, L.h, L.ea, self._scr[2])
            out[16] = float(np.count_nonzero((T == 0.0) & (E >= 0.0)))  # (a compressed link pushes: not slack)
        return out


def matched_body(line, *, tol: float = 1e-15, max_iter: int = 50):
    """The ``"matched"`` start of a line with a body: the problem's start shape and velocities,
    each link stretched to the tension the rigid chain with the same body carries the instant
    after release, so that every link's length has ``l_j'' = 0`` at t = 0 (no release wave).

    With the body's node forces ``F_i`` at the start (bending, bending damping, drag: they
    depend on positions and velocities only) and ``a_i = (T_i u_i - T_{i-1} u_{i-1} + F_i)/m_i
    + g e_y`` (``a_N`` the held end's), ``l_j'' = (a_{j+1} - a_j).u_j + l_j theta_j'^2 = 0`` is a
    tridiagonal linear system for the tensions; the strains ``f^{-1}(T)`` change the lengths, so
    it is repeated until they stop changing. A link the rigid chain would compress (``T_j <= 0``:
    a bending chain can push) is shortened by ``T_j/EA_j`` where the line's links push (a body
    with bending: :func:`compression`), else left at its rest length (a tension-only link). Returns
    (state vector, tensions, passes)."""
    from scipy.linalg import solve_banded

    from .elastic_statics import matched_lengths, start_angles, strain_of

    N = line.N
    th, om = start_angles(line)
    c, s = np.cos(th), np.sin(th)
    invm = 1.0 / line.m
    _, _, _, _, pax, pay = line.pin.kinematics(0.0)
    C = c[:-1] * c[1:] + s[:-1] * s[1:]  # u_j . u_{j+1}
    ab = np.zeros((3, N))
    ab[1] = -invm - np.concatenate([invm[1:], [0.0]])
    ab[0, 1:] = C * invm[1:]  # T_{j+1} in row j
    ab[2, :-1] = C * invm[1:]  # T_{j-1} in row j (over m_j)

    def tensions(lengths, z):
        FX, FY, _, _, _ = line.body.forces(0.0, z, push=False)  # (the links' own forces are the T_j)
        Fu = FX[:N] * c + FY[:N] * s  # F_j . u_j
        Fnu = np.concatenate([FX[1:N] * c[:-1] + FY[1:N] * s[:-1], [0.0]])  # F_{j+1} . u_j
        b = -(Fnu * np.concatenate([invm[1:], [0.0]]) - Fu * invm + lengths * om * om)
        b[-1] -= pax * c[-1] + pay * s[-1] - line.g * s[-1]
        T = solve_banded((1, 1), ab, b)
        return T, np.where(T > 0.0, strain_of(line, np.maximum(T, 0.0)), np.minimum(T, 0.0) / line.ea if
                           line.body.push else 0.0)

    return matched_lengths(line, th, om, tensions, tol, max_iter)
