"""What a new user meets first: the start-up cost of a table query, the suggestions for a
mistyped option, the echo of integers and the wording of the CLI's messages (issue 25, part 4)."""

import json
import os
import subprocess
import sys

import pytest

from snapping.cli import main

# the heavy packages a table query must not import (each costs 0.05 to 2 s of start-up)
HEAVY = ("numba", "snapping.simulate", "xarray", "scipy.optimize", "mpmath", "matplotlib", "pint", "dask",
         "pandas", "importlib.metadata")


def _imported_by(argv: list[str]) -> list[str]:
    code = ("import io, contextlib, sys\n"
            "from snapping.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    status = main({argv!r})\n"
            f"print(status, [m for m in {HEAVY!r} if m in sys.modules])\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True).stdout
    status, mods = out.strip().split(" ", 1)
    assert status == "0", out
    return eval(mods)  # noqa: S307 - our own list of names


@pytest.mark.parametrize("argv", [
    ["estimate", "--chi", "0.25", "--links", "229", "--length", "1.022", "--mass", "0.0208"],
    ["estimate", "--chi", "0.25", "--json"],
    ["design", "--max-tension", "20", "--length", "2", "--mass", "0.05", "--links", "100", "--tip-mass", "0"],
])
def test_a_table_query_imports_only_what_it_needs(argv):
    assert _imported_by(argv) == []


def test_t_star_of_the_estimates_is_the_ideal_one():
    from snapping.estimates.rules import _t_star
    from snapping.ideal import t_star

    assert _t_star() == float(t_star())


def test_catenary_parameter_solves_its_equation_to_rounding():
    import math

    from snapping.estimates import catenary_parameter

    for chi in (1e-100, 1e-8, 0.01, 0.25, 0.5, 0.9, 1 - 1e-6):
        a = catenary_parameter(chi)
        b = chi / (2 * a)  # log(sinh b / b) = -log chi, relative to the size of the terms
        lhs = math.log(math.sinh(b) / b) if b < 700 else b - math.log(2 * b)
        assert abs(lhs + math.log(chi)) <= 1e-14 * max(1.0, -math.log(chi)), chi


def test_version_still_reported(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.startswith("snapping ")


def test_a_mistyped_option_names_the_subcommand_and_suggests(capsys):
    assert main(["estimate", "--chi", "0.25", "--lenght", "2", "--mass", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == ("snapping estimate: error: unrecognized argument: --lenght (did you mean --length?); "
                   "see `snapping estimate --help`")
    assert main(["simulate", "--chi", "0.3", "--t-ned=1"]) == 2
    assert "snapping simulate: error: unrecognized argument: --t-ned (did you mean --t-end" in capsys.readouterr().err


def test_a_mistyped_subcommand_gets_a_suggestion(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["estmate", "--chi", "0.25"])
    assert exc.value.code == 2
    assert "did you mean estimate" in capsys.readouterr().err


def test_integers_are_echoed_as_integers(capsys):
    assert main(["estimate", "--chi", "0.25", "--links", "1000000", "--table"]) == 2
    err = capsys.readouterr().err
    assert "--links=1000000 is outside" in err and "[10, 10000]" in err and "e+0" not in err
    from snapping.cli import print_table

    print_table([("steps", 1234567.0), ("t", 1.5)])
    out = capsys.readouterr().out
    assert "1234567" in out and "e+06" not in out


def test_cli_messages_say_overwrite_the_cli_way(tmp_path, capsys):
    png = tmp_path / "d.png"
    png.write_bytes(b"x")
    argv = ["design", "--max-tension", "20", "--length", "2", "--mass", "0.05", "--links", "100", "--tip-mass", "0",
            "--plot", str(png)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--overwrite" in err and "overwrite=True" not in err


def test_design_says_the_table_end_is_no_limit_of_the_chain(capsys):
    main(["design", "--max-tension", "20", "--length", "2", "--mass", "0.05", "--links", "100", "--tip-mass", "0"])
    out = capsys.readouterr().out
    assert "admissible: 0.359-1.8 m (chi 0.18-0.9) [1.8 m: the end of the table's range, not a limit of the chain]" in out
    res = json.loads(_json(["design", "--max-tension", "20", "--length", "2", "--mass", "0.05", "--links", "100",
                            "--tip-mass", "0", "--json"]))
    assert res["rows"][0]["admissible_separation_m"][0][1] == pytest.approx(1.8)


def _json(argv):
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(argv) == 0
    return buf.getvalue()


# ------------------------------------------------------------------ runs: silence, fit width
@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    """One short run (chi 0.25, 300 links) with snapshots, written by the CLI."""
    import contextlib
    import io

    path = tmp_path_factory.mktemp("newcomer") / "run.nc"
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        assert main(["simulate", "--chi", "0.25", "--N", "300", "-o", str(path)]) == 0
    return path, err.getvalue()


def test_a_run_without_a_terminal_prints_progress_lines(run_file, tmp_path, capsys, monkeypatch):
    _, err = run_file  # (stderr was not a terminal): a run shorter than 10 s prints nothing
    assert "chain N=" not in err
    from snapping.simulate import progress_lines

    monkeypatch.setattr(progress_lines, "EVERY", 0.0)  # a line at every chunk of the compiled loop
    assert main(["simulate", "--chi", "0.25", "--N", "300", "--t-end", "0.5", "-o", str(tmp_path / "r.nc")]) == 0
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("chain N=300")]
    assert len(lines) >= 3 and "running (of t=0.5)" in lines[0] and lines[-1].startswith("chain N=300 (dop853): "
                                                                                        "stopped at t=0.5/0.5")
    assert all("/0.5, " in ln for ln in lines[1:]) and "v_max=" in lines[-1]  # t of t_end, v_max


def test_no_progress_lines_with_no_progress(tmp_path, capsys):
    assert main(["simulate", "--chi", "0.25", "--N", "50", "--no-progress", "-o", str(tmp_path / "r.nc")]) == 0
    assert "chain N=" not in capsys.readouterr().err


def test_sigterm_before_the_first_step_says_so(tmp_path, capsys, monkeypatch):
    import signal
    import time

    from snapping import simulate

    def killed(*a, **k):
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)
        raise AssertionError("SIGTERM did not interrupt")

    monkeypatch.setattr(simulate, "run", killed)
    out = tmp_path / "r.nc"
    assert main(["simulate", "--chi", "0.25", "--N", "50", "-o", str(out)]) == 143
    err = capsys.readouterr().err
    assert "terminated by SIGTERM before the run's first step: nothing was written" in err and not out.exists()
    assert signal.getsignal(signal.SIGTERM) is not None  # (restored: not ours any more)
    assert "_Terminated" not in repr(signal.getsignal(signal.SIGTERM))


def test_the_fit_table_fits_100_columns(run_file, capsys):
    path, _ = run_file
    assert main(["fit", str(path)]) == 0
    out = capsys.readouterr().out
    assert max(len(ln) for ln in out.splitlines()) <= 100
    assert "Exponents y ~ A (t* - t)^beta" in out and "v_max" in out
    assert main(["fit", str(path), str(path), "--no-joint"]) == 0
    out = capsys.readouterr().out
    assert max(len(ln) for ln in out.splitlines()) <= 100
    assert "kappa_max" in out and "delta_kappa_m" in out


# ------------------------------------------------------------------------ figures, plot, animate
def test_plot_draws_one_run(run_file, tmp_path, capsys):
    from PIL import Image

    path, _ = run_file
    out = tmp_path / "run.png"
    assert main(["plot", str(path), "-o", str(out), "--snapshots", "4"]) == 0
    assert capsys.readouterr().out.strip() == f"wrote {out}: chi = 0.25, N = 300"
    with Image.open(out) as im:
        assert im.format == "PNG" and im.size[0] > 800
    assert main(["plot", str(path), "-o", str(out)]) == 2  # exists
    assert "--overwrite" in capsys.readouterr().err


def test_plot_overview_panels_are_labelled(run_file):
    from snapping import figures
    from snapping.simulate import load_run

    fig = figures.overview(load_run(run_file[0]), n=3)
    for ax in fig.axes:
        assert ax.get_xlabel() and ax.get_ylabel() and ax.get_title(loc="left")
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_run_label_tells_general_problems_apart():
    import json as js

    import xarray as xr

    from snapping.figures import run_label

    def label(**problem):
        return run_label(xr.Dataset(attrs={"chi": float("nan"), "N": 100, "problem": js.dumps(problem)}))

    base = {"start": {"kind": "supports", "dx": 0.4, "dy": 0.2}, "chain": {"kind": "uniform", "tip_mass": 0.0},
            "pin": {"kind": "fixed"}, "gravity": 1.0}
    plain = label(**base)
    assert plain == "supports (0.4, 0.2), N = 100" and "nan" not in plain
    tip = label(**{**base, "chain": {"kind": "uniform", "tip_mass": 0.2}})
    taper = label(**{**base, "chain": {"kind": "taper", "ratio": 0.1, "power": 2.0, "tip_mass": 0.0}})
    flick = label(**{**base, "pin": {"kind": "flick", "accel": [3.0, 0.0], "period": 0.25, "t0": 0.0}})
    pull = label(**{**base, "pin": {"kind": "pull", "accel": [0.0, -2.0], "duration": 0.3, "t0": 0.1}})
    shape = label(**{**base, "start": {"kind": "curve", "name": "/some/dir/start.csv"}})
    labels = [plain, tip, taper, flick, pull, shape]
    assert len(set(labels)) == len(labels)
    assert "tip mass 0.2" in tip and "taper 0.1:2" in taper and "flick (3, 0) T 0.25" in flick
    assert "pull (0, -2) T 0.3 from t 0.1" in pull and "start start.csv" in shape


def test_shapes_mark_the_held_end_where_it_is(run_file):
    import numpy as np

    from snapping import figures
    from snapping.simulate import load_run

    ds = load_run(run_file[0]).copy()
    ds["x"] = ds["x"] + 0.1  # a held end that moved to x = 0.1
    fig = figures.shapes([ds], n=3)
    marks = [ln for ln in fig.axes[0].lines if ln.get_marker() == "s"]
    assert marks and all(np.allclose(m.get_xdata(), 0.1) for m in marks)
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_continuum_figure_ticks_legend_and_order(tmp_path):
    import numpy as np
    import xarray as xr

    from snapping import figures

    frac = np.array([0.08, 0.04, 0.02])
    ds = xr.Dataset({q: ("frac", v) for q, v in (("v_peak", [10.0, 10.5, 10.6]), ("a_peak", [900.0, 950, 960]),
                                                 ("sigma_peak", [20.0, 20.5, 20.6]))}, coords={"frac": frac},
                    attrs={"chi": 0.25, "lumping": "shared"})
    for q, lim in (("v_peak", 10.65), ("a_peak", 965.0), ("sigma_peak", 20.65)):
        ds.attrs.update({f"{q}_limit": lim, f"{q}_error": 0.01 * lim, f"{q}_order": 2.0})
    ds.attrs["a_peak_order"] = float("nan")
    fig = figures.convergence_figure(ds)
    ax1, ax2 = fig.axes[:2]
    texts = [t.get_text() for t in ax2.get_legend().get_texts()]
    assert not any("nan" in t for t in texts) and any("order not measured" in t for t in texts)
    for ax in (ax1, ax2):
        leg = ax.get_legend()
        assert leg.get_bbox_to_anchor().y0 < ax.get_window_extent().y0 + 1  # below the panel
        assert sorted(ax.get_xticks()) == sorted(frac)
        assert [t.get_text() for t in ax.get_xticklabels(minor=True) if t.get_text()] == []
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_chi_is_not_labelled_as_a_length():
    import inspect

    from snapping.scaling import plots

    src = inspect.getsource(plots)
    assert r"$\chi$  [" not in src and "separation $\\chi$ (fraction of the length)" in src


def test_animate_frames_reruns_with_dense_snapshots(run_file, tmp_path, capsys):
    import numpy as np

    from snapping.cli.analysis import _dense_rerun
    from snapping.simulate import load_run

    path, _ = run_file
    ds = load_run(path)
    dense = _dense_rerun(ds, 30, str(path))
    t = dense["t_snapshot"].values
    assert np.sum(t <= ds.attrs["t_snap_v"]) >= 30 > np.sum(ds["t_snapshot"].values <= ds.attrs["t_snap_v"])
    assert dense.attrs["v_peak"] == pytest.approx(ds.attrs["v_peak"], rel=1e-9)  # the same run
    capsys.readouterr()
    out = tmp_path / "a.gif"
    assert main(["animate", str(path), "-o", str(out), "--frames", "12", "--max-frames", "4"]) == 0
    cap = capsys.readouterr()
    assert "rerunning" in cap.err and "wrote" in cap.out and out.exists()
    assert main(["animate", str(path), "-o", str(tmp_path / "b.gif"), "--frames", "1"]) == 2
