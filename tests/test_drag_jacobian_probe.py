"""The drag-Jacobian probe (``benchmarks/probe_drag_jacobian.py``, ``dragjac``): its drag rows are the
compiled right side's, its dense Jacobian is the compiled right side's derivative, and its O(N)
augmented stage solve equals the dense exact one to rounding on random states."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from snapping.simulate import Body, Problem, stiff

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("probe_drag_jacobian", ROOT / "benchmarks" / "probe_drag_jacobian.py")
probe = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(probe)


def _problems():
    # quadratic and linear drag, wind and a tip body on a bent, damped chain; and the nylon answer's level -3
    body = Body(1e-3, damping=1e-4, drag_normal=0.8, drag_tangential=0.05, drag_linear_normal=0.3,
                drag_linear_tangential=0.02, wind=(0.4, -0.2), tip_drag=0.3)
    return {"general": Problem.catenary(0.25, 40, body=body), "nylon": probe.nylon_problem(0.1, -3)}


def _state(pr, seed):
    mdl, y = stiff.body_model(pr)
    res = probe.DragResidual(mdl)
    N = res.N
    rng = np.random.default_rng(seed)
    y = y.copy()
    y[:N] += 0.3 * rng.standard_normal(N)
    y[N:2 * N] = 2.0 * rng.standard_normal(N)
    f = np.empty_like(y)
    res.rhs(0.0, y, f)
    return res, y, f


@pytest.mark.parametrize("name", ["general", "nylon"])
def test_drag_rows_vanish_at_the_compiled_accelerations(name):
    res, y, f = _state(_problems()[name], 3)
    N = res.N
    assert res.hasdrag
    full = res.R_full(0.0, y[:N], y[N:2 * N], f[N:2 * N], res.sig.copy())
    nodrag = res.R(0.0, y[:N], y[N:2 * N], f[N:2 * N], res.sig.copy())
    scale = np.abs(nodrag).max()
    assert scale > 1e-3  # (drag matters here: without it the rows do not vanish)
    assert np.abs(full).max() < 1e-11 * scale


@pytest.mark.parametrize("name", ["general", "nylon"])
def test_dense_jacobian_is_the_right_sides_derivative(name):
    res, y, f = _state(_problems()[name], 4)
    N = res.N
    gh = 1e-2
    J = np.eye(2 * N) / gh - probe.dense_stage_matrix(res, res.jacobian(0.0, y, f), gh)
    rng = np.random.default_rng(5)
    for col in list(rng.choice(N, 3, replace=False)) + list(N + rng.choice(N, 3, replace=False)):
        e = 1e-6 * max(1.0, abs(y[col]))
        fp, fm = np.empty_like(y), np.empty_like(y)
        yp, ym = y.copy(), y.copy()
        yp[col] += e
        ym[col] -= e
        res.rhs(0.0, yp, fp)
        res.rhs(0.0, ym, fm)
        d = (fp - fm)[:2 * N] / (2.0 * e)  # (central differences of the compiled right side)
        assert np.abs(d - J[:, col]).max() <= 1e-5 * np.abs(d).max(), col


@pytest.mark.parametrize("name", ["general", "nylon"])
@pytest.mark.parametrize("gh", [1e-5, 1e-3, 0.1])
def test_augmented_stage_solve_is_the_dense_exact_one(name, gh):
    res, y, f = _state(_problems()[name], 6)
    N = res.N
    D = res.jacobian(0.0, y, f)
    S = probe.dense_stage_matrix(res, D, gh)
    rng = np.random.default_rng(7)
    b = rng.standard_normal(2 * N) / gh
    ref = np.linalg.solve(S, b)
    aug = np.concatenate(probe.AugStage(res, D, gh).solve(b[:N], b[N:]))
    assert np.abs(aug - ref).max() <= 1e-10 * np.abs(ref).max()
    # today's banded solve leaves drag out: it is not the exact one (the test can tell them apart)
    ban = np.concatenate(probe.StageMatrix(res, D, gh).solve(b[:N], b[N:]))
    assert np.abs(ban - ref).max() > 1e-6 * np.abs(ref).max()


@pytest.mark.parametrize("gh", [1e-4, 1e-3])
def test_one_defect_correction_by_a_difference_is_the_dense_corrected_solve(gh):
    # corrfd1 (J U by one difference of the compiled right side) = corr1 (the dense exact product)
    # to the difference's rounding, and both much closer to the exact solve than the banded one
    res, y, f = _state(_problems()["nylon"], 8)
    N = res.N
    D = res.jacobian(0.0, y, f)
    rng = np.random.default_rng(9)
    b = rng.standard_normal(2 * N) / gh
    ref = np.linalg.solve(probe.dense_stage_matrix(res, D, gh), b)
    ban = np.concatenate(probe.StageMatrix(res, D, gh).solve(b[:N], b[N:]))
    corr = np.concatenate(probe.stage_class("corr1")(res, D, gh).solve(b[:N], b[N:]))
    fd = np.concatenate(probe.stage_class("corrfd1")(res, D, gh).solve(b[:N], b[N:]))
    scale = np.abs(ref).max()
    assert np.abs(fd - corr).max() <= 1e-5 * scale
    e_ban, e_corr = np.abs(ban - ref).max(), np.abs(corr - ref).max()
    assert e_ban > 1e-6 * scale and e_corr < 0.2 * e_ban
