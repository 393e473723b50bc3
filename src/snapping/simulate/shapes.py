"""Initial shapes of a chain beyond the paper's level catenary.

* :func:`place_on_curve` puts the nodes of a chain with any link lengths ``h`` on
  a planar curve (a callable ``s -> (x, y)`` parametrised by arclength, or a
  polyline), walking from the pin so that every chord is exactly its link length
  (the generalisation of ``initial_state(..., chords="exact")`` to unequal links).
* :func:`catenary_between` is the catenary of a given length hanging between the
  pin and a second support at any position (unequal heights), as a curve
  parametrised by arclength from the pin.
* :func:`check_curve` validates node coordinates: equal lengths, finite values,
  no repeated consecutive nodes and no self-intersection.

Conventions of the package: nondimensional units, ``y`` grows downward (gravity
along +e2), the pin is at the origin, nodes are indexed 0 = free end ... N = pin
and link j joins nodes j and j + 1 with length ``h[j]``; arclength ``s`` is
measured from the pin.

Example
-------
>>> import numpy as np
>>> from snapping.simulate.shapes import catenary_between, place_on_curve, check_curve
>>> cat = catenary_between(0.5, 0.2)            # second support 0.2 lower than the pin
>>> x, y = place_on_curve(cat, np.full(8, 1 / 8))
>>> float(x[-1]), float(y[-1])                  # index N: the pin
(0.0, 0.0)
>>> bool(np.allclose(np.hypot(np.diff(x), np.diff(y)), 1 / 8, rtol=0, atol=1e-15))
True
>>> _ = check_curve(x, y)                       # a valid shape passes silently
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
from numba import njit
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from .. import _validate as V
from .. import estimates

__all__ = ["place_on_curve", "catenary_between", "Catenary", "check_curve"]

#: |curve(0)| may differ from the origin by this fraction of the length.
ORIGIN_RTOL = 1e-12
#: A polyline may be extended along its last tangent by this fraction of its length.
POLYLINE_EXTRAPOLATION = 0.01
#: Default evaluation limit of a callable curve, as a multiple of sum(h).
CALLABLE_S_MAX = 2.0


# =============================================================================
# place_on_curve
# =============================================================================
def _link_lengths(h) -> np.ndarray:
    h = V.float_array("h", h)
    if h.ndim != 1 or h.size < 1:
        raise V.SnappingInputError(
            f"h must be a 1-D array of N >= 1 link lengths; got shape {h.shape}"
        )
    bad = np.nonzero(~(np.isfinite(h) & (h > 0.0)))[0]
    if bad.size:
        j = int(bad[0])
        raise V.SnappingInputError(f"h[{j}]={float(h[j])!r} is out of range: link lengths must be finite and > 0")
    return h


def _scalar_curve(curve: Callable) -> Callable[[float], tuple[float, float]]:
    """Wrap a user callable: scalar float in, two finite floats out, or raise naming ``curve``."""

    def r(s: float) -> tuple[float, float]:
        out = curve(s)
        try:
            xv, yv = out
            xv = np.asarray(xv, dtype=float)
            yv = np.asarray(yv, dtype=float)
            if xv.size != 1 or yv.size != 1:
                raise ValueError
            xv, yv = float(xv.reshape(-1)[0]), float(yv.reshape(-1)[0])
        except (TypeError, ValueError):
            raise V.SnappingInputError(
                f"curve({s!r}) returned {V._short(out)}; a curve must return two real numbers (x, y)"
            ) from None
        if not (math.isfinite(xv) and math.isfinite(yv)):
            raise V.SnappingInputError(
                f"curve({s!r}) = ({xv!r}, {yv!r}) is not finite; the curve must be finite on [0, s_max]"
            )
        return xv, yv

    return r


def _polyline_curve(curve, s_max):
    """The cubic spline through a polyline on its cumulative chord length, extended
    linearly along the last tangent; returns (r, length, s_max)."""
    if len(curve) != 2:
        raise V.SnappingInputError(
            f"curve is a sequence of length {len(curve)}; give a callable s -> (x, y) or a polyline (xc, yc)"
        )
    xc = V.float_array("curve[0] (xc)", curve[0])
    yc = V.float_array("curve[1] (yc)", curve[1])
    if xc.ndim != 1 or xc.shape != yc.shape or xc.size < 2:
        raise V.SnappingInputError(
            f"curve polyline (xc, yc) must be two 1-D arrays of one length >= 2; got shapes {xc.shape}, {yc.shape}"
        )
    if not (np.all(np.isfinite(xc)) and np.all(np.isfinite(yc))):
        i = int(np.nonzero(~(np.isfinite(xc) & np.isfinite(yc)))[0][0])
        raise V.SnappingInputError(f"curve polyline point {i} = ({float(xc[i])!r}, {float(yc[i])!r}) is not finite")
    seg = np.hypot(np.diff(xc), np.diff(yc))
    if np.any(seg == 0.0):
        i = int(np.nonzero(seg == 0.0)[0][0])
        raise V.SnappingInputError(
            f"curve polyline points {i} and {i + 1} coincide at ({float(xc[i])!r}, {float(yc[i])!r}); consecutive points must differ"
        )
    t = np.concatenate([[0.0], np.cumsum(seg)])
    length = float(t[-1])
    _check_origin(xc[0], yc[0], length)
    cap = (1.0 + POLYLINE_EXTRAPOLATION) * length
    if s_max is None:
        s_max = cap
    else:
        s_max = V.real("s_max", s_max)
        if not 0.0 < s_max <= cap:
            raise V.SnappingInputError(
                f"s_max={s_max!r} is out of range for a polyline of length {length!r}: must lie in "
                f"(0, {cap!r}] (at most {POLYLINE_EXTRAPOLATION:.0%} linear extrapolation)"
            )
    xs, ys = CubicSpline(t, xc - xc[0]), CubicSpline(t, yc - yc[0])
    xe, ye = float(xs(length)), float(ys(length))
    tx, ty = float(xs(length, 1)), float(ys(length, 1))
    nt = math.hypot(tx, ty)
    if not nt > 0.0:  # pragma: no cover - a spline through distinct points has a nonzero end tangent
        raise V.SnappingInputError("curve polyline has a zero tangent at its end; cannot extrapolate")
    tx, ty = tx / nt, ty / nt

    def r(s: float) -> tuple[float, float]:
        if s <= length:
            return float(xs(s)), float(ys(s))
        return xe + (s - length) * tx, ye + (s - length) * ty

    return r, length, s_max


def _check_origin(x0: float, y0: float, length: float) -> None:
    tol = ORIGIN_RTOL * length
    if not math.hypot(x0, y0) <= tol:
        raise V.SnappingInputError(
            f"curve starts at ({x0!r}, {y0!r}); it must start at the pin, the origin (0, 0), "
            f"within {ORIGIN_RTOL:g} of its length ({tol:.3g})"
        )


def place_on_curve(curve, h, *, s_max: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Nodes of a chain with link lengths ``h`` on a planar curve, chords exact.

    Walking from the pin (arclength s = 0, the origin), each next node is the
    point of the curve beyond the previous node at chord distance exactly the
    link length: the first sign change of ``|r(s) - r_prev| - h`` on a grid of
    steps ``h/2`` in s, refined with ``brentq`` to ~1e-15 (so a curve that
    returns within a distance h inside half a link is not resolved). This is the
    ``chords="exact"`` placement of
    :func:`snapping.simulate.chain.initial_state` for any curve and unequal
    links. Chords are shorter than arcs, so the walk uses a little more than
    ``sum(h)`` of the curve (about ``sum(kappa^2 h^3)/24``).

    Parameters
    ----------
    curve : callable or (array_like, array_like)
        Either a callable ``curve(s) -> (x, y)`` taking a scalar arclength from
        the pin (it must also accept s slightly beyond the end of the chain,
        like the analytic catenary), or a polyline ``(xc, yc)`` starting at the
        pin, interpolated by a cubic spline
        (:class:`scipy.interpolate.CubicSpline`) on its cumulative chord length
        and extended linearly along its end tangent by at most 1 % of its length.
        ``curve(0)`` (or the first point) must be the origin within 1e-12 of the
        length. ``y`` grows downward.
    h : array_like, shape (N,)
        Link lengths, > 0, in the project's order: ``h[j]`` joins node j and
        node j + 1, so ``h[N - 1]`` is the link at the pin and ``h[0]`` the one
        at the free end.
    s_max : float, optional
        The largest curve parameter at which the curve is evaluated. Default for
        a callable: ``2 * sum(h)``; for a polyline: its length times 1.01 (a
        larger value raises).

    Returns
    -------
    x, y : ndarray, shape (N + 1,)
        Node positions, index 0 = free end, index N = the pin, exactly (0, 0);
        ``hypot(diff(x), diff(y)) == h`` to ~1e-15.

    Raises
    ------
    SnappingInputError
        ``h`` not a 1-D array of finite positive numbers; ``curve`` neither a
        callable nor a polyline, returning non-finite values, or not starting at
        the origin; ``s_max`` out of range; a chord that cannot be found before
        ``s_max`` (the curve is too short, or stays within a distance ``h[j]``).

    Examples
    --------
    A quarter circle of radius 1 from the origin, bending downward:

    >>> circle = lambda s: (math.sin(s), 1.0 - math.cos(s))
    >>> x, y = place_on_curve(circle, [0.3, 0.5, 0.4])
    >>> np.round(np.hypot(np.diff(x), np.diff(y)), 15).tolist()
    [0.3, 0.5, 0.4]
    >>> bool(np.allclose(np.hypot(x, y - 1.0), 1.0, atol=1e-15))   # on the circle
    True
    """
    h = _link_lengths(h)
    total = float(np.sum(h))
    if callable(curve):
        if s_max is None:
            s_max = CALLABLE_S_MAX * total
        else:
            s_max = V.positive("s_max", s_max)
        r = _scalar_curve(curve)
        _check_origin(*r(0.0), total)
    elif isinstance(curve, (tuple, list, np.ndarray)):
        r, _, s_max = _polyline_curve(curve, s_max)
    else:
        raise V.SnappingInputError(
            f"curve={V._short(curve)} is neither a callable s -> (x, y) nor a polyline (xc, yc)"
        )

    N = h.size
    xs = np.zeros(N + 1)
    ys = np.zeros(N + 1)
    s_prev = 0.0
    for k in range(1, N + 1):  # k-th node from the pin: array index N - k, link N - k
        j = N - k
        hj = float(h[j])
        x0, y0 = xs[k - 1], ys[k - 1]

        def f(sv, x0=x0, y0=y0, hj=hj):
            xv, yv = r(sv)
            return math.hypot(xv - x0, yv - y0) - hj

        # first sign change on the grid s_prev + i hj/2 (chord <= arc: a root lies at s >= s_prev + hj
        # for an arclength parameter; the grid also tolerates a parameter that is only near-arclength)
        lo = s_prev
        step = 0.5 * hj
        while True:
            hi = min(lo + step, s_max)
            if not hi > lo:
                raise V.SnappingInputError(
                    f"h[{j}]={hj!r}: no point of the curve at this chord distance from node {j + 1} "
                    f"(at curve parameter {s_prev!r}) before s_max={s_max!r}; the curve is too short "
                    f"for sum(h)={total!r} or stays within h[{j}] of that node"
                )
            f_hi = f(hi)
            if f_hi >= 0.0:
                break
            lo = hi
        s_new = brentq(f, lo, hi, xtol=1e-16, rtol=1e-15, maxiter=200)
        xs[k], ys[k] = r(s_new)
        s_prev = s_new
    xs[0] = 0.0
    ys[0] = 0.0
    # walking from the pin: reverse into the project's node order (index 0 = free end)
    return xs[::-1].copy(), ys[::-1].copy()


# =============================================================================
# catenary_between
# =============================================================================
@dataclass(frozen=True)
class Catenary:
    """A catenary of length ``length`` from the pin at the origin to (dx, dy), y down.

    With the signed arclength ``sigma = s + sigma0`` measured from the vertex
    (the lowest point, which may lie beyond either support), the curve is

        x(s) = a [asinh(sigma/a) - asinh(sigma0/a)],
        y(s) = sqrt(a^2 + sigma0^2) - sqrt(a^2 + sigma^2),

    its curvature is ``a / (a^2 + sigma^2)`` and, as a graph, it solves
    ``y'' = -sqrt(1 + y'^2)/a``. Call it with arclengths ``s`` from the pin; the
    same analytic curve is returned for s in [-length, 2 length] (beyond the
    supports, as an exact-chord walk needs).

    Attributes
    ----------
    dx, dy, length : float
        The second support (dy > 0: lower than the pin) and the length.
    a : float
        Catenary parameter (radius of curvature at the vertex).
    sigma0 : float
        Signed arclength from the vertex to the pin (< 0: the vertex lies
        towards the second support); the vertex is at ``s = -sigma0``.
    x_vertex, y_vertex : float
        Position of the vertex.
    """

    dx: float
    dy: float
    length: float
    a: float
    sigma0: float
    x_vertex: float
    y_vertex: float

    def _s(self, s) -> np.ndarray:
        s = V.float_array("s", s)
        L = self.length
        if s.size and (not np.all(np.isfinite(s)) or s.min() < -L or s.max() > 2.0 * L):
            raise V.SnappingInputError(
                f"s must lie in [-length, 2 length] = [{-L!r}, {2 * L!r}]; got values in [{s.min()!r}, {s.max()!r}]"
            )
        return s

    def __call__(self, s):
        """Position (x, y) at arclength ``s`` from the pin (scalar -> floats, array -> arrays)."""
        a, s0, L = self.a, self.sigma0, self.length
        if type(s) is float and -L <= s <= 2.0 * L:  # fast path for the exact-chord walk
            sig = s + s0
            x = a * (math.asinh(sig / a) - math.asinh(s0 / a))
            y = -s * (2.0 * s0 + s) / (math.sqrt(a * a + s0 * s0) + math.sqrt(a * a + sig * sig))
            return x, y
        scalar = np.ndim(s) == 0
        s = self._s(s)
        a, s0 = self.a, self.sigma0
        sig = s + s0
        x = a * (np.arcsinh(sig / a) - math.asinh(s0 / a))
        # sqrt(a^2+s0^2) - sqrt(a^2+sig^2) = (s0^2 - sig^2)/(...) = -s (2 s0 + s)/(...): no cancellation
        y = -s * (2.0 * s0 + s) / (math.sqrt(a * a + s0 * s0) + np.sqrt(a * a + sig * sig))
        if scalar:
            return float(x), float(y)
        return x, y

    def curvature(self, s):
        """Curvature a/(a^2 + sigma^2) at arclength ``s`` from the pin."""
        s = self._s(s)
        sig = s + self.sigma0
        return self.a / (self.a * self.a + sig * sig)


def catenary_between(dx: float, dy: float, length: float = 1.0) -> Catenary:
    """The catenary of length ``length`` hanging from the pin (origin) to a support at (dx, dy).

    ``y`` grows downward, so the curve sags towards +y and ``dy > 0`` means the
    second support is lower than the pin. The parameter ``a`` solves
    ``sqrt(L^2 - dy^2) = 2 a sinh(dx/(2a))`` (with ``L = length``), written as the
    level problem of :func:`snapping.estimates.catenary_parameter` for the
    effective separation ``chi = dx / sqrt(L^2 - dy^2)``, robust for tiny and
    near-taut separations. With ``b = dx/(2a)`` the vertex is at signed
    arclength ``-sigma0`` from the pin, ``sigma0 = -(L + dy coth b)/2``, and at
    ``x = dx/2 + a asinh(dy/sqrt(L^2 - dy^2))``. For ``dy = 0`` and ``L = 1`` the
    curve is the paper's initial catenary :func:`snapping.estimates.catenary_shape`
    with ``chi = dx``.

    Parameters
    ----------
    dx : float
        Horizontal separation of the supports, > 0.
    dy : float
        Vertical offset of the second support (positive: lower, y down).
    length : float
        Length of the catenary, > 0, with ``sqrt(dx^2 + dy^2) < length``.

    Returns
    -------
    Catenary
        A callable ``s -> (x, y)`` parametrised by arclength from the pin, with
        ``(x, y)(0) = (0, 0)`` and ``(x, y)(length) = (dx, dy)``.

    Raises
    ------
    SnappingInputError
        ``dx <= 0``, ``length <= 0``, non-finite input, or supports at least
        ``length`` apart (no slack to hang).

    Examples
    --------
    >>> cat = catenary_between(0.6, 0.3)
    >>> x, y = cat(1.0)                            # the free end is at the second support
    >>> round(x, 12), round(y, 12)
    (0.6, 0.3)
    >>> lev = catenary_between(0.25, 0.0)           # the paper's catenary chi = 0.25
    >>> round(lev.a, 6), round(lev.x_vertex, 12), lev.sigma0
    (0.038299, 0.125, -0.5)
    """
    dx = V.positive("dx", dx)
    dy = V.real("dy", dy)
    L = V.positive("length", length)
    ady = abs(dy)
    taut = (
        f"dx={dx!r}, dy={dy!r}: the supports must be closer than the length, "
        f"sqrt(dx^2 + dy^2) = {math.hypot(dx, dy)!r} < length={L!r}"
    )
    if not ady < L:
        raise V.SnappingInputError(taut)
    Leff = math.sqrt((L - ady) * (L + ady))  # sqrt(L^2 - dy^2) without cancellation
    chi = dx / Leff
    if not 0.0 < chi < 1.0:
        raise V.SnappingInputError(taut)
    if chi < estimates.CHI_MIN:
        raise V.SnappingInputError(f"dx={dx!r} is out of range: must be >= {estimates.CHI_MIN:g} sqrt(length^2 - "
                                   f"dy^2) = {estimates.CHI_MIN * Leff:.3g} (a narrower catenary is a folded string)")
    a = Leff * estimates.catenary_parameter(chi)
    b = dx / (2.0 * a)
    sigma0 = -0.5 * (L + dy / math.tanh(b))
    x_v = 0.5 * dx + a * math.asinh(dy / Leff)
    y_v = math.sqrt(a * a + sigma0 * sigma0) - a
    return Catenary(dx=dx, dy=dy, length=L, a=a, sigma0=sigma0, x_vertex=x_v, y_vertex=y_v)


# =============================================================================
# check_curve
# =============================================================================
@njit(cache=True, inline="always")
def _orient(ax, ay, bx, by, cx, cy):
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@njit(cache=True, inline="always")
def _between(a, b, p):
    return min(a, b) <= p <= max(a, b)


@njit(cache=True)
def _segments_meet(ax, ay, bx, by, cx, cy, dx, dy):
    """Closed segments ab and cd share a point (crossing or touching)."""
    d1 = _orient(cx, cy, dx, dy, ax, ay)
    d2 = _orient(cx, cy, dx, dy, bx, by)
    if (d1 > 0.0 and d2 > 0.0) or (d1 < 0.0 and d2 < 0.0):
        return False  # a and b strictly on one side of line cd
    d3 = _orient(ax, ay, bx, by, cx, cy)
    d4 = _orient(ax, ay, bx, by, dx, dy)
    if (d3 > 0.0 and d4 > 0.0) or (d3 < 0.0 and d4 < 0.0):
        return False
    if d1 != 0.0 and d2 != 0.0 and d3 != 0.0 and d4 != 0.0:
        return True  # proper crossing
    # a touching or collinear case: an endpoint on the other segment (bounding boxes on both axes)
    if d1 == 0.0 and _between(cx, dx, ax) and _between(cy, dy, ay):
        return True
    if d2 == 0.0 and _between(cx, dx, bx) and _between(cy, dy, by):
        return True
    if d3 == 0.0 and _between(ax, bx, cx) and _between(ay, by, cy):
        return True
    if d4 == 0.0 and _between(ax, bx, dx) and _between(ay, by, dy):
        return True
    return False


@njit(cache=True)
def _first_intersection(x, y):
    """A pair (i, j), i < j - 1, of links that meet, or (-1, -1).

    Sweep and prune: links sorted by their lower bound along the axis of larger
    extent (copied into contiguous arrays in that order); a link is tested only
    against those whose interval on that axis overlaps its own and whose
    bounding boxes overlap on the other axis. O(N log N + candidate pairs),
    O(N^2) at worst.
    """
    n = x.size - 1
    if (x.max() - x.min()) >= (y.max() - y.min()):
        u, v = x, y
    else:
        u, v = y, x
    lo0 = np.empty(n)
    for k in range(n):
        lo0[k] = min(u[k], u[k + 1])
    order = np.argsort(lo0, kind="mergesort")
    ulo = np.empty(n)
    uhi = np.empty(n)
    vlo = np.empty(n)
    vhi = np.empty(n)
    au = np.empty(n)
    av = np.empty(n)
    bu = np.empty(n)
    bv = np.empty(n)
    for p in range(n):
        k = order[p]
        au[p], av[p], bu[p], bv[p] = u[k], v[k], u[k + 1], v[k + 1]
        ulo[p] = lo0[k]
        uhi[p] = max(u[k], u[k + 1])
        vlo[p] = min(v[k], v[k + 1])
        vhi[p] = max(v[k], v[k + 1])
    for p in range(n):
        i = order[p]
        ui, vli, vhi_i = uhi[p], vlo[p], vhi[p]
        pau, pav, pbu, pbv = au[p], av[p], bu[p], bv[p]
        qend = np.searchsorted(ulo, ui, side="right")  # links q > p with ulo[q] <= uhi[p]
        # branch-free filter (vectorisable): bounding boxes overlap on v, neither segment strictly on
        # one side of the other's line, not adjacent; a superset of the meeting pairs
        hit = False
        for q in range(p + 1, qend):
            d1 = _orient(au[q], av[q], bu[q], bv[q], pau, pav)
            d2 = _orient(au[q], av[q], bu[q], bv[q], pbu, pbv)
            d3 = _orient(pau, pav, pbu, pbv, au[q], av[q])
            d4 = _orient(pau, pav, pbu, pbv, bu[q], bv[q])
            hit |= (
                (vlo[q] <= vhi_i) & (vhi[q] >= vli) & (d1 * d2 <= 0.0) & (d3 * d4 <= 0.0)
                & (abs(order[q] - i) != 1)
            )
        if hit:  # confirm exactly (touching and collinear cases) and name the pair
            for q in range(p + 1, qend):
                j = order[q]
                if vlo[q] > vhi_i or vhi[q] < vli or i - j == 1 or j - i == 1:
                    continue
                if _segments_meet(pau, pav, pbu, pbv, au[q], av[q], bu[q], bv[q]):
                    if i < j:
                        return i, j
                    return j, i
    return -1, -1


def check_curve(x, y, *, name: str = "shape") -> tuple[np.ndarray, np.ndarray]:
    """Validate node coordinates of a chain shape; return them as float arrays.

    Checks, in order: ``x`` and ``y`` are 1-D of one length N + 1 >= 2 and
    finite; no two consecutive nodes coincide; no link folds back onto the
    previous one (consecutive links may share only their common node); no two
    non-adjacent links (link j joins nodes j and j + 1) cross or touch. The last
    check is a compiled sweep over bounding boxes (O(N log N) for usual shapes,
    O(N^2) at worst).

    Parameters
    ----------
    x, y : array_like, shape (N + 1,)
        Node coordinates (index 0 = free end, index N = pin).
    name : str
        What the coordinates are, for the error message.

    Returns
    -------
    x, y : ndarray
        The coordinates as float arrays.

    Raises
    ------
    SnappingInputError
        Naming ``name``, the offending node or link index pair, and what is allowed.

    Examples
    --------
    >>> x, y = check_curve([1.0, 0.5, 0.0], [0.0, 0.5, 0.0])
    >>> check_curve([0.0, 1.0, 1.0, 0.0, 0.5], [0.5, 0.5, 0.0, 0.0, 1.0])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: shape: links 0 and 3 (nodes 0-1 and 3-4) intersect; ...
    """
    name = str(name)
    x = V.float_array(f"{name} x", x)
    y = V.float_array(f"{name} y", y)
    if x.ndim != 1 or x.shape != y.shape or x.size < 2:
        raise V.SnappingInputError(
            f"{name}: x and y must be 1-D arrays of one length N + 1 >= 2; got shapes {x.shape} and {y.shape}"
        )
    finite = np.isfinite(x) & np.isfinite(y)
    if not finite.all():
        i = int(np.nonzero(~finite)[0][0])
        raise V.SnappingInputError(f"{name}: node {i} = ({float(x[i])!r}, {float(y[i])!r}) is not finite; coordinates must be finite")
    dxs, dys = np.diff(x), np.diff(y)
    same = (dxs == 0.0) & (dys == 0.0)
    if same.any():
        i = int(np.nonzero(same)[0][0])
        raise V.SnappingInputError(
            f"{name}: nodes {i} and {i + 1} coincide at ({float(x[i])!r}, {float(y[i])!r}); consecutive nodes must be distinct "
            f"(every link has a positive length)"
        )
    if x.size >= 3:
        cross = dxs[:-1] * dys[1:] - dys[:-1] * dxs[1:]
        dot = dxs[:-1] * dxs[1:] + dys[:-1] * dys[1:]
        back = (cross == 0.0) & (dot < 0.0)
        if back.any():
            i = int(np.nonzero(back)[0][0])
            raise V.SnappingInputError(
                f"{name}: links {i} and {i + 1} fold back onto each other at node {i + 1} (turning angle pi); "
                f"consecutive links may share only their common node"
            )
    if x.size >= 4:
        i, j = _first_intersection(np.ascontiguousarray(x), np.ascontiguousarray(y))
        if i >= 0:
            raise V.SnappingInputError(
                f"{name}: links {i} and {j} (nodes {i}-{i + 1} and {j}-{j + 1}) intersect; a chain shape must "
                f"not cross or touch itself: only consecutive links may share a point (their common node)"
            )
    return x, y
