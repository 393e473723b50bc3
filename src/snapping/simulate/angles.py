"""The N-link chain in link angles: exactly inextensible, compiled (numba, ``cache=True``).

The same N-pendulum as :mod:`snapping.simulate.kernels` (the paper's appendix), with
the links written as ``d_k = r_{k+1} - r_k = (cos theta_k, sin theta_k)/N``, so that
every link has length 1/N to round-off whatever the time stepper does. Positions and
velocities follow by summing links from the pin (``r_{N+1} = 0``)::

    r_k = -sum_{j >= k} d_j,      r_k' = -sum_{j >= k} theta_j' n_j / N,
    t_k = (cos theta_k, sin theta_k),   n_k = (-sin theta_k, cos theta_k).

Derivation. The momentum balance (eq. (discretemo)) is unchanged,
``r_k'' = N^2 [sigma_k d_k - sigma_{k-1} d_{k-1}] + e2`` with ``sigma_0 = 0``. For a
link k < N (not at the pin), ``d_k'' = r_{k+1}'' - r_k''
= N^2 [sigma_{k+1} d_{k+1} - 2 sigma_k d_k + sigma_{k-1} d_{k-1}]``, while
differentiating ``d_k = t_k/N`` twice gives ``d_k'' = (theta_k'' n_k - theta_k'^2 t_k)/N``.
Projecting on ``t_k`` (with ``t_{k+1}.t_k = cos(theta_{k+1} - theta_k) =: C_k``) gives
the tension rows, and on ``n_k`` (``t_{k+1}.n_k = sin(theta_{k+1} - theta_k) =: S_k``)
the angular accelerations::

    C_k sigma_{k+1} - 2 sigma_k + C_{k-1} sigma_{k-1} = -theta_k'^2 / N^2
    theta_k'' = N^2 [sigma_{k+1} S_k - sigma_{k-1} S_{k-1}]

At the pin (link N, ``r_{N+1}'' = 0`` so ``d_N'' = -r_N''``)::

    -sigma_N + C_{N-1} sigma_{N-1} = -theta_N'^2 / N^2 + sin(theta_N) / N
    theta_N'' = -N^2 sigma_{N-1} S_{N-1} - N cos(theta_N)

These are the position form's rows with ``N^2 d_{k+1}.d_k = C_k`` and
``|d_k'|^2 = theta_k'^2/N^2``, now with the constraint exact (no restoring term is
needed or present). The system is the same symmetric, weakly diagonally dominant
tridiagonal one, solved with the same Thomas elimination by ratios of minors as
:func:`snapping.simulate.kernels.rhs`; O(N) per evaluation, no allocation.

Layout: a state is one float64 vector ``y`` of length 2N, ``y[:N] = theta`` and
``y[N:] = theta'`` (index j = link k = j + 1; j = 0 is the link at the free end,
j = N - 1 the link at the pin). Its derivative is ``[theta', theta'']``.

Example
-------
>>> import numpy as np
>>> from snapping.simulate import angles, initial_state
>>> y = angles.state_to_angles(initial_state(0.25, 8, chords="exact"))
>>> w = angles.Work(8); f = np.empty(16)
>>> angles.angle_rhs(8, y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig)
>>> bool(np.allclose(f, angles.reference_rhs(y)))
True
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .. import _validate as V
from . import kernels as K

__all__ = [
    "Work", "angle_rhs", "state_to_angles", "angles_to_state", "angles_to_Z", "measure_angles",
    "reference_rhs", "link_error_angles", "sincos",
]

#: the minors p_j are rescaled by a power of two every BLOCK rows (as in kernels.rhs)
BLOCK = 32


# fdlibm's Cody-Waite split of pi/2 and its sin/cos kernels on [-pi/4, pi/4] (|error| < 1 ulp)
_PIO2_1 = 1.57079632673412561417e+00
_PIO2_2 = 6.07710050650619224932e-11
_PIO2_3 = 2.02226624871116645580e-21
_TWO_OVER_PI = 0.63661977236758134308
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
#: beyond this |theta| the three-part reduction loses bits: use libm
SINCOS_FAST_MAX = 1.0e5


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def sincos(N, th, c, s):
    """c[j], s[j] = cos(th[j]), sin(th[j]) for j < N, to within ~1 ulp.

    A branch-free polynomial (fdlibm's kernels after a three-part reduction by pi/2)
    that the compiler vectorises: about 2 ns per angle against about 16 ns for two
    libm calls. Each angle beyond ``SINCOS_FAST_MAX`` in magnitude goes to libm.
    """
    nbig = 0  # (a count, not a running maximum: the count vectorises with the polynomial)
    for j in range(N):
        x = th[j]
        nbig += abs(x) > SINCOS_FAST_MAX
        c[j], s[j] = sincos1(x)
    if nbig:  # (each such angle alone, so that the result of one angle never depends on the others)
        for j in range(N):
            x = th[j]
            if abs(x) > SINCOS_FAST_MAX:
                c[j] = math.cos(x)
                s[j] = math.sin(x)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy", inline="always")
def sincos1(x):
    """(cos x, sin x) by the branch-free polynomial of :func:`sincos` (|x| <= SINCOS_FAST_MAX)."""
    k = np.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - k * _PIO2_1) - k * _PIO2_2) - k * _PIO2_3
    z = r * r
    sn = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    cs = 1.0 - 0.5 * z + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    q = k - 4.0 * np.floor(k * 0.25)  # quadrant 0..3
    swap = q == 1.0 or q == 3.0
    a = sn if swap else cs
    b = cs if swap else sn
    return (-a if (q == 1.0 or q == 2.0) else a), (-b if q >= 2.0 else b)


class Work:
    """Work arrays of :func:`angle_rhs` for N links (cos, sin, S_k, elimination, tension)."""

    def __init__(self, N: int):
        self.N = N
        self.c = np.zeros(N)
        self.s = np.zeros(N)
        self.S = np.zeros(max(N - 1, 1))
        self.cp = np.zeros(N)
        self.dp = np.zeros(N)
        self.sig = np.zeros(N)


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def angle_rhs(N, y, f, c, s, S, cp, dp, sig):
    """Derivative ``f = [theta', theta'']`` of the angle state ``y`` (length 2N).

    Also leaves ``cos theta`` in ``c``, ``sin theta`` in ``s``, ``sin(theta_{k+1} -
    theta_k)`` in ``S`` and the link tensions in ``sig`` (index j = link j + 1).
    Pass 0: trigonometry; pass 1: coupling coefficients and forward elimination
    (Thomas's pivots as ratios of leading minors, see :func:`kernels.rhs`);
    pass 2: back substitution and angular accelerations.
    """
    fN = float(N)
    n2 = fN * fN
    inv_n2 = 1.0 / n2
    sincos(N, y, c, s)
    for j in range(N):
        f[j] = y[N + j]
    if N == 1:
        w = y[1]
        sig[0] = w * w - s[0]
        f[1] = -c[0]
        return
    # ---- pass 1: forward elimination, rows j = 0 .. N-2
    cprev = 0.0
    pm = 1.0
    pmm = 0.0
    q = 0.0
    j0 = 0
    while j0 < N - 1:
        j1 = min(j0 + BLOCK, N - 1)
        for j in range(j0, j1):
            cj = c[j]
            sj = s[j]
            cn = c[j + 1]
            sn = s[j + 1]
            C = cn * cj + sn * sj
            S[j] = sn * cj - cn * sj
            w = y[N + j]
            r = -(w * w) * inv_n2
            p = -2.0 * pm - (cprev * cprev) * pmm
            q = r * pm - cprev * q
            inv = 1.0 / p
            cp[j] = C * pm * inv
            dp[j] = q * inv
            pmm = pm
            pm = p
            cprev = C
        e = math.frexp(pm)[1]
        sc = math.ldexp(1.0, -e)
        pm *= sc
        pmm *= sc
        q *= sc
        j0 = j1
    # last row (link N, at the pin): b = -1
    jl = N - 1
    w = y[N + jl]
    r = -(w * w) * inv_n2 + s[jl] / fN
    p = -pm - (cprev * cprev) * pmm
    q = r * pm - cprev * q
    s_next = q / p
    sig[jl] = s_next
    # ---- pass 2: back substitution; theta'' of link j + 1 once sigma_j is known
    # (at the pin: theta_N'' = -N^2 sigma_{N-1} S_{N-1} - N cos theta_N)
    s_nn = 0.0  # sigma_{j+2}
    for j in range(N - 2, -1, -1):
        sj = dp[j] - cp[j] * s_next
        sig[j] = sj
        if j + 1 == N - 1:
            f[N + j + 1] = -n2 * sj * S[j] - fN * c[j + 1]
        else:
            f[N + j + 1] = n2 * (s_nn * S[j + 1] - sj * S[j])
        s_nn = s_next
        s_next = sj
    f[N] = n2 * s_nn * S[0]


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def angles_to_Z(N, y, c, s, sig, Z):
    """Fill the (7, N + 1) position-form state ``Z`` (x, y, vx, vy, ax, ay, sigma) from
    the angle state ``y`` with its ``c = cos theta``, ``s = sin theta`` and tension
    ``sig`` (as left by :func:`angle_rhs`). Positions and velocities are summed from
    the pin; accelerations from the momentum balance
    ``a_k = N [sigma_k t_k - sigma_{k-1} t_{k-1}] + e2``."""
    fN = float(N)
    invN = 1.0 / fN
    Z[K.RX, N] = 0.0
    Z[K.RY, N] = 0.0
    Z[K.RVX, N] = 0.0
    Z[K.RVY, N] = 0.0
    Z[K.RAX, N] = 0.0
    Z[K.RAY, N] = 0.0
    Z[K.RSIG, N] = 0.0
    x = 0.0
    yy = 0.0
    vx = 0.0
    vy = 0.0
    for j in range(N - 1, -1, -1):
        w = y[N + j] * invN
        x -= c[j] * invN
        yy -= s[j] * invN
        vx += s[j] * w
        vy -= c[j] * w
        Z[K.RX, j] = x
        Z[K.RY, j] = yy
        Z[K.RVX, j] = vx
        Z[K.RVY, j] = vy
        Z[K.RSIG, j] = sig[j]
    for j in range(N):
        sx = sig[j] * c[j]
        sy = sig[j] * s[j]
        if j > 0:
            sx -= sig[j - 1] * c[j - 1]
            sy -= sig[j - 1] * s[j - 1]
        Z[K.RAX, j] = fN * sx
        Z[K.RAY, j] = fN * sy + 1.0


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def link_error_angles(N, c, s):
    """max_k |N |d_k| - 1| of the links d_k = (cos theta_k, sin theta_k)/N (round-off only)."""
    e = 0.0
    for j in range(N):
        v = abs(math.sqrt(c[j] * c[j] + s[j] * s[j]) - 1.0)
        if v > e:
            e = v
    return e


@njit(cache=True, fastmath=False, boundscheck=False, error_model="numpy")
def measure_angles(N, y, c, s, sig, Z, rinv0, meas):
    """The per-step diagnostics of :func:`kernels.measure` for an angle state: ``Z`` is
    filled by :func:`angles_to_Z`, measured, and the link-length entries (error against
    1/N and against the initial chords, total length) are replaced by those of the
    links themselves, ``|d_k| = |(cos theta_k, sin theta_k)|/N``: positions are sums of
    links and carry the round-off of that sum, the chain does not."""
    angles_to_Z(N, y, c, s, sig, Z)
    K.measure(N, Z, rinv0, meas)
    e = link_error_angles(N, c, s)
    meas[K.M_LINKERR] = e
    meas[K.M_LINKERR0] = e
    length = 0.0
    for j in range(N):
        length += math.sqrt(c[j] * c[j] + s[j] * s[j])
    meas[K.M_LENGTH] = length / float(N)


# ---------------------------------------------------------------- Python-side helpers
def state_to_angles(state) -> np.ndarray:
    """The angle state ``[theta, theta']`` (length 2N) of a :class:`ChainState`.

    theta_k = atan2 of the link d_k = r_{k+1} - r_k (unwrapped along the chain);
    theta_k' = N d_k'.n_k, the rotation rate of the link (any stretching rate of a
    state that is not exactly inextensible is dropped). The link lengths are taken
    to be exactly 1/N: a state whose chords differ from 1/N (e.g. the catenary sampled
    at equal arclength) is mapped to the chain with the same link directions.

    >>> from snapping.simulate import initial_state
    >>> y = state_to_angles(initial_state(0.5, 4, chords="exact"))
    >>> y.shape, bool(abs(y[4:]).max() == 0.0)
    ((8,), True)
    """
    N = state.N
    dx, dy = np.diff(state.x), np.diff(state.y)
    th = np.unwrap(np.arctan2(dy, dx))
    dvx, dvy = np.diff(state.vx), np.diff(state.vy)
    om = N * (-np.sin(th) * dvx + np.cos(th) * dvy)
    return np.concatenate([th, om]).astype(float)


def angles_to_state(y: np.ndarray, t: float = 0.0):
    """The :class:`ChainState` (positions and velocities summed from the pin) of an angle state.

    >>> import numpy as np
    >>> s = angles_to_state(np.array([-np.pi / 2, 0.0]))      # N = 1, hanging
    >>> bool(abs(s.x[0]) < 1e-15), float(s.y[0])
    (True, 1.0)
    """
    from .chain import ChainState

    y = np.asarray(y, dtype=float)
    N = y.size // 2
    if y.size != 2 * N or N < 1:
        raise V.SnappingInputError(f"angle state of length {y.size} must have even length 2N >= 2")
    w = Work(N)
    f = np.empty(2 * N)
    angle_rhs(N, y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig)
    Z = np.zeros((K.NROWS, N + 1))
    angles_to_Z(N, y, w.c, w.s, w.sig, Z)
    return ChainState(Z[K.RX].copy(), Z[K.RY].copy(), Z[K.RVX].copy(), Z[K.RVY].copy(), t)


def reference_rhs(y: np.ndarray) -> np.ndarray:
    """``[theta', theta'']`` by a dense linear solve of the rows above (numpy; O(N^3),
    for tests of :func:`angle_rhs`)."""
    y = np.asarray(y, dtype=float)
    N = y.size // 2
    th, om = y[:N], y[N:]
    A = np.zeros((N, N))
    b = -(om**2) / N**2
    for j in range(N):
        A[j, j] = -2.0 if j < N - 1 else -1.0
        if j + 1 < N:
            A[j, j + 1] = A[j + 1, j] = math.cos(th[j + 1] - th[j])
    b[N - 1] += math.sin(th[N - 1]) / N
    sig = np.linalg.solve(A, b)
    S = np.sin(np.diff(th))
    acc = np.zeros(N)
    for j in range(N):
        if j == N - 1:
            acc[j] = -N * math.cos(th[j]) - (N**2 * sig[j - 1] * S[j - 1] if j >= 1 else 0.0)
        else:
            acc[j] = N**2 * (sig[j + 1] * S[j] - (sig[j - 1] * S[j - 1] if j >= 1 else 0.0))
    return np.concatenate([om, acc])
