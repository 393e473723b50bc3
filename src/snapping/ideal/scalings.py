"""The power laws near t*: exact exponents and prefactors of s0', s0'', the tensions, the free
end and the moving arm (:func:`asymptotic_scalings`, from the derivation), and the paper's
observed exponents (:func:`observed_scalings`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

from .symbolic import derivation


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
