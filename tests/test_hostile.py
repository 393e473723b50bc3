"""Hostile input (#7): every command and public function fed wrong types, NaN, infinities,
negative and huge values, empty and malformed files, truncated netCDF, another program's
netCDF, unwritable paths.

Each case must give a clear one-line error: :class:`SnappingInputError` from Python, exit
status 2 with one line on stderr and no traceback from the command line; and no file that
existed before is changed (its bytes are compared before and after).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from snapping import SnappingInputError, estimates, ideal, scaling, simulate
from snapping import sweep as S
from snapping.cli import main
from snapping.simulate import ChainState

NAN, INF = float("nan"), float("inf")


# ------------------------------------------------------------------ the files
@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, str]:
    d = tmp_path_factory.mktemp("hostile")
    run = simulate.run(0.5, 40, tol=1e-6, method="euler-richardson", chords="arclength",
                       output=d / "completed.nc")  # to the snap: fit works on it (the paper's run, as designed)
    raw = Path(run.path).read_bytes()
    (d / "truncated.nc").write_bytes(raw[: len(raw) // 2])
    (d / "empty.nc").write_bytes(b"")
    (d / "garbage.nc").write_bytes(b"this is not a netCDF file\n" * 20)
    (d / "hdf5_header.nc").write_bytes(b"\x89HDF\r\n\x1a\n" + b"\x00" * 64)
    (d / "table.csv").write_text("t,v_max\n0,1\n1,2\n")
    xr.Dataset({"temperature": ("time", [280.0, 281.5, 279.9])}, coords={"time": [0, 1, 2]},
               attrs={"source": "a weather station"}).to_netcdf(d / "foreign.nc")
    # a file that looks almost like a run: time on 'step' but nothing else
    xr.Dataset({"dt": ("step", [0.1, 0.1])}, coords={"t": ("step", [0.0, 0.1])},
               attrs={"status": "interrupted"}).to_netcdf(d / "almost.nc")
    try:
        simulate.run(0.5, 10, method="euler-richardson-fixed", dt0=0.05, max_link_error=1e-3, output=d / "failed.nc")
    except simulate.SimulationError:
        pass
    (d / "a_directory").mkdir()
    out = {p.stem: str(p) for p in d.iterdir()}
    out["missing"] = str(d / "missing.nc")
    out["dir"] = out.pop("a_directory")
    out["no_parent"] = str(d / "no" / "such" / "dir" / "run.nc")
    out["under_file"] = str(d / "garbage.nc" / "run.nc")
    out["proc"] = "/proc/snapping-hostile-test.nc"
    out["root"] = str(d)
    return out


def _snapshot(root) -> dict[str, bytes]:
    return {str(p): p.read_bytes() for p in Path(root).rglob("*") if p.is_file()}


@pytest.fixture
def untouched(files):
    """Fails the test if any file that existed before was changed, or a file was left behind."""
    before = _snapshot(files["root"])
    yield
    after = _snapshot(files["root"])
    assert after == before


# ------------------------------------------------------------------ Python API
BAD_REALS = [NAN, INF, -INF, "0.3", None, [0.3], True, object()]
BAD_FRACTIONS = BAD_REALS + [-0.3, 0.0, 1.0, 1e300]


def _st(**kw):
    z = np.zeros(3)
    base = dict(x=[0.0, 0.0, 0.0], y=[1.0, 0.5, 0.0], vx=z, vy=z)
    base.update(kw)
    return ChainState(**base)


def _py_cases():
    c = []

    def add(name, fn):
        c.append(pytest.param(fn, id=name))

    # estimates
    for v in BAD_FRACTIONS:
        add(f"catenary_parameter({v!r})", lambda F, v=v: estimates.catenary_parameter(v))
    for f in ("available_energy", "kappa_m0", "delta_kappa0", "delta_crude"):
        for v in (NAN, INF, -1.0, 1.0, "x", None):
            add(f"{f}({v!r})", lambda F, f=f, v=v: getattr(estimates, f)(v))
    for v in (NAN, INF, -1.0, 0.0, "x"):
        add(f"chi_from_parameter({v!r})", lambda F, v=v: estimates.chi_from_parameter(v))
    add("catenary_shape(s=nan)", lambda F: estimates.catenary_shape([NAN], 0.3))
    add("catenary_shape(s=-1)", lambda F: estimates.catenary_shape([-1.0], 0.3))
    add("catenary_shape(s='x')", lambda F: estimates.catenary_shape("x", 0.3))
    add("catenary_shape(chi=2)", lambda F: estimates.catenary_shape([0.5], 2.0))
    for v in (0, -5, 2.5, NAN, "10", None):
        add(f"delta_N({v!r})", lambda F, v=v: estimates.delta_N(v))
    for P, d in ((NAN, 0.1), (-1.0, 0.1), (0.3, 0.0), (0.3, INF), ("x", 0.1), (0.3, None)):
        add(f"whirling_rod({P!r},{d!r})", lambda F, P=P, d=d: estimates.whirling_rod(P, d))
    for k, v in (("length", NAN), ("length", -1.0), ("length", 0.0), ("length", INF), ("length", "1"),
                 ("mass", -1.0), ("mass", NAN), ("g", 0.0), ("g", -9.81), ("g", INF)):
        add(f"Chain({k}={v!r})", lambda F, k=k, v=v: estimates.Chain(**{k: v}))
    ch = estimates.Chain()
    for kw in ({"chi": NAN}, {"chi": -1.0}, {"chi": 2.0}, {"separation": -1.0}, {"separation": 1e300},
               {"curvature": NAN}, {"curvature": -3.0}, {}, {"chi": 0.3, "separation": 0.2},
               {"chi": 0.3, "N": 0}, {"chi": 0.3, "N": -1}, {"chi": "0.3"}):
        add(f"design_estimate({kw})", lambda F, kw=kw: estimates.design_estimate(ch, **kw))
    add("design_estimate(chain='x')", lambda F: estimates.design_estimate("x", chi=0.3))
    add("delta_kappa_m(lengths)", lambda F: estimates.delta_kappa_m([0, 1, 2], [1, 2], [0.1, 0.2, 0.3]))
    add("delta_kappa_m(empty)", lambda F: estimates.delta_kappa_m([], [], []))
    add("delta_kappa_m(nan)", lambda F: estimates.delta_kappa_m([NAN] * 5, [NAN] * 5, [NAN] * 5))
    add("delta_kappa_m(str)", lambda F: estimates.delta_kappa_m("abc", "def", "ghi"))
    # ideal
    for v in (0, -5, 10**9, 2.5, "30", NAN, None):
        add(f"t_star_mp({v!r})", lambda F, v=v: ideal.t_star_mp(v))
    add("t_star_mp(method='x')", lambda F: ideal.t_star_mp(10, method="x"))
    for v in (0, -1, "x"):
        add(f"t_star_str({v!r})", lambda F, v=v: ideal.t_star_str(v))
        add(f"summary({v!r})", lambda F, v=v: ideal.summary(v))
    for f in ("s0", "s0_dot", "tether_tension", "free_end_speed"):
        for v in (NAN, "x", -1.0, 5.0):
            add(f"{f}({v!r})", lambda F, f=f, v=v: getattr(ideal, f)(v))
    add("kink_state()", lambda F: ideal.kink_state())
    add("kink_state(t, tau)", lambda F: ideal.kink_state(0.5, tau=0.5))
    # simulate.run: every input
    for v in BAD_FRACTIONS:
        add(f"run(chi={v!r})", lambda F, v=v: simulate.run(v, 10))
    for v in (0, -3, 2.5, NAN, "10", None, True, 10**12):
        add(f"run(N={v!r})", lambda F, v=v: simulate.run(0.3, v))
    numeric = {
        "tol": (0.0, -1e-8, NAN, INF, "1e-8", 1e300),
        "dt0": (0.0, -1.0, NAN, INF, "x"),
        "t_end": (0.0, -1.0, NAN, INF, 1e300),
        "t_end_max": (0.0, NAN, -INF),
        "stop_fraction": (0.0, 1.0, NAN, -0.5, "x"),
        "record_thin": (-0.1, 1.0, NAN, "x"),
        "max_link_error": (0.0, 1.0, NAN, -1.0),
        "max_energy_drift": (0.0, -1.0, NAN),
        "dt_min": (0.0, NAN, -1.0),
        "max_rejections": (-1, 2.5, "x"),
        "checkpoint_every": (-1.0, NAN, "x"),
        "progress": ("yes", 2),
    }
    for k, vals in numeric.items():
        for v in vals:
            add(f"run({k}={v!r})", lambda F, k=k, v=v: simulate.run(0.3, 10, **{k: v}))
    for k, v in (("method", "rk4"), ("method", None), ("method", 3), ("chords", "foo"), ("chords", 3),
                 ("snapshot_times", "0.1,0.2"), ("snapshot_times", [NAN]), ("snapshot_times", [-1.0]),
                 ("snapshot_times", ["a"]), ("snapshot_times", {"a": 1}), ("initial", "state"), ("initial", 3)):
        add(f"run({k}={v!r})", lambda F, k=k, v=v: simulate.run(0.3, 10, **{k: v}))
    add("run(fixed, dt0=None)", lambda F: simulate.run(0.3, 10, method="euler-richardson-fixed"))
    add("run(fixed, dt0=1e-12: memory)", lambda F: simulate.run(0.3, 10, method="euler-richardson-fixed", dt0=1e-12,
                                                               t_end=10.0))
    add("run(initial N mismatch)", lambda F: simulate.run(N=5, initial=_st()))
    add("run(initial links 0)", lambda F: simulate.run(initial=_st(y=[0.0, 0.0, 0.0]), t_end=0.1))
    add("run(initial links 3/N)", lambda F: simulate.run(initial=_st(y=[3.0, 1.5, 0.0]), t_end=0.1))
    add("run(initial v=1e200)", lambda F: simulate.run(initial=_st(vx=[1e200, 1e200, 0.0]), t_end=0.1))
    for k in ("dir", "no_parent", "under_file", "proc", "root"):
        add(f"run(output={k})", lambda F, k=k: simulate.run(0.3, 10, output=F[k]))
    for v in ("", 3, ["a.nc"]):
        add(f"run(output={v!r})", lambda F, v=v: simulate.run(0.3, 10, output=v))
    # ChainState and friends
    add("ChainState(nan)", lambda F: _st(x=[NAN, 0.0, 0.0]))
    add("ChainState(inf)", lambda F: _st(vy=[INF, 0.0, 0.0]))
    add("ChainState(pin)", lambda F: _st(x=[0.0, 0.0, 1.0]))
    add("ChainState(lengths)", lambda F: _st(x=[0.0, 0.0]))
    add("ChainState(one node)", lambda F: ChainState([0.0], [0.0], [0.0], [0.0]))
    add("ChainState(str)", lambda F: _st(x="abc"))
    add("ChainState(t=nan)", lambda F: ChainState([0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.0, 0.0], t=NAN))
    for args in ((2.0, 10), (0.3, 0), (0.3, 10, "x"), (NAN, 10), (0.3, "10")):
        add(f"initial_state{args}", lambda F, a=args: simulate.initial_state(*a))
    for args in ((0.0, 1), (-1e-3, 1), (NAN, 1), (1e-3, 0), (1e-3, 2.5)):
        add(f"integrate_fixed{args}", lambda F, a=args: simulate.integrate_fixed(_st(), *a))
    add("integrate_fixed(state='x')", lambda F: simulate.integrate_fixed("x", 1e-3, 1))
    add("evaluate('x')", lambda F: simulate.evaluate("x"))
    add("node_arclength(0)", lambda F: simulate.node_arclength(0))
    add("link_arclength(-1)", lambda F: simulate.link_arclength(-1))
    add("curvature_profile(mismatch)", lambda F: simulate.curvature_profile([0.0, 1.0], [0.0]))
    add("memory_need(N='x')", lambda F: simulate.memory_need("x"))
    # run files: resume, load_run, is_resumable, rerun, inputs_from_attrs, save
    bad_files = ("missing", "empty", "garbage", "hdf5_header", "truncated", "foreign", "almost", "table",
                 "dir", "completed", "failed")
    for k in bad_files:
        add(f"resume({k})", lambda F, k=k: simulate.resume(F[k]))
    for k in ("missing", "empty", "garbage", "truncated", "foreign", "table", "dir"):
        add(f"simulate.load_run({k})", lambda F, k=k: simulate.load_run(F[k]))
        add(f"scaling.load_run({k})", lambda F, k=k: scaling.load_run(F[k]))
    add("scaling.load_run(almost)", lambda F: scaling.load_run(F["almost"]))
    for v in (None, 3):
        add(f"resume({v!r})", lambda F, v=v: simulate.resume(v))
        add(f"simulate.load_run({v!r})", lambda F, v=v: simulate.load_run(v))
        add(f"scaling.load_run({v!r})", lambda F, v=v: scaling.load_run(v))
    add("resume(output=proc)", lambda F: simulate.resume(F["completed"], output=F["proc"]))
    add("resume(foreign, output=completed)", lambda F: simulate.resume(F["foreign"], output=F["completed"]))
    add("run(chi=nan, output=completed)", lambda F: simulate.run(NAN, 10, output=F["completed"]))
    add("run(tol=-1, output=foreign)", lambda F: simulate.run(0.3, 10, tol=-1.0, output=F["foreign"]))
    foreign = lambda F: xr.open_dataset(F["foreign"]).load()  # noqa: E731
    for name, fn in (("rerun", simulate.rerun), ("inputs_from_attrs", simulate.inputs_from_attrs),
                     ("initial_from_dataset", simulate.initial_from_dataset), ("check_run", scaling.check_run),
                     ("snapping_times", scaling.snapping_times), ("fit_run", scaling.fit_run),
                     ("delta_comparison", scaling.delta_comparison)):
        add(f"{name}(foreign)", lambda F, fn=fn: fn(foreign(F)))
        add(f"{name}('x')", lambda F, fn=fn: fn("x"))
    add("save('x')", lambda F: simulate.save("x", F["root"] + "/new.nc"))
    for k in ("dir", "no_parent", "under_file", "proc"):
        add(f"save(to {k})", lambda F, k=k: simulate.save(simulate.load_run(F["completed"]), F[k]))
    add("save(over a foreign file's directory)", lambda F: simulate.save(foreign(F), F["root"]))
    # scaling: pure functions
    tau = np.logspace(-5, 0, 200)
    good_t, good_y = 1.0 - tau, tau ** (-1 / 3)
    for name, t, y in (("lengths", good_t, good_y[:-1]), ("empty", [], []), ("nan", good_t * NAN, good_y),
                       ("str", "abc", "def"), ("2d", np.ones((3, 3)), np.ones((3, 3))), ("three", [0, 1, 2], [1, 2, 3])):
        add(f"fit_power_law({name})", lambda F, t=t, y=y: scaling.fit_power_law(t, y, t_star=1.0))
        add(f"peak_time({name})", lambda F, t=t, y=y: scaling.peak_time(t, y))
        add(f"local_slope({name})", lambda F, t=t, y=y: scaling.local_slope(t, y, 1.0))
    for kw in ({"t_star": NAN}, {"t_star": INF}, {"t_star": "1"}, {"t_star": 1.0, "window": (1.0, 0.1)},
               {"t_star": 1.0, "window": (-1.0, 0.1)}, {"t_star": 1.0, "window": "x"}, {"t_star": 1.0, "min_width": -1.0},
               {"t_star": 1.0, "min_width": NAN}, {"t_star": 1.0, "prefer": "x"}, {"t_star": 1.0, "tol": -1.0},
               {"t_star": 1.0, "t_star_err": -1.0}, {"t_star": 0.5}):
        add(f"fit_power_law({kw})", lambda F, kw=kw: scaling.fit_power_law(good_t, good_y, **kw))
    # sweeps
    for kw in ({"chi": [], "N": [10]}, {"chi": [NAN], "N": [10]}, {"chi": [2.0], "N": [10]}, {"chi": "0.3", "N": [10]},
               {"chi": None, "N": [10]}, {"chi": [0.3], "N": [0]}, {"chi": [0.3], "N": [2.5]}, {"chi": [0.3, 0.3], "N": [10]},
               {"chi": [0.3], "N": ["10"]}, {"chi": [0.3], "N": [10], "options": {"tol": -1.0}},
               {"chi": [0.3], "N": [10], "options": {"bogus": 1}}, {"chi": [0.3], "N": [10], "options": "x"}):
        add(f"Grid({kw})", lambda F, kw=kw: S.Grid(**kw))
    g = dict(chi=[0.5], N=[8], options={"tol": 1e-6})
    for k in ("garbage", "proc", "under_file"):
        add(f"run_sweep(out={k})", lambda F, k=k: S.run_sweep(S.Grid(**g), F[k], progress=False))
    for w in (0, -1, "2", 2.5):
        add(f"run_sweep(workers={w!r})", lambda F, w=w: S.run_sweep(S.Grid(**g), F["root"] + "/sw", workers=w,
                                                                   progress=False))
    add("combine([])", lambda F: S.combine([]))
    for k in ("missing", "garbage", "truncated", "foreign", "dir"):
        add(f"combine([{k}])", lambda F, k=k: S.combine([F[k]]))
    add("combine([completed, completed])", lambda F: S.combine([F["completed"], F["completed"]]))
    for k in ("proc", "dir", "under_file"):
        add(f"atomic_to_netcdf(to {k})", lambda F, k=k: S.atomic_to_netcdf(simulate.load_run(F["completed"]), F[k]))
    # reproduce
    from snapping.reproduce import reproduce

    add("reproduce(mode='x')", lambda F: reproduce(F["root"] + "/rep", "x", progress=False))
    add("reproduce(out=file)", lambda F: reproduce(F["garbage"], "quick", progress=False))
    add("reproduce(workers=0)", lambda F: reproduce(F["root"] + "/rep", "quick", workers=0, progress=False))
    return c


PY_CASES = _py_cases()


@pytest.mark.parametrize("call", PY_CASES)
def test_python_api_rejects_hostile_input(call, files, untouched):
    with pytest.raises(SnappingInputError) as info:
        call(files)
    msg = str(info.value)
    assert msg and "\n" not in msg and len(msg) < 600, msg


# ------------------------------------------------------------------ command line
def _cli_cases():
    c = []

    def add(*argv):
        c.append(pytest.param(list(argv), id=" ".join(argv)))

    for d in ("0", "-5", "abc", "100000000", "nan"):
        add("ideal", "--digits", d)
    for v in ("nan", "inf", "-1", "2", "abc", "1e400"):
        add("estimate", "--chi", v)
    add("estimate", "--separation", "-1")
    add("estimate", "--separation", "1e300")
    add("estimate", "--curvature", "nan")
    add("estimate", "--curvature", "-3")
    add("estimate", "--chi", "0.3", "--length", "-1")
    add("estimate", "--chi", "0.3", "--mass", "0")
    add("estimate", "--chi", "0.3", "--g", "inf")
    add("estimate", "--chi", "0.3", "--N", "0")
    add("estimate", "--chi", "0.3", "--separation", "0.2")
    add("estimate")
    sim = ("simulate", "--chi", "0.3", "--N", "10")
    for v in ("nan", "inf", "-1", "abc", "0", "1"):
        add("simulate", "--chi", v, "--N", "10")
    for v in ("0", "-3", "2.5", "1e12", "10000000000", "abc"):
        add("simulate", "--chi", "0.3", "--N", v)
    for flag, vals in (("--tol", ("0", "nan", "-1", "1e300")), ("--t-end", ("inf", "-1", "0")), ("--dt0", ("-1", "nan")),
                       ("--stop-fraction", ("2", "0")), ("--snapshot-times", ("a,b", "nan", "-1")),
                       ("--record-thin", ("1", "-0.5")), ("--chords", ("x",)), ("--method", ("x",)),
                       ("--checkpoint-every", ("-1", "nan")), ("--max-rejections", ("-1", "x")),
                       ("--dt-min", ("0", "-1")), ("--max-link-error", ("0", "2")), ("--max-energy-drift", ("-1",))):
        for v in vals:
            add(*sim, flag, v)
    add("simulate", "--chi", "0.3")
    add("simulate", "--N", "10")
    add(*sim, "--bogus")
    add("simulate", "--chi", "0.3", "--N", "10", "--method", "euler-richardson-fixed", "--dt0", "1e-12", "--t-end", "10")
    for k in ("dir", "no_parent", "under_file", "proc"):
        add(*sim, "-o", f"{{{k}}}")
    for k in ("missing", "empty", "garbage", "hdf5_header", "truncated", "foreign", "almost", "table", "dir",
              "completed", "failed"):
        add("simulate", "--resume", f"{{{k}}}")
    add("simulate", "--resume", "{completed}", "-o", "{proc}")
    for k in ("completed", "foreign", "failed"):  # a bad input never touches the file named by -o
        add("simulate", "--chi", "nan", "--N", "10", "-o", f"{{{k}}}")
        add("simulate", "--chi", "0.3", "--N", "10", "--tol", "-1", "-o", f"{{{k}}}")
    add("simulate", "--resume", "{failed}", "-o", "{completed}")
    # the general problem's options (#12): every one with bad values, and with -o never touching the file
    fast = ("simulate", "--chi", "0.3", "--N", "10", "--method", "fast")
    for flag, vals in (("--tip-mass", ("-1", "nan", "inf", "abc")),
                       ("--taper", ("0", "-0.5", "nan", "0.5:0", "0.5:-1", "0.5:2:3", "a", "")),
                       ("--lumping", ("nodes",)), ("--gravity", ("-1", "nan", "inf")),
                       ("--pin-motion", ("wiggle", "pull", "pull:1", "pull:a,b", "pull:1,0,-1", "pull:nan,0",
                                         "flick:1,0", "flick:1,0,0", "flick:1,0,-2", "flick:inf,0,1", "fixed:1"))):
        for v in vals:
            add(*fast, flag, v)
    for v in ("0.4", "0.4,0.2,1", "-0.4,0.2", "nan,0", "0.9,0.9", "a,b", "0,0"):
        add("simulate", "--supports", v, "--N", "10", "--method", "fast")
    for k in ("missing", "empty", "garbage", "dir", "foreign", "completed"):  # (a run file: x, y are 2-D)
        add("simulate", "--shape", f"{{{k}}}", "--N", "10", "--method", "fast")
    add("simulate", "--chi", "0.3", "--supports", "0.4,0.1", "--N", "10", "--method", "fast")
    add("simulate", "--chi", "0.3", "--N", "10", "--method", "euler-richardson", "--tip-mass", "0.5")  # refused
    add("simulate", "--chi", "0.3", "--N", "10", "--gravity", "0.5", "--method", "euler-richardson")
    for v in ("nan", "0", "1", "-0.2", "abc"):
        add("converge", "--chi", v)
    for flag, vals in (("--levels", ("0", "-1", "x")), ("--ratio", ("0", "1", "2", "nan")), ("--workers", ("0",)),
                       ("--tol", ("0", "-1")), ("--lumping", ("nodes",)), ("--free-end", ("none",)),
                       ("--first", ("x",))):
        for v in vals:
            add("converge", "--chi", "0.3", flag, v)
    for k in ("no_parent", "under_file", "proc", "dir"):
        add("converge", "--chi", "0.3", "--plot", f"{{{k}}}")
    add("converge", "--chi", "0.3", "-o", "{completed}")  # a file, not a directory
    add("converge")
    for k in ("completed", "foreign"):
        add(*fast, "--taper", "-1", "-o", f"{{{k}}}")
        add(*fast, "--pin-motion", "flick:1", "-o", f"{{{k}}}")
    for v in ("abc", "nan", "2", "0.3,0.3", ""):
        add("sweep", "--chi", v, "--N", "10", "-o", "{root}/sw")
    for v in ("0", "abc", "-5"):
        add("sweep", "--chi", "0.3", "--N", v, "-o", "{root}/sw")
    add("sweep", "--chi", "0.3", "--N", "10", "--workers", "0", "-o", "{root}/sw")
    add("sweep", "--chi", "0.3", "--N", "10", "--tol", "-1", "-o", "{root}/sw")
    add("sweep", "--chi", "0.3", "--N", "10", "--method", "rk4", "-o", "{root}/sw")
    add("sweep", "--chi", "0.3,0.4", "--N", "10", "--method", "euler-richardson", "--ensemble", "2", "-o",
        "{root}/sw")  # needs an angle method
    for v in ("0", "-3", "two"):
        add("sweep", "--chi", "0.3", "--N", "10", "--method", "fast", "--ensemble", v, "-o", "{root}/sw")
    for k in ("garbage", "proc", "under_file"):
        add("sweep", "--chi", "0.3", "--N", "10", "-o", f"{{{k}}}")
    for k in ("missing", "empty", "garbage", "truncated", "foreign", "almost", "table", "dir"):
        add("fit", f"{{{k}}}")
    add("fit", "{completed}", "{foreign}")
    for w in ("bad", "v_max=1", "v_max=a,b", "v_max=1,0.1", "v_max=-1,1", "nosuchvar=1e-3,1e-2"):
        add("fit", "{completed}", "--window", w)
    add("fit", "{completed}", "--tol", "-1")
    add("fit", "{completed}", "--min-width", "nan")
    for k in ("no_parent", "under_file", "proc"):
        add("fit", "{completed}", "--plot", f"{{{k}}}.png")
    add("fit", "{completed}", "--plot", "{root}/fig.xyz")
    add("reproduce", "-o", "{garbage}")
    add("reproduce", "-o", "{proc}")
    add("reproduce", "-o", "{root}/rep", "--workers", "0")
    add("nosuchcommand")
    return c


CLI_CASES = _cli_cases()


@pytest.mark.parametrize("argv", CLI_CASES)
def test_cli_rejects_hostile_input(argv, files, untouched, capsys):
    argv = [a.format(**files) for a in argv]
    try:
        status = main(argv)
    except SystemExit as exc:  # argparse errors exit from inside parse_args
        status = exc.code
    assert status == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "error" in lines[0] and "Traceback" not in err, err


def test_catalogue_size():
    """The closing note of #7 reports this number."""
    n = len(PY_CASES) + len(CLI_CASES)
    print(f"hostile inputs: {len(PY_CASES)} Python calls + {len(CLI_CASES)} command lines = {n}")
    assert n >= 300
