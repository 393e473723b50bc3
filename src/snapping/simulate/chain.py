"""The discrete chain: its state, the paper's initial catenary, and evaluations.

Nodes are numbered as in the paper's appendix: node 1 (array index 0) is the
free end, node N+1 (index N) the pin at the origin; node k sits at arclength
s = (N + 1 - k)/N (s = 0 at the pin, 1 at the free end). Gravity is along +e2,
so ``y`` grows downward.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from .. import _validate as V
from .. import estimates
from . import kernels as K

__all__ = ["ChainState", "initial_state", "evaluate", "node_arclength", "link_arclength", "curvature_profile"]

CHORDS = ("arclength", "exact")


@dataclass
class ChainState:
    """Positions and velocities of the N + 1 nodes (index 0: free end, index N: pin).

    Attributes
    ----------
    x, y, vx, vy : ndarray, shape (N + 1,)
        Node positions and velocities (nondimensional; y downward). The last
        entries (the pin) must be zero.
    t : float
        Time of the state.

    Examples
    --------
    >>> s = ChainState(x=[0.0, 0.0], y=[1.0, 0.0], vx=[0.0, 0.0], vy=[0.0, 0.0])
    >>> s.N
    1
    """

    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    t: float = 0.0
    extra: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        arrs = [V.float_array(n, a).ravel().copy() for n, a in zip(("x", "y", "vx", "vy"),
                                                                   (self.x, self.y, self.vx, self.vy))]
        n = arrs[0].size
        if n < 2 or any(a.size != n for a in arrs):
            raise V.SnappingInputError(
                f"state arrays must all have the same length N + 1 >= 2; got lengths {[a.size for a in arrs]}"
            )
        for name, a in zip(("x", "y", "vx", "vy"), arrs):
            if not np.all(np.isfinite(a)):
                raise V.SnappingInputError(f"state {name} contains non-finite values")
            if a[-1] != 0.0:
                raise V.SnappingInputError(f"state {name}[N]={a[-1]!r} must be 0: the pin is fixed at the origin")
        self.x, self.y, self.vx, self.vy = arrs
        self.t = V.real("t", self.t)

    @property
    def N(self) -> int:
        """Number of links."""
        return self.x.size - 1

    def link_lengths(self) -> np.ndarray:
        """|r_{k+1} - r_k| for the N links (index 0: link 1 at the free end)."""
        return np.hypot(np.diff(self.x), np.diff(self.y))

    def copy(self) -> "ChainState":
        return ChainState(self.x.copy(), self.y.copy(), self.vx.copy(), self.vy.copy(), self.t)

    def as_array(self) -> np.ndarray:
        """The (7, N + 1) kernel layout, with accelerations and tension evaluated."""
        Z = np.zeros((K.NROWS, self.N + 1))
        Z[K.RX], Z[K.RY], Z[K.RVX], Z[K.RVY] = self.x, self.y, self.vx, self.vy
        _eval_inplace(Z)
        return Z


def node_arclength(N: int) -> np.ndarray:
    """Arclength s = (N + 1 - k)/N of nodes k = 1..N+1 (index 0: free end, s = 1).

    >>> node_arclength(4)
    array([1.  , 0.75, 0.5 , 0.25, 0.  ])
    """
    N = V.integer("N", N, 1)
    return (N - np.arange(N + 1)) / N


def link_arclength(N: int) -> np.ndarray:
    """Arclength of the midpoints of links k = 1..N, (N + 1/2 - k)/N.

    >>> link_arclength(2)
    array([0.75, 0.25])
    """
    N = V.integer("N", N, 1)
    return (N - 0.5 - np.arange(N)) / N


def _catenary_xy(s, chi: float, a: float):
    """The paper's catenary formula (also beyond s = 1, for exact chords)."""
    u = np.asarray(s, dtype=float) - 0.5
    x = a * np.arcsinh(u / a) + 0.5 * chi
    y = math.sqrt(a * a + 0.25) - np.sqrt(a * a + u * u)
    return x, y


#: chains of at most this many links start, with ``chords="exact"``, held at both ends (:func:`few_links_start`)
FEW_LINKS = 3


def few_links_start(X: float, h) -> tuple[np.ndarray, np.ndarray] | None:
    """The catenary start of a chain of at most :data:`FEW_LINKS` links, chords exact: the
    chain at rest held at the pin (the origin) and at its free end at horizontal distance ``X``
    (chi L), at the pin's level when the links reach it; None for longer chains (and three
    unequal links), which walk the catenary (:func:`initial_state`, ``chords="exact"``).

    A walk along the catenary with chords of a link's length overshoots the curve's free end
    by about a link when the links are as long as its sag (one link: its node 0.96 L above
    the pin at chi 0.25). Held at both ends the few links have their static equilibrium,
    which their lengths alone fix: two links meet below the middle, at the intersection of
    the circles of their lengths about the two ends; three equal links hang symmetric, the
    middle one level (their nodes lie on a level catenary through both ends). One link
    cannot span the catenary's ends (chi < 1): it hangs from the pin with its end at
    horizontal distance X below the pin's level (a pendulum released at that angle).
    ``h`` in the project's order (``h[0]`` at the free end); ``y`` grows downward; index 0
    of the result is the free end.

    >>> x, y = few_links_start(0.25, [0.5, 0.5])
    >>> [round(float(v), 6) for v in (*x, *y)]
    [0.25, 0.125, 0.0, 0.0, 0.484123, 0.0]
    """
    h = np.asarray(h, dtype=float)
    N = h.size
    if N > FEW_LINKS or (N == 3 and not (h[0] == h[1] == h[2])):
        return None
    x, y = np.zeros(N + 1), np.zeros(N + 1)
    x[0] = X
    if N == 1:
        y[0] = math.sqrt(max(h[0] * h[0] - X * X, 0.0))
    elif N == 2:  # the free node: |r| = h[1] from the pin, |r - (X, 0)| = h[0] from the free end
        x[1] = (X * X + h[1] * h[1] - h[0] * h[0]) / (2.0 * X)
        y[1] = math.sqrt(max(h[1] * h[1] - x[1] * x[1], 0.0))
    else:  # three equal links: the middle one level, the outer ones symmetric
        x[2] = 0.5 * (X - h[1])
        x[1] = X - x[2]
        y[1] = y[2] = math.sqrt(max(h[0] * h[0] - x[2] * x[2], 0.0))
    return x, y


def initial_state(chi: float, N: int, chords: str = "arclength") -> ChainState:
    """The paper's initial condition: the catenary of end separation ``chi`` at rest.

    With ``chords="arclength"`` (the paper's) node k lies on the catenary at
    arclength s = (N + 1 - k)/N, from :func:`snapping.estimates.catenary_shape`;
    the chords are then slightly shorter than 1/N (relative error about
    kappa^2/(24 N^2), reported by the run as ``link_error_initial``) and the free
    end is exactly at (chi, 0). With ``chords="exact"`` the nodes are placed on the
    same curve, walking from the pin, at chord distance exactly 1/N (the free end
    then lies a little beyond s = 1); a chain of at most :data:`FEW_LINKS` links, whose
    walk would overshoot the curve by about a link, is held at both ends instead
    (:func:`few_links_start`: its static equilibrium, the free end at (chi, 0); one link
    at (chi, sqrt(1 - chi^2))).

    Parameters
    ----------
    chi : float
        End-to-end separation over length, in (0, 1).
    N : int
        Number of links, >= 1.
    chords : {"arclength", "exact"}
        Node placement.

    Returns
    -------
    ChainState
        Positions, zero velocities, t = 0.

    Examples
    --------
    >>> s0 = initial_state(0.25, 4)
    >>> round(float(s0.x[0]), 12), round(float(s0.y[0]), 12), float(s0.x[-1]), float(s0.y[-1])
    (0.25, 0.0, 0.0, 0.0)
    >>> bool(abs(initial_state(0.25, 4, chords="exact").link_lengths() - 0.25).max() < 1e-14)
    True
    """
    chi = estimates.check_chi(chi)
    N = V.integer("N", N, 1)
    if chords not in CHORDS:
        raise V.SnappingInputError(f"chords={chords!r} is not one of {CHORDS}")
    if chords == "arclength":
        s = node_arclength(N)
        x, y = estimates.catenary_shape(s, chi)
        x = np.array(x, dtype=float)
        y = np.array(y, dtype=float)
        x[-1] = 0.0
        y[-1] = 0.0
        x[0] = chi  # the formula's rounding: the free end is exactly at (chi, 0)
        y[0] = 0.0
    elif N <= FEW_LINKS:
        x, y = few_links_start(chi, np.full(N, 1.0 / N))
    else:
        a = estimates.catenary_parameter(chi)
        h = 1.0 / N
        s = np.zeros(N + 1)
        xs, ys = np.zeros(N + 1), np.zeros(N + 1)
        for k in range(1, N + 1):
            s0, x0, y0 = s[k - 1], xs[k - 1], ys[k - 1]

            def f(sv):
                xv, yv = _catenary_xy(sv, chi, a)
                return math.hypot(float(xv) - x0, float(yv) - y0) - h

            hi = s0 + 2.0 * h
            while f(hi) < 0.0:
                hi += h
            s[k] = brentq(f, s0 + 0.5 * h, hi, xtol=1e-16, rtol=1e-15, maxiter=200)
            xv, yv = _catenary_xy(s[k], chi, a)
            xs[k], ys[k] = float(xv), float(yv)
        # walking from the pin: reverse into the paper's node order (index 0 = free end)
        x, y = xs[::-1].copy(), ys[::-1].copy()
        x[-1] = 0.0
        y[-1] = 0.0
    z = np.zeros(N + 1)
    return ChainState(x, y, z.copy(), z.copy(), 0.0)


def _eval_inplace(Z: np.ndarray) -> None:
    N = Z.shape[1] - 1
    w = np.empty((4, N))
    K.rhs(N, Z, w[0], w[1], w[2], w[3])


def evaluate(state: ChainState) -> dict[str, np.ndarray]:
    """Link tensions and node accelerations of a state (the paper's eqs. (discretemo)
    and the tension system), O(N).

    Returns
    -------
    dict
        ``ax, ay`` (N + 1 node accelerations, zero at the pin) and ``tension``
        (N link tensions sigma_k, index 0 the link at the free end).

    Examples
    --------
    The vertically hanging chain is at rest with tension sigma_k = k/N:

    >>> N = 4
    >>> z = np.zeros(N + 1)
    >>> hang = ChainState(z, (N - np.arange(N + 1)) / N, z, z)
    >>> ev = evaluate(hang)
    >>> np.round(ev["tension"], 12).tolist(), float(abs(ev["ay"]).max()) < 1e-12
    ([0.25, 0.5, 0.75, 1.0], True)
    """
    if not isinstance(state, ChainState):
        raise V.SnappingInputError(f"state={type(state).__name__} is not a ChainState")
    Z = state.as_array()
    return {"ax": Z[K.RAX].copy(), "ay": Z[K.RAY].copy(), "tension": Z[K.RSIG, :-1].copy()}


def curvature_profile(x: np.ndarray, y: np.ndarray, h: np.ndarray | None = None) -> np.ndarray:
    """Discrete curvature kappa = N (theta_{k+1} - theta_k) at the nodes (the paper's
    formula, link angles unwrapped along the chain); NaN at the two end nodes. With link
    lengths ``h`` (a general chain): the turning angle over the mean of the two links,
    ``2 (theta_{k+1} - theta_k)/(h_k + h_{k+1})``.

    The link angle theta_k = atan2(d_k . e2, d_k . e1); the value for the joint
    between links k and k+1 is stored at their common node k+1.

    >>> N = 4; th = np.linspace(0, 1, N)          # links turning by 1/3 rad each
    >>> x = np.concatenate([[0.0], np.cumsum(np.cos(th) / N)]); y = np.concatenate([[0.0], np.cumsum(np.sin(th) / N)])
    >>> x, y = x - x[-1], y - y[-1]
    >>> np.round(curvature_profile(x, y), 6).tolist()
    [nan, 1.333333, 1.333333, 1.333333, nan]
    """
    x = V.float_array("x", x).ravel()
    y = V.float_array("y", y).ravel()
    if x.shape != y.shape or x.size < 2:
        raise V.SnappingInputError(f"x and y must have the same length N + 1 >= 2; got {x.size} and {y.size}")
    N = x.size - 1
    theta = np.unwrap(np.arctan2(np.diff(y), np.diff(x)))
    kappa = np.full(N + 1, np.nan)
    if N >= 2:
        kappa[1:N] = N * np.diff(theta) if h is None else 2.0 * np.diff(theta) / (h[:-1] + h[1:])
    return kappa
