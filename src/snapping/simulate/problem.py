"""What is solved: the chain, its start, its held end and gravity (nothing numerical).

A :class:`Problem` holds everything physical about a run:

* the chain (:class:`Links`): link lengths ``h_j`` and node masses ``m_j`` (index 0 the
  free end, as everywhere in :mod:`snapping.simulate`), with an optional point mass at
  the free end. Masses lumped from a mass per length ``lambda(s)`` take each node's share
  of its two links, ``m_j = mu_{j-1}/2 + mu_j/2`` with ``mu_j`` the mass of link j
  (``lumping="shared"``); the paper's rule, node j carrying the whole of link j
  (``lumping="paper"``), is exact only for equal links;
* the start: node positions and velocities at t = 0 (a catenary of end separation chi,
  a catenary between supports at different heights, any curve, or explicit nodes);
* the held end (:class:`PinMotion`): fixed, or a prescribed motion ``r_p(t)``;
* gravity ``g`` along +e2 (``y`` grows downward), any value >= 0.

Nondimensional units as everywhere: the paper's chain has length 1, mass 1 and g = 1.
:meth:`Problem.catenary` with the default links is the paper's problem exactly, so that
``run(Problem.catenary(chi, N))`` is ``run(chi, N)``.

Examples
--------
>>> from snapping.simulate.problem import Links, PinMotion, Problem
>>> p = Problem.catenary(0.25, 100, links=Links.taper(100, ratio=0.1))   # a tapered whip
>>> p.is_paper, round(float(p.links.link_mass.sum()), 12), bool(p.links.m[0] < p.links.m[-1])
(False, 1.0, True)
>>> Problem.catenary(0.25, 100).is_paper
True
>>> q = Problem.catenary(0.3, 50, links=Links.uniform(50, tip_mass=0.5), pin=PinMotion.flick((1.0, 0.0), 0.2))
>>> q.describe()["pin"]["kind"], q.links.tip_mass
('flick', 0.5)
"""

from __future__ import annotations

# One idea a module (a pure split of the former problem.py; every name is importable from here as before):
#   links        the chain: Links (link lengths, node masses, lumping, tapers) and its ranges
#   problem      the Problem (start, held end, gravity, body), its constructors, from_options
#   shape_files  read_shape (a start shape from a CSV or netCDF file)
import json
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as V
from . import general as G
from .body import Body
from .links import (BYTES_PER_LINK, FREE_END_RULES, LENGTH_RANGE, LUMPINGS, MASS_RANGE, Links,  # noqa: F401
                    _call, _check_masses, _links_count, _positive_array, _tip)
from .pin import PIN_KINDS, PinMotion, parse_pin_motion
from .shape_files import read_shape

__all__ = ["Links", "PinMotion", "Problem", "Body", "LUMPINGS", "PIN_KINDS"]

#: relative tolerance of a shape's link lengths against the chain's
SHAPE_RTOL = 1e-6

#: largest gravity (units of g) and largest initial speed (units of sqrt(g l)) accepted
GRAVITY_MAX = 1e6
SPEED_MAX = 1e6


def _node_values(name: str, v, n: int) -> None:
    """SnappingInputError unless ``v`` holds ``n`` finite numbers (one per node), naming the first bad one."""
    a = np.asarray(V.float_array(name, v), dtype=float).ravel()
    if a.size != n:
        raise V.SnappingInputError(f"{name} must be {n} finite numbers (one per node); got {a.size} numbers")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise V.SnappingInputError(f"{name}[{bad[0]}]={float(a[bad[0]])!r} is not finite: {name} must be {n} finite "
                                   f"numbers (one per node)")


def _gravity(gravity) -> float:
    g = V.real("gravity", gravity)
    if not 0.0 <= g <= GRAVITY_MAX:
        raise V.SnappingInputError(f"gravity={g!r} is out of range: must lie in [0, {GRAVITY_MAX:g}] (units of "
                                   f"g, along +e2, y downward)")
    return abs(g)  # (-0.0 is 0)


def _check_links(links) -> None:
    if not isinstance(links, Links):
        raise V.SnappingInputError(f"links={links!r} is not a snapping.simulate.Links (use Links.uniform, "
                                   f"Links.taper, Links.graded, Links.explicit, ...)")


# ---------------------------------------------------------------------------------- the problem
@dataclass(frozen=True, eq=False)
class Problem:
    """A chain, its start (node positions ``x, y`` and velocities ``vx, vy`` at t = 0, N + 1
    each, index N the held end at the origin), the held end's motion and gravity.

    Build it with :meth:`catenary`, :meth:`supports`, :meth:`curve` or :meth:`nodes`.
    ``start`` describes the start shape (recorded in the run file); ``chi`` and ``chords``
    are set for the paper's catenary start.
    """

    links: Links
    x: np.ndarray
    y: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    pin: PinMotion = field(default_factory=PinMotion)
    gravity: float = 1.0
    start: dict = field(default_factory=dict)
    chi: float | None = None
    chords: str | None = None
    #: what the line is made of (bending, damping, drag, a clamp): None, or an active Body
    body: Body | None = None

    def __post_init__(self):  # built directly too: a chain, a PinMotion and finite values, one per node
        _check_links(self.links)
        if not isinstance(self.pin, PinMotion):
            raise V.SnappingInputError(f"pin={type(self.pin).__name__} is not a PinMotion")
        for name in ("x", "y", "vx", "vy"):
            _node_values(name, getattr(self, name), self.links.N + 1)

    @property
    def N(self) -> int:
        return self.links.N

    @property
    def is_paper(self) -> bool:
        """The paper's problem: its chain from the catenary, at rest, fixed pin, g = 1."""
        return bool(self.links.is_paper and self.start.get("kind") == "catenary" and self.pin.is_fixed
                    and self.gravity == 1.0 and not self.start.get("velocities") and self.body is None
                    and self.start.get("rest", "catenary") == "catenary")

    @property
    def is_uniform_fixed(self) -> bool:
        """The paper's chain and held end with g = 1, from any start (what Euler-Richardson takes)."""
        return bool(self.links.is_paper and self.pin.is_fixed and self.gravity == 1.0 and self.body is None)

    # -- constructors
    @classmethod
    def catenary(cls, chi: float, N: int | None = None, *, chords: str = "exact", links: Links | None = None,
                 pin: PinMotion | None = None, gravity: float = 1.0, body: Body | None = None,
                 start: str | None = None) -> "Problem":
        """The paper's start: the level catenary of end separation ``chi``, at rest. With the
        paper's links (default: ``Links.uniform(N)``) the nodes are those of
        :func:`snapping.simulate.initial_state` (``chords`` as there); other links are placed
        on the same curve with chords exactly ``h_j`` (walking from the held end), except a chain
        of at most three links (two, or three equal), held at both ends at rest instead
        (:func:`snapping.simulate.chain.few_links_start`).

        ``start``: the shape the line is released from, held at both ends at rest before:
        ``"catenary"`` (the nodes above), or ``"equilibrium"``: the discrete static equilibrium
        of this chain and body held at the held end and at the catenary's free-end node
        (the heavy elastica when the body bends; :mod:`snapping.simulate.equilibrium`).
        Default (None): ``"equilibrium"`` when the body has bending stiffness, else the
        catenary (then bit for bit as without the option)."""
        from .chain import initial_state

        if links is None:
            links = Links.uniform(_links_count("N", N))
        _check_links(links)
        if N is not None and V.integer("N", N, 1) != links.N:
            raise V.SnappingInputError(f"N={N!r} disagrees with the chain's {links.N} links")
        from ..estimates import check_chi

        chi = check_chi(chi)
        if links.is_paper:
            st = initial_state(chi, links.N, chords)
            x, y = st.x, st.y
        else:
            from .. import estimates
            from . import placement, shapes
            from .chain import CHORDS, _catenary_xy, few_links_start

            if chords not in CHORDS:
                raise V.SnappingInputError(f"chords={chords!r} is not one of {CHORDS}")
            L = links.length
            if chords == "exact":
                a = estimates.catenary_parameter(chi)

                def cat(s):
                    cx, cy = _catenary_xy(np.asarray(s, dtype=float) / L, chi, a)
                    return L * cx, L * cy

                few = few_links_start(chi * L, links.h)  # (at most FEW_LINKS links: held at both ends)
                if few is None:  # every node at once (Newton), the walk's points to round-off; else the walk
                    few = placement.place_on_catenary(chi, a, L, links.h)
                x, y = shapes.place_on_curve(cat, links.h) if few is None else few
            else:  # nodes at their arclength on the curve (chords a little shorter than h_j)
                s = np.clip(np.concatenate([np.cumsum(links.h[::-1])[::-1], [0.0]]) / L, 0.0, 1.0)
                xs, ys = estimates.catenary_shape(s, chi)
                x, y = L * np.asarray(xs, dtype=float), L * np.asarray(ys, dtype=float)
                x[-1] = y[-1] = 0.0
        x, y, desc, body = _at_rest(links, x, y, body, gravity, start,
                                    {"kind": "catenary", "chi": chi, "chords": chords})
        return cls._make(links, x, y, None, None, pin, gravity, desc, chi=chi, chords=chords, body=body)

    @classmethod
    def supports(cls, dx: float, dy: float, N: int | None = None, *, links: Links | None = None,
                 pin: PinMotion | None = None, gravity: float = 1.0, body: Body | None = None,
                 start: str | None = None) -> "Problem":
        """The catenary hanging between the held end (origin) and a second support at
        ``(dx, dy)`` (``dy > 0``: lower, y grows downward), released at rest from there;
        nodes at chords exactly ``h_j``. ``start``: as for :meth:`catenary` (the equilibrium
        held at the origin and at the catenary's free-end node)."""
        from . import shapes

        links = links if links is not None else Links.uniform(_links_count("N", N))
        _check_links(links)
        dx = V.positive("dx", dx)
        dy = V.real("dy", dy)
        curve = shapes.catenary_between(dx, dy, links.length)
        x, y = shapes.place_on_curve(curve, links.h)
        x, y, desc, body = _at_rest(links, x, y, body, gravity, start, {"kind": "supports", "dx": dx, "dy": dy})
        return cls._make(links, x, y, None, None, pin, gravity, desc, body=body)

    @classmethod
    def curve(cls, curve, N: int | None = None, *, links: Links | None = None, vx=None, vy=None,
              pin: PinMotion | None = None, gravity: float = 1.0, name: str = "curve",
              body: Body | None = None) -> "Problem":
        """Any start curve: a function ``s -> (x, y)`` of the arclength from the held end (at
        the origin), or a polyline ``(xc, yc)`` starting at the held end; nodes at chords
        exactly ``h_j`` along it."""
        from . import shapes

        links = links if links is not None else Links.uniform(_links_count("N", N))
        _check_links(links)
        try:
            x, y = shapes.place_on_curve(curve, links.h)
        except V.SnappingInputError as exc:
            raise V.SnappingInputError(f"{name}: the chain ({links.N} links, length {links.length:.6g}) cannot be "
                                       f"placed on it: {exc}") from None
        except Exception as exc:  # noqa: BLE001 - the user's curve function failed
            raise V.SnappingInputError(f"{name}: the curve function failed or did not return (x, y) "
                                       f"({type(exc).__name__}: {str(exc)[:120]})") from None
        return cls._make(links, x, y, vx, vy, pin, gravity, {"kind": "curve", "name": str(name)}, body=body)

    @classmethod
    def nodes(cls, x, y, *, links: Links | None = None, vx=None, vy=None, pin: PinMotion | None = None,
              gravity: float = 1.0, name: str = "nodes", body: Body | None = None) -> "Problem":
        """Start from node coordinates (N + 1 each, index 0 the free end, index N the held end
        at the origin); ``links`` default: the uniform chain of the nodes' count. Link lengths
        must agree with the chain's ``h`` to ``SHAPE_RTOL``; velocities (default: at rest, or
        moving with the held end) must keep the links' lengths."""
        x = np.asarray(V.float_array("x", x), dtype=float).ravel()
        y = np.asarray(V.float_array("y", y), dtype=float).ravel()
        for k, a in (("x", x), ("y", y)):
            if not np.all(np.isfinite(a)):
                j = int(np.flatnonzero(~np.isfinite(a))[0])
                raise V.SnappingInputError(f"{k}[{j}]={float(a[j])!r} is not finite: node coordinates must be finite")
        if x.size != y.size or x.size < 2:
            raise V.SnappingInputError(f"shape x and y must have the same length N + 1 >= 2; got {x.size}, {y.size}")
        links = links if links is not None else Links.uniform(x.size - 1)
        _check_links(links)
        if x.size != links.N + 1:
            raise V.SnappingInputError(f"shape has {x.size} nodes but the chain has {links.N} links "
                                       f"({links.N + 1} nodes)")
        lens = np.hypot(np.diff(x), np.diff(y))
        rel = np.abs(lens - links.h) / links.h
        if rel.size and rel.max() > SHAPE_RTOL:
            j = int(np.argmax(rel))
            raise V.SnappingInputError(f"x, y: shape link {j} has length {lens[j]:.9g} but the chain's link is "
                                       f"{links.h[j]:.9g} (relative difference {rel[j]:.3g} > {SHAPE_RTOL:g})")
        return cls._make(links, x, y, vx, vy, pin, gravity, {"kind": "nodes", "name": str(name)}, body=body)

    @classmethod
    def _make(cls, links, x, y, vx, vy, pin, gravity, start, chi=None, chords=None, body=None) -> "Problem":
        from . import shapes

        _check_links(links)
        if body is not None:
            if not isinstance(body, Body):
                raise V.SnappingInputError(f"body={type(body).__name__} is not a snapping.simulate.Body")
            body.check(links.h)
            body = body if body.active else None  # (an inactive body: today's problem, bit for bit)
        if not (np.all(links.m >= 1.0 / MASS_RANGE) and np.all(links.m <= MASS_RANGE)):
            j = int(np.argmax((links.m < 1.0 / MASS_RANGE) | (links.m > MASS_RANGE)))
            raise V.SnappingInputError(f"m[{j}]={float(links.m[j])!r} is out of range: node masses must lie in "
                                       f"[{1.0 / MASS_RANGE:g}, {MASS_RANGE:g}] (units of the chain's mass)")
        pin = PinMotion() if pin is None else pin
        if not isinstance(pin, PinMotion):
            raise V.SnappingInputError(f"pin={type(pin).__name__} is not a PinMotion")
        g = _gravity(gravity)
        x = np.array(x, dtype=float)
        y = np.array(y, dtype=float)
        N = links.N
        if x.size != N + 1:
            raise V.SnappingInputError(f"start has {x.size} nodes, the chain {N + 1}")
        if x[-1] != 0.0 or y[-1] != 0.0:
            raise V.SnappingInputError(f"the held end (node {N}) must start at the origin; got ({x[-1]!r}, {y[-1]!r})")
        shapes.check_curve(x, y, name=start.get("name", start["kind"]))
        pvx, pvy = pin.velocity(0.0)
        moving = vx is not None or vy is not None
        vx = np.full(N + 1, pvx) if vx is None else np.array(V.float_array("vx", vx), dtype=float).ravel()
        vy = np.full(N + 1, pvy) if vy is None else np.array(V.float_array("vy", vy), dtype=float).ravel()
        for name, v in (("vx", vx), ("vy", vy)):
            _node_values(name, v, N + 1)
            if np.abs(v).max() > SPEED_MAX:
                j = int(np.argmax(np.abs(v)))
                raise V.SnappingInputError(f"{name}[{j}]={float(v[j])!r} is out of range: initial speeds must be "
                                           f"at most {SPEED_MAX:g} (units of sqrt(g l))")
        if abs(vx[-1] - pvx) > 1e-12 or abs(vy[-1] - pvy) > 1e-12:
            raise V.SnappingInputError(f"vx, vy: the held end's velocity ({float(vx[-1])!r}, {float(vy[-1])!r}) "
                                       f"must be the pin's, "
                                       f"({pvx!r}, {pvy!r}), at t = 0")
        dx, dy = np.diff(x), np.diff(y)
        stretch = np.abs(dx * np.diff(vx) + dy * np.diff(vy)) / np.hypot(dx, dy)
        vscale = max(1.0, float(np.abs(np.concatenate([vx, vy])).max()))
        if stretch.size and stretch.max() > 1e-9 * vscale:
            j = int(np.argmax(stretch))
            raise V.SnappingInputError(f"vx, vy: the initial velocities stretch link {j} at the rate "
                                       f"{stretch[j]:.3g}: they "
                                       f"must keep every link's length (relative velocity normal to the link)")
        if moving:
            start = {**start, "velocities": True}
        return cls(links, x, y, vx, vy, pin, g, start, chi, chords, None if body is None else body.resolved(x, y))

    def with_body(self, body: Body | None, start: str | None = None) -> "Problem":
        """This problem with another body (validated; None or an inactive body: none). A
        catenary or supports start is built again for the body, with ``start`` as there (by
        default the equilibrium when the body bends, else the catenary); any other start
        keeps its nodes (``start`` must then be None)."""
        kind = self.start.get("kind")
        kw = {"links": self.links, "pin": self.pin, "gravity": self.gravity, "body": body, "start": start}
        if kind == "catenary":
            return Problem.catenary(self.chi, chords=self.chords, **kw)
        if kind == "supports":
            return Problem.supports(self.start["dx"], self.start["dy"], **kw)
        if start is not None:
            _rest_shape(start)
            raise V.SnappingInputError(f"start={start!r} applies to the catenary and supports starts; this problem "
                                       f"starts from its {kind!r} nodes as given")
        return Problem._make(self.links, self.x, self.y, self.vx if self.start.get("velocities") else None,
                             self.vy if self.start.get("velocities") else None, self.pin, self.gravity,
                             dict(self.start), chi=self.chi, chords=self.chords, body=body)

    # -- the compiled form
    def model(self):
        """The model tuple of :mod:`snapping.simulate.general` (uniform kernels for the paper's
        chain with a fixed held end and g = 1, whatever the start)."""
        if self.is_uniform_fixed:
            return G.uniform_model(self.N)
        mdl = G.make_model(self.links.h, 1.0 / self.links.m, g=self.gravity, **self.pin.model_args())
        if self.body is not None:  # node forces: snapping.simulate.forced
            mdl = self.body.model(mdl, self.links.h, float(self.initial_angles()[self.N - 1]))
        return mdl

    def initial_angles(self) -> np.ndarray:
        """The initial state of the link-angle form: ``[theta, theta']`` (paper's chain) or
        ``[theta, theta', W = 0]`` (general), from the start's nodes."""
        dx, dy = np.diff(self.x), np.diff(self.y)
        th = np.unwrap(np.arctan2(dy, dx))
        dvx, dvy = np.diff(self.vx), np.diff(self.vy)
        if self.is_uniform_fixed:
            from . import angles as AG
            from .chain import ChainState

            return AG.state_to_angles(ChainState(self.x, self.y, self.vx, self.vy, 0.0))
        om = (-np.sin(th) * dvx + np.cos(th) * dvy) / self.links.h
        extra = [0.0, 0.0] if self.body is not None else [0.0]  # (W, and D with a body)
        return np.concatenate([th, om, extra]).astype(float)

    def estimate(self) -> dict:
        """The paper's estimates from this start shape and these masses
        (:func:`snapping.shape_estimates.shape_estimate`): P, kappa_m(0), the delta scales and
        the whirling-rod peaks.

        >>> shared = Problem.catenary(0.25, links=Links.uniform(2000, lumping="shared"), chords="arclength").estimate()
        >>> round(shared["P"], 5), round(shared["kappa_m0"], 2)     # the closed forms: 0.254055, 26.11
        (0.25405, 26.11)
        >>> round(Problem.catenary(0.25, 2000, chords="arclength").estimate()["P"], 5)  # the paper's lumping: O(1/N) off
        0.2543
        """
        from ..shape_estimates import shape_estimate

        return shape_estimate(self.x, self.y, np.concatenate([self.links.m, [0.0]]), self.gravity)

    def describe(self) -> dict:
        """JSON-friendly description (recorded in the run file)."""
        d = {"chain": self.links.describe(), "start": dict(self.start), "pin": self.pin.describe(),
             "gravity": self.gravity}
        if self.body is not None:
            d["body"] = self.body.describe(self.links.h)
        return d

    def describe_json(self) -> str:
        return json.dumps(self.describe(), sort_keys=True)


# ---------------------------------------------------------------------------------- the rest shape
#: the shapes a catenary or supports start is released from (the line held at both ends, at rest)
REST_SHAPES = ("catenary", "equilibrium")


def _rest_shape(start) -> None:
    if start is not None and not (isinstance(start, str) and start in REST_SHAPES):
        raise V.SnappingInputError(f"start={start!r} is not one of {REST_SHAPES} (the shape the line hangs in, held "
                                   f"at both ends at rest, before its free end is released; default: the "
                                   f"equilibrium when the body bends)")


def _at_rest(links, x, y, body, gravity, start, desc):
    """The start's nodes, description and body for ``start`` (None: the equilibrium when the
    body has bending stiffness, else the catenary's nodes as given). With the equilibrium, a
    body's ``clamp="start"`` holds the direction of the hinged equilibrium's held link (which
    is then the clamped equilibrium too: no moment at the clamp), and the description records ``rest`` (the residual is below
    :data:`snapping.simulate.equilibrium.EQUILIBRIUM_TOL`, else an error)."""
    _rest_shape(start)
    bends = False
    if isinstance(body, Body):
        _check_links(links)
        body.check(links.h)
        bends = body.active and bool(np.any(body.node_values("bending", links.h) != 0.0))
    shape = start if start is not None else ("equilibrium" if bends else "catenary")
    if shape == "catenary":
        return x, y, ({**desc, "rest": "catenary"} if bends else desc), body
    from .equilibrium import hanging_equilibrium

    g = _gravity(gravity)
    solve = body if isinstance(body, Body) and body.active else None
    if solve is not None and isinstance(solve.clamp, str):  # "start": the clamp holds the rest shape's direction,
        solve = solve.hinged()  # where the hinged equilibrium puts no moment on it (resolved on these nodes)
    eq = hanging_equilibrium(links, solve, x, y, gravity=g)
    from . import shapes

    try:
        shapes.check_curve(eq.x, eq.y, name="start='equilibrium'")
    except V.SnappingInputError as exc:
        raise V.SnappingInputError(f"{exc} (the line's rest shape with this bending is not a valid start; use "
                                   f"start='catenary')") from None
    return eq.x, eq.y, {**desc, "rest": "equilibrium"}, body


# ---------------------------------------------------------------------------------- from options
def from_options(*, chi=None, N=None, chords: str = "exact", supports=None, shape=None, tip_mass: float = 0.0,
                 taper=None, lumping: str | None = None, pin_motion=None, gravity: float = 1.0,
                 links: Links | None = None) -> Problem | None:
    """The problem the command-line options describe (``snapping simulate``), or None when
    they describe the paper's problem (then ``run(chi, N)``).

    ``supports``: ``(dx, dy)``; ``shape``: a file for :func:`read_shape`; ``taper``:
    ``ratio`` or ``(ratio, power)``; ``pin_motion``: a spec for :func:`parse_pin_motion`;
    ``links``: the chain as built elsewhere (a real line's, :meth:`snapping.lines.Line.links`),
    in place of ``N``, ``tip_mass``, ``taper`` and ``lumping``.

    >>> from_options(chi=0.3, N=10) is None
    True
    >>> from_options(chi=0.3, N=10, tip_mass=0.5).links.tip_mass
    0.5
    """
    starts = [k for k, v in (("chi", chi), ("supports", supports), ("shape", shape)) if v is not None]
    if (starts == ["chi"] and links is None and taper is None and lumping in (None, "paper")
            and pin_motion in (None, "", "fixed")
            and V.real("tip_mass", tip_mass) == 0.0 and V.real("gravity", gravity) == 1.0):
        return None  # the paper's problem: run(chi, N) (checks chi and N itself)
    if len(starts) != 1:
        raise V.SnappingInputError(f"give exactly one start: --chi, --supports DX,DY or --shape FILE (got "
                                   f"{starts or 'none'})")
    if chords != "exact" and chi is None:  # (the other starts place their nodes at exact chords)
        raise V.SnappingInputError(f"chords={chords!r} applies to the catenary start of chi only: the {starts[0]} "
                                   f"start places its nodes at exact chords")
    N = _links_count("N", N)
    if links is not None:
        _check_links(links)
    elif taper is not None:
        tv = [taper] if np.ndim(taper) == 0 else list(taper)
        if not 1 <= len(tv) <= 2:
            raise V.SnappingInputError(f"taper={taper!r} must be a ratio or (ratio, power)")
        ratio, power = (tv + [1.0])[:2]
        links = Links.taper(N, ratio, power=power, tip_mass=tip_mass, lumping=lumping or "shared")
    else:
        links = Links.uniform(N, tip_mass=tip_mass, lumping=lumping or "paper")
    pin = pin_motion if isinstance(pin_motion, PinMotion) else parse_pin_motion(pin_motion)
    if chi is not None:
        p = Problem.catenary(chi, links=links, chords=chords, pin=pin, gravity=gravity)
        return None if p.is_paper else p
    if supports is not None:
        try:
            dx, dy = (float(v) for v in supports)
        except (TypeError, ValueError):
            raise V.SnappingInputError(f"supports={supports!r} must be two numbers DX,DY") from None
        return Problem.supports(dx, dy, links=links, pin=pin, gravity=gravity)
    x, y = read_shape(shape)
    return Problem.curve((x, y), links=links, pin=pin, gravity=gravity, name=str(shape))
