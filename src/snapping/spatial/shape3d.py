"""A start curve in space: read from a file, nodes placed on it with exact chords, checked.

* :func:`read_shape3d`: points ``(x, y, z)`` from a CSV file of 3 columns (a header line is
  skipped; 2 columns: a planar curve, z = 0) or a netCDF file (variables ``x``, ``y``, ``z``),
  listed from the held end, translated so that the first point is the origin;
* :func:`place_on_curve3d`: the chain's nodes on the cubic splines through the points (on
  their cumulative chord length, extended along the end tangent by 1 %), each node at chord
  distance exactly its link's length from the previous one (as the planar
  :func:`snapping.simulate.shapes.place_on_curve`); a curve too short for the chain is refused;
* :func:`check_no_crossing`: no two links that are not neighbours come closer than
  :data:`CROSS_RTOL` of the shortest link (in space two curves meet only by accident: a
  curve that touches itself, e.g. a planar one that crosses, is refused; a near miss is not),
  and no link folds back onto its neighbour.

Example
-------
>>> import numpy as np
>>> from snapping.spatial.shape3d import place_on_curve3d
>>> s = np.linspace(0.0, 1.5, 301)
>>> pts = np.column_stack([0.2 * np.sin(s), s, 0.2 * (1 - np.cos(s))])   # a helix-like arc
>>> r = place_on_curve3d(pts, np.full(10, 0.1))
>>> bool(np.allclose(np.linalg.norm(np.diff(r, axis=0), axis=1), 0.1, rtol=0, atol=1e-14)), r[-1].tolist()
(True, [0.0, 0.0, 0.0])
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from .. import _validate as V

__all__ = ["read_shape3d", "place_on_curve3d", "check_no_crossing", "is_3d_shape", "CROSS_RTOL"]

#: two links that are not neighbours closer than this fraction of the shortest link: the curve crosses itself
CROSS_RTOL = 1e-6
#: how far a polyline is extended along its end tangent, as a fraction of its length
EXTRAPOLATION = 0.01


def is_3d_shape(path) -> bool:
    """Whether the shape file ``path`` holds a curve in space (a CSV of 3 columns, a netCDF
    file with ``z``): what makes ``snapping simulate --shape`` a 3D run. False when it
    cannot be read (the reader of the run says why)."""
    import os

    try:
        if not os.path.isfile(path):  # (a directory, a FIFO, a device: never opened here)
            return False
        if str(path).endswith((".nc", ".nc4", ".cdf")):
            from ..simulate._netcdf import open_netcdf

            return "z" in open_netcdf(str(path)).variables
        with open(path, encoding="utf-8", errors="replace") as f:
            for line in f:
                line = line.split("#")[0].strip()
                if line:
                    return len(line.split(",")) == 3
    except Exception:  # noqa: BLE001 - unreadable: the planar reader names the problem
        return False
    return False


def read_shape3d(path) -> np.ndarray:
    """Points (n, 3) of a start curve in space from ``path`` (see the module)."""
    from .._files import check_input

    p = check_input(path, name="shape")
    if p.endswith((".nc", ".nc4", ".cdf")):
        from ..simulate._netcdf import open_netcdf

        ds = open_netcdf(p)
        if not {"x", "y", "z"} <= set(map(str, ds.variables)):
            raise V.SnappingInputError(f"shape={p!r}: a 3D netCDF shape file needs variables x, y and z; it has "
                                       f"{sorted(map(str, ds.variables))[:6]}")
        a = np.column_stack([np.asarray(ds[k].values, dtype=float).ravel() for k in ("x", "y", "z")])
    else:
        import warnings

        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                a = np.genfromtxt(p, delimiter=",", dtype=float, comments="#")
        except (OSError, ValueError) as exc:
            first = (str(exc).strip().splitlines() or [""])[-1][:160]
            raise V.SnappingInputError(f"shape={p!r}: cannot read it as CSV of 3 columns x, y, z ({first})") from None
        a = np.atleast_2d(a)
        if a.ndim != 2 or a.shape[1] not in (2, 3) or a.shape[0] == 0:
            raise V.SnappingInputError(f"shape={p!r}: a 3D start needs 3 comma-separated columns x, y, z (2: a planar "
                                       f"curve); got {a.shape[1] if a.ndim == 2 else 0} columns")
        if np.all(np.isnan(a[0])):
            a = a[1:]
        bad = np.flatnonzero(np.any(np.isnan(a), axis=1))
        if bad.size:
            raise V.SnappingInputError(f"shape={p!r}: data row {int(bad[0]) + 1} is not {a.shape[1]} numbers (only "
                                       f"the first line may be a header)")
        if a.shape[1] == 2:
            a = np.column_stack([a, np.zeros(a.shape[0])])
    if a.shape[0] < 2 or not np.all(np.isfinite(a)):
        raise V.SnappingInputError(f"shape={p!r}: needs at least 2 finite points (x, y, z); got {a.shape[0]}")
    return a - a[0]


def place_on_curve3d(points, h, *, name: str = "curve") -> np.ndarray:
    """Node positions ((N + 1, 3), row N the held end at the origin) of links ``h`` along the
    curve through ``points`` ((n, 3), from the held end), chords exact to ~1e-15."""
    pts = np.asarray(V.float_array(name, points), dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or pts.shape[0] < 2:
        raise V.SnappingInputError(f"{name}: points must be an array of 3 columns x, y, z and at least 2 rows; got "
                                   f"shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        i = int(np.flatnonzero(~np.all(np.isfinite(pts), axis=1))[0])
        raise V.SnappingInputError(f"{name}: point {i} = {pts[i].tolist()} is not finite")
    h = np.asarray(h, dtype=float)
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if np.any(seg == 0.0):
        i = int(np.flatnonzero(seg == 0.0)[0])
        raise V.SnappingInputError(f"{name}: points {i} and {i + 1} coincide at {pts[i].tolist()}; consecutive points "
                                   f"must differ")
    s = np.concatenate([[0.0], np.cumsum(seg)])
    length = float(s[-1])
    if np.linalg.norm(pts[0]) > 1e-12 * length:
        raise V.SnappingInputError(f"{name}: the curve starts at {pts[0].tolist()}; it must start at the held end, "
                                   f"the origin")
    total = float(h.sum())
    cap = (1.0 + EXTRAPOLATION) * length
    if total > cap:
        raise V.SnappingInputError(f"{name}: the curve is {length:.6g} long (polyline), too short for the chain of "
                                   f"length {total:.6g}: it must be at least as long as the chain")
    sp = CubicSpline(s, pts - pts[0]) if pts.shape[0] > 2 else None
    end = sp(length) if sp is not None else pts[-1] - pts[0]
    tan = sp(length, 1) if sp is not None else (pts[-1] - pts[0]) / length
    tan = tan / np.linalg.norm(tan)

    def r(v):
        if v <= length:
            return sp(v) if sp is not None else (pts[-1] - pts[0]) * (v / length)
        return end + (v - length) * tan

    N = h.size
    out = np.zeros((N + 1, 3))
    s_prev = 0.0
    for k in range(1, N + 1):  # k-th node from the held end: row N - k, link N - k
        j = N - k
        hj = float(h[j])
        prev = out[N - k + 1]

        def f(v, prev=prev, hj=hj):
            return float(np.linalg.norm(r(v) - prev)) - hj

        lo, step = s_prev, 0.5 * hj
        while True:
            hi = min(lo + step, cap)
            if not hi > lo:
                raise V.SnappingInputError(f"{name}: no point of the curve at chord distance h[{j}]={hj:.6g} from node "
                                           f"{j + 1}: the curve ({length:.6g} long) is too short for the chain "
                                           f"(length {total:.6g}) or stays within a link of that node")
            if f(hi) >= 0.0:
                break
            lo = hi
        s_prev = brentq(f, lo, hi, xtol=1e-16, rtol=1e-15, maxiter=200)
        out[N - k] = r(s_prev)
    out[N] = 0.0
    return out


@njit(cache=True)
def _segment_distance(p0, p1, q0, q1):
    """The distance between segments p0-p1 and q0-q1 (closest points, clamped; Ericson,
    Real-Time Collision Detection, 5.1.9)."""
    d1 = p1 - p0
    d2 = q1 - q0
    rr = p0 - q0
    a = d1 @ d1
    e = d2 @ d2
    f = d2 @ rr
    c = d1 @ rr
    b = d1 @ d2
    den = a * e - b * b
    s = min(1.0, max(0.0, (b * f - c * e) / den)) if den > 1e-300 else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        t = 0.0
        s = min(1.0, max(0.0, -c / a))
    elif t > 1.0:
        t = 1.0
        s = min(1.0, max(0.0, (b - c) / a))
    d = (p0 + s * d1) - (q0 + t * d2)
    return math.sqrt(d @ d)


@njit(cache=True)
def _first_close_pair(r, tol):
    """A pair (i, j), j > i + 1, of links closer than tol, or (-1, -1): links sorted by their
    smallest x, each tested against those whose x-range (widened by tol) overlaps its own
    and whose y and z ranges do too."""
    n = r.shape[0] - 1
    lo = np.empty((n, 3))
    hi = np.empty((n, 3))
    for k in range(n):
        for c in range(3):
            lo[k, c] = min(r[k, c], r[k + 1, c]) - tol
            hi[k, c] = max(r[k, c], r[k + 1, c]) + tol
    order = np.argsort(lo[:, 0], kind="mergesort")
    for p in range(n):
        i = order[p]
        for q in range(p + 1, n):
            j = order[q]
            if lo[j, 0] > hi[i, 0]:
                break
            if abs(i - j) <= 1 or lo[j, 1] > hi[i, 1] or hi[j, 1] < lo[i, 1] or lo[j, 2] > hi[i, 2] \
                    or hi[j, 2] < lo[i, 2]:
                continue
            if _segment_distance(r[i], r[i + 1], r[j], r[j + 1]) < tol:
                return min(i, j), max(i, j)
    return -1, -1


def check_no_crossing(r, *, name: str = "shape") -> None:
    """SnappingInputError when the chain ``r`` ((N + 1, 3)) crosses or touches itself (see the module)."""
    r = np.ascontiguousarray(r, dtype=float)
    d = np.diff(r, axis=0)
    lens = np.linalg.norm(d, axis=1)
    if r.shape[0] > 2:
        cos = np.sum(d[1:] * d[:-1], axis=1) / (lens[1:] * lens[:-1])
        if np.any(cos <= -1.0 + 1e-12):
            j = int(np.flatnonzero(cos <= -1.0 + 1e-12)[0])
            raise V.SnappingInputError(f"{name}: link {j + 1} folds back onto link {j} (the chain crosses itself)")
    i, j = _first_close_pair(r, CROSS_RTOL * float(lens.min()))
    if i >= 0:
        raise V.SnappingInputError(f"{name}: links {i} and {j} (nodes {i}-{i + 1} and {j}-{j + 1}) meet: the start "
                                   f"crosses itself (closer than {CROSS_RTOL:g} of a link)")
