"""One obvious way: the defaults of run(), sweeps and the command line (the fast exact
method with exact chords), the paper's method kept by ``snapping reproduce``, and the
traps of the newcomer's toolkit (fit verdicts, estimate's --length, the sweep examples,
the progress bar's estimated snap time)."""

from __future__ import annotations

import json
import math
import shlex

import numpy as np
import pytest
from scipy.optimize import brentq

from snapping import ideal, reproduce, simulate, sweep
from snapping.cli import main
from snapping.simulate import driver
from snapping.simulate.dataset import summary

UNITS = "nondimensional (length L, mass M, time sqrt(L/g), force M g)"


def _help(command, capsys) -> str:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    return capsys.readouterr().out


def _examples(text: str) -> list[str]:
    lines = text.split("example", 1)[1].splitlines()[1:]
    return [l.split("#")[0].strip() for l in lines if l.strip().startswith("snapping ")]


# ---------------------------------------------------------------- defaults
def test_run_defaults_to_the_fast_exact_method_with_exact_chords():
    a = simulate.run(0.5, 12, t_end=0.1).dataset
    b = simulate.run(0.5, 12, t_end=0.1, method="fast", chords="exact", tol=1e-6).dataset
    assert (a.attrs["method"], a.attrs["chords"], a.attrs["tol"]) == ("dop853", "exact", 1e-6)
    assert np.array_equal(a["v_max"].values, b["v_max"].values) and np.array_equal(a["x"].values, b["x"].values)
    # exact chords: every link is 1/N at the start (the paper's arclength chords are shorter)
    assert a.attrs["link_error_initial"] < 1e-15
    # the paper's Euler-Richardson run keeps its own tolerance, 1e-8
    er = simulate.run(0.5, 12, t_end=0.1, method="euler-richardson").dataset.attrs
    assert er["tol"] == 1e-8 and er["chords"] == "exact"
    # the paper's problem as a Problem is the same run, bit for bit
    c = simulate.run(simulate.Problem.catenary(0.5, 12), t_end=0.1).dataset
    assert np.array_equal(a["v_max"].values, c["v_max"].values)


def test_default_tol_meets_the_accuracy_it_was_chosen_for():
    """The default tol of fast (1e-6) was chosen as the largest whose peaks agree with tol
    1e-11 to within 1e-7 (benchmarks/bench_default_tol.py); one case of that study, rerun."""
    d = simulate.run(0.25, 200).dataset.attrs
    ref = simulate.run(0.25, 200, tol=1e-11).dataset.attrs
    for k in ("v_peak", "a_peak", "sigma_peak"):
        assert abs(d[k] / ref[k] - 1) < 1e-7, k
    # and its snapping time is below the folded string's t* = 2E(pi/4|2) = 1.19814...
    assert 1.15 < d["t_snap_v"] < ideal.t_star() == pytest.approx(1.19814, abs=1e-5)


def test_check_inputs_and_grid_take_the_same_defaults(tmp_path):
    assert simulate.driver.check_inputs(0.3, 10) == simulate.driver.check_inputs(0.3, 10, method="fast", tol=1e-6,
                                                                                  chords="exact")
    g = sweep.Grid(chi=[0.5], N=[8])
    (p,) = sweep.run_sweep(g, tmp_path, workers=1, progress=False)
    a = simulate.load_run(p).attrs
    assert (a["method"], a["chords"], a["tol"]) == ("dop853", "exact", 1e-6)


def test_reproduce_keeps_the_papers_method_and_says_so():
    plan = reproduce.PLANS["quick"]
    opts = plan.options(plan.tol)
    assert opts["method"] == "euler-richardson" and opts["chords"] == "arclength" and opts["tol"] == 1e-8
    for g in plan.grids():
        assert g.options["method"] == "euler-richardson" and g.options["chords"] == "arclength"
    text = plan.describe()
    assert "euler-richardson" in text and "arclength" in text and UNITS in text


def test_summary_and_cli_state_method_chords_and_units(capsys):
    s = summary(simulate.run(0.5, 8, t_end=0.05).dataset)
    assert (s["method"], s["chords"], s["units"]) == ("dop853", "exact", UNITS)
    assert main(["simulate", "--chi", "0.5", "--N", "8", "--t-end", "0.05", "--no-progress"]) == 0
    out = capsys.readouterr().out
    for word in ("dop853", "exact", UNITS):
        assert word in out
    assert main(["simulate", "--chi", "0.5", "--N", "8", "--t-end", "0.05", "--json", "--method", "euler-richardson",
                 "--chords", "arclength"]) == 0
    js = json.loads(capsys.readouterr().out)
    assert (js["method"], js["chords"], js["tol"], js["units"]) == ("euler-richardson", "arclength", 1e-8, UNITS)


def test_sweep_table_states_method_chords_and_units(tmp_path, capsys):
    assert main(["sweep", "--chi", "0.5", "--N", "8", "-o", str(tmp_path / "sw")]) == 0
    out = capsys.readouterr().out
    assert "method dop853, chords exact, tol 1e-06" in out and UNITS in out


# ---------------------------------------------------------------- fit
def test_fit_help_window_example_is_conclusive_on_the_run_made_just_above(tmp_path, capsys, monkeypatch):
    text = _help("fit", capsys)
    ex = _examples(text)
    i = next(k for k, e in enumerate(ex) if "--window" in e)
    made = [e for e in ex[:i] if e.startswith("snapping simulate ")][-1]  # the run it fits, made above it
    assert "-o run.nc" in made and " run.nc " in ex[i]
    for part in ("least squares", "window choice", "t* choice", "slope drift"):
        assert part in text
    monkeypatch.chdir(tmp_path)
    assert main(shlex.split(made)[1:] + ["--no-progress"]) == 0
    capsys.readouterr()
    argv = shlex.split(ex[i])[1:]
    assert main(argv + ["--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    key, rng = next(a for a in argv if "=" in a).split("=")
    lo, hi = (float(v) for v in rng.split(","))
    row = next(r for r in res["rows"] if r["var"] == key)
    assert (row["fit"]["tau_lo"], row["fit"]["tau_hi"]) == (lo, hi)
    assert row["verdict"].startswith(("agrees with", "differs from")), row["verdict"]
    # the run's own words: v_max on this window is the folded string's -1/3 within 2 uncertainties
    f = row["fit"]
    assert row["verdict"].startswith("agrees with -1/3") == (abs(f["beta"] + 1 / 3) <= 2 * f["beta_err"])


def test_fit_table_has_one_row_per_quantity_and_plain_verdicts(tmp_path, capsys):
    path = tmp_path / "r.nc"
    simulate.run(0.25, 300, output=path)
    assert main(["fit", str(path), "--no-joint"]) == 0
    out = capsys.readouterr().out
    table = out.split("Exponents", 1)[1].split("Scales", 1)[0]
    # one line of numbers per quantity (indented 2), its verdict and notes wrapped below it (indented 6)
    rows, verdicts = [], {}
    for line in table.splitlines()[3:]:
        if line.startswith("  ") and not line.startswith("   ") and not line.startswith("  ("):
            rows.append(line.split()[0])
            verdicts[rows[-1]] = ""
        elif line.startswith("      ") and rows:
            verdicts[rows[-1]] += " " + line.strip()
    assert rows == ["v_max", "a_end", "a_max", "sigma_max", "kappa_max"]
    assert "differs; differs" not in out and "(late)" not in out and "(intermediate)" not in out
    assert "method dop853, chords exact, tol 1e-06" in out and UNITS in out
    for name, verdict in verdicts.items():
        assert verdict.strip().startswith(("agrees with", "differs from", "inconclusive:")), (name, verdict)


# ---------------------------------------------------------------- estimate
def test_estimate_separation_or_curvature_without_length_is_refused(capsys):
    for opt in ("--separation", "--curvature"):
        assert main(["estimate", opt, "0.3"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--length" in err and opt in err
    assert main(["estimate", "--separation", "0.3", "--length", "1.0", "--json"]) == 2  # the mass is needed too
    assert "without --mass" in capsys.readouterr().err
    assert main(["estimate", "--separation", "0.3", "--length", "1.0", "--mass", "0.05", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["chi"] == pytest.approx(0.3)


def _delta_kappa0(chi: float) -> float:
    """(pi/2)/kappa_m(0) of the catenary y = a cosh(x/a) of length 1 spanning chi:
    2 a sinh(chi/(2a)) = 1, kappa_m(0) = 1/a (solved here, independently of estimates)."""
    v = brentq(lambda v: math.sinh(v) / v - 1.0 / chi, 1e-9, 50.0, xtol=1e-15)
    return math.pi / 2 * chi / (2 * v)


@pytest.mark.parametrize("chi", [0.5, 0.95])
def test_estimate_warns_when_a_delta_is_longer_than_the_chain(chi, capsys):
    assert main(["estimate", "--chi", str(chi), "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    d0 = _delta_kappa0(chi)
    assert js["scales"]["delta_kappa0"] == pytest.approx(d0, rel=1e-9)
    long = sorted(k for k, d in js["scales"].items() if d > 1.0)
    assert (d0 > 1.0) == ("delta_kappa0" in long) and (chi == 0.95) == bool(long)
    assert sorted(w.split(" = ")[0] for w in js["warnings"]) == long
    assert main(["estimate", "--chi", str(chi)]) == 0
    out = capsys.readouterr().out
    assert out.count("warning: ") == len(long)


# ---------------------------------------------------------------- sweep help, progress
def test_sweep_help_examples_write_to_different_directories(capsys):
    ex = _examples(_help("sweep", capsys))
    outs = [shlex.split(e)[shlex.split(e).index("-o") + 1] for e in ex]
    assert len(outs) >= 2 and len(set(outs)) == len(outs), outs


def test_progress_bar_of_an_automatic_run_shows_the_estimated_snap(capsys):
    simulate.run(0.25, 60, progress=True)
    err = capsys.readouterr().err
    assert "estimated snap" in err and "/~1.18" in err
    simulate.run(0.25, 60, progress=True, t_end=0.3)  # a run to t_end shows its own end
    err = capsys.readouterr().err
    assert "/0.30000" in err and "estimated" not in err


@pytest.mark.parametrize("chi", [0.1, 0.25, 0.5])
def test_estimated_snap_time_is_within_one_percent_of_the_run(chi):
    est = driver.expected_snap_time({"chi": chi, "initial": "catenary"})
    t = simulate.run(chi, 200).dataset.attrs["t_snap_v"]
    assert abs(est / t - 1) < 0.01 and t < ideal.t_star()
