"""The stiffness of a chain with bending (snapping.simulate.stiffness): the shortest wave
against the eigenvalues of the exact Jacobian, DOP853's stability boundary from its tableau
and from its measured steps, the automatic choice of ``method="fast"`` on both sides of its
threshold, and the cost message of an explicit method named on a stiff problem."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.simulate import Body, Problem, run
from snapping.simulate import stiff_system as SS
from snapping.simulate import stiffness as SF


def _stability_boundary(direction):
    """Where DOP853's stability function first leaves the unit disc along ``direction`` (its
    Butcher tableau, scipy's coefficients; independent of the module)."""
    from scipy.integrate._ivp import dop853_coefficients as dc

    A, b = dc.A[:12, :12], dc.B
    for r in np.arange(0.01, 10.0, 0.01):
        z = r * direction
        if abs(1 + z * b @ np.linalg.solve(np.eye(12) - z * A, np.ones(12))) > 1 + 1e-9:
            return r - 0.01
    return 10.0


def test_dop853_stability_boundary():
    assert SF.R_DOP853 == pytest.approx(min(_stability_boundary(1j), _stability_boundary(-1.0)), abs=0.02)


def _problem(N, beta, zeta, **kw):
    return Problem.catenary(0.25, N, body=Body(bending=beta, damping=zeta * np.sqrt(beta) / (2 * N ** 2)), **kw)


@pytest.mark.parametrize("N,beta", [(20, 1e-2), (40, 1e-2), (40, 1e-3)])
def test_shortest_wave_is_the_jacobians_largest_eigenvalue(N, beta):
    """omega_max against the eigenvalues of the exact (dense) Jacobian at the catenary; the
    damping ratio against that eigenvalue's angle (bending-dominated: -zeta omega)."""
    for zeta in (0.0, 1.0):
        p = _problem(N, beta, zeta)
        mdl, y = SS.body_model(p)
        res = SS.Residual(mdl)
        f = np.empty_like(y)
        res.rhs(0.0, y, f)
        ev = np.linalg.eigvals(SS.dense_ode_jacobian(res, 0.0, y, res.jacobian(0.0, y, f)))
        om, z = SF.shortest_wave(p.model())
        top = ev[np.argmax(np.abs(ev))]
        assert 0.9 < abs(top) / om < 1.1
        assert z == pytest.approx(-top.real / abs(top), abs=0.08)  # (-zeta omega + i ...; T overestimated)
        assert z > 0.9 if zeta else z == 0.0


def test_dop853_steps_sit_at_the_stability_limit_when_the_waves_are_damped():
    """Damping ratio 1: dop853's median accepted step is R_DOP853/omega_max (stability, not
    accuracy, sets it: 6.3/omega measured); undamped it is smaller (the excited waves)."""
    p = _problem(100, 1e-2, 1.0)
    om, _ = SF.shortest_wave(p.model())
    dt = run(p, method="dop853", t_end=0.2).dataset["dt"].values[1:]
    assert 0.9 < np.median(dt) * om / SF.R_DOP853 < 1.2
    dt0 = run(_problem(100, 1e-2, 0.0), method="dop853", t_end=0.2).dataset["dt"].values[1:]
    assert np.median(dt0) * om < 0.4 * SF.R_DOP853
    p3 = _problem(100, 1e-2, 3.0)  # overdamped: the damping's eigenvalue -omega (zeta + sqrt(zeta^2 - 1))
    om3, z3 = SF.shortest_wave(p3.model())
    dt3 = run(p3, method="dop853", t_end=0.2).dataset["dt"].values[1:]
    assert 0.9 < np.median(dt3) * SF.largest_eigenvalue(om3, z3) / SF.R_DOP853 < 1.2


@pytest.mark.parametrize("zeta,expect", [(1.0, "dop853"), (10.0, "rodas4")])
def test_fast_chooses_the_cheaper_method_on_either_side_of_the_threshold(zeta, expect):
    """N = 300, beta = 1e-2, from rest: damping ratio 1 (measured: 1143 dop853 steps against
    1028 RODAS4 steps, each ~2.5 DOP853 steps of time) is dop853's, 10 (~23x fewer) rodas4's
    (ratio 2, the rule's threshold, is not tested: there the estimate chose dop853 at 4211
    against RODAS4's priced 1903 once the start was the rest shape); both run to t = 0.2 and the
    chosen one costs less, its steps priced at stiffness.RODAS4_PRICE (measured apart:
    benchmarks/bench_stiff_costs.py)."""
    p = _problem(300, 1e-2, zeta)
    method, why = SF.choose(p, t_end=0.2)
    assert SF.choose(p)[0] == method
    assert method == expect and why.startswith(f"{expect} chosen by method='fast'")
    ds = run(p, t_end=0.2).dataset
    assert ds.attrs["method"] == expect and ds.attrs["method_choice"] == why
    d = run(p, method="dop853", t_end=0.2).dataset.attrs
    r = run(p, method="rodas4", t_end=0.2).dataset.attrs
    cost = {"dop853": d["n_steps"] + d["n_rejected"], "rodas4": SF.RODAS4_PRICE * (r["n_steps"] + r["n_rejected"])}
    assert cost[expect] < cost["rodas4" if expect == "dop853" else "dop853"], cost


def test_undamped_bending_waves_keep_dop853():
    """Undamped, the release's grid-scale waves limit RODAS4 by accuracy too (it then needs
    4-8x dop853's steps, benchmarks/bench_stiff.py): fast stays explicit however stiff the
    line; the same line damped (ratio 1) at N = 3000 is RODAS4's."""
    method, why = SF.choose(_problem(3000, 1e-2, 0.0))
    assert method == "dop853" and "undamped" in why
    assert SF.choose(_problem(3000, 1e-2, 1.0))[0] == "rodas4"


def test_cli_names_the_stiff_method(capsys):
    from test_files import _cli, _one_line_error

    code, out, err = _cli(["simulate", "--N", "12", "--chi", "0.3", "--bending", "1e-3", "--method", "stiff",
                           "--t-end", "0.05", "--json", "--no-progress"], capsys)
    assert code == 0, err
    assert '"method": "rodas4"' in out
    code, out, err = _cli(["simulate", "--N", "12", "--chi", "0.3", "--method", "stiff", "--t-end", "0.05",
                           "--no-progress"], capsys)
    assert code == 2 and "method='rodas4' (stiff) solves chains with a body" in _one_line_error(err)


def test_runs_without_bending_keep_dop853_and_no_choice_attribute():
    for p in (Problem.catenary(0.25, 10), Problem.catenary(0.25, 10, body=Body(drag_normal=0.5))):
        a = run(p, t_end=0.05).dataset.attrs
        assert a["method"] == "dop853" and "method_choice" not in a


def test_cost_message_warns_then_refuses_and_names_the_stiff_method():
    stiff = _problem(2000, 1e-2, 1.0)  # ~1.6e5 explicit steps per unit time
    n = SF.explicit_steps(stiff.model(), 1.2)
    assert SF.WARN_STEPS < 20 * n < SF.REFUSE_STEPS
    with pytest.warns(SF.CostWarning, match=r"method='dop853'.*at least ~.* steps.*method='rodas4'"):
        SF.check_cost(stiff, "dop853", t_end=1.2 * 20)
    with pytest.raises(SnappingInputError,
                       match=r"method='dop853'.*at least.*method='rodas4'.*refused above 1e\+09 steps"):
        run(stiff, method="dop853", t_end=1.2 * 2e4 / n * 1e5, t_end_max=1e9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        SF.check_cost(stiff, "dop853", t_end=0.1)  # (a short run: no message)
        SF.check_cost(Problem.catenary(0.25, 2000), "dop853", t_end=100.0)
