"""The chain: link lengths ``h_j`` and node masses ``m_j`` (:class:`Links`), nothing else.

Index 0 is the free end, as everywhere in :mod:`snapping.simulate`; an optional point mass
sits at the free end. Masses lumped from a mass per length ``lambda(s)`` take each node's
share of its two links (``lumping="shared"``) or the whole of link j (``lumping="paper"``);
the constructors build uniform, tapered, graded and explicit chains and validate them
(lengths and masses in range, a chain that fits in memory).

Examples
--------
>>> from snapping.simulate.links import Links
>>> Links.uniform(4).m.tolist()
[0.25, 0.25, 0.25, 0.25]
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _validate as V

LUMPINGS = ("shared", "paper")
#: mass of the free-end node: its share of link 0, or all of it
FREE_END_RULES = ("half", "whole")


def _positive_array(name: str, a, n: int | None = None, bounds: tuple | None = None) -> np.ndarray:
    a = np.asarray(V.float_array(name, a), dtype=float)
    if a.ndim > 1:
        raise V.SnappingInputError(f"{name} must be one-dimensional (one value per link or node); got shape {a.shape}")
    a = a.ravel().copy()
    if a.size == 0 or (n is not None and a.size != n):
        want = f"{n}" if n is not None else ">= 1"
        raise V.SnappingInputError(f"{name} has {a.size} entries; expected {want}")
    bad = np.flatnonzero(~(np.isfinite(a) & (a > 0.0)))
    if bad.size:
        raise V.SnappingInputError(f"{name}[{bad[0]}]={a[bad[0]]!r} is out of range: every entry must be finite "
                                   f"and > 0")
    if bounds is not None:
        out = np.flatnonzero((a < bounds[0]) | (a > bounds[1]))
        if out.size:
            j = int(out[0])
            raise V.SnappingInputError(f"{name}[{j}]={float(a[j])!r} is out of range: every entry must lie in "
                                       f"[{bounds[0]:g}, {bounds[1]:g}]")
    return a


def _call_all(name: str, fn, args: np.ndarray) -> np.ndarray:
    """A vectorized user function's values at the array ``args`` (one call), as floats of its shape, or
    SnappingInputError naming it."""
    try:
        vals = np.asarray(fn(args), dtype=float)
    except Exception as exc:  # noqa: BLE001 - any failure of the user's function
        raise V.SnappingInputError(f"{name}(s) on an array of {args.size} arclengths failed or did not return "
                                   f"numbers ({type(exc).__name__}: {str(exc)[:120]})") from None
    if vals.shape != args.shape:
        raise V.SnappingInputError(f"{name}(s) on an array of shape {args.shape} returned shape {vals.shape}: a "
                                   f"vectorized density returns one number for each s")
    return vals


def _call(name: str, fn, args) -> np.ndarray:
    """A user function's values at ``args`` as floats, or SnappingInputError naming it."""
    try:
        vals = [np.asarray(fn(float(v)), dtype=float) for v in args]
    except Exception as exc:  # noqa: BLE001 - any failure of the user's function
        raise V.SnappingInputError(f"{name}({float(args[0])!r}) ... failed or did not return numbers "
                                   f"({type(exc).__name__}: {str(exc)[:120]})") from None
    for v, a in zip(args, vals):
        if a.ndim != 0:
            raise V.SnappingInputError(f"{name}({float(v)!r}) returned {a.size} values of shape {a.shape}: it must "
                                       f"return one number for each s")
    return np.asarray(vals, dtype=float)


#: node masses are kept within this factor of the unit (the tension solve's leading minors are
#: rescaled every general.BLOCK rows: they stay far from overflow for masses in [1/M, M])
MASS_RANGE = 1e15

#: link lengths (units of the chain's length) are kept within the same factor of the unit
LENGTH_RANGE = (1.0 / MASS_RANGE, MASS_RANGE)


def _tip(tip_mass) -> float:
    tip = V.real("tip_mass", tip_mass)
    if not 0.0 <= tip <= MASS_RANGE:
        raise V.SnappingInputError(f"tip_mass={tip!r} is out of range: must lie in [0, {MASS_RANGE:g}] (a ratio to "
                                   f"the chain's mass)")
    return tip


def _check_masses(m, source: str) -> None:
    bad = np.flatnonzero(~((m >= 1.0 / MASS_RANGE) & (m <= MASS_RANGE)))
    if bad.size:
        j = int(bad[0])
        raise V.SnappingInputError(f"{source}: node mass m[{j}]={float(m[j])!r} is out of range: node masses must "
                                   f"lie in [{1.0 / MASS_RANGE:g}, {MASS_RANGE:g}] (units of the chain's mass)")


#: bytes a chain needs per link, about (its arrays, the start, a run's state and stages)
BYTES_PER_LINK = 1000


def _links_count(name: str, N) -> int:
    """N >= 1, and small enough that a chain of N links fits in the available memory."""
    from ._memory import MEMORY_MARGIN, _available_memory

    N = V.integer(name, N, 1)
    avail = _available_memory()
    if avail is not None and N * BYTES_PER_LINK > MEMORY_MARGIN * avail:
        raise V.SnappingInputError(f"{name}={N} links would need about {N * BYTES_PER_LINK / 2**30:.3g} GiB of "
                                   f"memory, but only {avail / 2**30:.3g} GiB is available")
    return N



# ---------------------------------------------------------------------------------- the chain
@dataclass(frozen=True, eq=False)
class Links:
    """The chain: link lengths ``h`` and node masses ``m`` (N each, index 0 the free end).

    ``m[0]`` includes ``tip_mass``. ``link_mass``: the mass of each link, where the chain was
    lumped from a mass per length (None for explicit node masses); with ``lumping="shared"``
    half of the held link's mass goes to the held end, which carries no mass of its own, so
    ``m.sum() = link_mass.sum() - link_mass[-1]/2 + tip_mass``. Use the constructors; they
    validate.
    """

    h: np.ndarray
    m: np.ndarray
    tip_mass: float = 0.0
    kind: str = "explicit"
    params: dict = field(default_factory=dict)
    link_mass: np.ndarray | None = None

    def __post_init__(self):  # built directly too: h and m one per link, in range (the constructors check more)
        h = _positive_array("h", self.h, bounds=LENGTH_RANGE)
        m = _positive_array("m", self.m, h.size, bounds=(1.0 / MASS_RANGE, MASS_RANGE))
        lm = None if self.link_mass is None else _positive_array("link_mass", self.link_mass, h.size)
        for name, v in (("h", h), ("m", m), ("link_mass", lm), ("tip_mass", _tip(self.tip_mass))):
            object.__setattr__(self, name, v)

    @property
    def N(self) -> int:
        """Number of links."""
        return int(self.h.size)

    @property
    def length(self) -> float:
        return float(self.h.sum())

    @property
    def is_paper(self) -> bool:
        """The paper's chain: N equal links of length 1/N, N equal node masses 1/N, no tip mass."""
        N = self.N
        return bool(np.all(self.h == 1.0 / N) and np.all(self.m == 1.0 / N) and self.tip_mass == 0.0)

    # -- constructors
    @classmethod
    def uniform(cls, N: int, *, tip_mass: float = 0.0, lumping: str = "paper") -> "Links":
        """N equal links of total length 1 and mass 1, plus ``tip_mass`` (a ratio to the
        chain's mass) at the free end. ``lumping="paper"`` (default): every node carries
        1/N, the paper's chain; ``"shared"``: the free end carries 1/(2N).

        >>> Links.uniform(4).m.tolist(), Links.uniform(4, lumping="shared").m.tolist()
        ([0.25, 0.25, 0.25, 0.25], [0.125, 0.25, 0.25, 0.25])
        """
        N = _links_count("N", N)
        h = np.full(N, 1.0 / N)
        return cls.from_density(h, None, tip_mass=tip_mass, lumping=lumping, kind="uniform", params={})

    @classmethod
    def taper(cls, N: int, ratio: float, *, power: float = 1.0, tip_mass: float = 0.0,
              lumping: str = "shared", h=None) -> "Links":
        """A tapered chain (a whip): mass per length ``lambda(s) = lambda_0 (1 - c s)^power``
        along the arclength s from the held end (total length 1), with ``c`` set by
        ``lambda(1)/lambda(0) = ratio``, normalised to total mass 1; link masses are the
        exact integrals of lambda over each link, lumped by ``lumping``. ``h``: link
        lengths (default N equal links).

        >>> w = Links.taper(10, 0.5)                # lambda = (1 - s/2)/0.75
        >>> m_tip = (0.1 - 0.25 * (1 - 0.81)) / 2     # half the integral over [0.9, 1]
        >>> m_last = (0.2 - 0.25 * 0.04) / 2          # half the integral over [0, 0.2]
        >>> round(float(w.m[0] / w.m[-1]), 12) == round(m_tip / m_last, 12)
        True
        """
        N = _links_count("N", N)
        ratio = V.positive("ratio", ratio)
        if not 1e-6 <= ratio <= 1e6:
            raise V.SnappingInputError(f"ratio={ratio!r} is out of range: must lie in [1e-06, 1e+06]")
        power = V.positive("power", power)
        if not 1e-3 <= power <= 100.0:
            raise V.SnappingInputError(f"power={power!r} is out of range: must lie in [0.001, 100]")
        h = np.full(N, 1.0 / N) if h is None else _positive_array("h", h, N, bounds=LENGTH_RANGE)
        L = float(h.sum())
        c = 1.0 - ratio ** (1.0 / power)

        def prim(s):  # integral of (1 - c s/L)^power ds from 0 to s
            if c == 0.0:
                return s
            return L * (1.0 - (1.0 - c * s / L) ** (power + 1.0)) / (c * (power + 1.0))

        edges = np.concatenate([[0.0], np.cumsum(h[::-1])])  # from the held end
        mu_from_pin = np.diff([prim(float(e)) for e in edges])
        mu = (mu_from_pin / prim(L))[::-1]  # link masses, index 0 at the free end
        return cls._lumped(h, mu, tip_mass, lumping, "taper", {"ratio": ratio, "power": power})

    @classmethod
    def from_density(cls, h, density=None, *, tip_mass: float = 0.0, lumping: str = "shared",
                     free_end: str | None = None, kind: str = "density", params: dict | None = None,
                     vectorized: bool = False) -> "Links":
        """Links of lengths ``h`` (index 0 at the free end) with masses from a mass per length:
        ``density`` is None (1 everywhere), an array of link masses per length (one per
        link), or a function of the arclength from the held end (integrated over each link
        with Gauss-Legendre quadrature, 8 points: exact for polynomials of degree 15).
        ``free_end``: the free-end node's mass rule, ``"half"`` (its share of link 0, the
        ``lumping="shared"`` default) or ``"whole"`` (all of link 0, the paper's).
        ``vectorized``: ``density`` takes an array of arclengths and returns their values (one call on
        every link's quadrature points, shape (N, 8), instead of one call per point; the same masses
        when it returns, elementwise, what it returns for each point alone).

        >>> l = Links.from_density([0.5, 0.5], lambda s: 2 * s)   # heavier towards the tip
        >>> l.m.tolist()
        [0.375, 0.5]
        """
        h = _positive_array("h", h, bounds=LENGTH_RANGE)
        N = h.size
        if density is None:
            mu = h.copy()
        elif callable(density):
            xg, wg = np.polynomial.legendre.leggauss(8)
            edges = np.concatenate([[0.0], np.cumsum(h[::-1])])
            mu_p = np.zeros(N)
            if vectorized:
                a, b = edges[:-1, None], edges[1:, None]
                every = _call_all("density", density, 0.5 * (a + b) + 0.5 * (b - a) * xg)
            for k in range(N):
                a, b = edges[k], edges[k + 1]
                vals = every[k] if vectorized else _call("density", density, 0.5 * (a + b) + 0.5 * (b - a) * xg)
                if not np.all(np.isfinite(vals) & (vals > 0.0)):
                    raise V.SnappingInputError(f"density(s) must be finite and > 0 on the chain; got {vals.min()!r} "
                                               f"on link {N - 1 - k} (s in [{a:.6g}, {b:.6g}])")
                mu_p[k] = 0.5 * (b - a) * float(np.dot(wg, vals))
            mu = mu_p[::-1].copy()
        else:
            mu = h * _positive_array("density", density, N, bounds=(1.0 / MASS_RANGE, MASS_RANGE))
        return cls._lumped(h, mu, tip_mass, lumping, kind, dict(params or {}), free_end)

    @classmethod
    def graded(cls, h, *, lumping: str = "shared", free_end: str | None = None, tip_mass: float = 0.0,
               params: dict | None = None) -> "Links":
        """A chain of unit mass per length with links ``h`` (e.g. from
        :mod:`snapping.simulate.grading`), masses lumped consistently by default.

        >>> Links.graded([0.25, 0.75]).m.tolist(), Links.graded([0.25, 0.75], free_end="whole").m.tolist()
        ([0.125, 0.5], [0.25, 0.5])
        """
        return cls.from_density(h, None, tip_mass=tip_mass, lumping=lumping, free_end=free_end, kind="graded",
                                params=params)

    @classmethod
    def explicit(cls, h, m, *, tip_mass: float = 0.0) -> "Links":
        """Links of lengths ``h`` and node masses ``m`` as given (``tip_mass`` added to ``m[0]``).

        >>> Links.explicit([0.6, 0.4], [1.0, 2.0], tip_mass=0.5).m.tolist()
        [1.5, 2.0]
        """
        h = _positive_array("h", h, bounds=LENGTH_RANGE)
        m = _positive_array("m", m, h.size, bounds=(1.0 / MASS_RANGE, MASS_RANGE))
        tip = _tip(tip_mass)
        m[0] += tip
        _check_masses(m, "m with tip_mass")
        return cls(h, m, tip, "explicit", {}, None)

    @classmethod
    def _lumped(cls, h, mu, tip_mass, lumping, kind, params, free_end=None) -> "Links":
        if lumping not in LUMPINGS:
            raise V.SnappingInputError(f"lumping={lumping!r} is not one of {LUMPINGS}")
        if free_end not in (None, *FREE_END_RULES):
            raise V.SnappingInputError(f"free_end={free_end!r} is not one of {FREE_END_RULES}")
        tip = _tip(tip_mass)
        if lumping == "paper":
            m = mu.copy()
        else:
            m = 0.5 * mu
            m[1:] += 0.5 * mu[:-1]
        if free_end is not None:
            m[0] = (0.5 if free_end == "half" else 1.0) * mu[0]
            params = {**params, "free_end": free_end}
        m[0] += tip
        _check_masses(m, "h, density and tip_mass" if kind == "density" else f"the {kind} chain")
        return cls(h, m, tip, kind, {**params, "lumping": lumping}, np.asarray(mu, dtype=float))

    def describe(self) -> dict:
        return {"kind": self.kind, "N": self.N, "tip_mass": self.tip_mass, **self.params}
