"""Bending stiffness and bending (Kelvin-Voigt) damping as node forces (numba, ``cache=True``).

One force family of :mod:`snapping.simulate.forced` (where the families are gathered).

The discrete bending energy of the chain (links ``h_j``, angles ``theta_j``, node i
between link i - 1 and link i, index 0 the free end) is::

    V_b = sum_{i=1}^{N-1} B_i (theta_i - theta_{i-1} - kappa0_i l_i)^2 / (2 l_i),
    l_i = (h_{i-1} + h_i)/2,

the node's share of arclength, the same share the consistent (``lumping="shared"``)
masses take. It is the elastica's ``int B (kappa - kappa0)^2/2 ds`` with the curvature at
node i taken as its turning angle over its share of length, ``kappa_i = (theta_i -
theta_{i-1})/l_i``, integrated by the midpoint rule over the node's share: so refining
the chain converges to the elastic rod (``V_b -> int B (theta_s - kappa0)^2/2 ds``; the
tests check the cantilever's tip deflection q L^4/(8 B) and its order). A held end clamped
at the direction ``phi(t)`` (a link angle: the direction of the held link when straight
out of the clamp) adds the same term at node N with ``theta_N := phi(t)`` and
``l_N = h_{N-1}/2``. Kelvin-Voigt damping is the dissipation function
``R = sum_i eta_i (theta_i' - theta_{i-1}')^2 / (2 l_i)`` (the clamp's with
``theta_N' := phi'(t)``).

With the node moment ``M_i = B_i (theta_i - theta_{i-1} - kappa0_i l_i)/l_i + eta_i
(theta_i' - theta_{i-1}')/l_i`` (``M_0 = 0``, ``M_N = 0`` at a free hinge), the
generalised force on link j is ``Q_j = -dV_b/dtheta_j - dR/dtheta_j' = M_{j+1} - M_j``.
It is applied as a couple of node forces, ``+Q_j/h_j n_j`` on node j + 1 and
``-Q_j/h_j n_j`` on node j (zero net force; virtual work ``Q_j dtheta_j``, since
``dr_{j+1} - dr_j = h_j dtheta_j n_j``): exactly ``-dV_b/dr`` of the energy written in node
positions at ``|d_j| = h_j``. The couple of the held link on node N acts on the held end.

Arrays (length N + 1, by node): ``Bl = B_i/l_i``, ``K0L = kappa0_i l_i``, ``El = eta_i/l_i``
(zero where a node has no term); ``MM`` scratch for the moments; ``FX, FY`` the node forces
(added to).
"""

from __future__ import annotations

from numba import njit

__all__ = ["add_bending", "bending_energy"]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def add_bending(N, y, c, s, invh, Bl, K0L, El, clamped, phi, phid, MM, FX, FY):
    """Add the bending and damping couples to ``FX, FY``; returns ``(p_clamp, diss, Q_last)``:
    the power ``M_N phi'`` the clamp puts in, the damping's dissipation rate ``2R`` and the
    generalised force ``Q_{N-1}`` of the held link (whose couple acts on the held end)."""
    diss = 0.0
    MM[0] = 0.0
    for i in range(1, N):
        dom = y[N + i] - y[N + i - 1]
        MM[i] = Bl[i] * ((y[i] - y[i - 1]) - K0L[i]) + El[i] * dom
        diss += El[i] * dom * dom
    if clamped:
        dom = phid - y[2 * N - 1]
        MM[N] = Bl[N] * ((phi - y[N - 1]) - K0L[N]) + El[N] * dom
        diss += El[N] * dom * dom
    else:
        MM[N] = 0.0
    for j in range(N):
        fq = (MM[j + 1] - MM[j]) * invh[j]
        fx = -s[j] * fq
        fy = c[j] * fq
        FX[j + 1] += fx
        FY[j + 1] += fy
        FX[j] -= fx
        FY[j] -= fy
    return MM[N] * phid, diss, MM[N] - MM[N - 1]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def bending_energy(N, y, Bl, K0L, clamped, phi):
    """``V_b`` of the angles ``y[:N]`` (and the clamp direction ``phi`` when clamped)."""
    v = 0.0
    for i in range(1, N):
        d = (y[i] - y[i - 1]) - K0L[i]
        v += Bl[i] * d * d
    if clamped:
        d = (phi - y[N - 1]) - K0L[N]
        v += Bl[N] * d * d
    return 0.5 * v
