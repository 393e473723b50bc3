"""The exact-chord placement of a chain on the paper's catenary, every node at once.

:func:`place_on_catenary` puts the N + 1 nodes of a chain with any link lengths ``h`` on the
catenary of :meth:`snapping.simulate.Problem.catenary` (the paper's formula, chords exactly
``h_j``), the same points as the node-by-node walk of
:func:`snapping.simulate.shapes.place_on_curve` (a ``brentq`` root per node, Python calls of
the curve: 1.4 s of the fly line's 10-12 s design answer at chi 0.1, 8,779 roots) to round-off:
the arclengths of all nodes solve ``|r(s_k) - r(s_{k-1})| = h_k`` together by Newton's method
(the Jacobian is lower bidiagonal: one forward recurrence per iteration), the curve and its
tangent evaluated on all nodes at once with numpy.

The catenary is convex with its tangent angle in (-pi/2, pi/2), so the chord from a node grows
with the arclength beyond it while its tangent turns by less than pi/2: a node whose root lies
within 1.5 links of the previous node along the curve, over which the tangent turns by less than
pi/2, has the one root there, the one the walk finds (its grid of half links brackets it); any
other placement is left to the walk. Starting from
the arcs (``s_k`` = the sum of the links from the pin; a chord is shorter than its arc by
about ``kappa^2 h^3 / 24``), the iteration converges in 3-5 steps. It returns ``None`` where
it does not converge (or a node runs past ``s_max``, or a chord stops growing along the
curve), and the caller falls back to the walk, which raises the walk's errors.

>>> import numpy as np
>>> from snapping import estimates
>>> chi = 0.25
>>> a = estimates.catenary_parameter(chi)
>>> x, y = place_on_catenary(chi, a, 1.0, np.full(50, 1 / 50))
>>> bool(np.allclose(np.hypot(np.diff(x), np.diff(y)), 1 / 50, rtol=0, atol=1e-15))
True
>>> float(x[-1]), float(y[-1])
(0.0, 0.0)
>>> place_on_catenary(chi, a, 1.0, np.full(8, 1 / 8)) is None   # coarse links: left to the walk
True
"""

from __future__ import annotations

import math
from itertools import accumulate

import numpy as np

__all__ = ["place_on_catenary", "MAX_ITER", "RESIDUAL_EPS"]

#: at most this many Newton iterations (3-5 are needed from the arcs)
MAX_ITER = 30
#: converged when every chord is within this many round-offs of the chain's length (``|F| <= 8 eps L``)
RESIDUAL_EPS = 8.0


def _xy(s, chi, a, L):
    """The catenary at arclengths ``s`` from the pin (``chain._catenary_xy``'s formula, times L)."""
    u = s / L - 0.5
    return L * (a * np.arcsinh(u / a) + 0.5 * chi), L * (math.sqrt(a * a + 0.25) - np.sqrt(a * a + u * u))


def place_on_catenary(chi: float, a: float, L: float, h, *, s_max: float | None = None):
    """Nodes of the chain with links ``h`` (project order: ``h[0]`` at the free end) on the
    paper's catenary of separation ``chi``, parameter ``a`` (:func:`snapping.estimates.catenary_parameter`)
    and length ``L``, chords exact; ``(x, y)`` with index 0 the free end and index N the pin,
    exactly (0, 0); ``None`` where the Newton iteration does not converge (the caller walks the
    curve instead: :func:`snapping.simulate.shapes.place_on_curve`). ``s_max``: the largest
    arclength a node may take (default ``2 sum(h)``, the walk's)."""
    h = np.asarray(h, dtype=float)
    hp = h[::-1]  # from the pin: hp[k - 1] joins node k - 1 and node k (node 0 = the pin)
    total = float(np.sum(h))
    s_max = 2.0 * total if s_max is None else float(s_max)
    s = np.cumsum(hp)  # the arcs: a lower bound of every node's arclength
    # converged: every chord within a few round-offs of the positions' size (|F| ~ eps L is the floor)
    ftol = RESIDUAL_EPS * np.finfo(float).eps * max(L, total)
    for _ in range(MAX_ITER):
        x, y = _xy(s, chi, a, L)
        xp = np.concatenate([[0.0], x[:-1]])  # the previous node; the pin exactly at the origin
        yp = np.concatenate([[0.0], y[:-1]])
        dx, dy = x - xp, y - yp
        c = np.hypot(dx, dy)
        if not np.all(c > 0.0):
            return None
        F = c - hp
        if float(np.max(np.abs(F))) <= ftol:
            break
        # the unit tangent at every node (d/ds of _xy): (a, -u)/sqrt(a^2 + u^2)
        u = s / L - 0.5
        w = 1.0 / np.sqrt(a * a + u * u)
        tx, ty = a * w, -u * w
        d = (dx * tx + dy * ty) / c  # dF_k/ds_k: the chord grows along the curve
        e = np.concatenate([[0.0], (dx[1:] * tx[:-1] + dy[1:] * ty[:-1]) / c[1:]])  # -dF_k/ds_{k-1}
        if not np.all(d > 0.0):
            return None
        ra, rb = (-F / d).tolist(), (e / d).tolist()
        # the lower-bidiagonal Newton step: delta_k = ra_k + rb_k delta_{k-1} (rb_1 = 0: the pin is fixed)
        delta = np.fromiter(accumulate(zip(ra[1:], rb[1:]), lambda dk, p: p[0] + p[1] * dk, initial=ra[0]),
                            float, len(ra))
        s = s + delta
        if not (np.all(np.isfinite(s)) and s[-1] <= s_max and s[0] > 0.0 and np.all(np.diff(s) > 0.0)):
            return None
    else:
        return None
    # the walk's root: on [s_{k-1}, s_{k-1} + 1.5 h_k] (its grid of h/2 up to the root) the tangent turns
    # by less than pi/2, so the chord from node k - 1 grows there and has this one root
    sp = np.concatenate([[0.0], s[:-1]])
    reach = sp + 1.5 * hp
    turn = np.abs(np.arctan((reach / L - 0.5) / a) - np.arctan((sp / L - 0.5) / a))
    if not (np.all(s <= reach) and float(reach[-1]) <= s_max and np.all(turn < 0.5 * math.pi)):
        return None
    x, y = _xy(s, chi, a, L)
    xs = np.concatenate([[0.0], x])
    ys = np.concatenate([[0.0], y])
    return xs[::-1].copy(), ys[::-1].copy()
