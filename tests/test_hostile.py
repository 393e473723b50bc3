"""Hostile input (#7): every command and public function fed wrong types, NaN, infinities,
negative and huge values, empty and malformed files, truncated netCDF, another program's
netCDF, unwritable paths.

Each case must give a clear one-line error: :class:`SnappingInputError` from Python, exit
status 2 with one line on stderr and no traceback from the command line; and no file that
existed before is changed (its bytes are compared before and after).
"""

from __future__ import annotations

import os
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
    # #25: a text row in the middle of a shape (not a header), a third column
    (d / "shape_text_row.csv").write_text("x,y\n0,0\nabc,def\n0.1,0.1\n0.2,0.3\n0.3,0.5\n0.6,0.9\n")
    (d / "shape_three_columns.csv").write_text("0,0,9\n0.1,0.1,9\n0.2,0.3,9\n0.3,0.5,9\n0.6,0.9,9\n")
    # #25: two completed runs of different problems (tip masses): not one sweep
    from snapping.simulate.problem import Links, Problem

    for tip, N in ((0.2, 6), (0.3, 8)):
        simulate.run(Problem.catenary(0.5, links=Links.uniform(N, tip_mass=tip)), t_end=0.01,
                     output=d / f"tip{tip:g}.nc")
    out = {p.stem: str(p) for p in d.iterdir()}
    out["missing"] = str(d / "missing.nc")
    out["dir"] = out.pop("a_directory")
    out["no_parent"] = str(d / "no" / "such" / "dir" / "run.nc")
    out["under_file"] = str(d / "garbage.nc" / "run.nc")
    out["proc"] = "/proc/snapping-hostile-test.nc"
    out["root"] = str(d)
    return out


def _snapshot(root) -> dict[str, bytes]:
    """Every file's bytes and every directory (a refused command leaves no new empty directory)."""
    return {str(p): p.read_bytes() if p.is_file() else b"<dir>" for p in Path(root).rglob("*")}


@pytest.fixture
def untouched(files):
    """Fails the test if any file that existed before was changed, or a file was left behind."""
    before = _snapshot(files["root"])
    yield
    after = _snapshot(files["root"])
    assert after == before


# ------------------------------------------------------------------ Python API
class _Opaque:
    """A value of no number type (like ``object()``), with a fixed repr: the test ids it makes
    are the same in every process, as pytest-xdist needs of its workers' collections."""

    def __repr__(self) -> str:
        return "object()"


BAD_REALS = [NAN, INF, -INF, "0.3", None, [0.3], True, _Opaque()]
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
    _py_cases_25(add)
    return c


def _py_cases_25(add):
    """#25 section 3: public functions without type checks, objects built directly, values
    accepted silently, and the checks that came after the work."""
    from snapping import animation, design, table, units
    from snapping.simulate.problem import Links, PinMotion, Problem

    # public functions without type checks (a path, None, a sweep or another program's Dataset)
    for what, ds in (("path", lambda F: F["completed"]), ("None", lambda F: None),
                     ("sweep", lambda F: S.combine([F["completed"]])),
                     ("foreign", lambda F: xr.open_dataset(F["foreign"]).load())):
        add(f"animate({what})", lambda F, ds=ds: animation.animate(ds(F), F["root"] + "/a.gif"))
        add(f"summary({what})", lambda F, ds=ds: simulate.summary(ds(F)))
    add("to_si(foreign)", lambda F: units.to_si(xr.open_dataset(F["foreign"]).load(), length=1.0, mass=1.0))
    add("run_sweep('grid')", lambda F: S.run_sweep("grid", F["root"] + "/sw", progress=False))
    add("Links.from_density(returns a list)", lambda F: Links.from_density([0.5, 0.5], lambda s: [1.0, 2.0]))
    add("load_table(garbage)", lambda F: table.load_table(F["garbage"]))
    add("load_table(hdf5_header)", lambda F: table.load_table(F["hdf5_header"]))
    # objects built directly are checked as their constructors check them
    add("PinMotion('bogus')", lambda F: PinMotion("bogus"))
    add("PinMotion('pull', (nan, 0))", lambda F: PinMotion("pull", (NAN, 0.0)))
    add("PinMotion('flick') without a period", lambda F: PinMotion("flick", (1.0, 0.0)))
    add("PinMotion('table') without samples", lambda F: PinMotion("table"))
    add("Links(h 3, m 2)", lambda F: Links(np.full(3, 1 / 3), np.ones(2)))
    add("Links(tip_mass=nan)", lambda F: Links(np.full(2, 0.5), np.ones(2), NAN))
    add("Problem(x of 3 nodes)", lambda F: Problem(Problem.catenary(0.3, 4).links, np.zeros(3), np.zeros(5),
                                                   np.zeros(5), np.zeros(5)))
    # silently accepted before
    add("Links.explicit([True, True])", lambda F: Links.explicit([True, True], [1.0, 1.0]))
    add("Links.explicit(m=[True, True])", lambda F: Links.explicit([0.5, 0.5], [True, False]))
    add("PinMotion.from_table(x=1e300)", lambda F: PinMotion.from_table([0, 1, 2, 3], [0, 1e300, 0, 0], [0, 0, 0, 0]))
    add("table values(links=100.5)", lambda F: table.load_table().values("v_peak", 0.3, 100.5))
    add("table values(broadcast)", lambda F: table.load_table().values("v_peak", [0.3, 0.4], [100, 200, 300]))
    add("table values(chi='abc')", lambda F: table.load_table().values("v_peak", "abc", 100))
    add("computed_estimate(max_seconds=-1)", lambda F: design.computed_estimate(estimates.Chain(), chi=0.3, links=100,
                                                                               max_seconds=-1.0))
    add("run_instead(max_seconds=-1)", lambda F: design.run_instead(0.3, 100, 0.0, {}, max_seconds=-1.0))
    add("combine(runs of different problems)", lambda F: S.combine([F["tip0.2"], F["tip0.3"]]))
    add("run(snapshot_times after t_end)", lambda F: simulate.run(0.3, 6, t_end=0.01, snapshot_times=[0.5]))
    # errors that blamed the wrong thing (the message must name the culprit: checked in test_25_names)
    add("Links.taper(h=1e-300)", lambda F: Links.taper(2, 0.5, h=[1e-300, 1.0]))
    add("Problem.nodes(vx nan)", lambda F: Problem.nodes([1.0, 0.5, 0.0], [0.0, 0.0, 0.0],
                                                         vx=[0.0, NAN, 0.0]))
    # hangs: no bound
    add("dense_snapshot_times(n=10**9)", lambda F: animation.dense_snapshot_times(1.0, n=10**9))
    add("converge(chi=1e-100)", lambda F: __import__("snapping.continuum").continuum.converge(1e-100))


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
    # #25 section 3: silently accepted or dropped before
    add("simulate", "--shape", "{shape_text_row}", "--N", "4", "--method", "fast", "--t-end", "0.01")
    add("simulate", "--shape", "{shape_three_columns}", "--dims", "2", "--N", "4", "--method", "fast", "--t-end", "0.01")
    add("simulate", "--supports", "0.4,0.2", "--N", "6", "--chords", "arclength", "--t-end", "0.01")
    add("simulate", "--chi", "0.5", "--N", "6", "--t-end", "0.01", "--snapshot-times", "0.5", "-o", "{root}/new.nc")
    add("design", "--max-tension", "20", "--length", "2", "--mass", "0.05", "--links", "100", "--plot", "")
    for v in ("1e308", "5e-324", "0"):
        add("animate", "{completed}", "-o", "{root}/a.gif", "--fps", v)
    add("converge", "--chi", "1e-100", "-o", "{root}/conv")
    # a refused sweep or converge leaves no new -o directory (the untouched check sees directories)
    add("sweep", "--chi", "0.3", "--N", "10", "--workers", "0", "-o", "{root}/new/sw")
    add("sweep", "--chi", "0.3,0.4", "--N", "10", "--method", "fast", "--ensemble", "0", "-o", "{root}/sw")
    add("converge", "--chi", "0.3", "--workers", "0", "-o", "{root}/conv")
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


# ------------------------------------------------------------------ #25 section 3: behaviours
# (the refusals of #25 are in the catalogues above: _py_cases_25 and the end of _cli_cases)
from test_files import _cli  # noqa: E402 (the command run in-process: status, stdout, stderr)


def _interrupted_checkpoint(path, **kw):
    """A run stopped (as by SIGINT) at its second chunk and saved as a checkpoint at ``path``."""
    import signal

    from snapping.simulate import driver

    calls = [0]

    def stop(eng):
        calls[0] += 1
        return int(signal.SIGINT) if calls[0] == 2 else None

    driver._chunk_hook = stop
    try:
        with pytest.raises(KeyboardInterrupt):
            simulate.run(output=path, **kw)
    finally:
        driver._chunk_hook = None
    return path


def test_25_resume_of_a_run_that_then_fails_reports_it(tmp_path, monkeypatch, capsys):
    """Tracebacks: a resumed run that fails numerically printed a TypeError (its chi was None)."""
    with pytest.raises(simulate.SimulationError) as info:
        simulate.run(0.5, 10, method="euler-richardson-fixed", dt0=0.05, max_link_error=1e-3)
    failure = info.value

    def failing_resume(*a, **k):
        raise failure

    monkeypatch.setattr(simulate, "resume", failing_resume)
    ck = tmp_path / "ck.nc"
    ck.write_bytes(b"")  # (never read: the resume is the failing one above)
    status, out, err = _cli(["simulate", "--resume", ck], capsys)
    assert status == 1 and "Traceback" not in err, err
    assert err.strip().splitlines() == [err.strip()] and "error" in err, err
    assert "N=10" in out  # the stored run's summary, titled with its N


def test_25_worker_that_cannot_start_gives_its_reason_not_a_traceback(tmp_path, monkeypatch, capfd):
    """Tracebacks: workers that cannot import what they run printed multiprocessing tracebacks
    before the failure table; now the failure says why, and nothing else is printed."""
    import multiprocessing.spawn as spawn
    import sys

    from snapping import _workers

    mod = tmp_path / "only_here"
    mod.mkdir()
    (mod / "snapping_test_only_here.py").write_text("def f(x):\n    return x\n")
    monkeypatch.syspath_prepend(str(mod))
    import snapping_test_only_here as only

    prep = spawn.get_preparation_data

    def without(name):  # the workers do not see the module's directory
        d = prep(name)
        d["sys_path"] = [p for p in d["sys_path"] if p != str(mod)]
        return d

    monkeypatch.setattr(spawn, "get_preparation_data", without)
    got = []

    def collect(args, result):
        try:
            got.append(result())
        except Exception as exc:  # noqa: BLE001
            got.append(str(exc))

    _workers.run_all(1, only.f, [(1,)], collect)
    sys.modules.pop("snapping_test_only_here", None)
    out, err = capfd.readouterr()
    assert "Traceback" not in err and "Traceback" not in out, err
    assert len(got) == 1 and "could not run" in got[0] and "snapping_test_only_here" in got[0], got


def test_25_messages_name_the_culprit(files, tmp_path, capsys):
    """Unclear: errors that blamed the wrong thing."""
    from snapping.simulate.problem import Links, PinMotion, Problem

    with pytest.raises(SnappingInputError, match=r"^h\[0\]=1e-300"):  # not a node mass
        Links.taper(2, 0.5, h=[1e-300, 1.0])
    with pytest.raises(SnappingInputError, match=r"vx\[1\]=nan is not finite"):  # not "11 numbers; got 11"
        Problem.nodes([1.0, 0.5, 0.0], [0.0, 0.0, 0.0], vx=[0.0, NAN, 0.0])
    with pytest.raises(SnappingInputError, match="accel"):  # not 101 rejected steps
        Problem.catenary(0.3, 6, pin=PinMotion("pull", (NAN, 0.0)))
    status, out, err = _cli(["animate", files["completed"], "-o", tmp_path / "a.gif", "--fps", "5e-324"], capsys)
    assert status == 2 and "--fps" in err and "output" not in err.split("--fps")[0], err  # not an output failure


def test_25_long_and_undecodable_output_names_are_written(tmp_path):
    """Unclear: valid names of 240-255 bytes were refused (the lock and temporary names added
    16 bytes); an undecodable name failed after the run. Both are written, nothing left beside."""
    names = ["a" * 237 + ".nc", "b" * 252 + ".nc", os.fsdecode(b"bad\xff.nc")]
    for name in names:
        simulate.run(0.5, 6, t_end=0.01, output=tmp_path / name)
    assert sorted(os.listdir(tmp_path)) == sorted(names)
    with pytest.raises(SnappingInputError, match="256 bytes"):
        simulate.run(0.5, 6, t_end=0.01, output=tmp_path / ("c" * 253 + ".nc"))


def test_25_output_unwritable_mid_run_is_an_io_fault(tmp_path, capsys):
    """Unclear: an output that stopped being writable during the run exited 2 (bad input), not 1
    (an I/O fault). Here a directory takes the output's place while the run works (the same path
    as a directory made read-only: the output's check at the end fails)."""
    from snapping.simulate import driver

    out = tmp_path / "run.nc"

    def block(eng):
        if not out.exists():
            out.mkdir()

    driver._chunk_hook = block
    try:
        status, _, err = _cli(["simulate", "--chi", "0.5", "--N", "12", "-o", out], capsys)
    finally:
        driver._chunk_hook = None
    assert status == 1 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert out.is_dir() and not any(out.iterdir())


def test_25_two_threads_cannot_write_one_output(tmp_path):
    """Damage: two threads of one process writing one output both succeeded (the lock was
    re-entrant per process); the second now gets OutputBusyError, and the holder re-enters."""
    import threading

    from snapping import _files

    p = tmp_path / "run.nc"
    held, release, seen = threading.Event(), threading.Event(), []

    def holder():
        with _files.locked(p):
            with _files.locked(p):  # re-entrant in its own thread
                held.set()
                release.wait(10)

    t = threading.Thread(target=holder)
    t.start()
    held.wait(10)
    try:
        with pytest.raises(_files.OutputBusyError, match="another thread"):
            with _files.locked(p):
                seen.append("both")
    finally:
        release.set()
        t.join()
    assert not seen
    with _files.locked(p):  # released: free again
        pass


def test_25_foreign_files_named_like_runs_or_levels_are_kept(tmp_path, capsys):
    """Damage: another program's netCDF named like a run of a sweep, or a level of converge, was
    replaced without --overwrite."""
    for argv, name in ((["sweep", "--chi", "0.3", "--N", "10", "-o", tmp_path / "sw"], "run_chi0.3_N10.nc"),
                       (["converge", "--chi", "0.3", "-o", tmp_path / "cv"], "level1.nc")):
        d = Path(argv[-1])
        d.mkdir()
        xr.Dataset({"temperature": ("time", [280.0, 281.5])}).to_netcdf(d / name)
        before = _snapshot(d)
        status, _, err = _cli(argv, capsys)
        assert status == 2 and name in err and "--overwrite" in err, err
        assert _snapshot(d) == before


def test_25_resume_refuses_inputs_edited_and_resealed(tmp_path):
    """Silently accepted: a checkpoint whose attributes were edited and sealed again continued
    the stored dynamics under the new label; the stored inputs must give the stored start."""
    from snapping.simulate.dataset import load_run, save, seal

    ck = _interrupted_checkpoint(tmp_path / "ck.nc", chi=0.3, N=20, method="euler-richardson",
                                 chords="arclength", tol=1e-6)
    ds = load_run(ck)
    edited = ds.copy()
    edited.attrs["chi"] = 0.5
    save(seal(edited), tmp_path / "edited.nc")
    with pytest.raises(SnappingInputError, match="attributes were changed"):
        simulate.resume(tmp_path / "edited.nc")
    assert simulate.resume(ck).dataset.attrs["status"] == "completed"  # the honest file continues


def test_25_warnings_are_held_until_the_outcome(monkeypatch, capsys):
    """Unclear: numpy/scipy warnings were printed before our error. A refused command prints
    its one line only; one that works shows its warnings after its output."""
    import warnings

    from snapping.cli import estimate as cli_estimate

    def refused(args):
        warnings.warn("overflow encountered in a library", RuntimeWarning)
        raise SnappingInputError("--chi=2.0 is out of range")

    monkeypatch.setattr(cli_estimate, "_cmd_estimate", refused)
    status, _, err = _cli(["estimate", "--chi", "2"], capsys)
    assert status == 2 and err.strip().splitlines() == ["snapping estimate: error: --chi=2.0 is out of range"], err

    def works(args):
        warnings.warn("a library's note", UserWarning)
        print("answer")
        return 0

    monkeypatch.setattr(cli_estimate, "_cmd_estimate", works)
    status, out, err = _cli(["estimate", "--chi", "0.3"], capsys)
    assert status == 0 and out.strip() == "answer" and "a library's note" in err
