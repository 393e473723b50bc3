"""A catalogue of real lines: a steel ball chain, nylon monofilament, a fly line, a bullwhip,
a climbing rope and a bungee cord, in SI, with their sources.

Each entry is a :class:`Line`: mass per length, diameter, bending stiffness EI, drag
coefficients, axial stiffness EA where known (for the elastic work to come), an optional
taper and tip body, and where every number comes from. Values from a standard, a paper or
a data sheet say so; the others are **estimates**, and :attr:`Line.estimates` says how each
was derived. Use a line by name::

    >>> from snapping import lines
    >>> fly = lines.get("fly-line")
    >>> round((fly.mass(0.1524 + 9.144) - fly.mass(0.1524)) * 1e3, 3)   # g in 30 ft after the tip: 140 grains
    9.072
    >>> body = fly.body(9.144)             # the Body of 30 ft of line (a snapping.simulate.Body)
    >>> problem = fly.problem(0.25, 40, length=9.144)   # its catenary start, tapered masses included
    >>> lines.get("fly line")
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: line='fly line' is not in the catalogue; valid names: ball-chain, nylon-monofilament, fly-line, bullwhip, climbing-rope, bungee-cord

(:meth:`snapping.simulate.Body.from_line` is the same as ``lines.get(name).body(...)``; the
command line's ``--line NAME`` takes the same names, every value overridable by the SI options.)

A taper scales the diameter by a ratio r (piecewise linear between stations measured from the
free end: in metres for a fly line, whose head has a fixed profile, or as a fraction of the
length for a whip, which scales with its length); one material throughout gives the mass per
length ``lambda0 r^2`` and the bending stiffness ``EI0 r^4`` (``lambda0``, ``EI0``, ``diameter``:
the values where r = 1).

Sources (the full references; each entry cites its own in :attr:`Line.sources`):

* [Tomaszewski2006] W. Tomaszewski, P. Pieranski and J.-C. Geminard, "The motion of a freely
  falling chain tip", Am. J. Phys. 74, 776 (2006): the ball chain of the experiments the paper
  (arXiv:2206.07864) compares with, length 1.022 m, mass 20.8 g, 229 links.
* [AFFTA] American Fly Fishing Trade Association, fly line standards (from the AFTMA standard
  of 1961): a 5-weight line's first 30 ft, its level tip excluded, weighs 140 +- 6 grains.
* [Spolek1986] G. A. Spolek, "The mechanics of flycasting: the flyline", Am. J. Phys. 54, 832
  (1986); [GattiBono2002] C. Gatti-Bono and N. C. Perkins, "Physical and numerical modelling of
  the dynamic behavior of a fly line", J. Sound Vib. 255, 555 (2002).
* [Krehl1998] P. Krehl, S. Engemann and D. Schwenkel, "The puzzle of whip cracking -
  uncovered by a correlation of whip-tip kinematics with shock wave emission", Shock Waves 8,
  1 (1998); [Goriely2002] A. Goriely and T. McMillen, "Shape of a cracking whip", Phys. Rev.
  Lett. 88, 244301 (2002).
* [EN892] EN 892 / UIAA 101, dynamic mountaineering ropes: a single rope's static elongation
  (80 kg after a 5 kg preload) at most 10 %, impact force at most 12 kN; single ropes weigh
  60 to 85 g/m (Mammut, "Standards for dynamic ropes", manufacturer's technical notes).
* [Hoerner1965] S. F. Hoerner, Fluid-Dynamic Drag (1965): C_n = 1.2 for a long circular
  cylinder in cross-flow at subcritical Reynolds numbers; a sphere's C_d = 0.47.
* [Nylon] nylon 6 and 6,6: density 1.13-1.14 g/cm^3, tensile modulus 1.5-3 GPa for drawn
  monofilament (polymer data handbooks, e.g. J. E. Mark (ed.), Polymer Data Handbook, 1999).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np

from . import _validate as V

__all__ = ["Line", "CATALOGUE", "get", "names"]

#: the units of each SI field of a Line
UNITS = {"mass_per_length": "kg m-1", "diameter": "m", "ei": "N m2", "ea": "N", "cd_normal": "1",
         "cd_tangential": "1", "tip_drag_area": "m2", "tip_mass": "kg", "length": "m", "pitch": "m"}
#: the profiles of :meth:`Line.profile` (the diameter ratio's powers 1, 2, 4)
PROFILES = ("diameter", "mass_per_length", "ei")
#: the keywords of :meth:`snapping.simulate.Body.from_si` that :meth:`Line.body` passes on as overrides
BODY_KEYS = ("ei", "bending_damping", "curvature", "diameter", "air_density", "cd_normal", "cd_tangential",
             "tip_drag_area", "wind", "drag_linear_normal", "drag_linear_tangential", "clamp")


@lru_cache(maxsize=64)
def _stations(taper: tuple) -> tuple:
    """A taper's stations ``(x, r)`` as two read-only float arrays, made once per taper (:meth:`Line.ratio` is
    called per node and per quadrature point when a tapered line's chain is built: 246,326 times in the fly line's
    answer at chi 0.1 before its runs read their profiles once, ``caps_runs._on_nodes``)."""
    xs, rs = (np.asarray(c, dtype=float) for c in zip(*taper))
    xs.flags.writeable = False
    rs.flags.writeable = False
    return xs, rs


@dataclass(frozen=True)
class Line:
    """A real line in SI (see the module's text for the sources).

    Attributes
    ----------
    name, title : str
        The catalogue name (``fly-line``) and a description.
    mass_per_length : float
        lambda0, kg/m, where the taper ratio is 1 (the whole line without a taper).
    diameter : float
        m, where the ratio is 1 (drag per length 0.5 rho C_n d |v_n| v_n).
    ei : float
        Bending stiffness EI0, N m^2, where the ratio is 1.
    cd_normal, cd_tangential : float
        Cross-flow drag coefficient on d, skin-friction coefficient on pi d
        (:func:`snapping.units.body_numbers`).
    ea : float or None
        Axial stiffness EA, N (None: not known; an inextensible line here).
    length : float
        A typical length, m (the default of :meth:`body`).
    taper : tuple of (x, r) or None
        Diameter ratio r at distances x from the free end (piecewise linear, constant beyond).
    taper_units : str
        ``"m"`` (x in metres) or ``"fraction"`` (x as a fraction of the length).
    tip_mass, tip_drag_area : float
        A tip body at the free end (a fly, a cracker): kg and its drag area C_d A in m^2.
    pitch : float or None
        A line of discrete links (a ball chain): its link length, m; its answers run on its own
        round(length/pitch) links (:meth:`own_links`), where 1% in the links has no meaning (a
        chain is its links). None: a continuous line.
    sources : tuple of str
        The references (keys of the module's text, with what each gives).
    estimates : dict
        For each value that is an estimate, how it was derived.
    """

    name: str
    title: str
    mass_per_length: float
    diameter: float
    ei: float
    cd_normal: float
    cd_tangential: float
    ea: float | None
    length: float
    taper: tuple | None = None
    taper_units: str = "m"
    tip_mass: float = 0.0
    tip_drag_area: float = 0.0
    pitch: float | None = None
    sources: tuple = ()
    estimates: dict = field(default_factory=dict)

    def __post_init__(self):
        for k in ("name", "title"):
            if not isinstance(getattr(self, k), str):
                raise V.SnappingInputError(f"{k}={getattr(self, k)!r} is not a string")
        for k in ("mass_per_length", "diameter", "length"):
            V.positive(k, getattr(self, k))
        for k in ("ei", "cd_normal", "cd_tangential", "tip_mass", "tip_drag_area"):
            v = V.real(k, getattr(self, k))
            if not (math.isfinite(v) and v >= 0.0):
                raise V.SnappingInputError(f"{k}={v!r} is out of range: must be finite and >= 0 ({UNITS[k]})")
        if self.ea is not None:
            V.positive("ea", self.ea)
        if self.pitch is not None:
            V.positive("pitch", self.pitch)
            self.own_links()  # (its length holds 2 to 20000 links)
        if self.taper_units not in ("m", "fraction"):
            raise V.SnappingInputError(f"taper_units={self.taper_units!r} is not one of ('m', 'fraction')")
        if self.taper is not None:
            try:
                x, r = (np.asarray(c, dtype=float) for c in zip(*self.taper))
            except (TypeError, ValueError):
                raise V.SnappingInputError(f"taper={self.taper!r} must be stations (x, ratio) with x increasing "
                                           f"from >= 0 and ratios > 0") from None
            if x.size < 2 or not (np.all(np.diff(x) > 0) and x[0] >= 0 and np.all(np.isfinite(r)) and np.all(r > 0)):
                raise V.SnappingInputError(f"taper={self.taper!r} must be stations (x, ratio) with x increasing "
                                           f"from >= 0 and ratios > 0")

    def own_links(self, length: float | None = None) -> int | None:
        """The number of links of ``length`` m (default :attr:`length`) of a line of discrete links,
        round(length/pitch); None for a continuous line (no :attr:`pitch`)."""
        return own_links(self.pitch, self.length if length is None else length)

    # -- the profile
    def ratio(self, x, length: float | None = None):
        """The diameter ratio at distance ``x`` (m) from the free end of a line of ``length`` m."""
        if self.taper is None:
            return np.ones_like(np.asarray(x, dtype=float)) if np.ndim(x) else 1.0
        try:
            xs, rs = _stations(self.taper)
        except TypeError:  # stations given as lists (unhashable): made on each call
            xs, rs = (np.asarray(c, dtype=float) for c in zip(*self.taper))
        if self.taper_units == "fraction":
            xs = xs * (self.length if length is None else length)
        out = np.interp(np.asarray(x, dtype=float), xs, rs)
        return out if np.ndim(x) else float(out)

    def mass(self, length: float | None = None) -> float:
        """The mass (kg) of the first ``length`` m from the free end (default: :attr:`length`),
        tip body excluded: lambda0 times the integral of r^2 (exact: Simpson on each linear piece)."""
        L = self.length if length is None else V.positive("length", length)
        if self.taper is None:
            return self.mass_per_length * L
        xs = np.asarray([x for x, _ in self.taper], dtype=float)
        if self.taper_units == "fraction":
            xs = xs * L
        edges = np.unique(np.concatenate([[0.0, L], xs[(xs > 0) & (xs < L)]]))
        a, b = edges[:-1], edges[1:]
        r2 = lambda x: self.ratio(x, L) ** 2  # noqa: E731
        integral = np.sum((b - a) / 6.0 * (r2(a) + 4.0 * r2(0.5 * (a + b)) + r2(b)))
        return float(self.mass_per_length * integral)

    def profile(self, name: str, length: float | None = None):
        """``"ei"``, ``"diameter"`` or ``"mass_per_length"`` as a function of the arclength s (m)
        from the held end of a line of ``length`` m (a number when the line has no taper)."""
        if not isinstance(name, str) or name not in PROFILES:
            raise V.SnappingInputError(f"name={name!r} is not a profile of a line; valid: {', '.join(PROFILES)}")
        power = {"diameter": 1, "mass_per_length": 2, "ei": 4}[name]
        L = self.length if length is None else V.positive("length", length)
        v0 = getattr(self, name)
        if self.taper is None:
            return v0

        def f(s):
            return v0 * self.ratio(L - s, L) ** power

        def on_array(s):  # f at every s of an array, the same floats (the power by Python's float **)
            return [v0 * r ** power for r in self.ratio(L - np.asarray(s, dtype=float), L).tolist()]

        f.__name__ = f"{self.name} {name}"
        f.on_array = on_array
        return f

    # -- in the simulator
    def si(self, length: float | None = None) -> dict:
        """The keywords of :meth:`snapping.simulate.Body.from_si` for ``length`` m of this line
        (with ``length`` and ``mass``; profiles as functions of s in m from the held end)."""
        L = self.length if length is None else V.positive("length", length)
        kw = {"length": L, "mass": self.mass(L), "ei": self.profile("ei", L),
              "diameter": self.profile("diameter", L), "cd_normal": self.cd_normal,
              "cd_tangential": self.cd_tangential}
        if self.tip_drag_area:
            kw["tip_drag_area"] = self.tip_drag_area
        return kw

    def body(self, length: float | None = None, g: float = 9.81, **overrides):
        """The :class:`snapping.simulate.Body` of ``length`` m of this line under ``g``; any
        keyword of :meth:`snapping.simulate.Body.from_si` overrides the catalogue's value
        (``ei=``, ``diameter=``, ``cd_normal=``, ..., and ``clamp=``, ``wind=`` besides)."""
        from .simulate import Body

        bad = sorted(set(overrides) - set(BODY_KEYS))
        if bad:
            raise V.SnappingInputError(f"{bad[0]}= is not a body override of a line; valid: {', '.join(BODY_KEYS)}")
        kw = self.si(length)
        kw.update(overrides)
        return Body.from_si(kw.pop("length"), kw.pop("mass"), g, **kw)

    def links(self, N: int, length: float | None = None):
        """The chain of ``N`` equal links of ``length`` m of this line (nondimensional: total
        length 1, the line's mass 1): tapered masses from lambda0 r^2, consistently lumped,
        and the tip body's mass; the paper's uniform chain for a uniform line without one."""
        from .simulate import Links

        N = V.integer("N", N, 1)
        L = self.length if length is None else V.positive("length", length)
        M = self.mass(L)
        if self.taper is None and self.tip_mass == 0.0:
            return Links.uniform(N)
        lam = M / L
        return Links.from_density(np.full(N, 1.0 / N),
                                  lambda u: self.mass_per_length * self.ratio(L * (1.0 - u), L) ** 2 / lam,
                                  tip_mass=self.tip_mass / M, kind="line", params={"line": self.name})

    def problem(self, chi: float, N: int, length: float | None = None, *, pin=None, g: float = 9.81, **overrides):
        """The catenary start of end separation ``chi`` for ``N`` links of ``length`` m of this
        line, with its body (``overrides`` as in :meth:`body`) and held end ``pin``."""
        from .simulate import Problem

        return Problem.catenary(chi, links=self.links(N, length), pin=pin, body=self.body(length, g, **overrides))

    def numbers(self, length: float | None = None, g: float = 9.81) -> dict:
        """The nondimensional numbers of ``length`` m of this line (issue 24's, with the mean
        mass per length lambda = M/L): ``beta`` = EI0/(lambda g L^3) where r = 1, the drag
        numbers c_n, c_t there, ``stretch`` = sqrt(EA/lambda)/sqrt(g L) (None without EA),
        ``tip_mass`` = m/M."""
        from .units import body_numbers

        L = self.length if length is None else V.positive("length", length)
        M = self.mass(L)
        n = body_numbers(L, M, g, ei=self.ei, diameter=self.diameter, cd_normal=self.cd_normal,
                         cd_tangential=self.cd_tangential)
        stretch = None if self.ea is None else math.sqrt(self.ea / (M / L)) / math.sqrt(g * L)
        return {"beta": n["bending"], "drag_normal": n["drag_normal"], "drag_tangential": n["drag_tangential"],
                "stretch": stretch, "tip_mass": self.tip_mass / M}

    def replace(self, **changes) -> "Line":
        """This line with catalogue values changed (``mass_per_length=``, ``ea=``, ...)."""
        fields = [f for f in self.__dataclass_fields__]
        bad = sorted(set(changes) - set(fields))
        if bad:
            raise V.SnappingInputError(f"{bad[0]}= is not a field of a Line; valid: {', '.join(fields)}")
        return replace(self, **changes)


def own_links(pitch, length: float) -> int | None:
    """round(length/pitch): the links of a line of discrete links of ``pitch`` m (None: a
    continuous line), refused outside 2 to 20000 links naming both values.

    >>> own_links(1.022 / 229, 1.022), own_links(None, 3.0)
    (229, None)
    """
    if pitch is None:
        return None
    n = round(float(length) / float(pitch))
    if not 2 <= n <= 20000:
        raise V.SnappingInputError(f"pitch={pitch!r} m with length={length!r} m is out of range: a line of discrete "
                                   f"links holds 2 to 20000 of them (length/pitch = {float(length) / float(pitch):.6g})")
    return int(n)


_HOERNER = "[Hoerner1965] C_n = 1.2, a long cylinder in subcritical cross-flow"
_CT = ("C_t = 0.01: an estimate (skin friction of a long slender cylinder in axial flow is 0.005 to 0.02; "
       "the default of snapping.units.CD_TANGENTIAL)")

#: 30 ft after a 6 in (0.1524 m) level tip weigh 140 grains [AFFTA]; the ratio profile of the WF-5 head below
_FT, _GRAIN = 0.3048, 64.79891e-6
_WF5 = ((0.0, 0.7), (0.1524, 0.7), (2.0, 1.0), (11.0, 1.0), (13.5, 0.7))


def _wf5_lambda0() -> float:
    """lambda0 (kg/m) of the WF-5 head such that 30 ft after its level tip weigh 140 grains."""
    unit = Line("x", "", 1.0, 1.0, 0.0, 0.0, 0.0, None, 30.0, taper=_WF5)
    return 140 * _GRAIN / (unit.mass(0.1524 + 30 * _FT) - unit.mass(0.1524))


#: the catalogue, by name
CATALOGUE: dict[str, Line] = {ln.name: ln for ln in (
    Line("ball-chain", "steel ball chain of the falling-chain experiments (Tomaszewski et al. 2006)",
         mass_per_length=0.0208 / 1.022, diameter=3.0e-3, ei=0.0, cd_normal=0.25, cd_tangential=0.08, ea=None,
         length=1.022, pitch=1.022 / 229,
         sources=("[Tomaszewski2006]: length 1.022 m, mass 20.8 g, 229 links (the paper's chain)",
                  "[Hoerner1965]: a sphere's C_d = 0.47"),
         estimates={
             "diameter": "3.0 mm: an estimate, about 0.7 of the pitch 1.022 m / 229 = 4.46 mm (ball chains' balls "
                         "are hollow; solid steel balls of 20.4 g/m would be 2.8 mm)",
             "ei": "0: hinged links carry no moment until they lock at their largest angle",
             "cd_normal": "0.25: derived, one sphere (C_d 0.47 on pi d^2/4) per pitch p, on d per length: "
                          "0.47 (pi/4) d/p",
             "cd_tangential": "0.08: derived likewise on pi d per length: 0.47 d/(4 p) (the balls meet the air "
                              "alike from every side)",
             "ea": "None: steel links are inextensible here (their play, not their elasticity, sets any stretch)"}),
    Line("nylon-monofilament", "nylon monofilament fishing line, 0.30 mm (about 10 lb test)",
         mass_per_length=1140.0 * math.pi * 0.30e-3 ** 2 / 4, diameter=0.30e-3,
         ei=2.0e9 * math.pi * 0.30e-3 ** 4 / 64, cd_normal=1.2, cd_tangential=0.01,
         ea=2.0e9 * math.pi * 0.30e-3 ** 2 / 4, length=10.0,
         sources=("[Nylon]: density 1140 kg/m^3, modulus 1.5-3 GPa", _HOERNER),
         estimates={
             "mass_per_length": "derived: 1140 kg/m^3 times pi d^2/4 (8.06e-5 kg/m)",
             "ei": "derived: E pi d^4/64 with E = 2 GPa, an estimate within the 1.5-3 GPa of drawn nylon "
                   "(lower when wet)",
             "ea": "derived: E pi d^2/4 with the same E (141 N)",
             "cd_tangential": _CT}),
    Line("fly-line", "WF-5 floating fly line (weight forward, 5-weight)",
         mass_per_length=_wf5_lambda0(), diameter=1.1e-3, ei=2.0e-5, cd_normal=1.2, cd_tangential=0.01, ea=None,
         length=30 * _FT, taper=_WF5, taper_units="m", tip_mass=5e-5, tip_drag_area=1e-4,
         sources=("[AFFTA]: the first 30 ft after the level tip weigh 140 grains (9.07 g)",
                  "[Spolek1986], [GattiBono2002]: fly-line dynamics with normal and tangential drag", _HOERNER),
         estimates={
             "mass_per_length": "derived: lambda0 (the belly's, 1.05 g/m) such that the taper below puts 140 "
                                "grains in the 30 ft after the tip [AFFTA]",
             "diameter": "1.1 mm belly: an estimate (makers list 5-weight belly diameters of about 1.0 to 1.3 mm; "
                         "with 1.05 g/m a density of 1.1 g/cm^3)",
             "taper": "an estimate of a generic WF-5 head, from the tip: level tip 0.15 m at ratio 0.7, front "
                      "taper to 2.0 m, belly to 11.0 m, rear taper to 13.5 m, running line at 0.7; lambda ~ r^2, "
                      "EI ~ r^4 (one coating material)",
             "ei": "2e-5 N m^2: an estimate (a PVC coating of modulus 10-100 MPa on I = pi d^4/64 = 7.2e-14 m^4 "
                   "gives 1e-6 to 1e-5, the braided core adds to it)",
             "cd_tangential": _CT,
             "tip_mass": "0.05 g: an estimate for a dry fly",
             "tip_drag_area": "1e-4 m^2: an estimate, a fly about 1 cm across with C_d about 1",
             "ea": "None: not known here (the core's stretch is a few per cent at casting loads)"}),
    Line("bullwhip", "8-ft leather bullwhip thong, a cone from the handle to the tip, with a cracker",
         mass_per_length=1000.0 * math.pi * 0.015 ** 2 / 4, diameter=0.015, ei=5e7 * math.pi * 0.015 ** 4 / 64,
         cd_normal=1.2, cd_tangential=0.01, ea=None, length=2.44, taper=((0.0, 0.2), (1.0, 1.0)),
         taper_units="fraction", tip_mass=1e-3, tip_drag_area=1e-4,
         sources=("[Krehl1998]: the tip's supersonic motion and the crack", "[Goriely2002]: the tapered whip",
                  _HOERNER),
         estimates={
             "length": "2.44 m (8 ft): a common bullwhip's length",
             "diameter": "15 mm at the handle, 3 mm at the tip (taper): estimates for a plaited leather thong",
             "mass_per_length": "derived: leather of about 1000 kg/m^3 over the 15 mm section (0.177 kg/m; the "
                                "cone weighs 0.18 kg)",
             "ei": "derived: E pi d^4/64 with E = 50 MPa, an estimate for plaited leather (0.124 N m^2 at the "
                   "handle, 625 times less at the tip)",
             "taper": "a cone: d linear from the handle to 0.2 of it at the tip, lambda ~ r^2, EI ~ r^4",
             "tip_mass": "1 g: an estimate for a nylon cracker (popper)",
             "tip_drag_area": "1e-4 m^2: an estimate for the cracker's frayed end (C_d A)",
             "cd_tangential": _CT,
             "ea": "None: no published value found (the plaited thong is inextensible here)"}),
    Line("climbing-rope", "dynamic single climbing rope, 9.8 mm (EN 892)",
         mass_per_length=0.062, diameter=9.8e-3, ei=6e-4, cd_normal=1.2, cd_tangential=0.01,
         ea=75 * 9.81 / 0.08, length=30.0,
         sources=("[EN892]: static elongation <= 10 % (80 kg after 5 kg), single ropes 60-85 g/m", _HOERNER),
         estimates={
             "mass_per_length": "62 g/m: a typical data-sheet value of a 9.8 mm single rope (within [EN892]'s "
                                "60-85 g/m)",
             "ea": "derived: 75 kg x g over a static elongation of 8 % (data sheets give 6-9 %; [EN892] allows "
                   "10 %): 9.2 kN (the dynamic stiffness in a fall is of the same order)",
             "ei": "6e-4 N m^2: an estimate from a bending length (EI/(lambda g))^(1/3) of about 10 cm (the "
                   "length a kernmantle rope sticks out before it droops): lambda g (0.1 m)^3",
             "cd_tangential": _CT}),
    Line("bungee-cord", "bungee (shock) cord, 10 mm: rubber strands in a braided sheath",
         mass_per_length=0.065, diameter=10e-3, ei=1e-3, cd_normal=1.2, cd_tangential=0.01, ea=200.0, length=1.0,
         sources=(_HOERNER,),
         estimates={
             "mass_per_length": "65 g/m: an estimate, 900 kg/m^3 (rubber and sheath with voids) over pi d^2/4",
             "ea": "200 N: a rough estimate (a 10 mm shock cord doubles its length under some 200 N; rubber "
                   "E of 1-2 MPa on the core alone gives 100 N); the force is far from linear beyond 50 %",
             "ei": "1e-3 N m^2: an estimate, E pi d^4/64 with E = 2 MPa for the rubber core (1e-3), the sheath "
                   "adding little",
             "cd_tangential": _CT}),
)}


def names() -> list[str]:
    """The catalogue's names."""
    return list(CATALOGUE)


def get(name: str) -> Line:
    """The catalogue's line ``name`` (:func:`names`); a bad name lists the valid ones."""
    if not isinstance(name, str) or name not in CATALOGUE:
        raise V.SnappingInputError(f"line={name!r} is not in the catalogue; valid names: {', '.join(CATALOGUE)}")
    return CATALOGUE[name]
