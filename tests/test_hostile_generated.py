"""Hostile input, generated ("no traceback anywhere"): every numeric parameter of the public
functions and every numeric or list option of the command line, fed the same catalogue of bad
values (NaN, infinities, negative, zero, the smallest subnormal, the largest doubles, a 400-digit
integer, a string, None, an empty list).

Each case asserts one of two outcomes:

* refused: :class:`snapping._validate.SnappingInputError` whose one-line message names the
  parameter (Python), or exit status 2 with exactly one line on stderr containing ``error`` and
  the option as typed, e.g. ``--chi`` (command line); never a traceback, an exception of another
  kind, a hang or a non-finite result;
* valid (marked explicitly in ``VALID``/``CLI_VALID`` below): a finite, sensible result (exit 0
  and JSON without null from the command line, beyond the nulls of the same command without the
  bad value);

and, for the one bound a user can set that a run cannot meet (``max_energy_drift=5e-324``,
``FAILS``/``CLI_FAILS``), the run's one-line SimulationError (exit status 1). The data of the
fits are attacked too (negative, zero, constant, all after t*, one or two samples, huge).

Every call is cheap: N <= 10 links and t_end = 1e-3 for the simulator; a sweep, converge or
reproduce case is refused before any work starts (the valid values that would start a long
computation are listed in ``NOT_RUN`` and checked through the cheap function that owns them).
"""

from __future__ import annotations

import dataclasses
import json
import math
import numbers
import signal
from contextlib import contextmanager

import numpy as np
import pytest

from snapping import SnappingInputError, animation, continuum, design, estimates, ideal, scaling, shape_estimates, simulate, table
from snapping.cli import main
from snapping.simulate.problem import Links, PinMotion, Problem

NAN, INF = float("nan"), float("inf")

#: the bad values of every numeric parameter (tag, value)
BAD = (("nan", NAN), ("inf", INF), ("-inf", -INF), ("neg", -1.0), ("zero", 0.0), ("tiny", 5e-324),
       ("huge", 1e308), ("bigint", 10**400), ("str", "abc"), ("none", None), ("empty", []))
#: the bad values of every numeric command-line option, as typed
BAD_TEXT = ("nan", "inf", "-1", "0", "5e-324", "1e308", "1e400", "abc", "")
#: seconds any one case may take (a hang is a failure)
TIME_LIMIT = 20


@contextmanager
def _time_limit(seconds: int):
    def handler(signum, frame):
        raise TimeoutError(f"no answer within {seconds} s")

    old = signal.signal(signal.SIGALRM, handler)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


#: fields that are non-finite by design: an extrapolation's order when it does not converge, the
#: folded string's exponent of a row without one, the z against the alternative exponent of a
#: row without one, a pull that lasts for ever
ALLOW_NONFINITE = ("order", "ideal_window_beta", "z_alt", "duration")


def _finite(obj, path="result", allow=ALLOW_NONFINITE) -> None:
    """Assert that every number in ``obj`` (nested) is finite (keys/fields in ``allow`` excepted)."""
    import mpmath

    if obj is None or isinstance(obj, (str, bytes, bool, np.bool_)):
        return
    if isinstance(obj, numbers.Integral):
        assert abs(int(obj)) < 10**40, f"{path} = {str(obj)[:40]}... (an absurd integer)"
    elif isinstance(obj, scaling.LocalSlope):  # NaN where a centre has too few samples, by design
        _finite(obj.tau, f"{path}.tau")
        assert np.isfinite(obj.slope).any(), f"{path}.slope has no finite local slope"
    elif isinstance(obj, design.DesignResult):  # a bound above BOUND_TRUST is inf by design ("no bound")
        _finite(obj.rows, f"{path}.rows", allow + ("upper", "error"))
        for tip, per in obj.curves.items():
            for key, (chi, si, err) in per.items():
                _finite(chi, f"{path}.curves[{tip}][{key}].chi")
                _finite(si, f"{path}.curves[{tip}][{key}].peak")
                assert np.all(np.isfinite(err) | (err == np.inf)) and np.isfinite(err).any(), path
    elif isinstance(obj, mpmath.mpf):
        assert mpmath.isfinite(obj), f"{path} = {obj}"
    elif isinstance(obj, numbers.Number):
        assert math.isfinite(float(obj)), f"{path} = {obj!r}"
    elif isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fc":
            assert np.all(np.isfinite(obj)), f"{path} has non-finite entries"
        elif obj.dtype.kind == "O":
            for i, v in enumerate(obj.ravel()):
                _finite(v, f"{path}[{i}]", allow)
    elif isinstance(obj, dict):
        for k, v in obj.items():
            if k not in allow:
                _finite(v, f"{path}[{k!r}]", allow)
    elif isinstance(obj, (list, tuple)):
        for i, v in enumerate(obj):
            _finite(v, f"{path}[{i}]", allow)
    elif isinstance(obj, simulate.Run):
        st = obj.state
        for k in ("x", "y", "vx", "vy"):
            _finite(np.asarray(getattr(st, k)), f"{path}.state.{k}")
        for k in ("v_max", "a_max", "sigma_max", "energy"):
            if k in obj.dataset:
                _finite(obj.dataset[k].values, f"{path}.dataset[{k!r}]")
    elif dataclasses.is_dataclass(obj):
        for f in dataclasses.fields(obj):
            if f.name not in allow:
                _finite(getattr(obj, f.name), f"{path}.{f.name}", allow)


# ------------------------------------------------------------------ the shared inputs
@pytest.fixture(scope="module")
def F(tmp_path_factory) -> dict:
    d = tmp_path_factory.mktemp("hostile_gen")
    run = simulate.run(0.5, 40, tol=1e-6, method="euler-richardson", chords="arclength",
                       output=d / "run.nc")  # to the snap: fit works on it (the paper's run, as designed)
    # compile the kernels of the runs below before any case's clock starts: TIME_LIMIT catches a
    # hang on bad input, not a cold numba cache (which file compiles a kernel first depends on the
    # order the files run in: on two processes, pytest-xdist, this file may be the first)
    for key in ("Problem.run", "simulate.run", "simulate.run(fixed)", "simulate.run(fast)", "simulate.run_ensemble",
                "simulate.integrate_fixed"):
        call, base = SPECS[key][:2]
        call(None, **base)
    return {"ds": run.dataset, "run_nc": str(run.path), "root": str(d)}


TAU = np.logspace(-5, 0, 120)
T_GOOD, Y_GOOD = (1.0 - TAU).tolist(), (TAU ** (-1 / 3)).tolist()
T_PEAK = np.linspace(0.0, 2.0, 41).tolist()
Y_PEAK = (1.0 / (1e-2 + (np.linspace(0.0, 2.0, 41) - 1.0) ** 2)).tolist()
TRI_X, TRI_Y = [0.0, 0.3, 0.6], [0.0, 0.0, 0.0]  # shape (free end first, held end last): an L
SHAPE_X = [0.6, 0.3, 0.0]
SHAPE_Y = [0.3, 0.3, 0.0]
SHAPE_M = [0.5, 0.5, 0.0]


def _array_values(base: list):
    """The bad values of an array parameter: a valid array with its first entry replaced by each
    bad number, and the bad objects themselves (a string, None, an empty list)."""
    for tag, v in BAD:
        if tag in ("str", "none", "empty"):
            yield tag, v
        else:
            yield tag, [v] + list(base[1:])


# ------------------------------------------------------------------ Python: the table
# name: (call(F, **kw), base keyword arguments, scalar parameters, array parameters)
def _sim(F, **kw):  # the paper's method and chain (the bounds below are its); run(fast) passes method="fast"
    return simulate.run(**{"chi": 0.3, "N": 10, "t_end": 1e-3, "method": "euler-richardson", "chords": "arclength",
                            **kw})


def _fixed(F, **kw):
    return simulate.run(**{"chi": 0.3, "N": 10, "t_end": 1e-3, "method": "euler-richardson-fixed", "dt0": 1e-4, **kw})


def _problem_run(F, **kw):
    return simulate.run(Problem.catenary(0.3, links=Links.uniform(10, tip_mass=0.1), **kw), t_end=1e-3,
                        method="fast")


SPECS = {
    # ideal
    "ideal.t_star_mp": (lambda F, **k: ideal.t_star_mp(**k), {}, ["digits"], []),
    "ideal.t_star_str": (lambda F, **k: ideal.t_star_str(**k), {}, ["digits"], []),
    "ideal.summary": (lambda F, **k: ideal.summary(**k), {}, ["digits"], []),
    "ideal.check_printed_equations": (lambda F, **k: ideal.check_printed_equations(**k), {}, ["digits"], []),
    "ideal.kink_state(t)": (lambda F, **k: ideal.kink_state(**k), {"t": 0.5}, ["t"], []),
    "ideal.kink_state(tau)": (lambda F, **k: ideal.kink_state(**k), {"tau": 0.5}, ["tau"], []),
    **{f"ideal.{f}": (lambda F, f=f, **k: getattr(ideal, f)(**k), {"t": 0.5}, ["t"], [])
       for f in ("s0", "s0_dot", "s0_ddot", "moving_arm_length", "tether_tension", "fold_tension",
                 "free_end_speed", "free_end_acceleration")},
    "ideal.s0(array)": (lambda F, **k: ideal.s0(**k), {"t": [0.5, 1.0]}, [], ["t"]),
    "ideal.kink_energy": (lambda F, **k: ideal.kink_energy(**k), {"s0": 0.6, "s0_dot": 0.3}, ["s0", "s0_dot"], []),
    # estimates
    **{f"estimates.{f}": (lambda F, f=f, **k: getattr(estimates, f)(**k), {"chi": 0.3}, ["chi"], [])
       for f in ("catenary_parameter", "kappa_m0", "available_energy", "delta_kappa0", "delta_crude")},
    "estimates.chi_from_parameter": (lambda F, **k: estimates.chi_from_parameter(**k), {"a": 0.2}, ["a"], []),
    "estimates.catenary_shape": (lambda F, **k: estimates.catenary_shape(**k), {"s": [0.0, 0.5, 1.0], "chi": 0.3},
                                 ["chi"], ["s"]),
    "estimates.delta_N": (lambda F, **k: estimates.delta_N(**k), {"N": 10}, ["N"], []),
    "estimates.whirling_rod": (lambda F, **k: estimates.whirling_rod(**k), {"P": 0.3, "delta": 0.01},
                               ["P", "delta"], []),
    "estimates.Chain": (lambda F, **k: estimates.Chain(**k), {}, ["length", "mass", "g"], []),
    "estimates.design_estimate(chi)": (lambda F, **k: estimates.design_estimate(**k), {"chi": 0.3, "N": 100},
                                       ["chi", "N"], []),
    "estimates.design_estimate(separation)": (lambda F, **k: estimates.design_estimate(**k),
                                              {"separation": 0.3}, ["separation"], []),
    "estimates.design_estimate(curvature)": (lambda F, **k: estimates.design_estimate(**k),
                                             {"curvature": 20.0}, ["curvature"], []),
    "estimates.design_estimate(links)": (lambda F, **k: estimates.design_estimate(**k),
                                         {"chi": 0.3, "links": 100, "tip_mass": 0.05}, ["chi", "links", "tip_mass"],
                                         []),
    "table.lookup": (lambda F, **k: table.lookup(**k), {"chi": 0.3, "links": 100, "tip_mass": 0.05},
                     ["chi", "links", "tip_mass"], []),
    "design.design": (lambda F, **k: design.design(**k),
                      {"chain": estimates.Chain(length=2.0, mass=0.05), "links": 100, "max_tension": 20.0,
                       "tip_mass": 0.0}, ["links", "max_tension", "tip_mass"], []),
    "estimates.delta_kappa_m": (lambda F, **k: estimates.delta_kappa_m(**k),
                                {"t": [0.0, 0.5, 1.0, 1.1], "kappa_max": [1.0, 2.0, 8.0, 30.0],
                                 "s_kappa_max": [0.5, 0.6, 0.8, 0.95]}, [], ["t", "kappa_max", "s_kappa_max"]),
    # shape_estimates
    "shape_estimates.available_energy_shape": (lambda F, **k: shape_estimates.available_energy_shape(**k),
                                               {"x": SHAPE_X, "y": SHAPE_Y, "m": SHAPE_M, "g": 1.0}, ["g"],
                                               ["x", "y", "m"]),
    "shape_estimates.kappa_m0_shape": (lambda F, **k: shape_estimates.kappa_m0_shape(**k),
                                       {"x": SHAPE_X, "y": SHAPE_Y}, [], ["x", "y"]),
    "shape_estimates.shape_estimate": (lambda F, **k: shape_estimates.shape_estimate(**k),
                                       {"x": SHAPE_X, "y": SHAPE_Y, "m": SHAPE_M, "g": 1.0}, ["g"], ["x", "y", "m"]),
    # scaling: the pure functions
    "scaling.peak_time": (lambda F, **k: scaling.peak_time(**k), {"t": T_PEAK, "y": Y_PEAK}, ["min_drop"],
                          ["t", "y"]),
    "scaling.local_slope": (lambda F, **k: scaling.local_slope(**k), {"t": T_GOOD, "y": Y_GOOD, "t_star": 1.0},
                            ["t_star", "span", "spacing", "min_points"], ["t", "y"]),
    "scaling.find_window": (lambda F, **k: scaling.find_window(**k), {"t": T_GOOD, "y": Y_GOOD, "t_star": 1.0},
                            ["t_star", "min_width", "tol", "span", "spacing"], ["t", "y"]),
    "scaling.fit_power_law": (lambda F, **k: scaling.fit_power_law(**k), {"t": T_GOOD, "y": Y_GOOD, "t_star": 1.0},
                              ["t_star", "t_star_err", "min_width", "tol", "perturb", "span", "spacing"], ["t", "y"]),
    "scaling.fit_power_law(window)": (lambda F, **k: scaling.fit_power_law(**k),
                                      {"t": T_GOOD, "y": Y_GOOD, "t_star": 1.0, "window": [1e-4, 1e-1]}, [],
                                      ["window"]),
    "scaling.fit_power_law(joint)": (lambda F, **k: scaling.fit_power_law(**k),
                                     {"t": T_GOOD, "y": Y_GOOD, "t_star_guess": 1.0, "window": (1e-4, 1e-1)},
                                     ["t_star_guess"], []),
    "scaling.ideal_window_exponent": (lambda F, **k: scaling.ideal_window_exponent(**k),
                                      {"quantity": "free_end_speed", "tau_lo": 1e-3, "tau_hi": 1e-1}, ["tau_lo", "tau_hi"], []),
    "scaling.snapping_times": (lambda F, **k: scaling.snapping_times(F["ds"], **k), {}, ["min_drop"], []),
    "scaling.local_slopes": (lambda F, **k: scaling.local_slopes(F["ds"], **k), {"t_star": 1.15},
                             ["t_star", "span", "spacing"], []),
    "scaling.fit_run": (lambda F, **k: scaling.fit_run(F["ds"], joint=False, delta=False, **k), {},
                        ["tol", "min_width"], []),
    # continuum (no run)
    "continuum.level_parameters": (lambda F, **k: continuum.level_parameters(**k), {},
                                   ["levels", "ratio", "frac0", "h_min0", "h_max0", "first"], []),
    "continuum.extrapolate": (lambda F, **k: continuum.extrapolate(**k),
                              {"h": [0.1, 0.05, 0.025, 0.0125], "q": [3.02, 3.005, 3.00125, 3.0003125]}, [], ["h", "q"]),
    "continuum.converge": (lambda F, **k: continuum.converge(**k), {"chi": 0.3},
                           ["chi", "levels", "ratio", "first", "tol", "workers", "frac0", "h_min0", "h_max0"], []),
    # a line's body in SI (issue 21)
    "Body.from_si": (lambda F, **k: simulate.Body.from_si(**k), {"length": 2.0, "mass": 0.02, "diameter": 1e-3},
                     ["ei", "bending_damping", "diameter", "air_density", "cd_normal", "cd_tangential",
                      "tip_drag_area"], []),
    # simulate: the constructors
    "Links.uniform": (lambda F, **k: Links.uniform(**k), {"N": 10}, ["N", "tip_mass"], []),
    "Links.taper": (lambda F, **k: Links.taper(**k), {"N": 10, "ratio": 0.5}, ["N", "ratio", "power", "tip_mass"],
                    []),
    "Links.explicit": (lambda F, **k: Links.explicit(**k), {"h": [0.5, 0.5], "m": [0.5, 0.5]}, ["tip_mass"],
                       ["h", "m"]),
    "Links.from_density": (lambda F, **k: Links.from_density(**k), {"h": [0.5, 0.5], "density": [1.0, 2.0]},
                           ["tip_mass"], ["h", "density"]),
    "PinMotion.pull": (lambda F, **k: PinMotion.pull(**k), {"accel": (0.0, -1.0)}, ["duration", "t0"], ["accel"]),
    "PinMotion.flick": (lambda F, **k: PinMotion.flick(**k), {"accel": (1.0, 0.0), "period": 0.2},
                        ["period", "t0"], ["accel"]),
    "PinMotion.from_table": (lambda F, **k: PinMotion.from_table(**k),
                             {"t": [0.0, 0.1, 0.2, 0.3], "x": [0.0, 0.01, 0.02, 0.03], "y": [0.0, 0.0, 0.0, 0.0]},
                             [], ["t", "x", "y"]),
    "PinMotion.from_function": (lambda F, **k: PinMotion.from_function(lambda t: (0.1 * t * t, 0.0), **k),
                                {"t_max": 1.0, "samples": 11}, ["t_max", "samples"], []),
    "Problem.catenary": (lambda F, **k: Problem.catenary(**k), {"chi": 0.3, "N": 10}, ["chi", "N", "gravity"], []),
    "Problem.supports": (lambda F, **k: Problem.supports(**k), {"dx": 0.4, "dy": 0.2, "N": 10},
                         ["dx", "dy", "N", "gravity"], []),
    "Problem.nodes": (lambda F, **k: Problem.nodes(**k), {"x": [0.0, 0.0, 0.0], "y": [1.0, 0.5, 0.0],
                                                         "vx": [0.0, 0.0, 0.0], "vy": [0.0, 0.0, 0.0]}, [],
                      ["x", "y", "vx", "vy"]),
    "Problem.run": (_problem_run, {}, ["gravity"], []),
    # simulate.run and friends
    "simulate.run": (_sim, {"snapshot_times": [0.0, 5e-4, 1e-3]}, ["chi", "N", "tol", "dt0", "t_end", "stop_fraction", "t_end_max", "record_thin",
                                "max_link_error", "max_energy_drift", "dt_min", "max_rejections", "checkpoint_every"],
                     ["snapshot_times"]),
    "simulate.run(fixed)": (_fixed, {}, ["dt0", "t_end"], []),
    "simulate.run(fast)": (lambda F, **k: _sim(F, method="fast", **k), {}, ["tol", "dt0", "t_end", "dt_min"], []),
    "simulate.run_ensemble": (lambda F, **k: simulate.run_ensemble(**{"N": 10, "t_end": 1e-3, **k}),
                              {"chis": [0.3, 0.4]}, ["N", "tol", "t_end", "stop_fraction", "t_end_max", "dt_min"], ["chis"]),
    "simulate.memory_need": (lambda F, **k: simulate.memory_need(**{"N": 10, **k}), {},
                             ["N", "chi", "tol", "dt0", "t_end", "t_end_max"], []),
    "simulate.initial_state": (lambda F, **k: simulate.initial_state(**k), {"chi": 0.3, "N": 10}, ["chi", "N"], []),
    "simulate.node_arclength": (lambda F, **k: simulate.node_arclength(**k), {"N": 10}, ["N"], []),
    "simulate.link_arclength": (lambda F, **k: simulate.link_arclength(**k), {"N": 10}, ["N"], []),
    # #25: the animation's inputs, the design's run budget
    "animation.dense_snapshot_times": (lambda F, **k: animation.dense_snapshot_times(**k), {"t_snap": 1.0},
                                       ["t_snap", "n", "tau_min"], []),
    "animation.animate": (lambda F, **k: animation.animate(F["ds"], F["root"] + "/anim.gif", **k), {},
                          ["fps", "max_frames"], []),
    "design.computed_estimate": (lambda F, **k: design.computed_estimate(estimates.Chain(length=2.0, mass=0.05),
                                                                         chi=0.3, links=100, **k), {},
                                 ["max_seconds"], []),
    "simulate.integrate_fixed": (lambda F, **k: simulate.integrate_fixed(simulate.initial_state(0.3, 10), **k),
                                 {"dt": 1e-4, "n_steps": 3}, ["dt", "n_steps"], []),
}

#: the values of a data array that are legitimately valid: samples (a non-finite one is dropped)
DATA = ("nan", "inf", "-inf", "neg", "zero", "tiny", "huge")


def _data(*names):
    return {f"{n}={tag}" for n in names for tag in DATA}


#: the (function, parameter=tag) cases that are legitimately valid: a finite result is expected
#: ("fails": the run fails by design with a one-line SimulationError, a bound that cannot be met)
VALID = {
    # vectorised functions of time: t = 0, the smallest subnormal, an empty array
    **{f"ideal.{f}": {"t=zero", "t=tiny", "t=empty"} for f in (
        "s0", "s0_dot", "s0_ddot", "moving_arm_length", "tether_tension", "fold_tension", "free_end_speed",
        "free_end_acceleration")},
    "ideal.kink_state(t)": {"t=zero", "t=tiny", "t=empty"},
    "ideal.kink_state(tau)": {"tau=empty"},
    "ideal.s0(array)": {"t=zero", "t=tiny", "t=empty"},
    "ideal.kink_energy": {"s0=zero", "s0=tiny", "s0=neg", "s0_dot=zero", "s0_dot=tiny", "s0_dot=neg",
                          "s0=empty", "s0_dot=empty"},
    "estimates.catenary_shape": {"s=zero", "s=tiny", "s=empty"},
    "estimates.design_estimate(chi)": {"N=none"},
    "estimates.design_estimate(links)": {"tip_mass=zero", "tip_mass=tiny"},
    "table.lookup": {"tip_mass=zero", "tip_mass=tiny"},
    "design.design": {"tip_mass=zero", "tip_mass=tiny", "tip_mass=none", "max_tension=huge"},
    "estimates.delta_kappa_m": _data("t", "kappa_max") | {"s_kappa_max=" + t for t in ("nan", "inf", "-inf", "zero",
                                                                                        "tiny")},
    # a shape is any finite curve: its first node moved
    "shape_estimates.available_energy_shape": _data("x", "y", "m") - {"x=nan", "x=inf", "x=-inf", "y=nan", "y=inf",
                                                                     "y=-inf", "m=nan", "m=inf", "m=-inf", "m=neg"},
    "shape_estimates.kappa_m0_shape": {"x=neg", "x=zero", "x=tiny", "x=huge", "y=neg", "y=zero", "y=tiny",
                                       "y=huge"},
    "shape_estimates.shape_estimate": {"m=zero", "m=tiny", "x=neg", "x=zero", "x=tiny", "y=neg", "y=zero",
                                       "y=tiny"},
    "scaling.peak_time": _data("t", "y") - {"y=huge"} | {"min_drop=zero", "min_drop=tiny"},  # (y[0] the peak)
    "scaling.local_slope": _data("t", "y"),
    "scaling.find_window": _data("t", "y") | {"tol=tiny", "tol=huge"},
    "scaling.fit_power_law": _data("t", "y") | {"t_star_err=zero", "t_star_err=tiny", "perturb=zero",
                                                "perturb=tiny", "tol=tiny", "tol=huge", "t_star=none"},
    "scaling.fit_power_law(window)": {"window=tiny", "window=none"},
    "scaling.fit_power_law(joint)": {"t_star_guess=none"},
    "scaling.snapping_times": {"min_drop=zero", "min_drop=tiny"},
    "scaling.ideal_window_exponent": {"tau_hi=huge"},  # (the window ends at t*)
    "scaling.local_slopes": {"t_star=none"},
    "scaling.fit_run": {"tol=tiny", "tol=huge"},
    "continuum.level_parameters": {"first=zero", "first=neg"},
    "continuum.extrapolate": {"q=neg", "q=zero", "q=tiny", "q=huge"},
    # zero and the smallest subnormal are valid (negligible) bodies; None: no drag, or the defaults
    "Body.from_si": {f"{p}={t}" for p in ("ei", "bending_damping", "diameter", "air_density", "cd_normal",
                                           "cd_tangential", "tip_drag_area") for t in ("zero", "tiny")}
    | {"diameter=none", "air_density=none", "cd_normal=none", "cd_tangential=none", "tip_drag_area=none"},
    "Links.uniform": {"tip_mass=zero", "tip_mass=tiny"},
    "Links.taper": {"tip_mass=zero", "tip_mass=tiny"},
    "Links.explicit": {"tip_mass=zero", "tip_mass=tiny"},
    "Links.from_density": {"tip_mass=zero", "tip_mass=tiny", "density=none"},
    "PinMotion.pull": {"t0=zero", "t0=tiny", "t0=huge", "duration=inf", "duration=huge", "accel=zero", "accel=tiny",
                       "accel=neg"},
    "PinMotion.flick": {"t0=zero", "t0=tiny", "t0=huge", "period=huge", "accel=zero", "accel=tiny", "accel=neg"},
    "PinMotion.from_table": {"t=zero", "x=zero", "y=zero", "x=tiny", "y=tiny"},
    "Problem.catenary": {"gravity=zero", "gravity=tiny"},
    "Problem.supports": {"dy=zero", "dy=tiny", "gravity=zero", "gravity=tiny"},
    "Problem.nodes": {"x=zero", "x=tiny", "vx=none", "vy=none", "vx=neg", "vx=zero", "vx=tiny", "vy=zero",
                      "vy=tiny"},
    "Problem.run": {"gravity=zero", "gravity=tiny"},
    "simulate.run": {"dt0=none", "max_energy_drift=none", "checkpoint_every=none", "checkpoint_every=zero",
                     "checkpoint_every=tiny", "checkpoint_every=huge", "max_rejections=zero",
                     "snapshot_times=zero", "snapshot_times=tiny", "snapshot_times=empty",
                     "snapshot_times=none", "record_thin=zero", "record_thin=tiny", "stop_fraction=tiny",
                     "max_link_error=tiny", "max_energy_drift=huge", "dt_min=tiny",
                     "tol=none"},  # (tol=None: the method's default tolerance)
    "simulate.run(fast)": {"dt0=none", "dt_min=tiny", "tol=none"},
    "simulate.run_ensemble": {"stop_fraction=tiny", "dt_min=tiny", "tol=none"},
    # an estimate: an extreme (valid) time gives an astronomical count, refused by the run's guard
    "simulate.memory_need": {"chi=none", "dt0=none", "t_end=none", "dt0=tiny", "dt0=huge", "t_end=tiny", "t_end=huge",
                             "t_end_max=tiny", "t_end_max=huge"},
}
VALID.update({
    "animation.dense_snapshot_times": {"t_snap=tiny", "t_snap=huge", "tau_min=tiny"},
    "design.computed_estimate": {"max_seconds=zero", "max_seconds=tiny", "max_seconds=huge"},
})
#: a bound that cannot be met: the run fails by design (a one-line SimulationError)
FAILS = {"simulate.run": {"max_energy_drift=tiny"}}

#: valid values that would start a long computation (to the snap, or a convergence study):
#: checked through the cheap function that validates them (test_not_run_values_are_valid)
NOT_RUN = {
    "continuum.converge": {"first=zero", "first=neg"},
    "simulate.run": {"t_end=none"},
    "simulate.run(fixed)": {"t_end=none"},
    "simulate.run(fast)": {"t_end=none"},
    "simulate.run_ensemble": {"t_end=none"},
    "animation.animate": {"max_frames=none"},  # (all the snapshots: a whole animation)
}

#: the message must name this parameter instead (the user's name for an input passed inside another)
NAMES = {("simulate.run_ensemble", "chis"): "chi"}


def _py_cases():
    cases = []
    for name, (call, base, scalars, arrays) in SPECS.items():
        params = [(p, BAD) for p in scalars] + [(p, list(_array_values(base.get(p, [0.0, 0.5, 1.0])))) for p in arrays]
        for p, values in params:
            for tag, v in values:
                key = f"{p}={tag}"
                if key in NOT_RUN.get(name, ()):
                    continue
                kw = {**base, p: v}
                valid = key in VALID.get(name, ()) or ("fails" if key in FAILS.get(name, ()) else False)
                cases.append(pytest.param(call, kw, NAMES.get((name, p), p), valid, id=f"{name}({key})"))
    return cases


def _data_cases():
    """The data themselves hostile: negative, zero, all after t*, a single sample, unsorted."""
    tau = np.asarray(TAU)
    data = {
        "negative y": ((1.0 - tau).tolist(), (-(tau ** (-1 / 3))).tolist()),
        "zero y": ((1.0 - tau).tolist(), [0.0] * tau.size),
        "constant y": ((1.0 - tau).tolist(), [2.0] * tau.size),
        "all after t*": ((1.0 + tau).tolist(), (tau ** (-1 / 3)).tolist()),
        "one sample": ([0.5], [1.0]),
        "two samples": ([0.5, 0.6], [1.0, 2.0]),
        "same t": ([0.5] * 10, list(range(1, 11))),
        "huge y": ((1.0 - tau).tolist(), (1e300 * tau ** (-1 / 3)).tolist()),
    }
    fns = {
        "fit_power_law": lambda t, y: scaling.fit_power_law(t, y, t_star=1.0),
        "fit_power_law(joint)": lambda t, y: scaling.fit_power_law(t, y, t_star_guess=1.0),
        "find_window": lambda t, y: scaling.find_window(t, y, 1.0),
        "local_slope": lambda t, y: scaling.local_slope(t, y, 1.0),
        "peak_time": lambda t, y: scaling.peak_time(t, y),
        "local_slope(tiny spacing)": lambda t, y: scaling.local_slope(t, y, 1.0, spacing=1e-12),
    }
    # a constant or huge y has a valid local slope (0, -1/3) and a peak somewhere
    valid = {("local_slope", "constant y"), ("local_slope", "huge y"), ("find_window", "huge y"),
             ("fit_power_law", "huge y"), ("fit_power_law(joint)", "huge y")}
    cases = []
    for fname, fn in fns.items():
        for dname, (t, y) in data.items():
            cases.append(pytest.param(lambda F, fn=fn, t=t, y=y, **k: fn(t, y), {}, None, (fname, dname) in valid,
                                      id=f"scaling.{fname}(data: {dname})"))
    return cases


PY_CASES = _py_cases() + _data_cases()


def run_py_case(call, kw, name, F):
    """The outcome of one case: ('error', message) or ('value', result); other exceptions raise."""
    with _time_limit(TIME_LIMIT), np.errstate(all="ignore"):
        try:
            return "value", call(F, **kw)
        except SnappingInputError as exc:
            return "error", str(exc)
        except simulate.SimulationError as exc:
            return "simulation error", str(exc)


@pytest.mark.parametrize("call, kw, name, valid", PY_CASES)
def test_python_hostile_value(call, kw, name, valid, F):
    kind, out = run_py_case(call, kw, name, F)
    if valid is True:
        assert kind == "value", out
        _finite(out)
    elif valid == "fails":  # the run fails by design (a bound the user set cannot be met): one line
        assert kind == "simulation error", out
        assert out and "\n" not in out, out
    else:
        assert kind == "error", f"accepted: {out!r}"[:300]
        assert out and "\n" not in out and len(out) < 600, out
        if name is not None:
            assert name in out, f"the message does not name {name!r}: {out}"


# ------------------------------------------------------------------ command line
#: command: (base argv, {option: how the value goes in})
_SIM = ["simulate", "--chi", "0.3", "--N", "10", "--t-end", "1e-3", "--json", "--no-progress", "--method",
        "euler-richardson", "--chords", "arclength"]  # (the paper's method, as designed; _FAST's later --method fast wins)
_FAST = _SIM + ["--method", "fast"]
CLI_SPECS = {
    "ideal": (["ideal", "--json"], ["--digits"]),
    "estimate": (["estimate", "--chi", "0.3", "--json"], ["--chi", "--length", "--mass", "--g", "--N"]),
    "estimate(separation)": (["estimate", "--json"], ["--separation"]),
    "estimate(curvature)": (["estimate", "--json"], ["--curvature"]),
    "estimate(links)": (["estimate", "--chi", "0.3", "--links", "100", "--json"], ["--links", "--tip-mass"]),
    "design": (["design", "--max-tension", "20", "--length", "2", "--mass", "0.05", "--links", "100", "--tip-mass",
                "0", "--json"], ["--max-tension", "--max-speed", "--max-acceleration", "--length", "--mass", "--g",
                                 "--links", "--tip-mass"]),
    "simulate": (_SIM, ["--chi", "--N", "--tol", "--dt0", "--t-end", "--stop-fraction", "--snapshot-times",
                        "--record-thin", "--checkpoint-every", "--max-link-error", "--max-energy-drift", "--dt-min",
                        "--max-rejections"]),
    "simulate(fast)": (_FAST, ["--tip-mass", "--gravity", "--taper", "--pin-motion=pull:{},0",
                               "--pin-motion=flick:1,0,{}", "--supports={},0.2"]),
    "simulate(body)": (_FAST, ["--bending", "--bending-damping", "--drag-normal", "--drag-tangential", "--tip-drag",
                               "--wind={},0", "--drag-linear"]),
    "simulate(body SI)": (_FAST + ["--length", "2", "--mass", "0.02", "--diameter", "1e-3"],
                          ["--ei", "--diameter", "--air-density", "--cd-normal", "--cd-tangential", "--tip-drag-area",
                           "--wind-si={},0"]),
    "fit": (["fit", "{run_nc}", "--json", "--no-joint"], ["--tol", "--min-width", "--window=v_max={},1e-2",
                                                          "--window=v_max=1e-4,{}"]),
    "sweep": (["sweep", "--chi", "0.3", "--N", "10", "-o", "{root}/sweep"], ["--chi", "--N", "--tol", "--workers",
                                                                               "--ensemble"]),
    "converge": (["converge", "--chi", "0.3", "-o", "{root}/converge"], ["--chi", "--levels", "--ratio", "--first",
                                                                          "--tol", "--workers"]),
    "reproduce": (["reproduce", "-o", "{root}/reproduce"], ["--workers"]),
    "animate": (["animate", "{run_nc}", "-o", "{root}/anim.gif"], ["--fps", "--max-frames"]),
}

#: (command, option, value) that are legitimately valid: exit 0 and a finite JSON answer
CLI_VALID = {
    ("simulate", "--checkpoint-every", "0"), ("simulate", "--checkpoint-every", "5e-324"),
    ("simulate", "--checkpoint-every", "1e308"), ("simulate", "--max-rejections", "0"),
    ("simulate", "--snapshot-times", ""),  # (a time without -o is refused: the snapshots live in the file)
    ("simulate", "--record-thin", "0"), ("simulate", "--record-thin", "5e-324"),
    ("simulate", "--stop-fraction", "5e-324"), ("simulate", "--max-link-error", "5e-324"),
    ("simulate", "--max-energy-drift", "1e308"), ("simulate", "--dt-min", "5e-324"),
    ("simulate(fast)", "--tip-mass", "0"), ("simulate(fast)", "--tip-mass", "5e-324"),
    ("simulate(fast)", "--gravity", "0"), ("simulate(fast)", "--gravity", "5e-324"),
    ("simulate(fast)", "--pin-motion=pull:{},0", "0"), ("simulate(fast)", "--pin-motion=pull:{},0", "5e-324"),
    ("simulate(fast)", "--pin-motion=pull:{},0", "-1"), ("simulate(fast)", "--pin-motion=flick:1,0,{}", "1e308"),
    ("fit", "--tol", "5e-324"), ("fit", "--tol", "1e308"),
    ("estimate(links)", "--tip-mass", "0"), ("estimate(links)", "--tip-mass", "5e-324"),
    ("design", "--tip-mass", "0"), ("design", "--tip-mass", "5e-324"), ("design", "--max-tension", "1e308"),
    ("design", "--max-speed", "1e308"), ("design", "--max-acceleration", "1e308"),
    ("fit", "--window=v_max={},1e-2", "5e-324"), ("fit", "--window=v_max=1e-4,{}", "1e308"),
    # a line's body (issue 21): zero is no body, the smallest subnormal a valid (negligible) one, a wind any sign
    # (a wind without drag is refused on the command line: the base of simulate(body) has none, so only 0 there)
    *{("simulate(body)", o, v) for o in ("--bending", "--bending-damping", "--drag-normal", "--drag-tangential",
                                         "--tip-drag", "--drag-linear") for v in ("0", "5e-324")},
    ("simulate(body)", "--wind={},0", "0"),
    *{("simulate(body SI)", o, v) for o in ("--ei", "--diameter", "--air-density", "--cd-normal", "--cd-tangential",
                                            "--tip-drag-area", "--wind-si={},0") for v in ("0", "5e-324")},
    ("simulate(body SI)", "--wind-si={},0", "-1"),  # (a negative number is a value: --wind-si -1,0 too)
}
#: a bound that cannot be met: the run fails by design (exit 1, one line on stderr)
CLI_FAILS = {("simulate", "--max-energy-drift", "5e-324")}
#: valid values that would start a long computation (converge's --first: level_parameters checks it)
CLI_NOT_RUN = {("converge", "--first", "0"), ("converge", "--first", "-1")}


def _cli_cases():
    cases = []
    for name, (base, options) in CLI_SPECS.items():
        for opt in options:
            flag = opt.split("=")[0]
            for v in BAD_TEXT:
                if (name, opt, v) in CLI_NOT_RUN:
                    continue
                argv = list(base)
                if "=" in opt:
                    argv += [opt.split("=", 1)[0], opt.split("=", 1)[1].format(v)]
                elif opt in argv:
                    argv[argv.index(opt) + 1] = v
                else:
                    argv += [opt, v]
                valid = (name, opt, v) in CLI_VALID or ("fails" if (name, opt, v) in CLI_FAILS else False)
                cases.append(pytest.param(argv, flag, valid, base, id=f"{name} {opt} {v!r}"))
    return cases


CLI_CASES = _cli_cases()


def run_cli_case(argv, F, capsys):
    argv = [a.format(**F) for a in argv]
    with _time_limit(TIME_LIMIT):
        try:
            status = main(argv)
        except SystemExit as exc:  # argparse errors exit from inside parse_args
            status = exc.code
    out, err = capsys.readouterr()
    return status, out, err


def _nulls(obj, path="json") -> set:
    """The paths of the nulls in a JSON answer."""
    if obj is None:
        return {path}
    if isinstance(obj, dict):
        return set().union(*(_nulls(v, f"{path}[{k!r}]") for k, v in obj.items()))
    if isinstance(obj, list):
        return set().union(*(_nulls(v, f"{path}[{i}]") for i, v in enumerate(obj)))
    return set()


_BASE_NULLS: dict = {}


def base_nulls(base, F, capsys) -> set:
    """The nulls of the answer to the command without the bad value (absent by design, e.g. the
    alternative exponent of a row that has none)."""
    key = tuple(base)
    if key not in _BASE_NULLS:
        status, out, err = run_cli_case(base, F, capsys)
        assert status == 0, err
        _BASE_NULLS[key] = _nulls(json.loads(out))
    return _BASE_NULLS[key]


@pytest.mark.parametrize("argv, flag, valid, base", CLI_CASES)
def test_cli_hostile_value(argv, flag, valid, base, F, capsys):
    status, out, err = run_cli_case(argv, F, capsys)
    assert "Traceback" not in err, err
    if valid is True:
        assert status == 0, err
        allowed = base_nulls(base, F, capsys)
        bad = _nulls(json.loads(out)) - allowed
        assert not bad, f"non-finite results (null): {sorted(bad)[:5]}"
    elif valid == "fails":
        assert status == 1, err
        lines = err.strip().splitlines()
        assert len(lines) == 1 and "error" in lines[0], err
    else:
        assert status == 2, (status, out[-300:], err[-300:])
        lines = err.strip().splitlines()
        assert len(lines) == 1 and "error" in lines[0], err
        assert flag in lines[0], f"the message does not name {flag}: {lines[0]}"


def test_not_run_values_are_valid():
    """The valid values kept out of the generated cases because they would start long work."""
    assert len(continuum.level_parameters(2, first=-1)) == 2
    assert len(continuum.level_parameters(2, first=0)) == 2
    assert simulate.RunOptions(t_end=None).t_end is None  # run to the snap


def test_generated_case_count():
    n = len(PY_CASES) + len(CLI_CASES)
    print(f"generated hostile inputs: {len(PY_CASES)} Python calls + {len(CLI_CASES)} command lines = {n}")
    assert n >= 400
