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

import functools
from dataclasses import dataclass
from typing import Any

import mpmath
import numpy as np
from numpy.typing import ArrayLike

from . import _validate as V
from ._validate import SnappingInputError

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

# ============================================================================ t*
T_STAR_METHODS = ("ellipe", "carlson", "agm", "gamma")
_MAX_DIGITS = 100_000
_ELLIPE_MAX_DIGITS = 1000  # summary() switches to the (identical, faster) agm form beyond this


def t_star_mp(digits: int = 30, method: str = "ellipe") -> mpmath.mpf:
    """The ideal snapping time t* = 2 E(pi/4 | 2) to ``digits`` significant digits.

    Paper eq. for t* (after eq. shockvelocity)::

        t* = int_{1/2}^{1} 2 sqrt(2(1-s0)/(1-4(1-s0)^2)) ds0
           = int_0^{1/sqrt 2} 2 sqrt((1-2 z^2)/(1-z^2)) dz = 2 E(pi/4 | 2).

    E(phi | m) is the incomplete elliptic integral of the second kind with
    parameter m = 2 (so m sin^2 phi = 1 at the upper limit: a boundary case at
    which, e.g., ``scipy.special.ellipeinc(pi/4, 2)`` returns NaN; mpmath's
    ``ellipe(phi, m)`` and Carlson's ``elliprf``/``elliprd`` do not).
    Equivalent closed forms (all give the same number; the tests check them
    against each other and against direct quadrature):

    * ``"ellipe"``: ``2 * mpmath.ellipe(pi/4, 2)`` (the paper's form),
    * ``"carlson"``: ``2 [s R_F(c^2, 0, 1) - (2/3) s^3 R_D(c^2, 0, 1)]`` with
      ``s = c = 1/sqrt 2`` (Carlson form of E(phi|m) with 1 - m sin^2 phi = 0),
    * ``"agm"``: ``agm(1, sqrt 2)``, the reciprocal of Gauss's constant
      (t* = int_0^{pi/2} sqrt(sin th) d th = B(3/4, 1/2)/2 with x = sin(th)/2),
    * ``"gamma"``: ``2 sqrt(pi) Gamma(3/4) / Gamma(1/4)``.

    ``ellipe`` and ``carlson`` slow down beyond ~1000 digits; ``agm`` is fastest.

    Parameters
    ----------
    digits : int
        Significant decimal digits, in [1, 100000]. The value is computed with
        10 guard digits and rounded.
    method : str
        One of ``"ellipe"``, ``"carlson"``, ``"agm"``, ``"gamma"``.

    Returns
    -------
    mpmath.mpf
        t*, rounded to ``digits`` significant digits (an mpf at that precision;
        print it with ``mpmath.nstr(value, digits)`` or use :func:`t_star_str`,
        since ``print`` uses mpmath's global precision).

    Raises
    ------
    SnappingInputError
        If ``digits`` is not an integer in [1, 100000] or ``method`` is unknown.

    Examples
    --------
    >>> import mpmath
    >>> mpmath.nstr(t_star_mp(30), 30)
    '1.19814023473559220743992249228'
    >>> t_star_mp(40, "agm") == t_star_mp(40, "carlson")
    True
    """
    digits = V.integer("digits", digits, minimum=1, maximum=_MAX_DIGITS)
    if method not in T_STAR_METHODS:
        raise SnappingInputError(f"method={method!r} is not one of {', '.join(T_STAR_METHODS)}")
    with mpmath.workdps(digits + 10):
        if method == "ellipe":
            value = 2 * mpmath.ellipe(mpmath.pi / 4, 2)
        elif method == "carlson":
            s = 1 / mpmath.sqrt(2)
            value = 2 * (s * mpmath.elliprf(s * s, 0, 1) - mpmath.mpf(2) / 3 * s**3 * mpmath.elliprd(s * s, 0, 1))
        elif method == "agm":
            value = mpmath.agm(1, mpmath.sqrt(2))
        else:
            value = 2 * mpmath.sqrt(mpmath.pi) * mpmath.gamma(mpmath.mpf(3) / 4) / mpmath.gamma(mpmath.mpf(1) / 4)
        value = mpmath.re(value)
    with mpmath.workdps(digits):
        return +value  # round to the requested precision


def t_star_str(digits: int = 30) -> str:
    """t* = 2 E(pi/4 | 2) as a decimal string with exactly ``digits`` significant digits.

    Uses ``mpmath.ellipe`` (the paper's form) up to 1000 digits and the
    identical, faster agm(1, sqrt 2) beyond (see :func:`t_star_mp`).

    Parameters
    ----------
    digits : int
        Significant digits, in [1, 100000].

    Returns
    -------
    str
        Correctly rounded decimal string.

    Examples
    --------
    >>> t_star_str(6), t_star_str(40)
    ('1.19814', '1.198140234735592207439922492280323878227')
    """
    digits = V.integer("digits", digits, minimum=1, maximum=_MAX_DIGITS)
    method = "ellipe" if digits <= _ELLIPE_MAX_DIGITS else "agm"
    with mpmath.workdps(digits + 10):
        return mpmath.nstr(t_star_mp(digits, method), digits, strip_zeros=False).rstrip(".")


with mpmath.workdps(60):
    _T_MP = mpmath.agm(1, mpmath.sqrt(2))
    _T_HI = float(_T_MP)
    _T_LO = float(_T_MP - _T_HI)  # t* = _T_HI + _T_LO in double-double
    _T_STR = mpmath.nstr(_T_MP, 21)

#: t* = 2 E(pi/4 | 2) as the nearest double (paper eq. for t*).
T_STAR: float = _T_HI


def t_star() -> float:
    """The ideal snapping time t* = 2 E(pi/4 | 2) as a float (paper eq. for t*).

    See :func:`t_star_mp` for arbitrary precision and the closed forms.

    Returns
    -------
    float
        1.1981402347355923 (the double nearest to t*; t* itself is
        1.19814023473559220744..., so this double lies just above t*).

    Examples
    --------
    >>> t_star()
    1.1981402347355923
    """
    return T_STAR


# ===================================================================== symbolic
@dataclass(frozen=True)
class Derivation:
    """The symbolic derivation of the kink dynamics (sympy expressions).

    Symbols: ``t`` time, ``s`` = s0 (kink position), ``v`` = s0', ``x`` = 1 - s0
    (moving-arm length), ``zeta`` (paper's ζ, ζ^2 = s0 - 1/2).

    Attributes
    ----------
    kinetic, potential, energy
        Kinetic and potential energy per rho g of the folded string as
        functions of (s, v), from integrals over the two arms; energy = sum.
    ode_rhs
        Derived s0'' as a function of (s, v): (1/2)(1 + v^2/(1 - s)).
    first_integral
        Derived s0'^2 as a function of s, by sympy ``dsolve`` of the ODE for
        u(s) = s0'^2 with u(1/2) = 0: (1 - 4(1-s)^2)/(8(1-s)).
    printed_ode_rhs, printed_first_integral
        The paper's text: (1/2)(1 - v^2/(1-s)) and
        (1/4)(1 - 4(1-s)^2)/(2(1-s)) (the square of eq. shockvelocity).
    printed_ode_first_integral
        What the printed ODE actually integrates to: -(1-s) ln(2(1-s)).
    t_integrand_s, t_integrand_zeta
        The paper's two t* integrands, 2 sqrt(2(1-s)/(1-4(1-s)^2)) on
        [1/2, 1] and 2 sqrt((1-2ζ^2)/(1-ζ^2)) on [0, 1/sqrt 2].
    tether_tension
        sigma(0, t) from the momentum balance of the whole string,
        1 - d/dt(x * 2 s0'): equals s + v^2.
    fold_tension
        Tension at the kink in the fixed arm: tether_tension - s = v^2.
    """

    t: Any
    s: Any
    v: Any
    x: Any
    zeta: Any
    kinetic: Any
    potential: Any
    energy: Any
    ode_rhs: Any
    first_integral: Any
    printed_ode_rhs: Any
    printed_first_integral: Any
    printed_ode_first_integral: Any
    t_integrand_s: Any
    t_integrand_zeta: Any
    tether_tension: Any
    fold_tension: Any


@functools.lru_cache(maxsize=1)
def derivation() -> Derivation:
    """Derive the kink ODE, its first integral and the tether tension with sympy.

    Implements the paper's eq. (shockvelocity) and the ODE before it (with the
    sign corrected, see the module docstring). Steps:

    1. energies of the two arms (fixed arm at rest, y = s; moving arm at
       y = 2 s0 - s with speed 2 s0') -> E(s0, s0') = 2 x s0'^2 + x^2 - 1/2;
    2. dE/dt = 0 solved for s0'' -> the kink ODE;
    3. the ODE rewritten for u(s0) = s0'^2 (du/ds0 = 2 s0'') and solved with
       ``dsolve``, u(1/2) = 0 -> the first integral;
    4. the same ``dsolve`` for the printed ODE;
    5. momentum of the string P = x (2 s0') and sigma(0) = 1 - dP/dt.

    Returns
    -------
    Derivation
        The expressions (cached; sympy is imported on first call).

    Examples
    --------
    >>> d = derivation()
    >>> d.ode_rhs
    v**2/(2*(1 - s)) + 1/2
    >>> d.first_integral
    (2*s - 3)*(2*s - 1)/(8*(s - 1))
    """
    import sympy as sp

    t = sp.Symbol("t", real=True)
    s, v, zeta = sp.symbols("s v zeta", real=True)
    x = sp.Symbol("x", positive=True)
    r = sp.Symbol("r", real=True)  # material label (arclength from the pin)

    # 1. energies: fixed arm y(r) = r at rest; moving arm y(r) = 2 s - r, speed 2 v
    kinetic = sp.integrate(sp.Rational(1, 2) * (2 * v) ** 2, (r, s, 1))
    potential = -sp.integrate(r, (r, 0, s)) - sp.integrate(2 * s - r, (r, s, 1))
    energy = sp.expand(kinetic + potential)

    # 2. dE/dt = E_s v + E_v a = 0
    a = sp.Symbol("a")
    sol = sp.solve(sp.Eq(sp.diff(energy, s) * v + sp.diff(energy, v) * a, 0), a)[0]
    # keep a readable form, checked to be what the energy gives
    ode_rhs = sp.Rational(1, 2) * (1 + v**2 / (1 - s))
    if sp.simplify(sol - ode_rhs) != 0:  # pragma: no cover - a derivation error
        raise RuntimeError("energy-derived kink ODE differs from (1/2)(1 + v^2/(1 - s))")

    # 3./4. first integrals: u(s) = v^2, u' = 2 s0''
    u = sp.Function("u")

    def integrate_ode(rhs):
        # in x = 1 - s > 0 (real logarithms): du/dx = -2 s0''
        eq = sp.Eq(u(x).diff(x), -2 * rhs.subs(v**2, u(x)).subs(s, 1 - x))
        gen = sp.dsolve(eq, u(x)).rhs
        c = [sym for sym in gen.free_symbols if sym.name.startswith("C")][0]
        c_val = sp.solve(sp.Eq(gen.subs(x, sp.Rational(1, 2)), 0), c)[0]
        return sp.simplify(gen.subs(c, c_val)).subs(x, 1 - s)

    first_integral = sp.factor(sp.simplify(integrate_ode(ode_rhs)))
    printed_ode_rhs = sp.Rational(1, 2) * (1 - v**2 / (1 - s))
    printed_ode_first_integral = sp.expand_log(integrate_ode(printed_ode_rhs), force=True)
    printed_first_integral = sp.Rational(1, 4) * (1 - 4 * (1 - s) ** 2) / (2 * (1 - s))

    t_integrand_s = 2 * sp.sqrt(2 * (1 - s) / (1 - 4 * (1 - s) ** 2))
    t_integrand_zeta = 2 * sp.sqrt((1 - 2 * zeta**2) / (1 - zeta**2))

    # 5. momentum balance of the whole string (mass 1, gravity 1 downward):
    #    dP/dt = 1 - sigma(0),  P = x * 2 s0'
    S = sp.Function("S")(t)
    P = (1 - S) * 2 * S.diff(t)
    dP = P.diff(t).subs(S.diff(t, 2), ode_rhs.subs({s: S, v: S.diff(t)}))
    tether = sp.simplify((1 - dP).subs(S.diff(t), v).subs(S, s))
    fold = sp.simplify(tether - s)

    return Derivation(
        t=t,
        s=s,
        v=v,
        x=x,
        zeta=zeta,
        kinetic=kinetic,
        potential=sp.expand(potential),
        energy=energy,
        ode_rhs=ode_rhs,
        first_integral=first_integral,
        printed_ode_rhs=printed_ode_rhs,
        printed_first_integral=printed_first_integral,
        printed_ode_first_integral=printed_ode_first_integral,
        t_integrand_s=t_integrand_s,
        t_integrand_zeta=t_integrand_zeta,
        tether_tension=tether,
        fold_tension=fold,
    )


def check_printed_equations(digits: int = 20) -> dict[str, Any]:
    """Check the paper's printed ODE, first integral and t* against each other.

    The three printed statements of section "Ideal and anomalous evolution":
    (A) the ODE ``s0'' = (1/2)(1 - s0'^2/(1 - s0))``, (B) the first integral,
    eq. (shockvelocity), (C) ``t* = ... = 2E(pi/4|2) ~ 1.19814``. Checked here:

    * B satisfies the energy-derived ODE ``(1/2)(1 + s0'^2/(1 - s0))`` (True),
    * B does *not* satisfy A (residual ``-s0'^2/(1-s0)`` is nonzero),
    * A integrates to ``s0'^2 = -(1-s0) ln(2(1-s0))`` != B,
    * 1/s0' from B is the printed t* integrand, and ζ^2 = s0 - 1/2 maps it
      to the printed ζ integrand (both symbolic),
    * C: the ζ integral equals 2E(pi/4|2) = agm(1, sqrt 2) (mpmath, ``digits``),
    * the end time of A, int_0^{1/2} dx / sqrt(-x ln 2x) = sqrt(pi) != t*,
      and A's kink arrives at s0 = 1 with zero speed (no snap).

    Conclusion: B and C agree with each other and with energy conservation; A
    has a sign typo.

    Parameters
    ----------
    digits : int
        Working digits of the mpmath quadratures, in [5, 200].

    Returns
    -------
    dict
        JSON-serialisable booleans, residuals (as strings) and numbers, plus
        ``"conclusion"``.

    Examples
    --------
    >>> c = check_printed_equations()
    >>> c["first_integral_satisfies_derived_ode"], c["first_integral_satisfies_printed_ode"]
    (True, False)
    >>> c["printed_ode_end_time"]
    'sqrt(pi)'
    """
    import sympy as sp

    digits = V.integer("digits", digits, minimum=5, maximum=200)
    d = derivation()
    s, v, x = d.s, d.v, d.x
    u = d.printed_first_integral
    # an ODE s'' = f(s, s'^2) is satisfied by s'^2 = u(s) iff u'(s) = 2 f(s, u)
    res_derived = sp.simplify(sp.diff(u, s) - 2 * d.ode_rhs.subs(v**2, u))
    res_printed = sp.simplify(sp.diff(u, s) - 2 * d.printed_ode_rhs.subs(v**2, u))
    # printed ODE's own first integral
    printed_fi_matches = sp.simplify(d.printed_ode_first_integral - u) == 0
    a_fi_x = sp.simplify(d.printed_ode_first_integral.subs(s, 1 - x))
    a_fi_is_xlog = sp.simplify(sp.expand_log(a_fi_x + x * sp.log(2 * x), force=True)) == 0
    # 1/s0' from B == printed s-integrand (compare squares, both positive on (1/2, 1))
    integrand_ok = sp.simplify(d.t_integrand_s**2 - 1 / u) == 0
    # zeta substitution: ds0 = 2 zeta dzeta, s0 = 1/2 + zeta^2, zeta in (0, 1/sqrt 2)
    z = sp.Symbol("z", positive=True)
    lhs = (d.t_integrand_s.subs(s, sp.Rational(1, 2) + z**2) * 2 * z) ** 2
    rhs = d.t_integrand_zeta.subs(d.zeta, z) ** 2
    zeta_ok = sp.simplify(lhs - rhs) == 0
    # end time of the printed ODE: x = exp(-w)/2 maps int_0^{1/2} dx/sqrt(-x ln 2x)
    w = sp.Symbol("w", positive=True)
    a_integrand_w = sp.simplify(
        (1 / sp.sqrt(sp.Rational(1, 2) * sp.exp(-w) * w)) * sp.Rational(1, 2) * sp.exp(-w)
    )
    a_end_time = sp.simplify(sp.integrate(a_integrand_w, (w, 0, sp.oo)))
    a_end_speed_sq = sp.limit(a_fi_x, x, 0, "+")
    with mpmath.workdps(digits + 5):
        zeta_quad = 2 * mpmath.quad(
            lambda q: mpmath.sqrt((1 - 2 * q * q) / (1 - q * q)), [0, 1 / mpmath.sqrt(2)]
        )
        e_form = 2 * mpmath.ellipe(mpmath.pi / 4, 2)
        agm_form = mpmath.agm(1, mpmath.sqrt(2))
        a_end_quad = mpmath.quad(lambda q: 1 / mpmath.sqrt(-q * mpmath.log(2 * q)), [0, mpmath.mpf(1) / 2])
        t_ok = abs(mpmath.re(zeta_quad) - e_form) < mpmath.mpf(10) ** (-digits) and abs(
            e_form - agm_form
        ) < mpmath.mpf(10) ** (-digits)
        a_end_ok = abs(a_end_quad - mpmath.sqrt(mpmath.pi)) < mpmath.mpf(10) ** (-digits + 5)
        t_str = mpmath.nstr(mpmath.re(e_form), digits)
    return {
        "printed_ode": "s0'' = (1/2)(1 - s0'^2/(1 - s0))",
        "derived_ode": "s0'' = (1/2)(1 + s0'^2/(1 - s0))",
        "printed_first_integral": "s0'^2 = (1 - 4(1 - s0)^2) / (8(1 - s0))",
        "first_integral_satisfies_derived_ode": bool(res_derived == 0),
        "first_integral_satisfies_printed_ode": bool(res_printed == 0),
        "printed_ode_residual": f"s0''(from first integral) - printed RHS = {sp.sstr(sp.factor(sp.simplify((res_printed / 2).subs(s, 1 - x))))}  (x = 1 - s0)",
        "printed_ode_residual_is_speed_sq_over_x": bool(sp.simplify(res_printed / 2 - u / (1 - s)) == 0),
        "derived_first_integral_equals_printed": bool(sp.simplify(d.first_integral - u) == 0),
        "printed_ode_first_integral": (
            "s0'^2 = -(1 - s0) ln(2(1 - s0))" if a_fi_is_xlog else f"s0'^2 = {sp.sstr(a_fi_x)}  (x = 1 - s0)"
        ),
        "printed_ode_first_integral_equals_printed": bool(printed_fi_matches),
        "t_integrand_is_inverse_speed": bool(integrand_ok),
        "zeta_substitution_ok": bool(zeta_ok),
        "t_star_quadrature_equals_2E": bool(t_ok),
        "t_star": t_str,
        "printed_ode_end_time": str(a_end_time),
        "printed_ode_end_time_quadrature_ok": bool(a_end_ok),
        "printed_ode_end_speed_squared": str(a_end_speed_sq),
        "conclusion": (
            "The printed first integral (shockvelocity) and t* = 2E(pi/4|2) agree with each "
            "other and with energy conservation; the printed ODE has a sign typo: the "
            "consistent ODE is s0'' = (1/2)(1 + s0'^2/(1 - s0)). With the printed minus sign "
            "the kink reaches s0 = 1 at t = sqrt(pi) with zero speed (no snap)."
        ),
    }


# ============================================================ numerical solution
_GL_N = 24
_GL_V, _GL_W = np.polynomial.legendre.leggauss(_GL_N)
_GL_V = 0.5 * (_GL_V + 1.0)  # nodes on [0, 1]
_GL_W = 0.5 * _GL_W
_CHUNK = 1 << 15


def _tau_of_theta(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """tau(theta) = int_0^theta sqrt(sin u) du and d tau/d theta = sqrt(sin theta).

    With x = sin(theta)/2 this is t* - t (dt = -dx/s0' and s0' = cos th /(2 sqrt(sin th))).
    Computed as 2 theta^(3/2) int_0^1 v^2 sqrt(sinc(theta v^2)) dv by Gauss-Legendre
    (smooth for theta <= ~2): full relative precision as theta -> 0.
    """
    z = theta[:, None] * (_GL_V**2)[None, :]
    sinc = np.sinc(z / np.pi)
    integral = np.sqrt(sinc) @ (_GL_W * _GL_V**2)
    return 2.0 * theta**1.5 * integral, np.sqrt(np.sin(theta))


def _t_of_phi(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """t(phi) = int_0^phi sqrt(cos u) du, phi = pi/2 - theta, and dt/dphi (early times)."""
    z = phi[:, None] * _GL_V[None, :]
    integral = np.sqrt(np.cos(z)) @ _GL_W
    return phi * integral, np.sqrt(np.cos(phi))


def _solve_theta(tau: np.ndarray) -> np.ndarray:
    """theta with tau(theta) = tau, Newton on tau(theta)^(2/3) (nearly linear in theta)."""
    target = np.cbrt(tau) ** 2
    theta = np.cbrt(1.5 * tau) ** 2  # leading-order asymptote
    extra = 2  # quadratic convergence: two more steps after |step| < 1e-9 reach rounding level
    for _ in range(40):
        f, df = _tau_of_theta(theta)
        g = np.cbrt(f) ** 2 - target
        dg = (2.0 / 3.0) * df / np.cbrt(f)
        step = g / dg
        theta = theta - step
        if np.all(np.abs(step) <= 1e-9 * np.abs(theta)):
            extra -= 1
            if extra < 0:
                break
    else:  # pragma: no cover - never seen
        raise RuntimeError("kink inversion (theta) did not converge")
    return theta


def _solve_phi(t: np.ndarray) -> np.ndarray:
    """phi with t(phi) = t (early times), Newton."""
    phi = t.copy()
    extra = 2
    for _ in range(40):
        f, df = _t_of_phi(phi)
        step = (f - t) / df
        phi = phi - step
        if np.all(np.abs(step) <= 1e-9 * np.abs(phi)):
            extra -= 1
            if extra < 0:
                break
    else:  # pragma: no cover - never seen
        raise RuntimeError("kink inversion (phi) did not converge")
    return phi


@dataclass(frozen=True)
class KinkState:
    """State of the folded string at times t (arrays of the input's shape).

    Attributes
    ----------
    t : ndarray
        Time.
    tau : ndarray
        Time to snap t* - t, computed with t* in double-double (full relative
        precision even for tau ~ 1e-12).
    s0, s0_dot, s0_ddot : ndarray
        Kink position s0 and its first two time derivatives.
    moving_arm_length : ndarray
        x = 1 - s0, with full relative precision as t -> t*.
    tether_tension : ndarray
        sigma(0, t) = s0 + s0'^2 (pin tension).
    fold_tension : ndarray
        Tension at the kink, s0'^2 (equal on both sides of the energy-conserving fold).
    free_end_speed, free_end_acceleration : ndarray
        2 s0' and 2 s0'' (the whole moving arm moves at this speed; it is the
        maximum speed in the string).
    """

    t: np.ndarray
    tau: np.ndarray
    s0: np.ndarray
    s0_dot: np.ndarray
    s0_ddot: np.ndarray
    moving_arm_length: np.ndarray
    tether_tension: np.ndarray
    fold_tension: np.ndarray
    free_end_speed: np.ndarray
    free_end_acceleration: np.ndarray


def _as_array(name: str, value: ArrayLike) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SnappingInputError(f"{name}={value!r} is not a real number or array of real numbers") from None
    except OverflowError:  # an integer beyond the doubles (10**400)
        raise SnappingInputError(f"{name} holds a number too large for a float (|x| < 1.8e308)") from None
    if arr.size and not np.all(np.isfinite(arr)):
        bad = float(arr.ravel()[~np.isfinite(arr.ravel())][0])
        raise SnappingInputError(f"{name}={bad!r} must be a finite real number")
    return arr


#: smallest t* - t accepted (below, s0'' ~ tau^(-4/3) overflows a double)
TAU_MIN = 1e-230


def kink_state(t: ArrayLike | None = None, *, tau: ArrayLike | None = None) -> KinkState:
    """Exact state of the perfectly folded string at times ``t`` (or ``t* - t = tau``).

    Solves the kink ODE (paper, before eq. shockvelocity, sign corrected) via its
    first integral, eq. (shockvelocity), by inverting the time map in the
    variable theta with x = 1 - s0 = sin(theta)/2:

        t* - t = int_0^theta sqrt(sin u) du,

    (Newton on tau(theta)^(2/3), which is nearly linear in theta, so x, s0' and
    s0'' keep full relative precision as t -> t*), and for t < t*/2 in
    phi = pi/2 - theta with t = int_0^phi sqrt(cos u) du (full precision as
    t -> 0). Then s0' = cos(theta)/(2 sqrt(sin theta)) and
    s0'' = 1/2 + cot(theta)^2/4.

    Parameters
    ----------
    t : array_like, optional
        Times in [0, t*).
    tau : array_like, keyword-only, optional
        Times to snap t* - t in [TAU_MIN, t*] (TAU_MIN = 1e-230), instead of ``t``;
        use this to resolve tau below the double spacing near t* (~2e-16).

    Returns
    -------
    KinkState
        Arrays of the shape of the input (0-d arrays for scalars).

    Raises
    ------
    SnappingInputError
        If both or neither of ``t``/``tau`` are given, or a value is not finite
        or outside [0, t*) (``t``) / (0, t*] (``tau``).

    Examples
    --------
    >>> st = kink_state([0.0, 1.0])
    >>> st.s0.round(12)
    array([0.5       , 0.78364712])
    >>> st = kink_state(tau=1e-9)
    >>> float(st.s0_dot * 1e-9 ** (1 / 3))            # -> 12^(-1/3) = 0.43679...
    0.43679...
    """
    if (t is None) == (tau is None):
        raise SnappingInputError("give exactly one of t (in [0, t*)) or tau = t* - t (in (0, t*])")
    if t is not None:
        tt = _as_array("t", t)
        tau_arr = (_T_HI - tt) + _T_LO  # exact difference (Sterbenz) + low part
        bad = (tt < 0.0) | ~(tau_arr > 0.0)
        if np.any(bad):
            val = float(tt.ravel()[bad.ravel()][0])
            raise SnappingInputError(
                f"t={val!r} is out of range: must lie in [0, t*) with t* = 2E(pi/4|2) = {_T_STR}..."
            )
    else:
        tau_arr = _as_array("tau", tau)
        bad = ~(tau_arr >= TAU_MIN) | (tau_arr > _T_HI)
        if np.any(bad):
            val = float(tau_arr.ravel()[bad.ravel()][0])
            raise SnappingInputError(
                f"tau={val!r} is out of range: must lie in [{TAU_MIN:g}, t*] with t* = {_T_HI!r} (tau = t* - t; "
                f"closer to t* the acceleration ~ tau^(-4/3) leaves the doubles)"
            )
        tt = (_T_HI - tau_arr) + _T_LO
        tt = np.where(tau_arr >= _T_HI, 0.0, tt)  # tau = t* (as a double) means t = 0
    shape = tt.shape
    tt = tt.ravel()
    tau_f = tau_arr.ravel()

    sin_th = np.empty_like(tt)
    cos_th = np.empty_like(tt)
    late = tt >= 0.5 * _T_HI
    for start in range(0, tt.size, _CHUNK):
        sl = slice(start, start + _CHUNK)
        lt = late[sl]
        if np.any(lt):
            th = _solve_theta(tau_f[sl][lt])
            sin_th[sl][lt] = np.sin(th)
            cos_th[sl][lt] = np.cos(th)
        if np.any(~lt):
            ph = _solve_phi(tt[sl][~lt])
            sin_th[sl][~lt] = np.cos(ph)
            cos_th[sl][~lt] = np.sin(ph)

    x = 0.5 * sin_th
    s0_ = 1.0 - x
    with np.errstate(over="ignore"):  # tau < ~1e-230 overflows s0'' to inf
        sd = cos_th / (2.0 * np.sqrt(sin_th))
        sdd = 0.5 + 0.25 * (cos_th / sin_th) ** 2
        sd2 = sd * sd

    def r(a: np.ndarray) -> np.ndarray:
        return a.reshape(shape)[()]  # numpy scalars for scalar input

    return KinkState(
        t=r(tt),
        tau=r(tau_f),
        s0=r(s0_),
        s0_dot=r(sd),
        s0_ddot=r(sdd),
        moving_arm_length=r(x),
        tether_tension=r(s0_ + sd2),
        fold_tension=r(sd2),
        free_end_speed=r(2.0 * sd),
        free_end_acceleration=r(2.0 * sdd),
    )


def s0(t: ArrayLike) -> np.ndarray:
    """Kink position s0(t) of the folded string (paper eq. shockvelocity, integrated).

    Parameters
    ----------
    t : array_like
        Times in [0, t*).

    Returns
    -------
    ndarray
        s0 in [1/2, 1), same shape as ``t``.

    Examples
    --------
    >>> s0([0.0, 0.6, 1.19]).round(6)
    array([0.5     , 0.593083, 0.973498])
    """
    return kink_state(t).s0


def s0_dot(t: ArrayLike) -> np.ndarray:
    """Kink speed s0'(t) = sqrt((1 - 4x^2)/(8x)), x = 1 - s0 (paper eq. shockvelocity).

    Near t*: s0' ~ 12^(-1/3) (t* - t)^(-1/3). This is the *kink* speed; the
    free end (and the whole moving arm) moves at twice it, see
    :func:`free_end_speed`.

    Examples
    --------
    >>> s0_dot([0.0, 0.6]).round(6)
    array([0.      , 0.322071])
    """
    return kink_state(t).s0_dot


def s0_ddot(t: ArrayLike) -> np.ndarray:
    """Kink acceleration s0''(t) = (1/2)(1 + s0'^2/(1 - s0)) (the kink ODE, sign-corrected).

    Near t*: s0'' ~ (1/3) 12^(-1/3) (t* - t)^(-4/3).

    Examples
    --------
    >>> float(s0_ddot(0.0))
    0.5
    """
    return kink_state(t).s0_ddot


def moving_arm_length(t: ArrayLike) -> np.ndarray:
    """Length x = 1 - s0 of the moving arm, with full relative precision near t*.

    Near t*: x ~ (9/32)^(1/3) (t* - t)^(2/3). (The paper's cruder line through
    the initial point, (1/2)((t* - t)/t*)^(2/3), has a different prefactor.)

    Examples
    --------
    >>> float(moving_arm_length(0.0))
    0.5
    """
    return kink_state(t).moving_arm_length


def tether_tension(t: ArrayLike) -> np.ndarray:
    """Pin (tether) tension sigma(0, t) = s0 + s0'^2 (paper, after eq. for t*).

    From the momentum balance of the whole string; near t* it is
    ~ 12^(-2/3) (t* - t)^(-2/3).

    Examples
    --------
    >>> float(tether_tension(0.0))
    0.5
    """
    return kink_state(t).tether_tension


def fold_tension(t: ArrayLike) -> np.ndarray:
    """Tension at the kink, s0'^2 (the momentum flux through an energy-conserving fold).

    Examples
    --------
    >>> float(fold_tension(0.0))
    0.0
    """
    return kink_state(t).fold_tension


def free_end_speed(t: ArrayLike) -> np.ndarray:
    """Speed of the free end (and of the whole moving arm), 2 s0'.

    This is the maximum speed in the string; near t* it is
    ~ (2/3)^(1/3) (t* - t)^(-1/3) (twice the kink-speed prefactor 12^(-1/3)).

    Examples
    --------
    >>> float(free_end_speed(0.0))
    0.0
    """
    return kink_state(t).free_end_speed


def free_end_acceleration(t: ArrayLike) -> np.ndarray:
    """Acceleration of the free end, 2 s0'' = 1 + s0'^2/(1 - s0) (> g for t > 0).

    Near t*: ~ (1/3)(2/3)^(1/3) (t* - t)^(-4/3).

    Examples
    --------
    >>> float(free_end_acceleration(0.0))   # released from rest: g
    1.0
    """
    return kink_state(t).free_end_acceleration


def kink_energy(s0: ArrayLike, s0_dot: ArrayLike) -> np.ndarray:
    """Total energy E = 2 (1 - s0) s0'^2 + (1 - s0)^2 - 1/2 (per rho g, pin at y = 0).

    Conserved (= -1/4) along the ideal solution; see :func:`derivation`.

    Examples
    --------
    >>> float(kink_energy(0.5, 0.0))
    -0.25
    """
    s = _as_array("s0", s0)
    v = _as_array("s0_dot", s0_dot)
    x = 1.0 - s
    with np.errstate(over="ignore", invalid="ignore"):
        e = 2.0 * x * v * v + x * x - 0.5
    if not np.all(np.isfinite(e)):
        raise SnappingInputError(f"s0={V._short(s0)} with s0_dot={V._short(s0_dot)} is out of range: the energy "
                                 f"2 (1 - s0) s0'^2 + (1 - s0)^2 - 1/2 overflows a double")
    return e


# ====================================================================== scalings
@dataclass(frozen=True)
class Scaling:
    """A power law ``quantity ~ prefactor * (t* - t)^exponent`` as t -> t*.

    Attributes
    ----------
    quantity : str
        What the law describes (and which velocity/acceleration it is).
    exponent : sympy.Rational
        The exact exponent.
    prefactor : sympy.Expr or None
        Exact prefactor (None for observed or inferred-only laws).
    source : str
        ``"derived"`` (from the exact solution), ``"inferred"`` (from a
        scaling argument) or ``"observed"`` (the paper's numerics).
    note : str
        Where it comes from.
    """

    quantity: str
    exponent: Any
    prefactor: Any
    source: str
    note: str

    @property
    def exponent_float(self) -> float:
        """The exponent as a float."""
        return float(self.exponent)

    @property
    def prefactor_float(self) -> float | None:
        """The prefactor as a float (None if unknown)."""
        return None if self.prefactor is None else float(self.prefactor)

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable form: exponent as "p/q" and float, prefactor exact and float."""
        return {
            "quantity": self.quantity,
            "exponent": str(self.exponent),
            "exponent_float": self.exponent_float,
            "prefactor": None if self.prefactor is None else str(self.prefactor),
            "prefactor_float": self.prefactor_float,
            "source": self.source,
            "note": self.note,
        }


@functools.lru_cache(maxsize=1)
def asymptotic_scalings() -> dict[str, Scaling]:
    """Exponents and prefactors of the ideal singular solution as t -> t*, derived with sympy.

    Paper eq. (asymptoticscalings): v ~ s0' ~ tau^(-1/3), a ~ s0'' ~ tau^(-4/3),
    sigma ~ tau^(-2/3), tau = t* - t. Derivation (no number typed in):

    1. leading term of the first integral (shockvelocity) as x = 1 - s0 -> 0:
       s0'^2 ~ c x^alpha (sympy ``leadterm``: c = 1/8, alpha = -1);
    2. dx/dtau = s0' ~ sqrt(c) x^(alpha/2), integrated from x(0) = 0:
       x ~ X tau^q;
    3. s0' = sqrt(c) x^(alpha/2) ~ V tau^p; s0'' = -d s0'/d tau;
       sigma(0) = s0 + s0'^2 ~ s0'^2; free-end speed/acceleration = 2 x kink's;
    4. curvature, *inferred* (not derived from the singular solution, in which
       it is a delta function): kappa' ~ v kappa^2 with kappa ~ tau^k gives
       k - 1 = p + 2k, k = -2/3 (the paper's argument).

    Returns
    -------
    dict[str, Scaling]
        keys ``"s0_dot"``, ``"s0_ddot"``, ``"free_end_speed"``,
        ``"free_end_acceleration"``, ``"tether_tension"``, ``"fold_tension"``,
        ``"moving_arm_length"``, ``"curvature_inferred"``.

    Examples
    --------
    >>> sc = asymptotic_scalings()
    >>> [str(sc[k].exponent) for k in ("s0_dot", "s0_ddot", "tether_tension")]
    ['-1/3', '-4/3', '-2/3']
    >>> round(sc["s0_dot"].prefactor_float, 6), round(sc["free_end_speed"].prefactor_float, 6)
    (0.43679, 0.87358)
    """
    import sympy as sp

    d = derivation()
    x = d.x
    tau = sp.Symbol("tau", positive=True)
    X = sp.Symbol("X", positive=True)
    u_x = sp.simplify(d.first_integral.subs(d.s, 1 - x))
    c, alpha = sp.series(u_x, x, 0, 1).removeO().as_leading_term(x).as_coeff_exponent(x)
    c, alpha = sp.nsimplify(c), sp.nsimplify(alpha)
    vc = sp.sqrt(c)  # s0' ~ vc x^(alpha/2)
    # dx/dtau = vc x^(alpha/2), x(0) = 0
    lhs = sp.integrate(x ** (-alpha / 2), (x, 0, X))
    x_sol = sp.solve(sp.Eq(lhs, vc * tau), X)[0]
    x_coeff, x_exp = sp.powsimp(sp.expand_power_base(x_sol, force=True), force=True).as_coeff_exponent(tau)
    speed = sp.powsimp(sp.expand_power_base(vc * x_sol ** (alpha / 2), force=True), force=True)
    v_coeff, v_exp = speed.as_coeff_exponent(tau)
    acc = sp.powsimp(sp.expand_power_base(-sp.diff(speed, tau), force=True), force=True)
    a_coeff, a_exp = acc.as_coeff_exponent(tau)
    ten = sp.powsimp(sp.expand_power_base(speed**2, force=True), force=True)
    s_coeff, s_exp = ten.as_coeff_exponent(tau)
    k = sp.Symbol("k")
    k_exp = sp.solve(sp.Eq(k - 1, v_exp + 2 * k), k)[0]

    def nice(e):
        return sp.nsimplify(sp.simplify(e))

    out = {
        "s0_dot": Scaling(
            "kink speed s0'", sp.Rational(v_exp), nice(v_coeff), "derived",
            "leading term of the first integral (shockvelocity), integrated in time; the paper's v ~ s0'",
        ),
        "s0_ddot": Scaling(
            "kink acceleration s0''", sp.Rational(a_exp), nice(a_coeff), "derived",
            "time derivative of the s0' law; the paper's a ~ s0''",
        ),
        "free_end_speed": Scaling(
            "free-end speed 2 s0' (the maximum speed in the string)", sp.Rational(v_exp), nice(2 * v_coeff),
            "derived", "the moving arm falls rigidly at twice the kink speed",
        ),
        "free_end_acceleration": Scaling(
            "free-end acceleration 2 s0''", sp.Rational(a_exp), nice(2 * a_coeff), "derived",
            "twice the kink acceleration; the paper's free-end acceleration follows this law",
        ),
        "tether_tension": Scaling(
            "tether tension sigma(0) = s0 + s0'^2", sp.Rational(s_exp), nice(s_coeff), "derived",
            "s0 -> 1 is subdominant to s0'^2; the paper's sigma",
        ),
        "fold_tension": Scaling(
            "tension at the kink s0'^2", sp.Rational(s_exp), nice(s_coeff), "derived",
            "momentum flux through the energy-conserving fold",
        ),
        "moving_arm_length": Scaling(
            "moving-arm length 1 - s0", sp.Rational(x_exp), nice(x_coeff), "derived",
            "integral of dx/dtau = s0'",
        ),
        "curvature_inferred": Scaling(
            "curvature kappa (inferred)", sp.Rational(k_exp), None, "inferred",
            "from kappa' ~ v kappa^2 with v ~ tau^(-1/3) (paper); not observed in the chain",
        ),
    }
    return out


def observed_scalings() -> dict[str, Scaling]:
    """The paper's *observed* (numerical, not derived) exponents of the N = 5000 chain.

    * maximum curvature: apparently approaching (t* - t)^(-1/6) at late times
      before regularization, anomalously slower than the inferred -2/3;
    * maximum acceleration at intermediate times, located near the fold:
      what appears to be (t* - t)^(-5/6), before it crosses over to the free
      end, which follows the ideal -4/3.

    These are observations reported in the paper (section "Ideal and anomalous
    evolution", Fig. max), not consequences of the ideal solution; no
    prefactors are known.

    Returns
    -------
    dict[str, Scaling]
        keys ``"curvature_max"`` and ``"acceleration_max_intermediate"``.

    Examples
    --------
    >>> {k: str(v.exponent) for k, v in observed_scalings().items()}
    {'curvature_max': '-1/6', 'acceleration_max_intermediate': '-5/6'}
    """
    import sympy as sp

    return {
        "curvature_max": Scaling(
            "maximum curvature (anomalous)", sp.Rational(-1, 6), None, "observed",
            "paper, Fig. max(d): late times before regularization; slower than the inferred -2/3",
        ),
        "acceleration_max_intermediate": Scaling(
            "maximum acceleration at intermediate times (near the fold)", sp.Rational(-5, 6), None,
            "observed", "paper, Fig. max(b): before the maximum crosses over to the free end (-4/3)",
        ),
    }


# ======================================================================= summary
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
