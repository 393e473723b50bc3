"""snapping.estimates against closed forms, quadrature and the paper's derivations."""

import json
import math

import mpmath
import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from snapping import SnappingInputError, estimates as E
from snapping.cli import main

CHIS = [1e-9, 1e-4, 0.01, 0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 0.999, 1 - 1e-9]


@pytest.mark.parametrize("chi", CHIS)
def test_catenary_parameter_solves_its_equation(chi):
    a = E.catenary_parameter(chi)
    b = chi / (2 * a)
    # 1 = 2 a sinh(chi/2a)  <=>  sinh(b)/b = 1/chi; compare logs to stay finite for deep catenaries
    lhs = math.log(math.sinh(b) / b) if b < 700 else b - math.log(2 * b)
    assert lhs == pytest.approx(-math.log(chi), rel=1e-12, abs=1e-14)
    assert E.chi_from_parameter(a) == pytest.approx(chi, rel=1e-11)


def test_catenary_parameter_limits():
    # chi -> 1: nearly straight, 1 = 2a sinh(chi/2a) ~ chi + chi^3/(24 a^2)  =>  a ~ sqrt(chi^3 / (24 (1-chi)))
    chi = 1 - 1e-8
    assert E.catenary_parameter(chi) == pytest.approx(math.sqrt(chi**3 / (24 * (1 - chi))), rel=1e-6)
    # chi -> 0: the folded string; a -> 0 with chi = 2a asinh(1/2a) ~ 2a log(1/a)
    # (exactly chi = 2a asinh(1/2a) = 2a [log(1/a) + log((1 + sqrt(1 + 4a^2))/2)], the last
    # term ~ a^2 ~ 1e-27 here: the relative gap is set by the root finding alone)
    chi = 1e-12
    a = E.catenary_parameter(chi)
    assert chi == pytest.approx(2 * a * math.log(1 / a), rel=1e-12)


@pytest.mark.parametrize("chi", [0.01, 0.1, 0.25, 0.5, 0.9])
def test_catenary_shape_has_unit_length_and_right_ends(chi):
    a = E.catenary_parameter(chi)

    def speed(s):  # |r'(s)| by central differences of the closed form
        h = 1e-6
        lo, hi = max(s - h, 0.0), min(s + h, 1.0)
        x, y = E.catenary_shape([lo, hi], chi)
        return math.hypot(x[1] - x[0], y[1] - y[0]) / (hi - lo)

    length, _ = quad(speed, 0, 1, points=[0.5], limit=200)
    assert length == pytest.approx(1.0, rel=1e-8)
    x, y = E.catenary_shape([0.0, 0.5, 1.0], chi)
    assert x[0] == pytest.approx(0.0, abs=1e-14) and y[0] == pytest.approx(0.0, abs=1e-14)
    assert x[2] == pytest.approx(chi, abs=1e-14) and y[2] == pytest.approx(0.0, abs=1e-14)
    assert x[1] == pytest.approx(chi / 2)
    # the sag of a catenary with parameter a: sqrt(a^2 + 1/4) - a
    assert y[1] == pytest.approx(math.sqrt(a * a + 0.25) - a, rel=1e-12)
    # it is a catenary: y_bottom - y = a (cosh((x - chi/2)/a) - 1)
    s = np.linspace(0, 1, 101)
    xs, ys = E.catenary_shape(s, chi)
    assert np.allclose(y[1] - ys, a * (np.cosh((xs - chi / 2) / a) - 1), rtol=1e-10, atol=1e-13)


@pytest.mark.parametrize("chi", [0.05, 0.25, 0.75])
def test_curvature_maximum_is_one_over_a(chi):
    # curvature of the arclength-parametrised curve = |theta'(s)|; theta = atan2(y', x')
    a = E.catenary_parameter(chi)
    s = np.linspace(0.5 - 1e-3, 0.5 + 1e-3, 2001)
    x, y = E.catenary_shape(s, chi)
    theta = np.unwrap(np.arctan2(np.gradient(y, s), np.gradient(x, s)))
    kappa = np.abs(np.gradient(theta, s))
    assert kappa.max() == pytest.approx(1 / a, rel=1e-4)
    assert E.kappa_m0(chi) == pytest.approx(1 / a)


@pytest.mark.parametrize("chi", [0.01, 0.1, 0.25, 0.5, 0.9, 0.999])
def test_available_energy_matches_quadrature(chi):
    integral, _ = quad(lambda s: E.catenary_shape([s], chi)[1][0], 0, 1, points=[0.5], epsabs=1e-13, limit=200)
    # P = PE(catenary) - PE(hanging) = -int y ds - (-1/2)
    assert E.available_energy(chi) == pytest.approx(0.5 - integral, rel=1e-10)


def test_available_energy_limits():
    assert E.available_energy(1e-12) == pytest.approx(0.25, abs=1e-10)  # folded string: two arms of 1/2
    assert E.available_energy(1e-6) == pytest.approx(0.25, abs=1e-6)
    assert E.available_energy(1 - 1e-12) == pytest.approx(0.5, abs=1e-5)  # horizontal string
    P = [E.available_energy(c) for c in np.linspace(0.01, 0.99, 50)]
    assert np.all(np.diff(P) > 0)  # wider catenaries hold more energy to release


def test_delta_crude_is_where_the_two_paper_lines_meet():
    for chi in (0.1, 0.25, 0.4):
        k0 = E.kappa_m0(chi)
        front = lambda T: 0.5 * T ** (2 / 3)  # 1 - s(kappa_m) ~ (1/2) ((t*-t)/t*)^(2/3)
        scale = lambda T: 0.5 * math.pi / k0 * T ** (1 / 6)  # (pi/2) kappa_m^-1 ~ ... ((t*-t)/t*)^(1/6)
        T = brentq(lambda T: front(T) - scale(T), 1e-30, 1.0, xtol=1e-300, rtol=1e-15)
        assert T == pytest.approx((math.pi / k0) ** 2, rel=1e-12)
        assert E.delta_crude(chi) == pytest.approx(front(T), rel=1e-12)
        assert E.delta_crude(chi) < E.delta_kappa0(chi)


def _mp_catenary_parameter(chi):
    """a > 0 with 1 = 2 a sinh(chi/2a) (the paper, after Lockwood), in mpmath at 40 digits,
    by bisection in log a: 2 a sinh(chi/2a) falls from inf (a -> 0) to chi (a -> inf)."""
    with mpmath.workdps(40):
        chi = mpmath.mpf(chi)
        f = lambda a: 2 * a * mpmath.sinh(chi / (2 * a)) - 1  # noqa: E731
        lo, hi = mpmath.log(chi / (2 * (5 - mpmath.log(chi)))), mpmath.log(10**7)
        assert f(mpmath.exp(lo)) > 0 > f(mpmath.exp(hi))
        for _ in range(170):  # bracket width < 40 / 2^170 ~ 3e-50 in log a
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if f(mpmath.exp(mid)) > 0 else (lo, mid)
        return mpmath.exp((lo + hi) / 2)


@pytest.mark.parametrize("chi", [1e-9, 1e-4, 0.01, 0.1, 0.25, 0.5, 0.9, 0.999])
def test_scales_against_mpmath(chi):
    """delta_kappa0 = (pi/2)/kappa_m(0) and delta_c = (1/2)(pi/kappa_m(0))^(4/3), with
    kappa_m(0) = 1/a (paper, section "Amplification estimates" and eq. deltacrude), and
    P = 1/2 - int_0^1 y ds, all from an independent 40-digit solve for a (and quadrature)."""
    with mpmath.workdps(40):
        a = _mp_catenary_parameter(chi)
        dk0 = mpmath.pi / 2 * a
        dc = (mpmath.pi * a) ** (mpmath.mpf(4) / 3) / 2
        y = lambda s: mpmath.sqrt(a**2 + mpmath.mpf(1) / 4) - mpmath.sqrt(a**2 + (s - mpmath.mpf(1) / 2) ** 2)  # noqa: E731
        P = mpmath.mpf(1) / 2 - mpmath.quad(y, [0, mpmath.mpf(1) / 2, 1])
    assert E.catenary_parameter(chi) == pytest.approx(float(a), rel=1e-13, abs=0)
    assert E.delta_kappa0(chi) == pytest.approx(float(dk0), rel=1e-13, abs=0)
    assert E.delta_crude(chi) == pytest.approx(float(dc), rel=1e-13, abs=0)
    assert E.available_energy(chi) == pytest.approx(float(P), rel=1e-13, abs=0)


def test_whirling_rod_is_a_rigid_rotating_rod():
    P, delta = 0.27, 0.03
    pred = E.whirling_rod(P, delta)
    omega = pred["v"] / delta
    ke, _ = quad(lambda u: 0.5 * (omega * u) ** 2, 0, delta)  # rod of density 1 rotating about one end
    assert ke == pytest.approx(P, rel=1e-12)
    # tension of the rod from d sigma/du = -omega^2 u with sigma(delta) = 0 (free end)
    sol = solve_ivp(lambda u, s: [-(omega**2) * u], [delta, 0], [0.0], rtol=1e-12, atol=1e-14)
    assert sol.y[0, -1] == pytest.approx(pred["sigma"], rel=1e-9)
    assert pred["a"] == pytest.approx(omega**2 * delta, rel=1e-12)  # centripetal acceleration at the tip


def test_delta_N():
    assert E.delta_N(2000) == 1 / 2000
    with pytest.raises(SnappingInputError, match="N=0"):
        E.delta_N(0)


def test_si_equals_nondimensional_rescaled():
    chain = E.Chain(length=2.0, mass=0.5, g=9.0)
    est = E.design_estimate(chain, chi=0.25, N=1000)
    nd = E.design_estimate(E.Chain(length=1.0, mass=1.0, g=1.0), chi=0.25, N=1000)
    for name, p in est.predictions.items():
        q = est.si["predictions"][name]
        assert q["v_m_per_s"] == pytest.approx(p["v"] * math.sqrt(9.0 * 2.0))
        assert q["a_m_per_s2"] == pytest.approx(p["a"] * 9.0)
        assert q["sigma_N"] == pytest.approx(p["sigma"] * 0.5 * 9.0)
        # unit chain: SI numbers are the nondimensional ones
        r = nd.si["predictions"][name]
        assert (r["v_m_per_s"], r["a_m_per_s2"], r["sigma_N"]) == pytest.approx((p["v"], p["a"], p["sigma"]))
    assert est.si["t_star_s"] == pytest.approx(est.nondim["t_star"] * math.sqrt(2.0 / 9.0))
    assert est.si["kappa_m0_per_m"] == pytest.approx(est.nondim["kappa_m0"] / 2.0)
    # the same catenary given by its separation in metres, or by its curvature in 1/m
    by_sep = E.design_estimate(chain, separation=0.5)
    by_curv = E.design_estimate(chain, curvature=est.si["kappa_m0_per_m"])
    assert by_sep.nondim["chi"] == pytest.approx(0.25)
    assert by_curv.nondim["chi"] == pytest.approx(0.25, rel=1e-10)
    assert by_curv.predictions["delta_c"]["v"] == pytest.approx(est.predictions["delta_c"]["v"], rel=1e-9)


def test_paper_chain_worked_example():
    est = E.design_estimate(E.PAPER_CHAIN, chi=0.25)
    # M g for the paper's chain
    assert E.PAPER_CHAIN.force(1.0) == pytest.approx(0.0208 * 9.81)
    # delta_c predictions are larger than delta_kappa0 ones (smaller scale, more focusing)
    assert est.predictions["delta_c"]["a"] > est.predictions["delta_kappa0"]["a"]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(chi=0.0), r"chi=0\.0 .*\(0, 1\)"),
        (dict(chi=1.0), r"chi=1\.0 .*\(0, 1\)"),
        (dict(chi=-0.2), r"chi=-0\.2"),
        (dict(chi=float("nan")), r"chi=nan"),
        (dict(chi=float("inf")), r"chi=inf"),
        (dict(chi="0.2"), r"chi='0\.2'"),
        (dict(separation=2.0), r"separation=2\.0 .*\(0, 1\.022\)"),
        (dict(curvature=-1.0), r"curvature=-1\.0 .*> 0"),
        (dict(chi=0.2, N=0), r"N=0 .*\[1, inf\]"),
        (dict(chi=0.2, N=2.5), r"N=2\.5 is not an integer"),
        (dict(), r"exactly one of"),
        (dict(chi=0.2, curvature=3.0), r"exactly one of"),
    ],
)
def test_bad_input_names_parameter_value_range(kwargs, match):
    with pytest.raises(SnappingInputError, match=match):
        E.design_estimate(E.PAPER_CHAIN, **kwargs)


@pytest.mark.parametrize(
    "kwargs, match",
    [(dict(length=0.0), "length=0.0"), (dict(mass=-1.0), "mass=-1.0"), (dict(g=float("nan")), "g=nan")],
)
def test_bad_chain(kwargs, match):
    with pytest.raises(SnappingInputError, match=match):
        E.Chain(**kwargs)


def test_cli_estimate_table_and_json(capsys):
    assert main(["estimate", "--chi", "0.25"]) == 0
    out = capsys.readouterr().out
    assert "kappa_m(0)" in out and "delta_c" in out and "m/s" in out
    assert main(["estimate", "--chi", "0.25", "--N", "2000", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["chi"] == 0.25
    assert data["kappa_m0"] == pytest.approx(E.kappa_m0(0.25))
    assert set(data["predictions"]) == {"delta_kappa0", "delta_c", "delta_N"}
    assert data["si"]["predictions"]["delta_c"]["sigma_N"] == pytest.approx(
        E.PAPER_CHAIN.force(data["predictions"]["delta_c"]["sigma"])
    )


@pytest.mark.parametrize(
    "argv",
    [
        ["estimate", "--chi", "1.5"],
        ["estimate", "--chi", "nan"],
        ["estimate", "--chi", "0.2", "--length", "-1"],
        ["estimate", "--chi", "0.2", "--mass", "0"],
        ["estimate", "--chi", "0.2", "--g", "inf"],
        ["estimate", "--chi", "0.2", "--N", "0"],
        ["estimate", "--chi", "abc"],
        ["estimate"],
    ],
)
def test_cli_bad_input_is_one_line_exit_2(argv, capsys):
    with pytest.raises(SystemExit) if argv in (["estimate", "--chi", "abc"], ["estimate"]) else _nullctx() as e:
        code = main(argv)
    code = e.value.code if e is not None and hasattr(e, "value") else code
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "error" in err and "Traceback" not in err


class _nullctx:
    def __enter__(self):
        return None

    def __exit__(self, *exc):
        return False
