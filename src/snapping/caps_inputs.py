"""The inputs of a design answer (:mod:`snapping.caps`): the line and the end separations, checked.

This module owns what :func:`snapping.caps.cap` and :func:`snapping.caps.design` are given,
before any run: :class:`LineSpec` (a line in SI) and :func:`spec`, which builds it from a
catalogue line (:mod:`snapping.lines`), a :class:`snapping.lines.Line` or the parameters alone;
the overrides of a line's parameters (``**params`` of :func:`snapping.caps.cap`: each keyword
checked against :data:`SPEC_KEYS` and its range, :func:`as_spec`); and the list of end
separations of a design (:func:`check_chis`). A bad value is a
:class:`snapping.SnappingInputError` naming it, its value and its valid range. The public names
(:class:`LineSpec`, :func:`spec`, :data:`SPEC_KEYS`, :data:`SPEC_UNITS`, :data:`END_MASS_MAX`) are
importable from :mod:`snapping.caps` as before.

>>> spec(None, length=2.0, mass=0.1).mass
0.1
>>> check_chis((0.5, 0.2))
[0.2, 0.5]
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, replace

from . import _validate as V

__all__ = ["LineSpec", "spec", "as_spec", "check_chis", "SPEC_KEYS", "SPEC_UNITS", "END_MASS_MAX"]


@dataclass(frozen=True)
class LineSpec:
    """A line in SI, checked (:func:`spec`): what :func:`snapping.caps.cap` runs. ``ei`` and
    ``diameter`` may be functions of the arclength s (m) from the held end (a catalogue line's taper)."""

    name: str
    length: float
    mass: float
    g: float
    ei: object = 0.0
    ea: float | None = None
    diameter: object = None
    cd_normal: float | None = None
    cd_tangential: float | None = None
    air_density: float | None = None
    end_mass: float = 0.0
    tip_drag_area: float = 0.0
    line: object = None  # the snapping.lines.Line with a taper, or None
    pitch: float | None = None  # a line of discrete links (snapping.lines.Line.pitch): its link length, m

    def own_links(self) -> int | None:
        """A line of discrete links: its round(length/pitch) links (None: a continuous line)."""
        from .lines import own_links

        return own_links(self.pitch, self.length)

    def has(self, mechanism: str) -> bool:
        """Whether the line has this mechanism at all."""
        if mechanism == "bending":
            return callable(self.ei) or self.ei > 0.0
        if mechanism == "drag":
            return self.diameter is not None or self.tip_drag_area > 0.0
        if mechanism == "end-mass":
            return self.end_mass > 0.0
        if mechanism == "taper":
            return self.line is not None and self.line.taper is not None
        return self.ea is not None  # stretching

    def numbers(self, N: int | None = None) -> dict:
        """The nondimensional numbers (:func:`snapping.dimensionless.line_numbers`; a taper's at the held end)."""
        from .dimensionless import line_numbers

        at0 = (lambda v: v(0.0) if callable(v) else v)  # noqa: E731
        return line_numbers(self.length, self.mass, self.g, N=N, ei=at0(self.ei), ea=self.ea,
                            diameter=at0(self.diameter), air_density=self.air_density, cd_normal=self.cd_normal,
                            cd_tangential=self.cd_tangential, end_mass=self.end_mass)


def _nonneg(name: str, v, unit: str) -> float:
    x = V.real(name, v)
    if not (math.isfinite(x) and x >= 0.0):
        raise V.SnappingInputError(f"{name}={v!r} is out of range: must be finite and >= 0 ({unit})")
    return x


def _pos(name: str, v, unit: str) -> float:
    x = V.real(name, v)
    if not (math.isfinite(x) and x > 0.0):
        raise V.SnappingInputError(f"{name}={v!r} is out of range: must be finite and > 0 ({unit})")
    return x


#: the keywords of :func:`spec` (what ``**params`` of :func:`snapping.caps.cap` and ``design`` may hold)
SPEC_KEYS = ("length", "mass", "g", "ei", "ea", "diameter", "cd_normal", "cd_tangential", "air_density",
             "end_mass", "tip_drag_area")
#: the units of each keyword of :func:`spec`
SPEC_UNITS = {"length": "m", "mass": "kg", "g": "m s-2", "ei": "N m2", "ea": "N", "diameter": "m", "cd_normal": "1",
              "cd_tangential": "1", "air_density": "kg m-3", "end_mass": "kg", "tip_drag_area": "m2"}
_NONNEG = ("ei", "end_mass", "tip_drag_area", "cd_normal", "cd_tangential")


def _check_params(params: dict) -> None:
    """Refuse a keyword that :func:`spec` does not take, and check each value given (None: not
    given) against its range, naming it: a bad keyword is a SnappingInputError, not a TypeError."""
    bad = sorted(k for k in params if k not in SPEC_KEYS)
    if bad:
        raise V.SnappingInputError(f"{bad[0]}={params[bad[0]]!r} is not a parameter of a line; valid: "
                                   f"{', '.join(SPEC_KEYS)}")
    for k, v in params.items():
        if v is None:
            continue
        (_nonneg if k in _NONNEG else _pos)(k, v, SPEC_UNITS[k])
        if k in ("length", "mass", "g"):  # (the SI scales: beyond, the SI values leave the doubles)
            lo, hi = V.SI_SCALE_RANGE
            if not lo <= float(v) <= hi:
                raise V.SnappingInputError(f"{k}={float(v)!r} {SPEC_UNITS[k]} is out of range: must lie in "
                                           f"[{lo:g}, {hi:g}] (beyond, the SI values leave the doubles)")


def spec(line=None, *, length=None, mass=None, g: float = 9.81, ei=None, ea=None, diameter=None, cd_normal=None,
         cd_tangential=None, air_density=None, end_mass=None, tip_drag_area=None) -> LineSpec:
    """The :class:`LineSpec` of ``line`` (a catalogue name, a :class:`snapping.lines.Line`, or
    None: the parameters alone, then ``length`` and ``mass`` are needed), every value
    overridable: ``length`` m, ``mass`` kg (the line's, without the end mass), ``g`` m/s^2,
    ``ei`` N m^2, ``ea`` N, ``diameter`` m, ``cd_normal``, ``cd_tangential``, ``air_density``
    kg/m^3, ``end_mass`` kg, ``tip_drag_area`` m^2. A bad value is refused naming it."""
    from . import lines

    _check_params({"g": g, "ei": ei, "end_mass": end_mass, "tip_drag_area": tip_drag_area, "cd_normal": cd_normal,
                   "cd_tangential": cd_tangential, "length": length, "mass": mass, "ea": ea, "diameter": diameter,
                   "air_density": air_density})
    g = float(g)
    if line is None:
        if length is None or mass is None:
            missing = "length" if length is None else "mass"
            raise V.SnappingInputError(f"{missing}=None: without a catalogue line both length (m) and mass (kg) "
                                       f"are needed")
        if (cd_normal is not None or cd_tangential is not None) and diameter is None:
            k, v = ("cd_normal", cd_normal) if cd_normal is not None else ("cd_tangential", cd_tangential)
            raise V.SnappingInputError(f"{k}={v!r} needs a diameter (m): the drag per length is "
                                       f"0.5 rho C d |v| v")
        if air_density is not None and diameter is None and not tip_drag_area:
            raise V.SnappingInputError(f"air_density={air_density!r} (kg m-3) acts on nothing: give a diameter (m) "
                                       f"or a tip body's drag area (m2) with it (the drag is 0.5 rho C d |v| v)")
        return LineSpec("custom", float(length), float(mass), g, float(ei or 0.0), None if ea is None else float(ea),
                        None if diameter is None else float(diameter), cd_normal, cd_tangential, air_density,
                        float(end_mass or 0.0), float(tip_drag_area or 0.0))
    ln = lines.get(line) if isinstance(line, str) else line
    if not isinstance(ln, lines.Line):
        raise V.SnappingInputError(f"line={line!r} is neither a catalogue name ({', '.join(lines.names())}) nor a Line")
    L = ln.length if length is None else float(length)
    ln.own_links(L)  # (a line of discrete links: its length holds 2 to 20000 of them, else refused)
    if mass is not None:
        if ln.taper is not None:
            raise V.SnappingInputError(f"mass={mass!r}: line {ln.name} is tapered, its mass follows from its "
                                       f"profile (change the Line's mass_per_length instead)")
        ln = ln.replace(mass_per_length=float(mass) / L)
    si = ln.si(L)
    return LineSpec(ln.name, L, float(si["mass"]), g, si["ei"] if ei is None else float(ei),
                    ln.ea if ea is None else float(ea), si["diameter"] if diameter is None else float(diameter),
                    ln.cd_normal if cd_normal is None else float(cd_normal),
                    ln.cd_tangential if cd_tangential is None else float(cd_tangential), air_density,
                    ln.tip_mass if end_mass is None else float(end_mass),
                    ln.tip_drag_area if tip_drag_area is None else float(tip_drag_area),
                    ln if ln.taper is not None else None, ln.pitch)


#: the largest end mass, as a ratio to the line's mass
END_MASS_MAX = 1e4


def as_spec(line_or_spec, params: dict) -> LineSpec:
    """The :class:`LineSpec` of ``line_or_spec`` (what :func:`spec` takes, or a LineSpec) with the
    overrides ``params`` (:func:`spec`'s keywords; None: not given), each checked; a LineSpec's
    length and mass cannot be overridden (its profiles follow from its length); the end mass is
    at most :data:`END_MASS_MAX` times the line's."""
    _check_params(params)  # (a keyword spec does not take: named, with the valid ones)
    if isinstance(line_or_spec, LineSpec):
        fixed = sorted(k for k in ("length", "mass") if params.get(k) is not None)
        if fixed:
            raise V.SnappingInputError(f"{fixed[0]}={params[fixed[0]]!r} cannot override a LineSpec (its mass and "
                                       f"profiles follow from its length): give the line's name or Line with "
                                       f"{fixed[0]}=..., or build it again with caps.spec")
        params = {k: float(v) for k, v in params.items() if v is not None}
        sp = replace(line_or_spec, **params) if params else line_or_spec
    else:
        sp = spec(line_or_spec, **params)
    if sp.end_mass > END_MASS_MAX * sp.mass:
        raise V.SnappingInputError(f"end_mass={sp.end_mass!r} is out of range: at most {END_MASS_MAX:g} times the "
                                   f"line's mass ({sp.mass:g} kg)")
    return sp


def check_chis(chis) -> list:
    """``chis`` of :func:`snapping.caps.design` as a sorted list of distinct separations, each in
    [CHI_MIN, 1), every one checked before any run (a bad one is named with its place: ``chis[2]=1.5``)."""
    from .estimates import check_chi

    if isinstance(chis, numbers.Real) and not isinstance(chis, bool):
        chis = [chis]
    if isinstance(chis, (str, bytes, dict)) or chis is None or not hasattr(chis, "__iter__"):
        raise V.SnappingInputError(f"chis={chis!r} is not a sequence of end separations (each in (0, 1), "
                                   f"e.g. (0.2, 0.3, 0.5))")
    out = [check_chi(c, f"chis[{i}]") for i, c in enumerate(list(chis))]
    if not out:
        raise V.SnappingInputError("chis=[] holds no end separation: give at least one, each in (0, 1)")
    twice = sorted({c for c in out if out.count(c) > 1})
    if twice:
        raise V.SnappingInputError(f"chis={[float(c) for c in chis]!r} gives chi={twice[0]!r} more than once: "
                                   f"each separation is run once")
    return sorted(out)
