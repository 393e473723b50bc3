"""The angle formulation, the compiled DOP853 integrator (method 'dop853' / 'fast') and ensembles."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipk

from snapping import schema
from snapping.simulate import ChainState, evaluate, initial_state, run
from snapping.simulate import angles as AG
from snapping.simulate import kernels as K


def _moving_angle_state(chi: float, N: int, seed: int = 1) -> np.ndarray:
    y = AG.state_to_angles(initial_state(chi, N, chords="exact"))
    y[N:] = np.random.default_rng(seed).standard_normal(N) * 3.0
    return y


def _rhs(y):
    N = y.size // 2
    w = AG.Work(N)
    f = np.empty(2 * N)
    AG.angle_rhs(N, y, f, w.c, w.s, w.S, w.cp, w.dp, w.sig)
    return f, w


# ---------------------------------------------------------------- the angle formulation
@pytest.mark.parametrize("N", [1, 2, 3, 8, 60])
def test_angle_form_agrees_with_position_form(N):
    """Same state (exact chords, rotating links): same tensions and node accelerations."""
    y = _moving_angle_state(0.3, N)
    f, w = _rhs(y)
    np.testing.assert_allclose(f, AG.reference_rhs(y), rtol=1e-10, atol=1e-9)  # vs a dense solve
    state = AG.angles_to_state(y)
    np.testing.assert_allclose(state.link_lengths() * N, 1.0, rtol=0, atol=1e-13)
    ev = evaluate(state)  # the paper's position form, kernels.rhs
    Z = np.zeros((K.NROWS, N + 1))
    AG.angles_to_Z(N, y, w.c, w.s, w.sig, Z)
    scale = max(1.0, np.abs(ev["tension"]).max())
    np.testing.assert_allclose(w.sig, ev["tension"], rtol=0, atol=1e-11 * scale)
    ascale = max(1.0, np.abs(ev["ax"]).max(), np.abs(ev["ay"]).max())
    np.testing.assert_allclose(Z[K.RAX], ev["ax"], rtol=0, atol=1e-11 * ascale)
    np.testing.assert_allclose(Z[K.RAY], ev["ay"], rtol=0, atol=1e-11 * ascale)
    # and the angular accelerations are the rotation of the links: theta_k'' = N (d_k'' . n_k) + ...
    ax, ay = Z[K.RAX], Z[K.RAY]
    th, om = y[:N], y[N:]
    ddx, ddy = np.diff(ax), np.diff(ay)
    np.testing.assert_allclose(N * (-np.sin(th) * ddx + np.cos(th) * ddy), f[N:], rtol=0, atol=1e-9 * N * ascale)
    np.testing.assert_allclose(N * (np.cos(th) * ddx + np.sin(th) * ddy), -om**2, rtol=0, atol=1e-9 * N * ascale)


def test_sincos_is_libm_to_an_ulp():
    x = np.concatenate([np.linspace(-50, 50, 100001), [0.0, -0.0, math.pi / 4, 1e4 + 0.3]])
    c, s = np.empty_like(x), np.empty_like(x)
    AG.sincos(x.size, x, c, s)
    np.testing.assert_allclose(c, np.cos(x), rtol=0, atol=3e-16)
    np.testing.assert_allclose(s, np.sin(x), rtol=0, atol=3e-16)
    big = np.array([1e6, -3e7])  # beyond the fast reduction: libm
    c, s = np.empty(2), np.empty(2)
    AG.sincos(2, big, c, s)
    assert c.tolist() == [math.cos(v) for v in big] and s.tolist() == [math.sin(v) for v in big]
    mixed = np.array([0.7, 1e6])  # each angle by its own path: the small one as it is alone
    AG.sincos(2, mixed, c, s)
    c1, s1 = np.empty(1), np.empty(1)
    AG.sincos(1, mixed[:1], c1, s1)
    assert (c[0], s[0], c[1], s[1]) == (c1[0], s1[0], math.cos(1e6), math.sin(1e6))


def test_hanging_chain_is_an_equilibrium_with_linear_tension():
    N = 30
    z = np.zeros(N + 1)
    y = AG.state_to_angles(ChainState(z, (N - np.arange(N + 1)) / N, z, z))
    f, w = _rhs(y)
    assert np.abs(f).max() < 1e-12
    np.testing.assert_allclose(w.sig, np.arange(1, N + 1) / N, atol=1e-13)


# ---------------------------------------------------------------- N = 1 and N = 2, exact
def test_simple_pendulum_period_and_peak_from_dense_output():
    phi0 = 1.2
    period = 4.0 * ellipk(math.sin(phi0 / 2) ** 2)
    st = ChainState([math.sin(phi0), 0.0], [math.cos(phi0), 0.0], [0.0, 0.0], [0.0, 0.0])
    r = run(initial=st, t_end=period / 2, tol=1e-12, method="dop853")
    s = r.state
    assert s.x[0] == pytest.approx(-math.sin(phi0), abs=1e-9)
    assert s.y[0] == pytest.approx(math.cos(phi0), abs=1e-9)
    assert math.hypot(s.vx[0], s.vy[0]) < 1e-9
    a = r.dataset.attrs
    assert a["energy_drift"] < 1e-11 and a["link_drift"] < 1e-15
    auto = run(initial=st, tol=1e-12, method="fast").dataset.attrs
    # the speed peak at the bottom, a quarter period in, located between steps
    assert auto["t_snap_v"] == pytest.approx(period / 4, abs=1e-8)
    assert auto["v_peak"] == pytest.approx(math.sqrt(2 * (1 - math.cos(phi0))), rel=1e-11)
    assert auto["sigma_peak"] == pytest.approx(1 + 2 * (1 - math.cos(phi0)), rel=1e-11)
    assert auto["n_steps"] < 60  # large steps: the peak is not a step sample


def _double_pendulum_rhs(t, u):
    m, l = 0.5, 0.5
    th1, th2, w1, w2 = u
    c, s = math.cos(th1 - th2), math.sin(th1 - th2)
    A = np.array([[2 * m * l, m * l * c], [l * c, l]])
    b = np.array([-m * l * w2 * w2 * s - 2 * m * math.sin(th1), l * w1 * w1 * s - math.sin(th2)])
    a1, a2 = np.linalg.solve(A, b)
    return [w1, w2, a1, a2]


def test_double_pendulum_against_lagrange_equations():
    th1, th2, T, l = 0.8, 2.0, 1.5, 0.5
    x1, y1 = l * math.sin(th1), l * math.cos(th1)
    x0, y0 = x1 + l * math.sin(th2), y1 + l * math.cos(th2)
    state = ChainState([x0, x1, 0.0], [y0, y1, 0.0], [0.0] * 3, [0.0] * 3)
    r = run(initial=state, t_end=T, tol=1e-12, method="dop853")
    ref = solve_ivp(_double_pendulum_rhs, (0, T), [th1, th2, 0.0, 0.0], method="DOP853", rtol=1e-13, atol=1e-13)
    a1, a2, w1, w2 = ref.y[:, -1]
    xe1, ye1 = l * math.sin(a1), l * math.cos(a1)
    xe0, ye0 = xe1 + l * math.sin(a2), ye1 + l * math.cos(a2)
    vx1, vy1 = l * w1 * math.cos(a1), -l * w1 * math.sin(a1)
    vx0, vy0 = vx1 + l * w2 * math.cos(a2), vy1 - l * w2 * math.sin(a2)
    s = r.state
    np.testing.assert_allclose([s.x[0], s.y[0], s.x[1], s.y[1]], [xe0, ye0, xe1, ye1], atol=1e-9)
    np.testing.assert_allclose([s.vx[0], s.vy[0], s.vx[1], s.vy[1]], [vx0, vy0, vx1, vy1], atol=1e-8)


# ---------------------------------------------------------------- full runs
@pytest.fixture(scope="module")
def pair():
    """chi = 0.5, N = 60 to the snap with both methods, same initial chain (exact chords)."""
    er = run(0.5, 60, chords="exact", method="euler-richardson")  # the paper's scheme, tol 1e-8
    ho = run(0.5, 60, chords="exact", method="fast", tol=1e-8, snapshot_times=(0.3, 0.71))
    return er, ho


def test_same_peaks_as_euler_richardson(pair):
    er, ho = pair
    a, b = er.dataset.attrs, ho.dataset.attrs
    assert b["method"] == "dop853" and b["status"] == "completed" and "snap" in b["stop_reason"]
    for q, rel in (("v_peak", 1e-6), ("sigma_peak", 1e-6), ("a_peak", 1e-5), ("kappa_peak", 1e-5)):
        assert b[q] == pytest.approx(a[q], rel=rel), q
    for q in ("t_snap_v", "t_snap_a", "t_snap_sigma"):
        assert b[q] == pytest.approx(a[q], abs=1e-6), q
    assert b["n_rhs"] * 20 < a["n_rhs"]


def test_invariants_exact_and_energy_to_tolerance(pair):
    _, ho = pair
    a = ho.dataset.attrs
    assert a["link_drift"] < 1e-14 and a["length_drift"] < 1e-14
    assert float(ho.dataset["link_error"].max()) < 1e-14
    assert a["energy_drift"] < 1e-9
    # positions are float64 sums of exact links: chords 1/N to round-off too
    for i in range(ho.dataset.sizes["snapshot"]):
        sn = ho.dataset.isel(snapshot=i)
        L = np.hypot(np.diff(sn["x"].values), np.diff(sn["y"].values))
        assert np.abs(L * 60 - 1).max() < 60 * 4e-16


def test_energy_drift_follows_the_tolerance():
    d = [run(0.5, 40, chords="exact", method="dop853", tol=tol).dataset.attrs["energy_drift"] for tol in (1e-5, 1e-8)]
    assert d[1] < 1e-9 and d[1] < d[0]


def test_dense_output_peak_matches_a_direct_evaluation(pair):
    _, ho = pair
    a = ho.dataset.attrs
    # the peak snapshot is the state at t_snap_v, and its largest speed is v_peak
    kinds = [str(k) for k in ho.dataset["snapshot_kind"].values]
    pk = ho.dataset.isel(snapshot=kinds.index("peak"))
    assert float(pk["t_snapshot"]) == a["t_snap_v"]
    assert float(pk["speed"].max()) == pytest.approx(a["v_peak"], rel=1e-12)
    # integrating straight to t_snap_v (the last step lands on it) gives the same speed
    direct = run(0.5, 60, chords="exact", method="dop853", tol=1e-8, t_end=a["t_snap_v"])
    assert float(direct.dataset["v_max"][-1]) == pytest.approx(a["v_peak"], rel=1e-8)
    # and it is a maximum: the samples never exceed it
    assert float(ho.dataset["v_max"].max()) <= a["v_peak"] * (1 + 1e-12)
    assert float(ho.dataset["a_max"].max()) <= a["a_peak"] * (1 + 1e-12)


def test_same_dataset_schema_and_exact_snapshot_times(pair):
    er, ho = pair
    assert set(ho.dataset.data_vars) == set(er.dataset.data_vars)
    assert set(ho.dataset.coords) == set(er.dataset.coords)
    for name in schema.STEP_VARS:
        assert ho.dataset[name].attrs["long_name"] == schema.STEP_VARS[name]["long_name"]
    kinds = [str(k) for k in ho.dataset["snapshot_kind"].values]
    tq = ho.dataset["t_snapshot"].values
    req = [float(t) for t, k in zip(tq, kinds) if k == "requested"]
    assert req == [0.3, 0.71]
    assert {"initial", "speed_level", "peak", "after_peak", "final"} <= set(kinds)


def test_rerun_and_file_round_trip(tmp_path):
    from snapping.simulate import load_run, rerun

    r = run(0.4, 20, method="fast", t_end=0.3, output=tmp_path / "r.nc")
    ds = load_run(tmp_path / "r.nc")
    assert ds.attrs["method"] == "dop853"
    r2 = rerun(ds)
    np.testing.assert_array_equal(r2.dataset["v_max"].values, r.dataset["v_max"].values)


def test_arclength_chords_keep_directions_with_exact_lengths():
    r = run(0.5, 30, method="dop853", chords="arclength", t_end=0.05)
    a = r.dataset.attrs
    assert a["link_error_initial"] < 1e-15 and a["link_drift"] < 1e-15
    ref = initial_state(0.5, 30)  # the paper's sampling: directions kept
    sn = r.dataset.isel(snapshot=0)
    th = np.arctan2(np.diff(sn["y"].values), np.diff(sn["x"].values))
    np.testing.assert_allclose(th, np.arctan2(np.diff(ref.y), np.diff(ref.x)), atol=1e-13)


def test_a_requested_time_inside_the_run_s_last_step_is_taken():
    """At tol 1e-6 a short run of N = 6 to t = 0.2 takes 3 steps: the last passes both
    requested times and t_end (its end code wins over the requested-time return); the
    snapshots are still taken there, from the dense output, and agree with runs that
    end at those times (tol 1e-10)."""
    ds = run(0.5, 6, method="fast", tol=1e-6, t_end=0.2, snapshot_times=(0.1, 0.15)).dataset
    assert ds.sizes["step"] <= 4  # the case: few, long steps
    kinds = [str(k) for k in ds["snapshot_kind"].values]
    req = [i for i, k in enumerate(kinds) if k == "requested"]
    assert [float(ds["t_snapshot"][i]) for i in req] == [0.1, 0.15]
    for i, te in zip(req, (0.1, 0.15)):
        s = run(0.5, 6, method="fast", tol=1e-10, t_end=te).state
        sn = ds.isel(snapshot=i)
        assert np.abs(sn["x"].values - s.x).max() < 1e-5 and np.abs(sn["vy"].values - s.vy).max() < 1e-4


def test_cli_lists_methods_and_runs_fast(capsys):
    from snapping.cli import main

    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    out = capsys.readouterr().out
    for m in ("euler-richardson", "euler-richardson-fixed", "dop853", "fast"):
        assert m in out
    assert main(["simulate", "--chi", "0.5", "--N", "20", "--method", "fast", "--json", "--no-progress"]) == 0
    assert '"method": "dop853"' in capsys.readouterr().out


# ---------------------------------------------------------------- ensembles
def test_ensemble_members_equal_single_runs_bit_for_bit():
    """The lanes do a single run's arithmetic in a single run's order: every attribute but
    the wall time and every variable of each member equal those of its single run
    exactly, through rejected steps (some lanes accept while others reject), members
    leaving the lanes at their snaps, and the last member finishing on the single kernel."""
    from snapping.simulate import run_ensemble

    chis = [0.3, 0.5, 0.5, 0.42]
    dss = run_ensemble(chis, 40, chords="exact", tol=1e-8, snapshot_times=(0.5,))
    assert sum(ds.attrs["n_rejected"] for ds in dss) > 0
    assert len({ds.attrs["n_steps"] for ds in dss}) > 1
    for chi, ds in zip(chis, dss):
        single = run(chi, 40, chords="exact", method="fast", tol=1e-8, snapshot_times=(0.5,)).dataset
        a, b = ds.attrs, single.attrs
        assert a["status"] == "completed" and a["chi"] == chi and a["method"] == "dop853"
        assert {k for k in set(a) | set(b) if str(a.get(k)) != str(b.get(k))} <= {"wall_time", "integrity_sha256"}
        assert set(ds.data_vars) == set(single.data_vars)
        for v in ds.data_vars:
            np.testing.assert_array_equal(ds[v].values, single[v].values, err_msg=v)
        assert a["link_drift"] < 1e-14 and a["energy_drift"] < 1e-9
        assert 0.5 in ds["t_snapshot"].values


def test_ensemble_member_failing_on_a_rejected_step_equals_its_single_run(monkeypatch):
    """A member that fails on a rejected attempt (its step below dt_min) while another
    member accepts in the same iteration: its Dataset, failure node and reason included,
    equals the single run's (which keeps the failed attempt for the diagnosis). Two
    members kept in the lanes (not handed to the single-run kernel) to reach that case."""
    from snapping.simulate import SimulationError, run_ensemble
    from snapping.simulate import ensemble as E

    monkeypatch.setattr(E, "SINGLE_BELOW", 1)
    with pytest.warns(UserWarning, match="chi=0.1 failed"):
        dss = run_ensemble([0.1, 0.2], 40, tol=1e-8, dt_min=3e-4)  # (chi = 0.1 needs steps below 3e-4)
    assert dss[0]["t"].values[-1] < dss[1]["t"].values[-1]  # failed while both were in the lanes
    with pytest.raises(SimulationError) as info:
        run(0.1, 40, method="fast", tol=1e-8, dt_min=3e-4)
    singles = [info.value.dataset, run(0.2, 40, method="fast", tol=1e-8, dt_min=3e-4).dataset]
    for ds, single in zip(dss, singles):
        a, b = ds.attrs, single.attrs
        assert {k for k in set(a) | set(b) if str(a.get(k)) != str(b.get(k))} <= {"wall_time", "integrity_sha256"}
        for v in ds.data_vars:
            np.testing.assert_array_equal(ds[v].values, single[v].values, err_msg=v)
    assert dss[0].attrs["status"] == "failed" and dss[0].attrs["failure_node"] > 0
    assert dss[1].attrs["status"] == "completed"


@pytest.mark.parametrize("N", [1, 2, 3, 37])
@pytest.mark.parametrize("W", [1, 2, 3, 8])
def test_rhs_lanes_equals_angle_rhs_bit_for_bit(N, W):
    """The lane kernel (elementwise passes over node x lane, recurrences across lanes) gives
    each lane exactly angles.angle_rhs of that chain, tensions included; also on the libm
    path taken when an angle is too large for the polynomial's reduction."""
    from snapping.simulate.ensemble import LaneWork, rhs_lanes

    rng = np.random.default_rng(N * 10 + W)
    for big in (False, True):
        y = np.vstack([np.cumsum(rng.normal(0.0, 0.7, (N, W)), axis=0), rng.normal(0.0, 3.0, (N, W))])
        if big:
            y[0, 0] = 3.0e5 + 0.25
        f = np.empty_like(y)
        w = LaneWork(N, W)
        rhs_lanes(N, y, f, *w.args())
        one = AG.Work(N)
        f1 = np.empty(2 * N)
        for lane in range(W):
            AG.angle_rhs(N, np.ascontiguousarray(y[:, lane]), f1, one.c, one.s, one.S, one.cp, one.dp, one.sig)
            np.testing.assert_array_equal(f[:, lane], f1)
            np.testing.assert_array_equal(w.sig[:, lane], one.sig)
        np.testing.assert_allclose(f[:, 0], AG.reference_rhs(y[:, 0]), rtol=1e-9, atol=1e-9 * np.abs(f[:, 0]).max())


def test_ensemble_bad_input():
    from snapping import SnappingInputError
    from snapping.simulate import run_ensemble

    with pytest.raises(SnappingInputError, match="chi"):
        run_ensemble([0.3, 1.5], 10)
    with pytest.raises(SnappingInputError, match="method"):
        run_ensemble([0.3], 10, method="euler-richardson")
    with pytest.raises(SnappingInputError, match="empty"):
        run_ensemble([], 10)


@pytest.mark.parametrize("name", ["angles", "rk", "methods", "methods.dop853", "ensemble", "options"])
def test_docstring_examples(name):
    import doctest
    import importlib

    module = importlib.import_module(f"snapping.simulate.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    # a module without examples would pass by construction: require that some ran
    assert result.failed == 0 and result.attempted > 0, result
