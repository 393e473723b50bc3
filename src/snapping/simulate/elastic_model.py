"""The extensible line: lumped masses joined by tension-only springs (what it is made of).

A :class:`Problem` gives the geometry (link rest lengths ``h_j``, node masses ``m_j`` with the
tip mass, the start, the held end's motion, gravity); an :class:`Elastic` gives what the links
are made of: axial stiffness ``EA_j`` (a number or one per link) or a tension-strain table,
and Kelvin-Voigt damping ``c_j``. Together they make an :class:`ElasticLine`: planar node
positions with no constraint, link j carrying

    T_j = max(0, f_j(e_j) + c_j de_j/dt)  while e_j = l_j/h_j - 1 > 0,   T_j = 0 otherwise,

so a link shorter than its rest length carries nothing (slack) and a link never pushes. The
node masses are the problem's (:class:`Links`: for ``lumping="shared"`` the consistent lumped
masses), node 0 the free end, node N the held end, as everywhere in :mod:`snapping.simulate`.

Units are the project's: the chain's length L, mass M and g are 1, forces in M g; for a line
of mass per length lambda (= 1 for the uniform unit chain) ``EA`` in units of M g gives the
longitudinal wave speed ``c = sqrt(EA/lambda)`` in units of sqrt(g L)
(:meth:`Elastic.from_wave_speed`). Damping ``c_j`` is in M g sqrt(L/g) (a force per unit
strain rate).

Starts: ``"stretched"`` (default), the static equilibrium of the line hanging between the
start's two end nodes (both held), the minimum of its potential energy (convex for
tension-only links; :mod:`~snapping.simulate.elastic_statics`: a few O(N) Newton steps
from the start taken as a rigid chain, at any N and stiffness); or
``"unstretched"``, the nodes exactly at the problem's start (every link at its rest length:
no tension at t = 0, so the whole line first falls freely); or ``"matched"``, the problem's
start shape and velocities with each link stretched to the tension the rigid chain carries the
instant after release (:func:`~snapping.simulate.elastic_statics.matched`: every taut link's
length has zero second derivative at t = 0, so no release wave is launched; as EA -> infinity
it is the inextensible chain's release). ``"stretched"`` is a physical sudden release (a line
hanging between two holds, one let go: its unloading wave rings along the line); ``"matched"``
is the start to compare with the rigid chain.

A problem's :class:`~snapping.simulate.body.Body` (bending stiffness and damping, natural
curvature, drag, wind, a clamped held end) adds its node forces
(:mod:`~snapping.simulate.elastic_body`; methods ``"radau"`` and ``"dop853"``): the
``"stretched"`` start's statics then include the bending energy (its Newton iteration runs on
the full forces), the ``"matched"`` start takes the rigid chain's tensions with the body's
forces (:func:`~snapping.simulate.elastic_body.matched_body`).

Example
-------
>>> from snapping.simulate.problem import Links, Problem
>>> from snapping.simulate.elastic_model import Elastic, ElasticLine
>>> line = ElasticLine(Problem.catenary(0.25, links=Links.uniform(20, lumping="shared")), Elastic.from_wave_speed(30.0))
>>> round(float(line.ea[0]), 6), round(line.wave_speed, 6)
(900.0, 30.0)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .. import _validate as V
from . import elastic_kernels as EK

__all__ = ["Elastic", "ElasticLine", "STARTS"]

STARTS = ("stretched", "unstretched", "matched")
#: largest axial stiffness accepted (units of M g): c = 1e8 sqrt(g L) and more is beyond the doubles' use
EA_MAX = 1e16


@dataclass(frozen=True, eq=False)
class Elastic:
    """What the links are made of: ``ea`` (axial stiffness EA, units of M g: a number or one
    per link, index 0 at the free end), or ``table = (strain, tension)``, a tension-strain
    curve for every link (strains increasing from 0, tensions non-decreasing from 0,
    interpolated linearly, extended with the last slope; a first point other than (0, 0) is
    joined to (0, 0)); ``damping``: Kelvin-Voigt c (a number or one per link, >= 0), the
    tension ``+ c de/dt`` while taut (the total never below 0); ``grid_damping``: zeta >= 0, a
    further Kelvin-Voigt damping ``zeta h_j sqrt(EA_j lambda_j)`` per link, the damping ratio
    zeta for the line's shortest longitudinal mode (nodes moving against their neighbours,
    omega = 2 c/h) and about ``zeta omega/omega_max`` for a mode of frequency omega (the long
    waves: zeta pi h/(4 L) for the slowest), a numerical damping of the grid-scale ringing
    that the release excites (see the elastic guide: it takes most of the cost away).

    >>> Elastic(ea=100.0).describe()
    {'ea': 100.0, 'damping': 0.0, 'table': None, 'grid_damping': 0.0}
    >>> Elastic(ea=-1.0)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: ea=-1.0 is out of range: EA must be finite and in (0, 1e+16] (units of M g)
    """

    ea: object = None
    damping: object = 0.0
    table: tuple | None = None
    grid_damping: float = 0.0

    def __post_init__(self):
        if (self.ea is None) == (self.table is None):
            raise V.SnappingInputError(f"give exactly one of ea (axial stiffness) and table (tension-strain curve); "
                                       f"got ea={V._short(self.ea)}, table={V._short(self.table)}")
        if self.ea is not None:
            a = np.asarray(V.float_array("ea", self.ea), dtype=float)
            if a.ndim > 1 or a.size == 0:
                raise V.SnappingInputError(f"ea={V._short(self.ea)} must be a number or one number per link")
            bad = np.flatnonzero(~(np.isfinite(a.ravel()) & (a.ravel() > 0.0) & (a.ravel() <= EA_MAX)))
            if bad.size:
                v = float(a.ravel()[bad[0]])
                nm = "ea" if a.ndim == 0 else f"ea[{bad[0]}]"
                raise V.SnappingInputError(f"{nm}={v!r} is out of range: EA must be finite and in (0, {EA_MAX:g}] "
                                           f"(units of M g)")
            object.__setattr__(self, "ea", float(a) if a.ndim == 0 else a.copy())
        d = np.asarray(V.float_array("damping", self.damping), dtype=float)
        if d.ndim > 1 or d.size == 0:
            raise V.SnappingInputError(f"damping={V._short(self.damping)} must be a number or one number per link")
        bad = np.flatnonzero(~(np.isfinite(d.ravel()) & (d.ravel() >= 0.0)))
        if bad.size:
            nm = "damping" if d.ndim == 0 else f"damping[{bad[0]}]"
            raise V.SnappingInputError(f"{nm}={float(d.ravel()[bad[0]])!r} is out of range: Kelvin-Voigt damping "
                                       f"must be finite and >= 0")
        object.__setattr__(self, "damping", abs(float(d)) if d.ndim == 0 else d.copy())
        if self.table is not None:
            object.__setattr__(self, "table", _check_table(self.table))
        z = V.real("grid_damping", self.grid_damping)
        if not (np.isfinite(z) and z >= 0.0):
            raise V.SnappingInputError(f"grid_damping={z!r} is out of range: the damping ratio must be finite and >= 0")
        object.__setattr__(self, "grid_damping", float(z))

    @classmethod
    def from_wave_speed(cls, c: float, *, lam: float = 1.0, damping=0.0, grid_damping: float = 0.0) -> "Elastic":
        """EA = lambda c^2 for the wave speed ``c`` (units of sqrt(g L)) on a line of mass per
        length ``lam`` (units of M/L; 1 for the uniform unit chain).

        >>> Elastic.from_wave_speed(300.0).ea
        90000.0
        """
        c = V.positive("c", c)
        lam = V.positive("lam", lam)
        return cls(ea=lam * c * c, damping=damping, grid_damping=grid_damping)

    @classmethod
    def from_describe(cls, d) -> "Elastic":
        """The :class:`Elastic` of a :meth:`describe` dict (or its JSON text).

        >>> Elastic.from_describe(Elastic(ea=100.0, damping=0.5).describe()).describe()["damping"]
        0.5
        """
        import json

        if isinstance(d, str):
            try:
                d = json.loads(d)
            except ValueError:
                raise V.SnappingInputError(f"elastic={V._short(d)} is not the JSON of Elastic.describe()") from None
        if not isinstance(d, dict) or not set(d) <= {"ea", "damping", "table", "grid_damping"}:
            raise V.SnappingInputError(f"elastic={V._short(d)} is not an Elastic's description (keys ea, damping, "
                                       f"table, grid_damping)")
        tab = d.get("table")
        return cls(ea=d.get("ea"), damping=d.get("damping", 0.0), table=None if tab is None else tuple(tab),
                   grid_damping=d.get("grid_damping", 0.0))

    def describe(self) -> dict:
        def j(v):
            return v if np.ndim(v) == 0 else np.asarray(v).tolist()

        tab = None if self.table is None else [self.table[0].tolist(), self.table[1].tolist()]
        return {"ea": None if self.ea is None else j(self.ea), "damping": j(self.damping), "table": tab,
                "grid_damping": self.grid_damping}


def _check_table(table) -> tuple:
    try:
        e, t = (np.asarray(V.float_array(f"table[{k}]", v), dtype=float).ravel() for k, v in
                zip((0, 1), table))
    except (TypeError, ValueError) as exc:
        if isinstance(exc, V.SnappingInputError):
            raise
        raise V.SnappingInputError(f"table={V._short(table)} must be (strain, tension): two arrays") from None
    if e.size != t.size or e.size < 1:
        raise V.SnappingInputError(f"table: strain and tension must have the same length >= 1; got {e.size}, "
                                   f"{t.size}")
    if not (np.all(np.isfinite(e)) and np.all(np.isfinite(t))):
        raise V.SnappingInputError("table: strains and tensions must be finite")
    if e[0] < 0.0 or t[0] < 0.0:
        raise V.SnappingInputError(f"table: the first point ({e[0]!r}, {t[0]!r}) must have strain >= 0 and "
                                   f"tension >= 0")
    if e[0] == 0.0 and t[0] != 0.0:
        raise V.SnappingInputError(f"table: at strain 0 the tension must be 0; got {t[0]!r}")
    if e[0] > 0.0:
        e, t = np.concatenate([[0.0], e]), np.concatenate([[0.0], t])
    de, dt = np.diff(e), np.diff(t)
    if np.any(de <= 0.0):
        k = int(np.flatnonzero(de <= 0.0)[0])
        raise V.SnappingInputError(f"table: strains must increase; strain[{k + 1}]={e[k + 1]!r} <= {e[k]!r}")
    if np.any(dt < 0.0):
        k = int(np.flatnonzero(dt < 0.0)[0])
        raise V.SnappingInputError(f"table: tensions must not decrease (monotone); tension[{k + 1}]={t[k + 1]!r} "
                                   f"< {t[k]!r}")
    if dt[-1] <= 0.0:
        raise V.SnappingInputError("table: the last segment must rise (it is extended with its slope)")
    return e, t


class ElasticLine:
    """A :class:`Problem` made of :class:`Elastic` links: the compiled model's arrays.

    Attributes: ``N``, ``h``, ``m`` (node masses, tip mass included), ``ea``, ``damp`` (per
    link), ``tabe``, ``tabt``, ``tabw`` (the table, its energy; empty for a linear law),
    ``snode`` (rest arclength of each node from the held end), ``lam`` (mass per length of each
    link), ``g``, ``pin`` (the problem's :class:`PinMotion`).
    """

    def __init__(self, problem, elastic: Elastic, *, compression: bool | None = None):
        from .problem import Problem

        if not isinstance(problem, Problem):
            raise V.SnappingInputError(f"problem={type(problem).__name__} is not a snapping.simulate.Problem")
        if not isinstance(elastic, Elastic):
            raise V.SnappingInputError(f"elastic={type(elastic).__name__} is not a snapping.simulate.elastic.Elastic")
        self.problem, self.elastic = problem, elastic
        links = problem.links
        N = self.N = links.N
        self.h = links.h.astype(float)
        self.m = links.m.astype(float)
        self.g = float(problem.gravity)
        self.pin = problem.pin
        self.lam = (links.link_mass if links.link_mass is not None else links.m) / self.h
        self.snode = np.concatenate([np.cumsum(self.h[::-1])[::-1], [0.0]])[:N]

        def per_link(name, v):
            a = np.asarray(v, dtype=float)
            if a.ndim == 0:
                return np.full(N, float(a))
            if a.size != N:
                raise V.SnappingInputError(f"{name} has {a.size} entries; the line has {N} links")
            return a.astype(float).copy()

        self.damp = per_link("damping", elastic.damping)
        if elastic.table is not None:
            self.tabe, self.tabt = (np.ascontiguousarray(a) for a in elastic.table)
            seg = np.diff(self.tabe) * 0.5 * (self.tabt[1:] + self.tabt[:-1])
            self.tabw = np.concatenate([[0.0], np.cumsum(seg)])
            self.ea = np.full(N, (self.tabt[1] - self.tabt[0]) / (self.tabe[1] - self.tabe[0]))
        else:
            self.tabe = self.tabt = self.tabw = np.zeros(0)
            self.ea = per_link("ea", elastic.ea)
        if elastic.grid_damping > 0.0:
            self.damp = self.damp + elastic.grid_damping * self.h * np.sqrt(self.ea * self.lam)
        self._invm = 1.0 / self.m
        self._work = tuple(np.zeros(N) for _ in range(4))
        #: the problem's active :class:`Body` on this line (:class:`elastic_body.LineBody`), or None
        self.body = None
        if compression is not None and not isinstance(compression, (bool, np.bool_)):
            raise V.SnappingInputError(f"compression={compression!r} must be True, False or None (automatic)")
        if problem.body is not None and problem.body.active:
            from .elastic_body import LineBody

            self.body = LineBody(self, problem.body, compression)
        elif compression:
            raise V.SnappingInputError("compression=True needs a body with bending (problem.body): the line without "
                                       "one is tension-only")

    def solve_inputs(self, method: str, inputs: dict) -> None:
        """With a body: refuse a method that has none, record ``compression``
        (:func:`snapping.simulate.elastic_body.body_inputs`)."""
        if self.body is not None:
            from .elastic_body import body_inputs

            body_inputs(self, method, inputs)

    def check_method(self, method: str, asked=()) -> None:
        """With a body: refuse a method without one and checkpoint options
        (:func:`snapping.simulate.elastic_body.check_method`)."""
        if self.body is not None:
            from .elastic_body import check_method

            check_method(self, method, asked)

    @property
    def wave_speed(self) -> float:
        """The smallest longitudinal wave speed sqrt(EA_j/lambda_j) (initial slope for a table)."""
        return float(np.sqrt(self.ea / self.lam).min())

    # -- the state
    def pin_state(self, t: float) -> np.ndarray:
        if self.pin.kind == "fixed":  # (a fixed end: computed once; its kinematics cost a quarter of a run)
            if getattr(self, "_pin0", None) is None:
                x, y, vx, vy, _, _ = self.pin.kinematics(0.0)
                self._pin0 = np.array([x, y, vx, vy])
            return self._pin0
        x, y, vx, vy, _, _ = self.pin.kinematics(float(t))
        return np.array([x, y, vx, vy])

    def pack(self, x, y, vx, vy) -> np.ndarray:
        """The state vector (:mod:`elastic_kernels`) of N + 1 node values (the last the held end's), W = D = 0."""
        N = self.N
        z = np.zeros(4 * N + 2)
        z[0:4 * N:4], z[1:4 * N:4], z[2:4 * N:4], z[3:4 * N:4] = x[:N], y[:N], vx[:N], vy[:N]
        return z

    def unpack(self, z, t: float):
        """(x, y, vx, vy) of the N + 1 nodes (the held end's from the pin motion)."""
        p = self.pin_state(t)
        N = self.N
        return tuple(np.concatenate([z[k:4 * N:4], [p[k]]]) for k in range(4))

    def start(self, kind: str = "stretched") -> np.ndarray:
        """The state at t = 0: ``"unstretched"`` (the problem's nodes and velocities),
        ``"stretched"`` (the static equilibrium between the start's end nodes, at rest; only
        for a start at rest) or ``"matched"`` (the start's shape and velocities stretched to
        the rigid chain's tensions after release: :func:`snapping.simulate.elastic_statics.matched`)."""
        if not isinstance(kind, str) or kind not in STARTS:
            raise V.SnappingInputError(f"start={kind!r} is not one of {STARTS}")
        if kind == "matched":
            if self.body is not None:  # (the rigid chain's tensions with the body's forces)
                from .elastic_body import matched_body

                return matched_body(self)[0]
            from .elastic_statics import matched

            return matched(self)[0]
        p = self.problem
        z = self.pack(p.x, p.y, p.vx, p.vy)
        if kind == "stretched":
            if np.any(p.vx != p.vx[-1]) or np.any(p.vy != p.vy[-1]) or p.vx[-1] != 0.0 or p.vy[-1] != 0.0:
                sp = float(np.hypot(p.vx, p.vy).max())
                raise V.SnappingInputError(f"start='stretched' needs a start at rest; the problem's nodes move (speed up "
                                           f"to {sp:.6g}): use start='matched' (the rigid chain's tensions with these "
                                           f"velocities) or 'unstretched'")
            z = self.statics(z, hold_free_end=True)
        return z

    # -- the compiled model
    def rhs(self, t: float, z: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        dz = np.empty_like(z) if out is None else out
        if self.body is not None:
            return self.body.rhs(t, z, dz)
        EK.rhs(self.N, z, self.pin_state(t), self.h, self._invm, self.ea, self.damp, self.tabe, self.tabt, self.g,
               dz, *self._work)
        return dz

    def _pattern(self):
        """CSC structure of the block-tridiagonal Jacobian: (indices, indptr, order) so that
        ``csc_matrix((blocks.ravel()[order], indices, indptr))`` is the Jacobian."""
        if getattr(self, "_pat", None) is None:
            self._pat = EK.block_band_pattern(self.N, 3)
            self._blocks = np.zeros((self.N, 3, 4, 4))
        return self._pat

    def jac(self, t: float, z: np.ndarray) -> sp.csc_matrix:
        """The Jacobian of :meth:`rhs` (analytic, banded: 7 sub- and super-diagonals), sparse;
        with a body, 15 (:meth:`elastic_body.LineBody.jac`)."""
        if self.body is not None:
            return self.body.jac(t, z)
        indices, indptr, order = self._pattern()
        B = self._blocks
        EK.jac_blocks(self.N, z, self.pin_state(t), self.h, self._invm, self.ea, self.damp, self.tabe, self.tabt,
                      B, *self._work)
        n = 4 * self.N + 2
        return sp.csc_matrix((B.ravel()[order], indices, indptr), shape=(n, n))

    def measure(self, t: float, z: np.ndarray) -> np.ndarray:
        if self.body is not None:
            return self.body.measure(t, z)
        out = np.zeros(EK.NMEAS)
        EK.measure(self.N, z, self.pin_state(t), self.h, self.m, self.ea, self.damp, self.tabe, self.tabt,
                   self.tabw, self.g, self.snode, np.empty_like(z), *self._work, out)
        return out

    def link_state(self, t: float, z: np.ndarray):
        """(tension, strain, strain rate) of every link."""
        T, E, ED, FV = (np.zeros(self.N) for _ in range(4))
        EK.tensions(self.N, z, self.pin_state(t), self.h, self.ea, self.damp, self.tabe, self.tabt, T, E, ED, FV)
        return T, E, ED

    def energy(self, t: float, z: np.ndarray) -> float:
        """Kinetic + gravity + elastic energy (zero hanging unstretched at rest from the origin);
        with a body the elastic energy includes the bending energy V_b."""
        mm = self.measure(t, z)
        return float(mm[12] + mm[13] + mm[14])

    # -- statics
    def statics(self, z0: np.ndarray, *, hold_free_end: bool = False, tol: float = 1e-12,
                max_iter: int = 200) -> np.ndarray:
        """The static equilibrium nearest ``z0`` (:func:`snapping.simulate.elastic_statics.statics`);
        ``self.statics_iterations`` records the Newton steps it took."""
        from .elastic_statics import statics

        return statics(self, z0, hold_free_end=hold_free_end, tol=tol, max_iter=max_iter)
