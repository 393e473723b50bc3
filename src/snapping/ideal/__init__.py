"""The perfectly folded falling string (chi = 0): the paper's ideal singular limit.

Geometry and units
------------------
Nondimensional units (length l, velocity sqrt(g l), time sqrt(l/g), force
rho g l). The string hangs from a pin at the origin, ``y`` grows downward. At
t = 0 both ends are at the pin and the string is folded at depth 1/2. The kink
(fold) is at arclength ``s0(t)`` from the pin:

* the *fixed arm* ``0 <= s <= s0`` hangs at rest, vertically, from the pin;
* the *moving arm* ``s0 <= s <= 1`` has length ``x = 1 - s0`` and falls
  rigidly at the free-end speed ``2 s0'``; the free end is at depth
  ``2 s0 - 1``.

Energy (per rho g) is ``E = 2 x s0'^2 + x^2 - 1/2``, conserved by the
energy-conserving fold of the singular solution the paper normalizes (its refs.
Heywood 1955, Calkin & March 1989, ...). With
``s0(0) = 1/2, s0'(0) = 0`` this gives the paper's first integral,
eq. (shockvelocity),

    s0'^2 = (1 - 4 (1 - s0)^2) / (8 (1 - s0)),

the kink ODE (derived by differentiating it, see *printed-ODE note* below)

    s0'' = (1/2) (1 + s0'^2 / (1 - s0)),

and the snapping time (paper eq. for t*)

    t* = int_{1/2}^{1} ds0 / s0' = 2 E(pi/4 | 2) = agm(1, sqrt 2)
       = 2 sqrt(pi) Gamma(3/4) / Gamma(1/4) = 1.19814023473559220743992249228...

Printed-ODE note
----------------
The paper prints the kink ODE as ``s0'' = (1/2)(1 - s0'^2/(1 - s0))``. That
sign is inconsistent with the paper's own first integral (shockvelocity) and
with its t* = 2E(pi/4|2): differentiating (shockvelocity) gives a ``+`` sign, and
the printed ``-`` ODE integrates instead to ``s0'^2 = -(1 - s0) ln(2(1 - s0))``,
which reaches the free end at t = sqrt(pi) ~ 1.77245 with *zero* velocity (no
snap) and does not conserve energy. The first integral and t* agree with each
other and with energy conservation, so this module follows the derivation (the
``+`` sign); :func:`check_printed_equations` demonstrates all of this
symbolically.

Near t* (tau = t* - t -> 0+), with exact sympy prefactors (:func:`asymptotic_scalings`):

    s0'  ~ 12^(-1/3) tau^(-1/3)          free-end speed        2 s0'  ~ (2/3)^(1/3) tau^(-1/3)
    s0'' ~ (1/3) 12^(-1/3) tau^(-4/3)    free-end acceleration 2 s0'' ~ (1/3)(2/3)^(1/3) tau^(-4/3)
    sigma(0) = s0 + s0'^2 ~ 12^(-2/3) tau^(-2/3)
    1 - s0 ~ (9/32)^(1/3) tau^(2/3)

Example
-------
>>> from snapping import ideal
>>> round(ideal.t_star(), 12)
1.198140234736
>>> ideal.t_star_str(30)
'1.19814023473559220743992249228'
>>> float(ideal.s0(0.0)), float(ideal.s0_dot(0.0)), float(ideal.s0_ddot(0.0))
(0.5, 0.0, 0.5)
>>> str(ideal.asymptotic_scalings()["s0_dot"].exponent)
'-1/3'
"""

from __future__ import annotations

# The package holds one idea a module (a pure split of the former ideal.py; every name is
# importable from snapping.ideal as before):
#   snap_time  t* to any number of digits
#   symbolic   the sympy derivation of the kink ODE and first integral, the printed-ODE check
#   kink       the exact motion s0(t), tensions, free end (numerical inversion of the time map)
#   scalings   exponents and prefactors of the power laws near t*
#   report     summary() / print_summary() (snapping ideal)
from . import snap_time as _snap_time
from .kink import (TAU_MIN, KinkState, fold_tension, free_end_acceleration, free_end_speed, kink_energy, kink_state,
                   moving_arm_length, s0, s0_ddot, s0_dot, tether_tension)
from .report import print_summary, summary
from .scalings import Scaling, asymptotic_scalings, observed_scalings
from .snap_time import _T_HI, _T_LO, T_STAR_METHODS, t_star, t_star_mp, t_star_str  # noqa: F401 (_T_*)
from .symbolic import Derivation, check_printed_equations, derivation

#: t* = 2 E(pi/4 | 2) as the nearest double (paper eq. for t*).
T_STAR: float = _snap_time.T_STAR

__all__ = [
    "T_STAR",
    "t_star",
    "t_star_mp",
    "t_star_str",
    "T_STAR_METHODS",
    "Derivation",
    "derivation",
    "check_printed_equations",
    "KinkState",
    "kink_state",
    "s0",
    "s0_dot",
    "s0_ddot",
    "moving_arm_length",
    "tether_tension",
    "fold_tension",
    "free_end_speed",
    "free_end_acceleration",
    "kink_energy",
    "Scaling",
    "asymptotic_scalings",
    "observed_scalings",
    "summary",
    "print_summary",
]
