"""The chain simulator: physics, numerics, the run Dataset, inputs and the CLI."""

from __future__ import annotations

import json
import math
import os

import mpmath
import numpy as np
import pytest
import xarray as xr
from scipy.integrate import solve_ivp
from scipy.special import ellipk

from snapping import SnappingInputError, schema
from snapping.cli import main
from snapping.simulate import (
    ChainState,
    SimulationError,
    evaluate,
    initial_state,
    integrate_fixed,
    load_run,
    rerun,
    run,
    summary,
)

T_STAR = float(2 * mpmath.ellipe(mpmath.pi / 4, 2))  # ideal snapping time 2E(pi/4|2)


def pendulum_state(phi0: float) -> ChainState:
    """N = 1: the unit-length pendulum at rest at angle phi0 from the downward vertical."""
    return ChainState([math.sin(phi0), 0.0], [math.cos(phi0), 0.0], [0.0, 0.0], [0.0, 0.0])


def hanging_state(N: int) -> ChainState:
    z = np.zeros(N + 1)
    return ChainState(z, (N - np.arange(N + 1)) / N, z, z)


# ---------------------------------------------------------------- N = 1 and N = 2
def test_simple_pendulum_period_and_tension():
    phi0 = 1.2
    period = 4.0 * ellipk(math.sin(phi0 / 2) ** 2)  # exact, K(m) with m = k^2
    r = run(initial=pendulum_state(phi0), t_end=period / 2, tol=1e-11)
    s = r.state
    # half a period later: at rest at the opposite angle
    assert s.x[0] == pytest.approx(-math.sin(phi0), abs=1e-7)
    assert s.y[0] == pytest.approx(math.cos(phi0), abs=1e-7)
    assert math.hypot(s.vx[0], s.vy[0]) < 1e-6
    # tension m g cos(phi) + m v^2 / l in every snapshot, and energy conserved
    ds = r.dataset
    y, v2 = ds["y"].isel(node=0).values, (ds["speed"].isel(node=0) ** 2).values
    np.testing.assert_allclose(ds["tension"].isel(link=0).values, y + v2, rtol=0, atol=1e-12)
    assert ds.attrs["energy_drift"] < 1e-8
    # the automatic stop finds the speed peak at the bottom, a quarter period in
    auto = run(initial=pendulum_state(phi0), tol=1e-11)
    assert auto.dataset.attrs["t_snap_v"] == pytest.approx(period / 4, abs=1e-6)
    assert auto.dataset.attrs["v_peak"] == pytest.approx(math.sqrt(2 * (1 - math.cos(phi0))), rel=1e-8)
    assert auto.dataset.attrs["sigma_peak"] == pytest.approx(1 + 2 * (1 - math.cos(phi0)), rel=1e-8)


def _double_pendulum_rhs(t, u):
    """Lagrange equations of two point masses m = 1/2 on massless rods l = 1/2, g = 1
    (angles from the downward vertical; 1 = upper link, 2 = lower link)."""
    m, l = 0.5, 0.5
    th1, th2, w1, w2 = u
    c, s = math.cos(th1 - th2), math.sin(th1 - th2)
    # [2 m l, m l c; l c, l] [th1'', th2''] = [-m l w2^2 s - 2 m sin th1, l w1^2 s - sin th2]
    A = np.array([[2 * m * l, m * l * c], [l * c, l]])
    b = np.array([-m * l * w2 * w2 * s - 2 * m * math.sin(th1), l * w1 * w1 * s - math.sin(th2)])
    a1, a2 = np.linalg.solve(A, b)
    return [w1, w2, a1, a2]


def test_double_pendulum_against_lagrange_equations():
    th1, th2, T = 0.8, 2.0, 1.5
    l = 0.5
    x1, y1 = l * math.sin(th1), l * math.cos(th1)  # node 2 (index 1)
    x0, y0 = x1 + l * math.sin(th2), y1 + l * math.cos(th2)  # node 1, the free end
    state = ChainState([x0, x1, 0.0], [y0, y1, 0.0], [0.0] * 3, [0.0] * 3)
    r = run(initial=state, t_end=T, tol=1e-11)
    ref = solve_ivp(_double_pendulum_rhs, (0, T), [th1, th2, 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12)
    a1, a2, w1, w2 = ref.y[:, -1]
    xe1, ye1 = l * math.sin(a1), l * math.cos(a1)
    xe0, ye0 = xe1 + l * math.sin(a2), ye1 + l * math.cos(a2)
    vx1, vy1 = l * w1 * math.cos(a1), -l * w1 * math.sin(a1)
    vx0, vy0 = vx1 + l * w2 * math.cos(a2), vy1 - l * w2 * math.sin(a2)
    s = r.state
    np.testing.assert_allclose([s.x[0], s.y[0], s.x[1], s.y[1]], [xe0, ye0, xe1, ye1], atol=2e-6)
    np.testing.assert_allclose([s.vx[0], s.vy[0], s.vx[1], s.vy[1]], [vx0, vy0, vx1, vy1], atol=2e-5)


# ---------------------------------------------------------------- statics, invariants, order
def test_hanging_chain_stays_at_rest_with_linear_tension():
    N = 40
    ev = evaluate(hanging_state(N))
    np.testing.assert_allclose(ev["tension"], np.arange(1, N + 1) / N, rtol=0, atol=1e-13)
    assert np.abs(ev["ax"]).max() < 1e-12 and np.abs(ev["ay"]).max() < 1e-12
    r = run(initial=hanging_state(N), t_end=2.0, method="euler-richardson")  # (the position form)
    s = r.state
    np.testing.assert_allclose(s.y, hanging_state(N).y, atol=1e-12)
    assert np.abs(s.x).max() < 1e-12 and np.abs(s.vy).max() < 1e-12
    last = r.dataset.isel(snapshot=-1)
    # (the tension system of the hanging chain has condition number ~ N^2: 1e-12 in the
    # positions, from the few huge steps the error rule allows at rest, is ~1e-9 here)
    np.testing.assert_allclose(last["tension"].values, np.arange(1, N + 1) / N, rtol=0, atol=1e-8)
    assert float(r.dataset["pin_force_y"][-1]) == pytest.approx(1.0, abs=1e-8)  # the whole weight
    assert float(r.dataset["pin_force_x"][-1]) == pytest.approx(0.0, abs=1e-8)


def test_initial_tension_and_chords():
    N = 200
    s0 = initial_state(0.25, N)
    x, y = s0.x, s0.y
    assert (x[0], y[0], x[-1], y[-1]) == (0.25, 0.0, 0.0, 0.0)
    ev = evaluate(s0)
    assert ev["tension"][0] > 0 and np.all(np.diff(ev["tension"]) > 0)  # rises from the free end to the pin
    # equal arclength sampling (the paper's chain) shortens the chords by about kappa^2 / (24 N^2)
    r = run(0.25, N, t_end=1e-3, method="euler-richardson", chords="arclength")
    kappa0 = r.dataset.attrs["kappa_max_0"]
    assert r.dataset.attrs["link_error_initial"] == pytest.approx(kappa0**2 / (24 * N**2), rel=0.05)
    # exactly: the largest chord deficit 1 - N |r(s_k) - r(s_k+1)| of the closed-form catenary
    # (mpmath; at the links beside the bottom, where kappa is largest)
    mp, _, xy = _mp_catenary(0.25)
    nodes = [xy(mp.mpf(k) / N) for k in range(N + 1)]
    deficit = max(abs(1 - N * mp.hypot(x1 - x0, y1 - y0)) for (x0, y0), (x1, y1) in zip(nodes, nodes[1:]))
    assert r.dataset.attrs["link_error_initial"] == pytest.approx(float(deficit), rel=1e-9, abs=0)
    exact = initial_state(0.25, N, chords="exact")
    np.testing.assert_allclose(exact.link_lengths(), 1.0 / N, rtol=1e-12)


def test_energy_and_link_drift_within_paper_bounds():
    r = run(0.5, 100, method="euler-richardson", chords="exact")  # the paper's scheme, tol 1e-8, to after the snap
    a = r.dataset.attrs
    assert a["status"] == "completed" and "snap" in a["stop_reason"]
    assert a["energy_drift"] < 8e-7
    assert a["link_drift"] < 5e-4
    assert a["length_drift"] < 4e-6
    e = r.dataset["energy"].values
    assert np.abs(e - a["energy_initial"]).max() <= a["energy_drift"] * (1 + 1e-12)


def test_second_order_at_fixed_step():
    s0 = initial_state(0.5, 6, chords="exact")
    T = 0.4
    ref = integrate_fixed(s0, T / 6400, 6400)
    errs = []
    for n in (50, 100, 200):
        s = integrate_fixed(s0, T / n, n)
        errs.append(max(np.abs(s.x - ref.x).max(), np.abs(s.vx - ref.vx).max(), np.abs(s.vy - ref.vy).max()))
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.15), orders


def test_peaks_converge_as_tol_decreases():
    peaks = {}
    for tol in (1e-7, 1e-9):
        a = run(0.3, 50, chords="exact", tol=tol).dataset.attrs
        peaks[tol] = a
    for q, rel in (("v_peak", 1e-6), ("a_peak", 1e-5), ("sigma_peak", 1e-5), ("t_snap_v", 1e-7)):
        assert peaks[1e-9][q] == pytest.approx(peaks[1e-7][q], rel=rel), q


def test_snapping_time_approaches_ideal_as_chi_decreases():
    gaps = [abs(run(chi, 150).dataset.attrs["t_snap_v"] - T_STAR) for chi in (0.4, 0.2, 0.1)]
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 2e-3


def test_snap_diagnostics_agree():
    ds = run(0.25, 300, method="euler-richardson", chords="arclength").dataset  # (peaks at recorded steps)
    a = ds.attrs
    # snapping times from speed, acceleration, tension agree (paper: ~5 significant digits at N = 2000)
    assert abs(a["t_snap_a"] - a["t_snap_v"]) < 1e-3 * a["t_snap_v"]
    assert abs(a["t_snap_sigma"] - a["t_snap_v"]) < 1e-3 * a["t_snap_v"]
    assert a["v_peak"] == pytest.approx(float(ds["v_max"].max()))
    assert a["a_peak"] > 1e3
    kinds = list(ds["snapshot_kind"].values)
    assert kinds[0] == "initial" and kinds[-1] == "final" and "peak" in kinds and "after_peak" in kinds
    assert kinds.count("speed_level") >= 4
    peak = ds.isel(snapshot=kinds.index("peak"))
    assert float(peak["speed"].max()) == pytest.approx(a["v_peak"], rel=1e-12)
    assert float(peak["t_snapshot"]) == pytest.approx(a["t_snap_v"], abs=1e-5)
    # the curvature profile's maximum matches the per-step record
    step = int(np.argmin(np.abs(ds["t"].values - float(peak["t_snapshot"]))))
    assert float(np.nanmax(np.abs(peak["curvature"]))) == pytest.approx(float(ds["kappa_max"][step]), rel=1e-9)


def test_thinned_record_keeps_snap_results():
    ER = dict(method="euler-richardson", chords="arclength")  # (many small steps to thin)
    full = run(0.5, 40, **ER).dataset
    thin = run(0.5, 40, record_thin=1e-3, **ER).dataset
    assert thin.sizes["step"] < full.sizes["step"] / 5
    for k in ("t_snap_v", "t_snap_a", "t_snap_sigma", "v_peak", "a_peak", "sigma_peak", "energy_drift"):
        assert thin.attrs[k] == full.attrs[k]


# ---------------------------------------------------------------- the Dataset on disk
def test_saved_file_is_self_describing_and_reruns(tmp_path):
    path = tmp_path / "run.nc"
    r = run(0.5, 20, snapshot_times=[0.5, 1.0], output=path)
    ds = load_run(path)
    for name, var in {**ds.data_vars, **ds.coords}.items():
        if name in schema.ALL_VARS or name in schema.COORDS:
            assert var.attrs["units"] and var.attrs["long_name"], name
    for k in list(schema.INPUT_ATTRS) + list(schema.RESULT_ATTRS):
        assert k in ds.attrs, k
    assert ds.attrs["status"] == "completed"
    assert (ds["snapshot_kind"].values == "requested").sum() == 2
    with xr.open_dataset(path) as raw:
        assert raw.sizes["step"] == r.dataset.sizes["step"]
    again = rerun(ds)
    np.testing.assert_array_equal(again.dataset["v_max"].values, ds["v_max"].values)
    assert again.dataset.attrs["t_snap_v"] == ds.attrs["t_snap_v"]


def test_custom_initial_state_reruns_from_file(tmp_path):
    path = tmp_path / "pend.nc"
    run(initial=pendulum_state(0.7), t_end=0.5, output=path)
    ds = load_run(path)
    assert ds.attrs["initial"] == "snapshot"
    np.testing.assert_array_equal(rerun(ds).dataset["v_end"].values, ds["v_end"].values)


# ---------------------------------------------------------------- bad input and failures
@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"chi": 0.0, "N": 10}, "chi"),
        ({"chi": 1.0, "N": 10}, "chi"),
        ({"chi": -0.3, "N": 10}, "chi"),
        ({"chi": 0.3, "N": 0}, "N"),
        ({"chi": 0.3, "N": 2.5}, "N"),
        ({"chi": 0.3, "N": 10, "tol": 0.0}, "tol"),
        ({"chi": 0.3, "N": 10, "tol": -1e-8}, "tol"),
        ({"chi": 0.3, "N": 10, "t_end": 0.0}, "t_end"),
        ({"chi": 0.3, "N": 10, "t_end": -1.0}, "t_end"),
        ({"chi": 0.3, "N": 10, "method": "rk4"}, "method"),
        ({"chi": 0.3, "N": 10, "output": "/nonexistent-dir/run.nc"}, "output"),
    ],
)
def test_bad_input_raises(kwargs, name):
    with pytest.raises(SnappingInputError, match=name):
        run(**kwargs)


def test_unwritable_output_checked_before_running(tmp_path):
    with pytest.raises(SnappingInputError, match="output"):
        run(0.3, 10, output=tmp_path)  # a directory


@pytest.mark.parametrize(
    "argv",
    [
        ["--chi", "1.5", "--N", "10"],
        ["--chi", "0.3", "--N", "0"],
        ["--chi", "0.3", "--N", "10", "--tol", "0"],
        ["--chi", "0.3", "--N", "10", "--t-end", "-1"],
        ["--chi", "0.3", "--N", "10", "-o", "/nonexistent-dir/run.nc"],
    ],
)
def test_cli_bad_input_exit_2(argv, capsys):
    assert main(["simulate", *argv]) == 2
    err = capsys.readouterr().err
    assert "error" in err and len(err.strip().splitlines()) == 1


def test_numerical_failure_saves_partial_run(tmp_path):
    path = tmp_path / "fail.nc"
    with pytest.raises(SimulationError, match="drift") as info:
        run(0.5, 10, method="euler-richardson-fixed", dt0=0.05, max_link_error=1e-3, output=path)
    assert info.value.path == str(path)
    ds = load_run(path)
    assert ds.attrs["status"] == "failed" and "drift" in ds.attrs["stop_reason"]
    assert ds.sizes["step"] >= 2 and ds["snapshot_kind"].values[-1] == "final"


# ---------------------------------------------------------------- command line
def test_cli_simulate_json_and_table(tmp_path, capsys):
    path = tmp_path / "cli.nc"
    assert main(["simulate", "--chi", "0.5", "--N", "10", "--t-end", "0.2", "-o", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["N"] == 10 and out["status"] == "completed" and out["n_rhs"] > 0
    assert load_run(path).attrs["t_final"] == pytest.approx(0.2)
    assert main(["simulate", "--chi", "0.5", "--N", "10", "--t-end", "0.1", "--no-progress"]) == 0
    table = capsys.readouterr().out
    for key in ("v_peak", "t_snap_v", "energy_drift", "link_drift", "n_steps", "n_rhs", "wall_time"):
        assert key in table
    assert os.path.exists(path)


# ---------------------------------------------------------------- docstring examples
@pytest.mark.parametrize(
    "name", ["snapping.simulate", "snapping.simulate.chain", "snapping.simulate.driver", "snapping.simulate.resuming",
             "snapping.simulate.dataset"]
)
def test_simulate_docstring_examples(name):
    import doctest
    import importlib

    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted > 0


def _chain_from_link_angles(theta, omega):
    """Node positions and velocities (index 0 free end, index N the pin at the origin) of
    links of length 1/N at angles ``theta`` turning at rates ``omega``: d_j = (cos, sin)/N,
    d_j' = omega_j (-sin, cos)/N, so |d_j| = 1/N and d_j.d_j' = 0 hold exactly."""
    N = theta.size
    parts = (np.cos(theta), np.sin(theta), -omega * np.sin(theta), omega * np.cos(theta))
    return [np.append(-np.cumsum(p[::-1] / N)[::-1], 0.0) for p in parts]


def _tension_test_states(N):
    """Order-1 states: the catenary start (exact chords), a bent and a hanging chain;
    each at rest (gravity alone drives it) and with link rates ~1 (speeds ~0.5)."""
    s = (N - np.arange(N) - 0.5) / N  # arclength of the link midpoints from the pin
    cat = initial_state(0.25, N, chords="exact")
    shapes = {"catenary": np.arctan2(np.diff(cat.y), np.diff(cat.x)),
              "bent": -np.pi / 2 + 1.2 * np.sin(np.pi * s), "hanging": np.full(N, -np.pi / 2)}
    for name, th in shapes.items():
        for rates in ("rest", "moving"):
            om = np.zeros(N) if rates == "rest" else 0.8 * np.cos(3 * s) + 0.3
            yield f"{name}/{rates}", _chain_from_link_angles(th, om)


def _kernel_solve(kernel, N, x, y, vx, vy):
    from snapping.simulate import kernels as K

    Z = np.zeros((K.NROWS, N + 1))
    Z[K.RX], Z[K.RY], Z[K.RVX], Z[K.RVY] = x, y, vx, vy
    w = np.zeros((4, N))
    kernel(N, Z, w[0], w[1], w[2], w[3])
    return Z[K.RAX, :N], Z[K.RAY, :N], Z[K.RSIG, :N]


def test_tension_solves_match_dense_kkt_reference():
    """Both tension solvers of kernels.py (rhs and the textbook rhs_thomas) against the
    independent dense KKT solve of tests/reference_chain.py (m = h = 1/N, g = 1, T = sigma),
    on order-1 states. Tensions and accelerations are O(1) here, so the tolerance
    (1e-14 N^2: the system's condition number ~ N^2; seen <= 3.6e-10 at N = 300) is far
    below what a 1e-6 relative change of gravity in either solver moves them (~1e-6)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import reference_chain as RC
    from snapping.simulate import kernels as K

    N = 300
    h = np.full(N, 1.0 / N)
    tol = 1e-14 * N * N
    for name, (x, y, vx, vy) in _tension_test_states(N):
        speed = np.hypot(vx, vy).max()
        assert speed < 1.0
        ax, ay, T = RC.dense_accelerations(x, y, vx, vy, h, h, 1.0)
        assert 0.3 < np.abs(T).max() < 2.0, name  # order-1 tensions
        for kernel in (K.rhs, K.rhs_thomas):
            kax, kay, ksig = _kernel_solve(kernel, N, x, y, vx, vy)
            for got, ref in ((ksig, T), (kax, ax), (kay, ay)):
                np.testing.assert_allclose(got, ref, rtol=0, atol=tol, err_msg=f"{kernel.__name__} {name}")
    # the hanging chain at rest, in closed form: T_j = (j + 1)/N, no acceleration
    x, y, vx, vy = _chain_from_link_angles(np.full(N, -np.pi / 2), np.zeros(N))
    for kernel in (K.rhs, K.rhs_thomas):
        kax, kay, ksig = _kernel_solve(kernel, N, x, y, vx, vy)
        np.testing.assert_allclose(ksig, np.arange(1, N + 1) / N, rtol=0, atol=tol)
        assert np.abs(kax).max() < tol and np.abs(kay).max() < tol


def test_fast_tension_solve_matches_textbook_thomas():
    """rhs against rhs_thomas at N = 3000 on the same order-1 states (the old version of
    this test used independent random node velocities, sigma ~ 4e5, under which a 1e-6
    error in the gravity term passed)."""
    from snapping.simulate import kernels as K

    N = 3000
    for name, (x, y, vx, vy) in _tension_test_states(N):
        fast = _kernel_solve(K.rhs, N, x, y, vx, vy)
        ref = _kernel_solve(K.rhs_thomas, N, x, y, vx, vy)
        for a, b in zip(fast, ref):
            # condition number ~ N^2; seen <= 1.2e-10 (hanging, moving)
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-15 * N * N, err_msg=name)


# ---------------------------------------------------------------- the absolute energy
def _mp_catenary(chi, dps=30):
    """(a, y(s)) of the unit catenary in mpmath, from its definition 1 = 2 a sinh(chi/2a),
    y(s) = sqrt(a^2 + 1/4) - sqrt(a^2 + (s - 1/2)^2), x(s) = a asinh((s - 1/2)/a) + chi/2."""
    mp = mpmath.mp.clone()
    mp.dps = dps
    chi = mp.mpf(chi)
    # in b = chi/2a: sinh(b)/b = 1/chi (monotone); start from the large-b root b ~ log(2b/chi)
    b = mp.findroot(lambda b: mp.sinh(b) / b - 1 / chi, mp.log(2 / chi) + mp.log(mp.log(2 / chi)))
    a = chi / (2 * b)
    xy = lambda s: (a * mp.asinh((s - mp.mpf(1) / 2) / a) + chi / 2,  # noqa: E731
                    mp.sqrt(a**2 + mp.mpf(1) / 4) - mp.sqrt(a**2 + (s - mp.mpf(1) / 2) ** 2))
    return mp, a, xy


def test_initial_energy_is_the_catenarys_potential_energy_arclength_chords():
    """The recorded energy at t = 0 (Euler-Richardson, the paper's arclength nodes) is the
    discrete chain's potential energy relative to hanging at rest, computed here in mpmath
    from the catenary's closed form: E0 = sum_i m (-y_i) + sum_i m s_i with m = 1/N,
    s_i = (N - i)/N. A constant offset of 1e-6 in the measured energy fails it. And it
    tends to the available energy P(chi) of snapping.estimates: E0 = 1/2 + 1/(2N) - T_N[y]
    with T_N the trapezoid sum of int y ds (y = 0 at both ends), and Euler-Maclaurin gives
    T_N = int y ds - (h^2/12)(y'(0) - y'(1)) + ..., so (h = 1/N)
    E0 = P + h/2 + (h^2/12)(y'(0) - y'(1)) + O(h^4), the remainder ~ exp(-2 pi a N) for
    y analytic within a of the real axis (tiny at N = 200: a N ~ 7.7)."""
    from snapping import estimates

    chi, N = 0.25, 200
    ds = run(chi, N, t_end=1e-4, method="euler-richardson", chords="arclength").dataset
    assert float(ds["t"][0]) == 0.0
    mp, a, xy = _mp_catenary(chi)
    E0 = mp.fsum(-xy(mp.mpf(N - i) / N)[1] / N for i in range(N)) + mp.mpf(N + 1) / (2 * N)
    assert float(ds["energy"][0]) == pytest.approx(float(E0), rel=0, abs=1e-13)
    assert ds.attrs["energy_initial"] == pytest.approx(float(E0), rel=0, abs=1e-13)
    # the same from the recorded node coordinates of the initial snapshot
    snap = ds.isel(snapshot=0)
    assert str(snap["snapshot_kind"].values) == "initial"
    assert -float(snap["y"][:N].sum()) / N + (N + 1) / (2 * N) == pytest.approx(float(E0), abs=1e-13)
    # Euler-Maclaurin: y'(0) - y'(1) = 1/sqrt(a^2 + 1/4)
    h = mp.mpf(1) / N
    em = estimates.available_energy(chi) + float(h / 2 + h**2 / (12 * mp.sqrt(a**2 + mp.mpf(1) / 4)))
    assert float(E0) == pytest.approx(em, abs=1e-11)


def test_initial_energy_exact_chords_and_a_general_chain():
    """The same for the angle-form DOP853 run (exact chords 1/N, nodes walked from the pin
    on the catenary: recomputed in mpmath here) and for a tapered chain (general kernel):
    E0 = sum_j m_j (|v_j|^2/2 - y_j) + sum_j m_j s_j from the Problem's nodes and masses."""
    from snapping.simulate.problem import Links, Problem

    chi, N = 0.25, 20
    ds = run(chi, N, t_end=1e-4, method="dop853", chords="exact").dataset
    mp, a, xy = _mp_catenary(chi)
    h = mp.mpf(1) / N
    s, nodes = mp.mpf(0), [(mp.mpf(0), mp.mpf(0))]
    for _ in range(N):
        x0, y0 = nodes[-1]
        s = mp.findroot(lambda u: mp.hypot(xy(u)[0] - x0, xy(u)[1] - y0) - h, s + h)
        nodes.append(xy(s))
    E0 = mp.fsum(-yv / N for _, yv in nodes[1:]) + mp.mpf(N + 1) / (2 * N)
    assert float(ds["energy"][0]) == pytest.approx(float(E0), rel=0, abs=1e-13)
    assert ds.attrs["energy_initial"] == pytest.approx(float(E0), rel=0, abs=1e-13)
    # a tapered chain (equal links 1/N, masses falling to half at the free end) on the
    # exact-chord catenary nodes, spinning rigidly about the held end (v = w e3 x r)
    links = Links.taper(N, 0.5)
    st = initial_state(chi, N, chords="exact")
    w = 0.4
    q = Problem.nodes(st.x, st.y, links=links, vx=-w * st.y, vy=w * st.x)
    assert not q.is_paper
    dq = run(problem=q, t_end=1e-4, method="dop853").dataset
    m, hl = links.m, links.h
    s_node = np.cumsum(hl[::-1])[::-1]  # arclength of node j from the held end
    v2 = w * w * (q.x[:N] ** 2 + q.y[:N] ** 2)
    E_ref = math.fsum(m * (v2 / 2 - q.y[:N])) + math.fsum(m * s_node)
    assert float(dq["energy"][0]) == pytest.approx(E_ref, rel=0, abs=1e-13)


# ---------------------------------------------------------------- results claim only what was computed
@pytest.mark.parametrize("method", ["euler-richardson", "fast"])
def test_a_run_ended_by_t_end_before_the_snap_has_no_snapping_time(method):
    auto = run(0.5, 10, method=method).dataset.attrs
    assert auto["snap_reached"] == 1 and auto["snap_note"] == ""
    assert all(0 < auto[k] < auto["t_final"] for k in ("t_snap_v", "t_snap_a", "t_snap_sigma"))
    early = run(0.5, 10, method=method, t_end=0.5).dataset.attrs  # the snap is near t = 1.15
    assert early["snap_reached"] == 0 and early["status"] == "completed"
    assert all(math.isnan(early[k]) for k in ("t_snap_v", "t_snap_a", "t_snap_sigma"))
    assert "ended at t=0.5 before the snap" in early["snap_note"] and "stop_fraction=0.5" in early["snap_note"]
    assert 0 < early["v_peak"] < auto["v_peak"]  # kept: the maximum over the run
    s = summary(run(0.5, 10, method=method, t_end=0.5).dataset)
    assert s["snap_reached"] is False and s["t_snap_v"] is None and s["t_snap_a"] is None
    assert "maxima over the run" in s["peaks"] and s["snap_note"] == early["snap_note"]
    # run on past the fall of v_max below stop_fraction of its peak: the same snap as the automatic run
    late = run(0.5, 10, method=method, t_end=auto["t_final"] + 0.05).dataset.attrs
    assert late["snap_reached"] == 1 and late["t_snap_v"] == auto["t_snap_v"]
    # a larger stop_fraction accepts a smaller fall after the peak
    between = dict(method=method, t_end=0.5 * (auto["t_snap_v"] + auto["t_final"]))
    assert run(0.5, 10, **between).dataset.attrs["snap_reached"] == 0
    assert run(0.5, 10, stop_fraction=0.95, **between).dataset.attrs["snap_reached"] == 1


def test_a_run_that_fails_before_the_snap_has_no_snapping_time():
    with pytest.raises(SimulationError) as info:
        run(0.1, 40, method="fast", tol=1e-8, dt_min=3e-4)  # (its steps near the snap fall below 3e-4)
    a = info.value.dataset.attrs
    assert a["status"] == "failed" and a["snap_reached"] == 0 and math.isnan(a["t_snap_v"])
    assert "failed at t=" in a["snap_note"]


def test_cli_says_when_the_snap_was_not_reached(capsys):
    assert main(["simulate", "--chi", "0.5", "--N", "10", "--t-end", "0.5", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "t_snap_v" in out and "absent  no snap reached" in out
    assert "maximum over the run, not a snap peak" in out and "note: the run ended at t=0.5 before the snap" in out
    assert "nan" not in out.lower()
    assert main(["simulate", "--chi", "0.5", "--N", "10", "--t-end", "0.5", "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["t_snap_v"] is None and js["snap_reached"] is False and "before the snap" in js["snap_note"]
    assert main(["simulate", "--chi", "0.5", "--N", "10", "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["snap_reached"] is True and js["t_snap_v"] > 1 and "snap_note" not in js


def test_cli_non_finite_results_are_an_error_not_null(capsys, monkeypatch):
    import snapping.simulate.dataset as D

    real = D.summary
    monkeypatch.setattr(D, "summary", lambda ds: {**real(ds), "energy_drift": float("inf"), "v_peak": float("nan")})
    for extra in ([], ["--json"]):
        assert main(["simulate", "--chi", "0.5", "--N", "6", "--t-end", "0.05", *extra]) == 1
        cap = capsys.readouterr()
        assert cap.out == ""
        assert cap.err.count("\n") == 1 and "non-finite result" in cap.err
        assert "v_peak=nan" in cap.err and "energy_drift=inf" in cap.err


def test_cli_snapshot_times_need_an_output_file(tmp_path, capsys):
    assert main(["simulate", "--chi", "0.5", "--N", "6", "--t-end", "0.2", "--snapshot-times", "0.1"]) == 2
    err = capsys.readouterr().err
    assert "without -o RUN.nc" in err and err.count("\n") == 1
    assert main(["simulate", "--chi", "0.5", "--N", "6", "--t-end", "0.2", "--snapshot-times", "nan"]) == 2
    assert "--snapshot-times=nan" in capsys.readouterr().err  # a bad time is named first, as typed
    path = tmp_path / "r.nc"
    assert main(["simulate", "--chi", "0.5", "--N", "6", "--t-end", "0.2", "--snapshot-times", "0.1",
                 "-o", str(path), "--no-progress"]) == 0
    assert list(load_run(path)["snapshot_kind"].values).count("requested") == 1


def test_cli_a_general_problem_has_no_chi_and_is_no_error(capsys):
    assert main(["simulate", "--supports", "0.4,0.2", "--N", "5", "--method", "fast", "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["chi"] is None and js["start"] == "supports" and js["snap_reached"] is True
