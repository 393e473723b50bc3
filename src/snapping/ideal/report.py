"""Everything exact about the folded string as one JSON-serialisable dict (:func:`summary`, behind
``snapping ideal``) and its printed form (:func:`print_summary`).
"""

from __future__ import annotations

import functools
from typing import Any

from .. import _validate as V
from .scalings import asymptotic_scalings, observed_scalings
from .snap_time import _MAX_DIGITS, T_STAR, t_star_str
from .symbolic import check_printed_equations


@functools.lru_cache(maxsize=1)
def _default_check() -> dict[str, Any]:
    return check_printed_equations()


def summary(digits: int = 15) -> dict[str, Any]:
    """Everything exact about the folded string, as one JSON-serialisable dict.

    Backs ``snapping ideal [--digits D] [--json]``.

    Parameters
    ----------
    digits : int
        Significant digits of t*, in [1, 100000] (2E(pi/4|2) via mpmath
        ``ellipe`` up to 1000 digits, the identical agm(1, sqrt 2) beyond).

    Returns
    -------
    dict
        ``t_star`` (string with ``digits`` significant digits), ``t_star_float``,
        ``t_star_closed_forms``, ``equations``, ``exponents`` (derived laws:
        exponent strings like "-1/3", floats, exact and float prefactors, which
        quantity), ``observed_exponents``, ``printed_ode_check`` and ``notes``.

    Raises
    ------
    SnappingInputError
        If ``digits`` is not an integer in [1, 100000].

    Examples
    --------
    >>> s = summary(30)
    >>> s["t_star"]
    '1.19814023473559220743992249228'
    >>> s["exponents"]["tether_tension"]["exponent"], s["exponents"]["tether_tension"]["exponent_float"]
    ('-2/3', -0.666...)
    >>> import json; _ = json.dumps(s)
    """
    digits = V.integer("digits", digits, minimum=1, maximum=_MAX_DIGITS)
    check = dict(_default_check())
    return {
        "model": "perfectly folded falling string (chi = 0), energy-conserving fold; units l, g, rho",
        "digits": digits,
        "t_star": t_star_str(digits),
        "t_star_float": T_STAR,
        "t_star_closed_forms": [
            "2 E(pi/4 | 2)",
            "agm(1, sqrt(2)) (1/Gauss's constant)",
            "2 sqrt(pi) Gamma(3/4) / Gamma(1/4)",
            "int_0^(pi/2) sqrt(sin theta) dtheta",
        ],
        "equations": {
            "first_integral": "s0'^2 = (1 - 4(1 - s0)^2) / (8(1 - s0))   (paper eq. shockvelocity)",
            "kink_ode": "s0'' = (1/2)(1 + s0'^2/(1 - s0))   (derived; the paper prints a minus sign)",
            "initial_conditions": "s0(0) = 1/2, s0'(0) = 0",
            "energy": "2(1 - s0) s0'^2 + (1 - s0)^2 - 1/2 = -1/4",
            "tether_tension": "sigma(0, t) = s0 + s0'^2",
            "free_end": "speed 2 s0', acceleration 2 s0''",
        },
        "exponents": {k: v.to_dict() for k, v in asymptotic_scalings().items()},
        "observed_exponents": {k: v.to_dict() for k, v in observed_scalings().items()},
        "printed_ode_check": check,
        "notes": [
            "Exponents are of (t* - t); prefactors are exact leading-order coefficients.",
            "The paper's v ~ s0' is a proportionality: the kink moves at s0', the free end "
            "(the maximum speed in the string) at 2 s0'.",
            check["conclusion"],
            "Observed exponents (-1/6 curvature, -5/6 intermediate maximum acceleration) are "
            "the paper's numerical observations, not consequences of the ideal solution.",
        ],
    }


def print_summary(summary: dict[str, Any]) -> None:
    """Print a :func:`summary` dict as readable tables (``snapping ideal``).

    Parameters
    ----------
    summary : dict
        The output of :func:`summary`.

    Examples
    --------
    >>> print_summary(summary(20))   # doctest: +ELLIPSIS
    Perfectly folded falling string (chi = 0)
    ...
      t* = 2E(pi/4|2)  1.1981402347355922074
    ...
    """
    print("Perfectly folded falling string (chi = 0)")
    print("=========================================")
    print(f"  model: {summary['model']}")
    print()
    print(f"  t* = 2E(pi/4|2)  {summary['t_star']}")
    print(f"  ({summary['digits']} significant digits; = " + " = ".join(summary["t_star_closed_forms"][1:]) + ")")
    print()
    print("Equations")
    print("---------")
    for k, v in summary["equations"].items():
        print(f"  {k:<18} {v}")
    print()
    print("Asymptotics as t -> t*: quantity ~ prefactor * (t* - t)^exponent")
    print("-----------------------------------------------------------------")
    rows = [("quantity", "exponent", "", "prefactor", "", "source")]
    for e in list(summary["exponents"].values()) + list(summary["observed_exponents"].values()):
        pf = e["prefactor_float"]
        rows.append(
            (
                e["quantity"],
                e["exponent"],
                f"{e['exponent_float']:+.6f}",
                "-" if pf is None else f"{pf:.10g}",
                "" if e["prefactor"] is None else e["prefactor"],
                e["source"],
            )
        )
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        print("  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    print()
    print("Printed-equation check (paper section 'Ideal and anomalous evolution')")
    print("----------------------------------------------------------------------")
    c = summary["printed_ode_check"]
    print(f"  printed ODE:             {c['printed_ode']}")
    print(f"  derived ODE:             {c['derived_ode']}")
    print(f"  printed first integral:  {c['printed_first_integral']}")
    print(f"  first integral satisfies derived ODE: {c['first_integral_satisfies_derived_ode']}")
    print(f"  first integral satisfies printed ODE: {c['first_integral_satisfies_printed_ode']}")
    print(f"  printed ODE integrates to: {c['printed_ode_first_integral']}")
    print(f"  printed ODE end time: {c['printed_ode_end_time']} (speed^2 there: {c['printed_ode_end_speed_squared']})")
    print(f"  t* quadrature = 2E(pi/4|2): {c['t_star_quadrature_equals_2E']}")
    print()
    print("Notes")
    print("-----")
    for n in summary["notes"]:
        print(f"  * {n}")
