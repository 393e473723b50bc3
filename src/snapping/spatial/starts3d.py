"""What a 3D run solves: the chain, its start in space, its held end and gravity.

:class:`Problem3D` holds node positions ``r`` and velocities ``v`` ((N + 1, 3), row N the
held end at the origin), the chain (:class:`snapping.simulate.links.Links`: link lengths
and lumped node masses, tip mass), the held end's motion (:class:`Pin3D`), gravity (a
magnitude and a unit direction, default ``(0, 1, 0)``: ``y`` downward as in the planar
problems) and the normal of the reference plane whose out-of-plane amplitude is measured
(default ``(0, 0, 1)``), and what the line is made of (``body``: a
:class:`snapping.simulate.Body`: bending stiffness, Kelvin-Voigt bending damping, quadratic
and linear drag, a 3D wind, tip drag; :mod:`snapping.spatial.forces3d`; no clamped held end
yet, and a natural curvature only in a planar problem).

Starts: any planar :class:`snapping.simulate.problem.Problem` placed in the plane z = 0
(:meth:`Problem3D.from_planar`), the paper's catenary (:meth:`Problem3D.catenary`), node
coordinates (:meth:`Problem3D.nodes`), and the start only 3D has, a planar start with an
out-of-plane perturbation of amplitude ``eps`` (:meth:`Problem3D.perturbed`) of its velocity
or of its shape (displaced and placed again with exact chords): the mode ``sin(k pi s/L)`` of
the arclength ``s`` from the held end, random node values with a seed, or a smooth random
field of eight sine modes.

Example
-------
>>> from snapping.spatial.starts3d import Problem3D
>>> p = Problem3D.catenary(0.25, 50).perturbed(1e-4)
>>> p.v.shape, float(abs(p.v[:, 2]).max()) <= 1e-4, p.start["perturbation"]["eps"]
((51, 3), True, 0.0001)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .. import _validate as V
from ..simulate.links import Links
from . import chain3d as C
from .held3d import Pin3D, unit3

__all__ = ["Problem3D", "MODES", "planar_body"]  # (Pin3D: snapping.spatial.held3d, importable here too)

#: perturbation modes of :meth:`Problem3D.perturbed`
MODES = ("sin", "random", "modes")
#: the number of sine modes of a smooth random perturbation (mode "modes")
RANDOM_MODES = 8
#: what :meth:`Problem3D.perturbed` perturbs
KINDS = ("velocity", "shape")
#: relative tolerance of a start's link lengths against the chain's, and of a unit direction's length
SHAPE_RTOL = 1e-6


_unit = unit3


def planar_body(body):
    """``body`` with its wind in the plane (what a planar problem that places a 3D start takes;
    the 3D problem keeps the body as given); None stays None."""
    if body is None or len(body.wind) == 2:
        return body
    from ..simulate.body import Body

    return Body.from_describe({**body.describe(), "wind": list(body.wind[:2])})


@dataclass(frozen=True, eq=False)
class Problem3D:
    """A chain in space, its start (``r``, ``v``: (N + 1, 3), row N the held end at the
    origin), its held end, gravity ``gravity * g_dir`` and the reference plane's normal."""

    links: Links
    r: np.ndarray
    v: np.ndarray
    pin: Pin3D = field(default_factory=Pin3D)
    gravity: float = 1.0
    g_dir: tuple = (0.0, 1.0, 0.0)
    normal: tuple = (0.0, 0.0, 1.0)
    start: dict = field(default_factory=dict)
    body: object = None

    def __post_init__(self):
        if not isinstance(self.links, Links):
            raise V.SnappingInputError(f"links={self.links!r} is not a snapping.simulate.Links")
        if not isinstance(self.pin, Pin3D):
            raise V.SnappingInputError(f"pin={type(self.pin).__name__} is not a Pin3D")
        N = self.links.N
        for name in ("r", "v"):
            a = np.array(V.float_array(name, getattr(self, name)), dtype=float)
            if a.ndim != 2 or a.shape != (N + 1, 3):
                raise V.SnappingInputError(f"{name} must be an array of shape ({N + 1}, 3) (N + 1 nodes, 3 columns "
                                           f"x, y, z); got shape {a.shape}")
            if not np.all(np.isfinite(a)):
                raise V.SnappingInputError(f"{name} must be finite")
            object.__setattr__(self, name, a)
        g = V.real("gravity", self.gravity)
        if not 0.0 <= g <= 1e6:
            raise V.SnappingInputError(f"gravity={g!r} is out of range: must lie in [0, 1e6] (units of g)")
        object.__setattr__(self, "gravity", abs(g))
        object.__setattr__(self, "g_dir", tuple(_unit("g_dir", self.g_dir).tolist()))
        object.__setattr__(self, "normal", tuple(_unit("normal", self.normal).tolist()))
        r, v = self.r, self.v
        if np.any(r[N] != 0.0):
            raise V.SnappingInputError(f"r: the held end (node {N}) must start at the origin; got {r[N].tolist()}")
        d = np.diff(r, axis=0)
        lens = np.linalg.norm(d, axis=1)
        rel = np.abs(lens - self.links.h) / self.links.h
        if rel.max() > SHAPE_RTOL:
            j = int(np.argmax(rel))
            raise V.SnappingInputError(f"r: link {j} has length {lens[j]:.9g} but the chain's link is "
                                       f"{self.links.h[j]:.9g} (relative difference {rel[j]:.3g} > {SHAPE_RTOL:g})")
        vp = np.asarray(self.pin.velocity(0.0))
        if np.abs(v[N] - vp).max() > 1e-12 * max(1.0, float(np.abs(vp).max())):
            raise V.SnappingInputError(f"v: the held end (node {N}) must move as the pin at t = 0, {vp.tolist()}; got "
                                       f"{v[N].tolist()} (Problem3D.with_pin carries a start with a moving pin)")
        stretch = np.abs(np.sum(d * np.diff(v, axis=0), axis=1)) / lens
        if stretch.max() > 1e-9 * max(1.0, float(np.abs(v).max())):
            j = int(np.argmax(stretch))
            raise V.SnappingInputError(f"v: the initial velocities stretch link {j} at the rate {stretch[j]:.3g}: "
                                       f"they must keep every link's length")
        self._check_body()

    def _check_body(self) -> None:
        """A body in space: its profiles against the chain; no clamp (refused); a natural
        curvature only when the whole problem lies in the reference plane."""
        from ..simulate.body import Body

        b = self.body
        if b is None:
            return
        if not isinstance(b, Body):
            raise V.SnappingInputError(f"body={type(b).__name__} is not a snapping.simulate.Body")
        b.check(self.links.h, dims=3)
        if b.clamp is not None:
            raise V.SnappingInputError(f"clamp={b.clamp!r}: a clamped held end has no 3D form yet (it would hold the "
                                       f"line's direction in space, and with a twisting rope its frame); use a hinged "
                                       f"held end (clamp=None) or the planar method")
        if not np.all(b.node_values("curvature", self.links.h) == 0.0):
            n = np.asarray(self.normal)
            wind = np.zeros(3)
            wind[:len(b.wind)] = b.wind
            off = {"r": float(np.abs(self.r @ n).max()), "v": float(np.abs(self.v @ n).max()),
                   "g_dir": abs(float(np.asarray(self.g_dir) @ n)), "pin accel": abs(float(np.asarray(self.pin.accel) @ n)),
                   "wind": abs(float(wind @ n))}
            bad = [k for k, x in off.items() if x != 0.0]
            if bad:
                raise V.SnappingInputError(f"curvature: a natural curvature in space needs a material frame to curl in "
                                           f"(a chain has none; a twisting rope would): it is accepted only in a planar "
                                           f"problem, but {', '.join(bad)} leave the plane normal to {tuple(n.tolist())}")

    @property
    def body_active(self) -> bool:
        """Whether the run has body forces (a body that changes nothing is solved as none)."""
        return self.body is not None and self.body.active

    @property
    def N(self) -> int:
        return self.links.N

    # -- constructors
    @classmethod
    def from_planar(cls, problem, **kw) -> "Problem3D":
        """A planar :class:`snapping.simulate.problem.Problem` in the plane z = 0 (same chain,
        nodes, velocities, held end, gravity and body)."""
        if problem.body is not None:
            kw.setdefault("body", problem.body)
        N = problem.N
        r = np.column_stack([problem.x, problem.y, np.zeros(N + 1)])
        v = np.column_stack([problem.vx, problem.vy, np.zeros(N + 1)])
        return cls(problem.links, r, v, Pin3D.from_planar(problem.pin), problem.gravity,
                   start={"kind": "planar", **problem.start}, **kw)

    @classmethod
    def catenary(cls, chi: float, N: int | None = None, **kw) -> "Problem3D":
        """The planar catenary start (:meth:`snapping.simulate.problem.Problem.catenary`, same
        keywords: ``links``, ``chords``, ``pin``, ``gravity``, ``body``: a body with bending
        starts from its rest shape, as in the plane; its wind may blow out of the plane) in the
        plane z = 0."""
        from ..simulate.problem import Problem

        body = kw.pop("body", None)
        return cls.from_planar(Problem.catenary(chi, N, body=planar_body(body), **kw), body=body)

    def perturbed(self, eps: float, mode: str = "sin", *, seed: int | None = None, k: int = 1,
                  kind: str = "velocity") -> "Problem3D":
        """This start perturbed out of its plane with amplitude ``eps`` along ``normal``, in the
        mode shape ``phi(s)`` (``s``: arclength from the held end, ``L`` the chain's length):
        ``mode="sin"``: ``phi = sin(k pi s/L)`` (zero at both ends for every integer ``k``;
        ``k = 0``: no perturbation at all); ``"random"``: independent normal values (``seed``),
        scaled to max 1, zero at the held end (rough: a different field for every N);
        ``"modes"``: a smooth random field, ``sum_{j=1}^{8} a_j sin(j pi s/L) / j`` with normal
        ``a_j`` (``seed``), scaled to max 1 over the nodes (the same field for every N, so that
        a study can refine it).

        ``kind="velocity"``: ``eps * phi(s) * normal`` is added to every node's velocity
        (relative link velocities stay normal to links lying in the plane).
        ``kind="shape"``: the start is displaced out of its plane by ``eps * L * phi(s) *
        normal`` and placed again with exact chords (link j from the held end along the
        displaced curve's chord direction, its length exactly the link's: every link turns
        out of the plane by O(eps), the in-plane positions move at O(eps^2)); the velocities
        keep their value where the new links allow it (each link's relative velocity made
        normal to the link, summed from the held end; a start at rest stays at rest)."""
        e = V.real("eps", eps)
        if not math.isfinite(e) or abs(e) > 1e3:
            raise V.SnappingInputError(f"eps={eps!r} is out of range: the perturbation amplitude must be finite, "
                                       f"|eps| <= 1e3")
        if mode not in MODES:
            raise V.SnappingInputError(f"mode={mode!r} is not one of {MODES}")
        if kind not in KINDS:
            raise V.SnappingInputError(f"kind={kind!r} is not one of {KINDS}")
        kk = V.integer("k", k, 0)
        h = self.links.h
        s = np.concatenate([np.cumsum(h[::-1])[::-1], [0.0]])
        if mode == "sin":
            phi = np.sin(kk * np.pi * s / s[0])
        elif mode == "modes":
            a = np.random.default_rng(seed).standard_normal(RANDOM_MODES)
            j = np.arange(1, RANDOM_MODES + 1)
            phi = np.sin(np.pi * np.outer(s / s[0], j)) @ (a / j)
            phi[-1] = 0.0
            phi /= np.abs(phi).max()
        else:
            phi = np.random.default_rng(seed).standard_normal(self.N + 1)
            phi[-1] = 0.0
            phi /= np.abs(phi).max()
        n = np.asarray(self.normal)
        r, v = self.r, self.v
        if kind == "velocity":
            v = v + e * phi[:, None] * n[None, :]
        elif e != 0.0 and np.any(phi != 0.0):  # (a zero displacement leaves the start as it is, bit for bit)
            d = np.diff(r + (e * s[0]) * phi[:, None] * n[None, :], axis=0)  # link j: node j -> node j + 1
            d = d / np.linalg.norm(d, axis=1)[:, None]
            links = h[:, None] * d
            r = np.zeros_like(self.r)
            r[:-1] = -np.cumsum(links[::-1], axis=0)[::-1]  # from the held end (origin) outward
            dv = np.diff(self.v, axis=0)
            dv -= np.sum(dv * d, axis=1)[:, None] * d
            v = np.zeros_like(self.v)
            v[:-1] = -np.cumsum(dv[::-1], axis=0)[::-1]
            v += self.v[-1]  # (the held end's own velocity, the pin's at t = 0)
        pert = {"eps": e, "mode": mode, "seed": seed, "kind": kind}
        if mode == "sin":
            pert["k"] = kk
        start = {**self.start, "perturbation": pert}
        return replace(self, r=r, v=v, start=start)

    @classmethod
    def whirling(cls, omega: float, N: int | None = None, *, links: Links | None = None, gravity: float = 1.0,
                 **kw) -> "Problem3D":
        """The chain rotating steadily at rate ``omega`` about the vertical (gravity's direction,
        +y) through its held end, free end out (the first mode), in the plane z = 0 at t = 0
        with velocities ``omega yhat x r``. Its discrete shape: node by node from the free end
        (radius ``x0``), ``T_j e_j = T_{j-1} e_{j-1} - m_j (g yhat + omega^2 x_j xhat)``, with
        ``x0`` found (bisection, then Brent) so that the held end lies on the axis. Below the
        first critical rate (about ``1.2 sqrt(g/L)`` for a uniform chain) the only steady state
        is hanging straight: SnappingInputError."""
        from scipy.optimize import brentq

        links = Links.uniform(V.integer("N", N, 1)) if links is None else links
        w = V.real("omega", omega)
        g = V.real("gravity", gravity)
        h, m = links.h, links.m

        def shoot(x0):
            x, y, Fx, Fy = x0, 0.0, 0.0, 0.0
            pts = [(x, y)]
            for j in range(links.N):
                Fx, Fy = Fx - m[j] * w * w * x, Fy - m[j] * g
                T = math.hypot(Fx, Fy)
                x, y = x + h[j] * Fx / T, y + h[j] * Fy / T
                pts.append((x, y))
            return np.array(pts)

        L = links.length
        xs = np.linspace(1e-6 * L, L, 2001)
        xN = np.array([shoot(x)[-1, 0] for x in xs])
        P = None
        for k in np.flatnonzero(np.sign(xN[1:]) != np.sign(xN[:-1])) if w > 0.0 and g > 0.0 else []:
            x0 = brentq(lambda x: shoot(x)[-1, 0], xs[k], xs[k + 1], xtol=1e-15 * L, rtol=1e-15)
            Q = shoot(x0)
            if np.all(Q[:, 0] - Q[-1, 0] >= -1e-12 * L):  # (the first mode: the chain does not cross the axis)
                P = Q - Q[-1]
                break
        if P is None:
            raise V.SnappingInputError(f"omega={omega!r} has no steady whirling shape (gravity {g:g}): the rate must "
                                       f"exceed the chain's first critical rate (about 1.2 sqrt(g/L) uniform)")
        r = np.column_stack([P[:, 0], P[:, 1], np.zeros(links.N + 1)])
        v = np.column_stack([np.zeros(links.N + 1), np.zeros(links.N + 1), -w * P[:, 0]])
        return cls(links, r, v, gravity=g, start={"kind": "whirling", "omega": w, "x0": float(P[0, 0])}, **kw)

    @classmethod
    def nodes(cls, r, v=None, *, links: Links | None = None, **kw) -> "Problem3D":
        """Start from node coordinates ((N + 1, 3), row N the held end at the origin); ``links``
        default: uniform links of the chords' length (the chords must be equal)."""
        r = np.array(V.float_array("r", r), dtype=float)
        if r.ndim != 2 or r.shape[1] != 3 or r.shape[0] < 2:
            raise V.SnappingInputError(f"r must have 3 columns (x, y, z) and at least 2 rows; got shape {r.shape}")
        if links is None:
            links = Links.uniform(r.shape[0] - 1)
        if r.shape[0] != links.N + 1:
            raise V.SnappingInputError(f"r has {r.shape[0]} nodes but the chain has {links.N} links ({links.N + 1} "
                                       f"nodes)")
        from .shape3d import check_no_crossing

        check_no_crossing(r, name="r")
        if v is None:  # (at rest, or moving with the held end)
            v = np.zeros_like(r) + np.asarray(kw.get("pin", Pin3D()).velocity(0.0))[None, :]
        return cls(links, r, v, **kw)

    def with_pin(self, pin: Pin3D) -> "Problem3D":
        """This start with the held end moving as ``pin``: every node's velocity changed by the
        difference of the two motions' velocities at t = 0 (a Galilean shift: the motion
        relative to the held end is kept; nothing changes for motions that start at rest)."""
        if not isinstance(pin, Pin3D):
            raise V.SnappingInputError(f"pin={type(pin).__name__} is not a Pin3D")
        dv = np.asarray(pin.velocity(0.0)) - np.asarray(self.pin.velocity(0.0))
        return replace(self, pin=pin, v=self.v + dv[None, :])

    @classmethod
    def hanging(cls, N: int | None = None, *, links: Links | None = None, **kw) -> "Problem3D":
        """The chain hanging straight down (along +y) from its held end, at rest."""
        links = Links.uniform(V.integer("N", N, 1)) if links is None else links
        s = np.concatenate([np.cumsum(links.h[::-1])[::-1], [0.0]])
        r = np.column_stack([np.zeros_like(s), s, np.zeros_like(s)])
        return cls(links, r, np.zeros_like(r), start={"kind": "hanging"}, **kw)

    @classmethod
    def spun_up(cls, omega: float, N: int | None = None, *, radius: float = 0.05, ramp: float = 2.0,
                links: Links | None = None, gravity: float = 1.0, **kw) -> "Problem3D":
        """The whirl spun up: the chain hanging straight at rest, its held end driven around a
        horizontal circle of ``radius`` about the vertical (:meth:`Pin3D.circle`), the rate
        ramped from 0 to ``omega`` over ``ramp`` (continuous acceleration). No damping: the
        chain swings about the whirling shape of :meth:`whirling` rather than settling on it."""
        p = cls.hanging(N, links=links, gravity=gravity, **kw)
        p = p.with_pin(Pin3D.circle(radius, omega, ramp))
        return replace(p, start={"kind": "spun_up", "omega": float(omega), "radius": float(radius),
                                 "ramp": float(ramp)})

    @classmethod
    def curve(cls, points, N: int | None = None, *, links: Links | None = None, name: str = "curve",
              **kw) -> "Problem3D":
        """Nodes at chords exactly ``h_j`` along a curve in space: ``points`` ((n, 3), listed from
        the held end at the origin), interpolated by cubic splines on the cumulative chord
        length (:func:`snapping.spatial.shape3d.place_on_curve3d`); refused when the curve is
        too short for the chain or the placed chain crosses itself."""
        from .shape3d import check_no_crossing, place_on_curve3d

        links = Links.uniform(V.integer("N", N, 1)) if links is None else links
        r = place_on_curve3d(points, links.h, name=name)
        check_no_crossing(r, name=name)
        return cls(links, r, np.zeros_like(r), start={"kind": "curve", "name": str(name)}, **kw)

    # -- the compiled form
    def model(self):
        """The model tuple ``(par, h, invm)`` of :mod:`snapping.spatial.chain3d`."""
        g = self.gravity * np.asarray(self.g_dir)
        body = None
        if self.body_active:
            b = self.body
            body = {"arrays": b.node_arrays(self.links.h), "wind": b.wind, "tip_drag": b.tip_drag,
                    "signed": not np.all(b.node_values("curvature", self.links.h) == 0.0)}
        return C.make_model(self.links.h, 1.0 / self.links.m, g=g, pin=self.pin.model_args(), normal=self.normal,
                            body=body)

    def initial_state(self) -> np.ndarray:
        """``[e, u, W = 0]`` of the start (:func:`snapping.spatial.chain3d.nodes_to_state`), and
        ``D = 0`` (the energy dissipated) with a body."""
        y = C.nodes_to_state(self.r, self.v, self.links.h)
        return np.append(y, 0.0) if self.body_active else y
