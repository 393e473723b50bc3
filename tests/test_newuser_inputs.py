"""A new user's bad inputs to the newest features (branch ``newuser``): every one is refused before
any run with a SnappingInputError (CLI: one line, exit 2) that names the parameter as the user gave
it, the value and the valid range; options that would be silently ignored are refused; and
``python -m snapping`` runs the command. Each check here needs no simulation (fast)."""

from __future__ import annotations

import math
import re
import os
import subprocess
import sys

import numpy as np
import pytest

from snapping import caps, lines
from snapping._validate import SnappingInputError
from snapping.cli import main

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _cli(capsys, *argv):
    """(exit status, stderr) of ``snapping argv`` in this process."""
    rc = main(list(argv))
    return rc, capsys.readouterr().err


def _one_line_error(capsys, *argv) -> str:
    rc, err = _cli(capsys, *argv)
    assert rc == 2, (rc, err)
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    return err


# ------------------------------------------------------------------ python -m snapping
def test_python_m_snapping_runs_the_command():
    env = {**os.environ, "PYTHONPATH": os.path.join(ROOT, "src")}
    r = subprocess.run([sys.executable, "-m", "snapping", "estimate", "--line", "no-such-line", "--chi", "0.25"],
                       capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 2, r.stderr
    assert "--line='no-such-line' is not in the catalogue" in r.stderr


# ------------------------------------------------------------------ caps: the Python API
def test_unknown_keyword_is_an_input_error_naming_the_valid_ones():
    for call in (lambda: caps.cap("bungee-cord", 0.25, N=4, EI=1.0),
                 lambda: caps.design("bungee-cord", chis=[0.2], max_tension=1.0, N=4, diametre=0.01),
                 lambda: caps.cap(caps.spec("bungee-cord"), 0.25, N=4, foo=1.0)):
        with pytest.raises(SnappingInputError, match=r"is not a parameter of a line; valid: length, mass"):
            call()


@pytest.mark.parametrize("key, value, words", [("ei", -1.0, r"ei=-1.0 is out of range: must be finite and >= 0"),
                                               ("ea", 0.0, r"ea=0.0 is out of range: must be finite and > 0"),
                                               ("diameter", math.nan, r"diameter=nan must be a finite"),
                                               ("air_density", math.inf, r"air_density=inf must be a finite"),
                                               ("end_mass", "1", r"end_mass='1' is not a real number")])
def test_overrides_of_a_linespec_are_checked(key, value, words, monkeypatch):
    """cap(LineSpec, **params) replaced the spec's fields unchecked: ei=-1 ran."""
    monkeypatch.setattr(caps, "Runs", lambda *a, **k: pytest.fail("runs were set up before the check"))
    with pytest.raises(SnappingInputError, match=words):
        caps.cap(caps.spec("bungee-cord"), 0.25, N=4, **{key: value})


def test_a_linespec_length_or_mass_is_not_overridden_silently():
    """replace(spec, length=2) kept the 1 m line's mass (and a taper's profiles of its 1 m)."""
    for key in ("length", "mass"):
        with pytest.raises(SnappingInputError, match=rf"{key}=2.0 cannot override a LineSpec"):
            caps.cap(caps.spec("bungee-cord"), 0.25, N=4, **{key: 2.0})


@pytest.mark.parametrize("key, value", [("length", 1e300), ("mass", 1e-300), ("g", 1e300), ("length", 1e-31)])
def test_si_scales_out_of_the_doubles_are_refused(key, value):
    kw = {"length": 1.0, "mass": 0.1, key: value}
    with pytest.raises(SnappingInputError, match=rf"{key}={re.escape(repr(value))} [a-z0-9 -]+ is out of range: must lie in \[1e-30, 1e\+30\]"):
        caps.spec(None, **kw)
    with pytest.raises(SnappingInputError, match=rf"{key}="):
        caps.spec("bungee-cord", **{key: value})


def test_air_density_without_anything_to_act_on_is_refused():
    with pytest.raises(SnappingInputError, match=r"air_density=1.2 \(kg m-3\) acts on nothing"):
        caps.spec(None, length=1.0, mass=0.1, air_density=1.2)
    with pytest.raises(SnappingInputError, match=r"air_density=1.2 \(kg m-3\) acts on nothing"):
        caps.spec(None, length=1.0, mass=0.1, air_density=1.2, tip_drag_area=0.0)  # (a tip body without drag)
    # with a diameter or a tip body it acts: accepted
    assert caps.spec(None, length=1.0, mass=0.1, air_density=1.2, diameter=0.01).air_density == 1.2
    assert caps.spec(None, length=1.0, mass=0.1, air_density=1.2, tip_drag_area=1e-3).air_density == 1.2


@pytest.mark.parametrize("chis, words", [([], r"chis=\[\] holds no end separation"),
                                         ("0.2", r"chis='0.2' is not a sequence of end separations"),
                                         (None, r"chis=None is not a sequence"),
                                         ([0.2, 0.2], r"gives chi=0.2 more than once"),
                                         ([0.2, float("nan")], r"chis\[1\]=nan must be a finite"),
                                         (np.array([0.2, 1.5]), r"chis\[1\]=1.5 is out of range"),
                                         ([0.3, True], r"chis\[1\]=True is not a real number")])
def test_design_checks_every_chi_before_any_run(chis, words, monkeypatch):
    """design ran the chis one by one: [] gave an empty design, a bad chi was found after the good
    ones' runs, '0.2' was read as the characters '.', '0', '2'."""
    monkeypatch.setattr(caps, "cap", lambda *a, **k: pytest.fail("a run was made before the check"))
    with pytest.raises(SnappingInputError, match=words):
        caps.design("bungee-cord", chis=chis, max_tension=1.0, N=4)


def test_design_checks_n_and_quantity_before_any_run(monkeypatch):
    monkeypatch.setattr(caps, "cap", lambda *a, **k: pytest.fail("a run was made before the check"))
    with pytest.raises(SnappingInputError, match=r"N='many'"):  # (N="auto": each chi resolved, since designres)
        caps.design("bungee-cord", chis=[0.2], max_tension=1.0, N="many")
    with pytest.raises(SnappingInputError, match=r"N=1 is out of range: must be an integer in \[2, 20000\]"):
        caps.design("bungee-cord", chis=[0.2], max_tension=1.0, N=1)
    with pytest.raises(SnappingInputError, match=r"quantity='T' is not one of"):
        caps.design("bungee-cord", chis=[0.2], max_tension=1.0, N=4, quantity="T")


def test_design_runs_each_chi_once_in_order(monkeypatch):
    seen = []

    def fake(sp, chi, **kw):
        seen.append(chi)
        peaks = {"v_peak": 1.0, "a_peak": 1.0, "sigma_peak": 1.0}
        return {"chi": chi, "ideal": peaks, "real": peaks, "factor": peaks, "cap": "none", "alone": {},
                "mechanisms": [], "graded": {}, "stretching": {}, "n_rhs": 1}

    monkeypatch.setattr(caps, "cap", fake)
    d = caps.design("bungee-cord", chis=(0.5, 0.2, 0.3), max_tension=2.0, N=4)
    assert seen == [0.2, 0.3, 0.5] and d["admissible_chi"] == [0.2, 0.3, 0.5]
    caps.design("bungee-cord", chis=0.25, max_tension=2.0, N=4)  # one number: one chi
    assert seen[-1] == 0.25


# ------------------------------------------------------------------ the catalogue's Line
def test_line_inputs_are_input_errors():
    bw = lines.get("bullwhip")
    with pytest.raises(SnappingInputError, match=r"name='foo' is not a profile of a line; valid: diameter"):
        bw.profile("foo")
    with pytest.raises(SnappingInputError, match=r"length=-1.0 is out of range"):
        bw.profile("ei", -1.0)
    with pytest.raises(SnappingInputError, match=r"foo= is not a field of a Line"):
        bw.replace(foo=1.0)
    with pytest.raises(SnappingInputError, match=r"name=3 is not a string"):
        lines.Line(3, "", 1.0, 1.0, 0.0, 0.0, 0.0, None, 1.0)
    with pytest.raises(SnappingInputError, match=r"taper=5 must be stations"):
        lines.Line("x", "", 1.0, 1.0, 0.0, 0.0, 0.0, None, 1.0, taper=5)
    # the taper's profile at the held end (s = 0): the ratio at x = L from the free end, EI0 r^4
    L = 2.0
    r = bw.ratio(L, L)
    assert bw.profile("ei", L)(0.0) == pytest.approx(bw.ei * r**4, rel=1e-12)


# ------------------------------------------------------------------ the command line
@pytest.mark.parametrize("argv, words", [
    (("estimate", "--line", "bungee-cord", "--chi", "0.25", "--links", "1"),
     "--links=1 is out of range: must be an integer in [2, 20000]"),
    (("design", "--max-tension", "3", "--line", "bungee-cord", "--links", "30000", "--chis", "0.2"),
     "--links=30000 is out of range: must be an integer in [2, 20000]"),
    (("estimate", "--line", "bungee-cord", "--separation", "2"),
     "--separation=2.0 m is out of range: must lie in the open interval (0, 1) m"),
    (("estimate", "--line", "bungee-cord", "--length", "4", "--separation", "-0.3"),
     "--separation=-0.3 m is out of range: must lie in the open interval (0, 4) m"),
    (("design", "--max-tension", "3", "--line", "bungee-cord", "--chis", ""), "--chis=[] holds no end separation"),
    (("design", "--max-tension", "3", "--line", "bungee-cord", "--chis", "0.3,0.3"), "gives chi=0.3 more than once"),
    (("design", "--max-tension", "3", "--line", "bungee-cord", "--chis", "0.2,1.2"), "--chis[1]=1.2 is out of range"),
    (("estimate", "--chi", "0.25", "--links", "229", "--quantity", "v_peak"), "--quantity is a real line's option"),
    (("estimate", "--chi", "0.25", "--links", "229", "--resolve"), "--resolve is a real line's option"),
    (("design", "--max-tension", "20", "--length", "2", "--mass", "0.05", "--links", "100", "--quantity", "a_peak"),
     "--quantity is a real line's option"),
    (("design", "--max-tension", "3", "--line", "bungee-cord", "--resolve"), "unrecognized argument: --resolve"),
    (("estimate", "--chi", "0.25", "--length", "1", "--mass", "0.1", "--cd-tangential", "0.02"),
     "--cd-tangential=0.02 needs a diameter (m)"),
    (("estimate", "--chi", "0.25", "--length", "1", "--mass", "0.1", "--air-density", "1.2"),
     "--air-density=1.2 (kg m-3) acts on nothing"),
    (("simulate", "--chi", "0.25", "--N", "8", "--stretching", "1e300"),
     "--stretching=1e+300 is out of range: the wave speed c/sqrt(g L) must lie in (0, 1e+08]"),
    (("simulate", "--chi", "0.25", "--N", "8", "--stretching", "1e9"),  # (c^2 = 1e18 M g: beyond EA's 1e16)
     "--stretching=1000000000.0 is out of range: the wave speed c/sqrt(g L) must lie in (0, 1e+08]"),
    (("simulate", "--chi", "0.25", "--N", "8", "--length", "1", "--mass", "1", "--ea", "1e20"),
     "--ea=1e+20 is out of range: the axial stiffness EA must lie in (0, 9.81e+16] N"),
    (("regimes", "--mechanism", "drag", "--chi", "0.5", "--numbers", "0.3", "--damping", "2"),
     "--damping=2.0 is the grid damping of the bending and stretching studies: the drag study has none"),
    (("regimes", "--mechanism", "end-mass", "--chi", "0.5", "--numbers", "0.3", "--start", "stretched"),
     "--start stretched is the elastic line's start"),
    (("regimes", "--mechanism", "drag", "--chi", "0.5", "--numbers", "0.3", "--n0", "30"),
     "--n0=30 sets the links of uniform levels"),
    (("regimes", "--mechanism", "drag", "--chi", "0.5", "--numbers", "0.3", "--overwrite"),
     "--overwrite replaces an existing --plot file"),
    (("regimes", "--mechanism", "drag", "--chi", "0.5", "--numbers", "0.3", "--quantity", "a_peak"),
     "--quantity a_peak is the peak of the regime map"),
    (("regimes", "--load", "no-such-study.nc", "--levels", "3"), "--levels is an option of a study's runs"),
    (("regimes", "--load", "no-such-study.nc"), "--load='no-such-study.nc' does not exist"),
    (("regimes", "--mechanism", "drag", "--chi", "", "--numbers", "0.3"), "--chi=[]"),
])
def test_cli_refuses_naming_the_option_as_typed(capsys, argv, words):
    err = _one_line_error(capsys, *argv)
    assert words in err, err


def test_cli_real_line_still_answers_with_the_default_quantity(capsys, monkeypatch):
    """--quantity sigma_peak (the default) with a real line is taken, and reaches caps.cap."""
    got = {}

    def fake_cap(sp, chi, N, quantity, combined=False):
        got.update(chi=chi, N=N, quantity=quantity, length=sp.length, combined=combined)
        raise SnappingInputError("stop here")

    monkeypatch.setattr(caps, "cap", fake_cap)
    rc, err = _cli(capsys, "estimate", "--line", "bungee-cord", "--length", "2", "--separation", "0.5", "--links",
                   "40", "--quantity", "v_peak")
    assert rc == 2 and "stop here" in err
    assert got == {"chi": 0.25, "N": 40, "quantity": "v_peak", "length": 2.0, "combined": False}


def test_elastic_run_interrupted_says_nothing_was_kept(capsys, monkeypatch, tmp_path):
    """A SIGTERM inside the extensible line's solve (no checkpoint) was reported as 'before the
    run's first step'."""
    from snapping.cli import _Terminated
    from snapping.simulate import elastic

    def interrupted(*a, **k):
        raise _Terminated()

    monkeypatch.setattr(elastic, "solve", interrupted)
    out = tmp_path / "el.nc"
    rc, err = _cli(capsys, "simulate", "--chi", "0.25", "--N", "4", "--stretching", "30", "-o", str(out))
    assert rc == 143 and not out.exists()
    assert "during the extensible line's run, which keeps no checkpoint" in err and "first step" not in err, err


# ------------------------------------------------------------------ the elastic line of one link
def test_stretched_start_of_one_link_is_its_start():
    """One link held at both ends has no free node: its static equilibrium is the start itself
    (the Newton iteration failed on its empty residual: numpy's 'zero-size array' error)."""
    from snapping.simulate.elastic import Elastic
    from snapping.simulate.elastic_model import ElasticLine
    from snapping.simulate.problem import Links, Problem

    for n_links in (1,):
        p = Problem.catenary(0.25, links=Links.uniform(n_links, lumping="shared"))
        line = ElasticLine(p, Elastic.from_wave_speed(30.0))
        assert np.array_equal(line.start("stretched"), line.start("unstretched"))
    # with a free node (two links) the stretched start is the equilibrium, not the start
    p = Problem.catenary(0.25, links=Links.uniform(2, lumping="shared"))
    line = ElasticLine(p, Elastic.from_wave_speed(30.0))
    assert not np.array_equal(line.start("stretched"), line.start("unstretched"))


def test_failed_elastic_run_words():
    """A run that reached the snap with its peaks refused by the peak guard said 'failed: snap'."""
    from snapping.cli.simulate import elastic_failure_words

    s = {"status": "failed", "stop_reason": "snap", "peak_note": "slack: a link slack during 0.9 of the fall"}
    w = elastic_failure_words(s, "g.nc")
    assert w.startswith("the extensible line's run reached the snap, but its peaks are not resolved (peak guard: "
                        "slack: a link slack during 0.9 of the fall)")
    assert w.endswith("the run is written to g.nc with status 'failed'") and "failed: snap" not in w
    s = {"status": "failed", "stop_reason": "energy error above 0.1", "peak_note": ""}
    assert elastic_failure_words(s, None).startswith("the extensible line's run failed: energy error above 0.1;")
