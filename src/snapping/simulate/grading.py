"""Graded chains: link lengths that are fine where the snap happens and coarse elsewhere.

The snap lives in a boundary layer at the free end, and before that the fold travels
from the bottom of the catenary (arclength 1/2 from the held end) to the free end,
tightening as it goes. A uniform chain refines everywhere; a graded one refines along
the fold's path only:

* :func:`fold_following`: along the fold's path (distance x from the free end below
  1/2 + ``margin``) the links are a fraction ``frac`` of the fold's radius of curvature
  when it passes there, ``R(x) = a (2x)^(1/4)`` (``a`` the catenary parameter, the radius
  at the bottom, and the exponent from the fold's evolution: the fold is at
  ``x = (1/2)(tau/t*)^(2/3)`` when its length scale is ``a (tau/t*)^(1/6)``, see
  :func:`snapping.estimates.delta_crude`); towards the free end they shrink as
  ``h_min + gamma x``; the held arm is at most ``h_max``, reached with slope ``gamma``
  (no kinks in the grading where the chain is under tension);
* :func:`tip_graded`: fine only near the free end (``h_min + gamma x`` up to ``h_max``),
  for comparison.

Both return link lengths ``h`` with index 0 at the free end (the simulator's order),
summing to exactly 1: the nodes are the equal divisions of the link-count function
``n(x) = int_0^x dx'/h(x')``, so the spacing follows the target ``h(x)`` smoothly.
Masses are lumped from them consistently by :meth:`snapping.simulate.problem.Links.from_density`.

Example
-------
>>> from snapping.simulate import grading
>>> h = grading.fold_following(0.25, frac=0.02, h_min=2e-6, h_max=2e-3)
>>> h.size, round(float(h.sum()), 15), bool(h[0] < 1e-5 < h.max() <= 2e-3)
(1237, 1.0, True)
>>> bool((grading.tip_graded(1e-3, 1e-3) == 1e-3).all())      # constant spacing: the uniform chain
True
"""

from __future__ import annotations

import math

import numpy as np

from .. import _validate as V
from .. import estimates

__all__ = ["fold_following", "tip_graded", "from_spacing", "GRADINGS"]

#: samples of the spacing function (geometric towards the free end)
SAMPLES = 40_000
#: at most this many links (the chain's memory and run time grow with it)
MAX_LINKS = 5_000_000


def from_spacing(spacing, h_min: float) -> np.ndarray:
    """Link lengths (index 0 at the free end, sum 1) following the spacing function
    ``spacing(x)`` of the distance x from the free end (vectorised, values >= ``h_min``).
    A constant spacing 1/N gives exactly N links of 1/N."""
    h_min = V.positive("h_min", h_min)
    x = np.unique(np.concatenate([[0.0], np.geomspace(max(h_min * 1e-3, 1e-15), 1.0, SAMPLES)]))
    h = np.asarray(spacing(x), dtype=float)
    if not np.all(np.isfinite(h) & (h > 0.0)):
        raise V.SnappingInputError("the spacing of the grading must be finite and > 0 everywhere")
    if np.all(h == h[0]):
        N = int(math.ceil(1.0 / h[0] - 1e-9))
        return np.full(N, 1.0 / N)
    n = np.concatenate([[0.0], np.cumsum(0.5 * (1.0 / h[1:] + 1.0 / h[:-1]) * np.diff(x))])
    N = int(math.ceil(n[-1]))
    if N > MAX_LINKS:
        raise V.SnappingInputError(f"the grading would have {N} links (at most {MAX_LINKS}): coarsen it")
    xs = np.interp(np.linspace(0.0, n[-1], N + 1), n, x)
    xs[0], xs[-1] = 0.0, 1.0
    return np.diff(xs)


def fold_following(chi: float, *, frac: float = 0.01, h_min: float = 1e-6, h_max: float = 1e-3,
                   gamma: float = 0.1, margin: float = 0.1) -> np.ndarray:
    """Links following the fold of the catenary of separation ``chi`` (see the module).

    Parameters
    ----------
    chi : float
        End separation of the catenary start, in (0, 1).
    frac : float
        Link length along the fold's path, as a fraction of its radius of curvature there.
    h_min : float
        Link length at the free end.
    h_max : float
        Largest link (the held arm).
    gamma : float
        Largest growth of the link length per unit length (``h_min + gamma x`` at the free
        end; the slope of the transitions), in (0, 1].
    margin : float
        The fold-following part extends to ``x = 1/2 + margin`` from the free end.
    """
    chi = V.open_interval("chi", chi, 0.0, 1.0)
    frac = V.open_interval("frac", frac, 0.0, 1.0)
    h_min = V.positive("h_min", h_min)
    h_max = V.open_interval("h_max", h_max, 0.0, 1.0)
    if h_max < h_min:
        raise V.SnappingInputError(f"h_max={h_max!r} is out of range: must be >= h_min={h_min!r}")
    gamma = V.open_interval("gamma", gamma, 0.0, 1.0 + 1e-12)
    margin = V.real("margin", margin)
    if not 0.0 <= margin <= 0.5:
        raise V.SnappingInputError(f"margin={margin!r} is out of range: must lie in [0, 0.5]")
    a = estimates.catenary_parameter(chi)
    xf = 0.5 + margin

    def spacing(x):
        fold = frac * a * np.power(np.minimum(2.0 * x, 1.0), 0.25)
        target = np.where(x <= xf, fold, frac * a + gamma * (x - xf))
        return np.maximum(h_min, np.minimum(np.minimum(target, h_max), h_min + gamma * x))

    return from_spacing(spacing, h_min)


def tip_graded(h_min: float, h_max: float, gamma: float = 0.1) -> np.ndarray:
    """Links fine only at the free end: ``min(h_max, h_min + gamma x)``."""
    h_min = V.positive("h_min", h_min)
    h_max = V.open_interval("h_max", h_max, 0.0, 1.0)
    if h_max < h_min:
        raise V.SnappingInputError(f"h_max={h_max!r} is out of range: must be >= h_min={h_min!r}")
    gamma = V.open_interval("gamma", gamma, 0.0, 1.0 + 1e-12)
    return from_spacing(lambda x: np.minimum(h_max, h_min + gamma * x), h_min)


#: the named gradings (``snapping converge --grading``)
GRADINGS = ("fold", "tip", "uniform")
