"""The library's unit of each kind of quantity in SI: :class:`Scales` (L, M, g), checked by pint.

The scales and the unit of each kind (:data:`KIND_UNITS`) that :mod:`snapping.units` converts
with (that module's text gives the table of kinds and how each unit follows from L, M and g;
its names ``Scales``, ``KIND_UNITS``, ``G_STANDARD`` are these). The exponents of a kind's unit
L^a M^b g^c come from the dimension of its SI unit, read by `pint <https://pint.readthedocs.io>`_
(:func:`registry`, which also reads CF unit strings such as ``"m s-2"``).

Example
-------
>>> from snapping.unit_scales import Scales
>>> s = Scales(length=1.022, mass=0.0208)        # the paper's chain, g = 9.81
>>> round(s.energy, 6), s.units("energy")        # M g L in J
(0.208537, 'J')
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass, field

from . import _validate as V

__all__ = ["Scales", "KIND_UNITS", "G_STANDARD", "SCALE_RANGE", "registry"]

#: the default gravity, m s-2 (what ``snapping estimate`` has always used)
G_STANDARD = 9.81
#: range of a length, mass or g in SI (as :data:`snapping.estimates.CHAIN_RANGE`): beyond, SI
#: values of the library's numbers leave the doubles
SCALE_RANGE = V.SI_SCALE_RANGE

#: The SI unit (CF string) of each kind of quantity.
KIND_UNITS: dict[str, str] = {
    "length": "m",
    "mass": "kg",
    "time": "s",
    "speed": "m s-1",
    "acceleration": "m s-2",
    "force": "N",
    "energy": "J",
    "curvature": "m-1",
    "rate": "s-1",
    "angular_momentum": "kg m2 s-1",
    "dimensionless": "1",
}

#: short names of the kinds (the keys of KIND_UNITS; :mod:`snapping.units`' tables use them too)
_L, _M, _T, _V, _A, _F, _E, _K, _1 = ("length", "mass", "time", "speed", "acceleration", "force", "energy",
                                      "curvature", "dimensionless")
_W, _H = "rate", "angular_momentum"


# --------------------------------------------------------------------------- pint
_REGISTRY = None


def _cf_to_pint(text: str) -> str:
    """CF exponents (``m s-1``) in pint's notation (``m s**-1``)."""
    return re.sub(r"(?<=[A-Za-z])(-?\d+)", r"**\1", text)


def registry():
    """The :class:`pint.UnitRegistry` of this module (built once, on first use), which also
    reads CF unit strings such as ``"m s-2"``."""
    global _REGISTRY
    if _REGISTRY is None:
        import pint

        _REGISTRY = pint.UnitRegistry(preprocessors=[_cf_to_pint], cache_folder=None)
    return _REGISTRY


def _unit(cf: str):
    ureg = registry()
    return ureg.dimensionless if cf == "1" else ureg.parse_units(cf)


def _exponents(kind: str) -> tuple[float, float, float]:
    """Exponents (a, b, c) of the unit L^a M^b g^c of ``kind``, from the dimension
    [length]^p [mass]^q [time]^r of its SI unit: g^c carries [time]^(-2c), so c = -r/2,
    and [length]^(a + c) = [length]^p gives a = p + r/2; b = q."""
    dim = _unit(KIND_UNITS[kind]).dimensionality
    extra = set(dim) - {"[length]", "[mass]", "[time]"}
    if extra:  # (not reached by KIND_UNITS)
        raise V.SnappingInputError(f"kind={kind!r} has a dimension {sorted(extra)} that L, M and g do not make")
    p, q, r = (float(dim.get(d, 0)) for d in ("[length]", "[mass]", "[time]"))
    return p + r / 2.0, q, -r / 2.0


def _check_kind(kind: str) -> str:
    if kind not in KIND_UNITS:
        raise V.SnappingInputError(f"kind={kind!r} is not one of {list(KIND_UNITS)}")
    return kind


# ------------------------------------------------------------------------- scales
def _derive(length: float, mass: float, g: float, kind: str) -> float:
    """:meth:`Scales._derive` of the scales ``(length, mass, g)``."""
    ureg = registry()
    a, b, c = _exponents(kind)
    q = ((length * ureg.meter) ** a * (mass * ureg.kilogram) ** b
         * (g * ureg.meter / ureg.second ** 2) ** c)
    return float(q.to(_unit(KIND_UNITS[kind])).magnitude)


@functools.lru_cache(maxsize=64)
def _factors_of(length: float, mass: float, g: float) -> dict:
    """Every kind's factor of the scales ``(length, mass, g)``, derived by pint once per scales (a
    design answer makes ~10 bodies of one line: 99 conversions, ~0.2 s, each the same floats)."""
    return {k: _derive(length, mass, g, k) for k in KIND_UNITS}


@dataclass(frozen=True)
class Scales:
    """The SI value of the library's unit of each kind of quantity, for a chain of
    ``length`` [m] and ``mass`` [kg] under gravity ``g`` [m s-2].

    Each must be a positive finite number in [1e-30, 1e30]; else
    :class:`~snapping._validate.SnappingInputError` names it.

    >>> s = Scales(1.022, 0.0208)
    >>> round(s.factor("speed"), 4), s.units("speed")   # sqrt(g L)
    (3.1664, 'm s-1')
    >>> round(s.to_si(2.0, "energy"), 6)                 # 2 M g L in J
    0.417074
    >>> Scales(-1.0, 0.02)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: length=-1.0 is out of range: must be > 0
    """

    length: float
    mass: float
    g: float = G_STANDARD
    _factors: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        for name, x in zip(("length", "mass", "g"), V.si_scales(self.length, self.mass, self.g)):
            object.__setattr__(self, name, x)
        object.__setattr__(self, "_factors", dict(_factors_of(self.length, self.mass, self.g)))

    def _derive(self, kind: str) -> float:
        """L^a M^b g^c (exponents from :func:`_exponents`), converted by pint to the kind's SI
        unit: a wrong exponent would raise pint's DimensionalityError here."""
        return _derive(self.length, self.mass, self.g, kind)


    def factor(self, kind: str) -> float:
        """The SI value of one library unit of ``kind`` (a key of :data:`KIND_UNITS`)."""
        return self._factors[_check_kind(kind)]

    def units(self, kind: str) -> str:
        """The CF units string of ``kind`` in SI."""
        return KIND_UNITS[_check_kind(kind)]

    def quantity(self, kind: str):
        """The library's unit of ``kind`` as a :class:`pint.Quantity` in SI."""
        return self.factor(kind) * _unit(self.units(kind))

    def to_si(self, value, kind: str):
        """Nondimensional ``value`` (a number or an array) of ``kind`` -> SI."""
        return value * self.factor(kind)

    def from_si(self, value, kind: str):
        """SI ``value`` of ``kind`` -> nondimensional."""
        return value / self.factor(kind)

    @property
    def time(self) -> float:
        """sqrt(L/g) in s."""
        return self.factor(_T)

    @property
    def speed(self) -> float:
        """sqrt(g L) in m s-1."""
        return self.factor(_V)

    @property
    def acceleration(self) -> float:
        """g in m s-2."""
        return self.factor(_A)

    @property
    def force(self) -> float:
        """M g in N."""
        return self.factor(_F)

    @property
    def energy(self) -> float:
        """M g L in J."""
        return self.factor(_E)

    @property
    def curvature(self) -> float:
        """1/L in m-1."""
        return self.factor(_K)

    def to_dict(self) -> dict:
        """``{kind: {"value": factor, "units": CF string}}`` for every dimensional kind."""
        return {k: {"value": self.factor(k), "units": u} for k, u in KIND_UNITS.items() if k != _1}


def _scales(scales=None, length=None, mass=None, g=G_STANDARD) -> Scales:
    if isinstance(scales, Scales):
        return scales
    if scales is not None:
        raise V.SnappingInputError(f"scales={scales!r} is not a snapping.units.Scales")
    if length is None or mass is None:
        raise V.SnappingInputError("give length (m) and mass (kg), or scales=Scales(...)")
    return Scales(length, mass, g)
