"""The paper's estimates for any start shape and node masses (the discrete chain).

:mod:`snapping.estimates` holds them for the paper's catenary from chi alone; here the same
quantities come from node coordinates and masses (index 0 the free end, index N the held
end): the available energy P, the initial maximum curvature kappa_m(0), the delta scales
and the whirling-rod predictions. Takes coordinates, never imports :mod:`snapping.simulate`
(:meth:`snapping.simulate.Problem.estimate` calls it).

Example
-------
>>> from snapping.shape_estimates import available_energy_shape
>>> available_energy_shape([1.0, 0.5, 0.0], [0.0, 0.0, 0.0], [0.25, 0.5, 0.25])   # horizontal string
0.5
"""

from __future__ import annotations

import math

import numpy as np

from . import _validate as V
from .estimates import available_energy, catenary_shape, kappa_m0, whirling_rod  # noqa: F401 (doctests)

__all__ = ["available_energy_shape", "kappa_m0_shape", "shape_estimate"]


# =============================================================================
# Any start shape and mass distribution: the discrete chain (appended section).
# Node order of the simulator: index 0 = free end, index N = pin; link j joins
# nodes j and j + 1. Takes coordinates, never imports snapping.simulate.
# =============================================================================
def _shape_arrays(x, y):
    """x, y as finite 1-D float arrays of one length N + 1 >= 2 with links of positive length."""
    x = V.float_array("x", x)
    y = V.float_array("y", y)
    if x.ndim != 1 or x.shape != y.shape or x.size < 2:
        raise V.SnappingInputError(
            f"x and y must be 1-D arrays of one length N + 1 >= 2; got shapes {x.shape} and {y.shape}"
        )
    finite = np.isfinite(x) & np.isfinite(y)
    if not finite.all():
        i = int(np.nonzero(~finite)[0][0])
        raise V.SnappingInputError(f"node {i} = (x, y) = ({float(x[i])!r}, {float(y[i])!r}) is not finite")
    h = np.hypot(np.diff(x), np.diff(y))
    if not np.all(h > 0.0):
        i = int(np.nonzero(~(h > 0.0))[0][0])
        raise V.SnappingInputError(
            f"nodes {i} and {i + 1} coincide at ({float(x[i])!r}, {float(y[i])!r}); every link must have a positive length"
        )
    return x, y, h


def available_energy_shape(x, y, m, g: float = 1.0) -> float:
    """Available energy of a discrete chain of any shape and node masses.

    The potential energy released when the chain falls from the shape (x, y) to
    hanging straight down from the pin (y downward, gravity ``g`` along +e2):

        P = g sum_i m_i (s_i - (y_i - y_N)),

    where s_i is the distance along the chain from the pin (node N) to node i,
    the sum of the lengths of links i, ..., N-1 (for the pin at the origin,
    ``P = g sum_i m_i (s_i - y_i)``). This is the discrete version of the
    paper's P (section "Regularization is not by discreteness"): for the
    uniform catenary of total mass 1 it converges to :func:`available_energy`
    as N^-2 when the masses are lumped from the mass per length lambda by each
    node's share of its two links,

        m_0 = (lambda h)_0 / 2,   m_i = ((lambda h)_{i-1} + (lambda h)_i) / 2,

    (the trapezoidal rule; the pin's share does not matter, since
    s_N = y_N - y_N = 0), with (lambda h)_j the mass of link j.

    Parameters
    ----------
    x, y : array_like, shape (N + 1,)
        Node positions, index 0 = free end, index N = pin.
    m : array_like, shape (N + 1,)
        Node masses, finite and >= 0 (``m[N]``, the pin's, is irrelevant).
    g : float
        Gravity, > 0 (1 in the library's units).

    Returns
    -------
    float
        P (in units of M g l for masses in units of M).

    Examples
    --------
    The horizontal string of two links (P = 1/2, the paper's chi -> 1 limit):

    >>> available_energy_shape([1.0, 0.5, 0.0], [0.0, 0.0, 0.0], [0.25, 0.5, 0.25])
    0.5

    and the chain hanging straight down has nothing to release:

    >>> available_energy_shape([0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [0.25, 0.5, 0.25])
    0.0
    """
    x, y, h = _shape_arrays(x, y)
    m = V.float_array("m", m)
    if m.shape != x.shape:
        raise V.SnappingInputError(
            f"m must hold one mass per node, shape {x.shape} like x and y; got shape {m.shape}"
        )
    bad = np.nonzero(~(np.isfinite(m) & (m >= 0.0)))[0]
    if bad.size:
        i = int(bad[0])
        raise V.SnappingInputError(f"m[{i}]={float(m[i])!r} is out of range: node masses must be finite and >= 0")
    g = V.positive("g", g)
    s = np.zeros(x.size)
    s[:-1] = np.cumsum(h[::-1])[::-1]  # s_i = h_i + ... + h_{N-1}, s_N = 0
    return g * math.fsum(m * (s - (y - y[-1])))


def kappa_m0_shape(x, y) -> float:
    """Maximum discrete curvature of a chain shape (the kappa_m(0) of any start shape).

    At each interior node i (between link i-1, nodes i-1 -> i, and link i,
    nodes i -> i+1) the curvature is the turning angle |angle(d_{i-1}, d_i)| in
    [0, pi] divided by the mean (h_{i-1} + h_i)/2 of the two link lengths. For
    equal links 1/N this is |N (theta_{k+1} - theta_k)| of the paper's discrete
    curvature; for the catenary sampled at arclength 1/N (N even, a node at
    the vertex) it converges to :func:`kappa_m0` = 1/a as N^-2.

    Parameters
    ----------
    x, y : array_like, shape (N + 1,)
        Node positions (index 0 = free end, index N = pin).

    Returns
    -------
    float
        max_i kappa_i; 0.0 for a single link (N = 1, no joint).

    Examples
    --------
    A right-angle corner between two unit links:

    >>> round(kappa_m0_shape([1.0, 1.0, 0.0], [1.0, 0.0, 0.0]), 12)   # (pi/2) / 1
    1.570796326795
    """
    x, y, h = _shape_arrays(x, y)
    if x.size < 3:
        return 0.0
    dx, dy = np.diff(x), np.diff(y)
    cross = dx[:-1] * dy[1:] - dy[:-1] * dx[1:]
    dot = dx[:-1] * dx[1:] + dy[:-1] * dy[1:]
    turn = np.abs(np.arctan2(cross, dot))
    return float(np.max(turn / (0.5 * (h[:-1] + h[1:]))))




def shape_estimate(x, y, m, g: float = 1.0) -> dict:
    """The paper's estimates from any start shape and node masses (no simulation).

    The available energy P (:func:`available_energy_shape`), the initial maximum
    curvature kappa_m(0) (:func:`kappa_m0_shape`), the scales delta_kappa0 =
    (pi/2)/kappa_m(0) and delta_c = (1/2)(pi/kappa_m(0))^(4/3), and the whirling-rod
    peaks (:func:`whirling_rod`, eq. estimates) for each scale. The rod model is the
    paper's (a unit mass per length near the tip): for a chain whose mass per length
    near the free end differs from 1, or with a tip mass, it is that model applied to
    this shape's P and kappa_m(0), not a result for such chains.

    Parameters
    ----------
    x, y : array_like, shape (N + 1,)
        Node positions (index 0 the free end, N the held end).
    m : array_like, shape (N + 1,)
        Node masses (``m[N]``, the held end's, is irrelevant).
    g : float
        Gravity (the unit of P is then M g l).

    Returns
    -------
    dict
        ``P``, ``kappa_m0``, ``delta_kappa0``, ``delta_c`` and ``predictions``
        (``{"delta_kappa0": {"v", "a", "sigma"}, "delta_c": {...}}``).

    Examples
    --------
    The catenary of chi = 0.25 sampled finely reproduces the closed forms:

    >>> s = np.linspace(1.0, 0.0, 2001)                    # node arclengths, free end first
    >>> xs, ys = catenary_shape(s, 0.25)
    >>> m = np.full(2001, 1 / 2000); m[0] = m[-1] = 1 / 4000
    >>> e = shape_estimate(xs, ys, m)
    >>> round(e["P"], 6), round(available_energy(0.25), 6), round(e["kappa_m0"], 3), round(kappa_m0(0.25), 3)
    (0.254055, 0.254055, 26.11, 26.11)
    """
    P = available_energy_shape(x, y, m, g)
    k0 = kappa_m0_shape(x, y)
    if not k0 > 0.0:
        raise V.SnappingInputError("the start shape is straight (kappa_m(0) = 0): the curvature scales are undefined")
    scales = {"delta_kappa0": 0.5 * math.pi / k0, "delta_c": 0.5 * (math.pi / k0) ** (4.0 / 3.0)}
    preds = {k: whirling_rod(P, d) for k, d in scales.items()} if P > 0.0 else {}
    return {"P": P, "kappa_m0": k0, **scales, "predictions": preds}


