"""`snapping simulate --ea/--stretching/--damping/--strain-table`: the extensible line from the
command line (snapping.cli._elastic), and snapping.simulate.elastic.climbing_fall. Expected values
are computed here by hand (unit conversions, the massless-rope formula), never by the code under test."""

from __future__ import annotations

import json
import math
import os

import pytest
import xarray as xr

from snapping.cli import main
from snapping.simulate.elastic import climbing_fall

L, M, G = 2.0, 0.5, 9.81
BASE = ["simulate", "--chi", "0.25", "--N", "6", "--t-end", "0.15", "--no-progress"]
SI = ["--length", str(L), "--mass", str(M), "--g", str(G)]


def _json(capsys, argv):
    assert main(argv + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_si_ea_and_damping_become_the_nondimensional_line(tmp_path, capsys):
    """--ea EA [N] is EA/(M g) in units of M g (wave speed sqrt(EA/(M g)) in sqrt(gL) for the uniform
    line), --damping D [N s] is D/(M g sqrt(L/g)); the run file holds the elastic names."""
    EA, D = 400.0, 0.7
    out = tmp_path / "run.nc"
    s = _json(capsys, BASE + SI + ["--ea", str(EA), "--damping", str(D), "--grid-damping", "0.5", "-o", str(out)])
    assert s["wave_speed"] == pytest.approx(math.sqrt(EA / (M * G)), rel=1e-12)
    el = json.loads(s["elastic"])
    assert el["ea"] == pytest.approx(EA / (M * G), rel=1e-12)
    assert el["damping"] == pytest.approx(D / (M * G * math.sqrt(L / G)), rel=1e-12)
    assert el["grid_damping"] == 0.5
    assert s["status"] == "completed" and s["model"] == "elastic"
    with xr.open_dataset(out) as ds:
        for name in ("strain", "elastic_energy", "axial_stiffness", "dissipated", "n_slack"):
            assert name in ds
        assert float(ds["axial_stiffness"].max()) == pytest.approx(EA / (M * G), rel=1e-12)
        assert ds.attrs["model"] == "elastic"


def test_stretching_twin_and_a_linear_strain_table_give_the_same_run(tmp_path, capsys):
    """--stretching c is EA = c^2 M g; a two-point table (0, 0), (1, EA) is the linear law: all three
    runs give the same peaks (the table's interpolation is exact for a straight line)."""
    c = 12.0
    EA = c * c * M * G  # N
    a = _json(capsys, BASE + SI + ["--ea", str(EA)])
    b = _json(capsys, BASE + ["--stretching", str(c)])
    tab = tmp_path / "rope.csv"
    tab.write_text(f"strain,tension\n0,0\n1,{EA!r}\n")
    t = _json(capsys, BASE + SI + ["--strain-table", str(tab)])
    for k in ("v_peak", "a_peak", "sigma_peak"):
        assert b[k] == pytest.approx(a[k], rel=1e-9)
        assert t[k] == pytest.approx(a[k], rel=1e-7)
    # (the peak tension in N is sigma_peak M g)
    assert a["si"]["values"]["sigma_peak"]["value"] == pytest.approx(a["sigma_peak"] * M * G, rel=1e-12)
    # the stretching number c/sqrt(g L) = sqrt(EA/(lambda g L)), lambda = M/L, from --ea and from the table
    assert a["si"]["dimensionless_numbers"]["stretching"] == pytest.approx(c, rel=1e-12)
    assert t["si"]["dimensionless_numbers"]["stretching"] == pytest.approx(c, rel=1e-12)


@pytest.mark.parametrize("method", ["fast", "rodas4"])
def test_the_lines_body_rides_on_the_extensible_line(method, capsys):
    """--ea with --ei/--diameter (SI): the extensible line carries the line's bending and drag; the run is
    snapping.simulate.elastic.solve on the problem built here by hand (EI/(lambda g L^3), 0.5 rho C d L/lambda,
    0.5 rho C_t pi d L/lambda written out), to round-off; the summary gives the body's numbers."""
    from snapping.simulate import Body, Links, Problem
    from snapping.simulate.elastic import Elastic, solve

    EA, EI, d, rho, cn, ct = 300.0, 2e-3, 0.01, 1.2, 1.2, 0.01
    lam = M / L
    s = _json(capsys, BASE + SI + ["--ea", str(EA), "--ei", str(EI), "--diameter", str(d), "--elastic-start",
                                   "matched", "--method", method])
    body = Body(EI / (lam * G * L ** 3), drag_normal=0.5 * rho * cn * d * L / lam,
                drag_tangential=0.5 * rho * ct * math.pi * d * L / lam)
    p = Problem.catenary(0.25, links=Links.uniform(6, lumping="shared"), body=body)
    r = solve(p, Elastic(ea=EA / (M * G)), t_end=0.15, tol=1e-6, method={"fast": "radau"}.get(method, method),
              start="matched").dataset.attrs
    for k in ("v_peak", "a_peak", "sigma_peak", "energy_drift"):
        assert s[k] == pytest.approx(float(r[k]), rel=1e-9, abs=1e-14), k
    assert s["body"]["beta"] == pytest.approx(EI / (lam * G * L ** 3), rel=1e-12)
    assert s["body"]["drag_normal"] == pytest.approx(0.5 * rho * cn * d * L / lam, rel=1e-12)
    assert s["method"] == {"fast": "radau"}.get(method, method) and s["status"] == "completed"


@pytest.mark.parametrize("extra, needle", [
    (SI + ["--ea", "0"], "--ea=0.0 is out of range"),
    (SI + ["--ea", "-5"], "--ea=-5.0 is out of range"),
    (SI + ["--ea", "nan"], "--ea=nan is out of range"),
    (SI + ["--ea", "inf"], "--ea=inf is out of range"),
    (["--stretching", "0"], "--stretching=0.0 is out of range"),
    (SI + ["--ea", "100", "--damping", "-1"], "--damping=-1.0 is out of range"),
    (["--stretching", "10", "--axial-damping", "nan"], "--axial-damping=nan is out of range"),
    (["--stretching", "10", "--grid-damping", "-1"], "--grid-damping=-1.0 is out of range"),
    (["--grid-damping", "1"], "exactly one of --ea"),
    (["--stretching", "10", "--method", "euler-richardson"], "--stretching (the extensible line) with --method euler"),
    (["--ea", "100"], "--ea is in SI: it needs --length"),
    (SI + ["--ea", "100", "--stretching", "3"], "exactly one of --ea"),
    (["--stretching", "10", "--bending", "0.01", "--method", "rodas4-links"], "--method rodas4-links does not carry"),
    (["--stretching", "10", "--drag-normal", "1", "--method", "rodas4", "--checkpoint", "ck.nc"], "with a body"),
    (["--stretching", "10", "--bending", "0.01", "--start", "equilibrium"], "--start (the bending line's start"),
    (["--stretching", "10", "--dims", "3"], "is planar"),
    (SI + ["--strain-table", "TABLE"], "strains must increase"),
    (SI + ["--strain-table", "NOTCSV"], "is not two comma-separated numbers"),
])
def test_bad_elastic_options_are_one_line_exit_2_before_any_work(extra, needle, tmp_path, capsys):
    (tmp_path / "t.csv").write_text("0,0\n0.1,100\n0.05,200\n")
    (tmp_path / "n.csv").write_text("0,0\n0.1;100\n")
    extra = [str(tmp_path / "t.csv") if a == "TABLE" else str(tmp_path / "n.csv") if a == "NOTCSV" else a
             for a in extra]
    out = tmp_path / "run.nc"
    assert main(BASE + extra + ["-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err, err
    assert not os.path.exists(out)


# ------------------------------------------------------------------ the climbing fall
def test_climbing_fall_with_a_light_rope_is_the_massless_formula():
    """80 kg, fall factor 1.77, EA = 20 kN, a rope of 1e-4 of the mass: the peak force within
    5e-4 of m g (1 + sqrt(1 + 2 f EA/(m g))) = 8280.1 N (computed here), below the 12 kN limit."""
    m, f, EA, g = 80.0, 1.77, 20e3, 9.81
    F = m * g * (1.0 + math.sqrt(1.0 + 2.0 * f * EA / (m * g)))
    r = climbing_fall(mass=m, fall_factor=f, ea=EA, mass_per_length=m * 1e-4 / 2.6, rope_length=2.6, N=6)
    assert F == pytest.approx(8280.115, abs=1e-3)
    assert r["formula_force"] == pytest.approx(F, rel=1e-12)
    assert r["peak_force"] == pytest.approx(F, rel=5e-4)
    assert r["anchor_force"] == pytest.approx(F, rel=5e-3)
    # the rope's strain at the peak: F/EA (linear law)
    assert r["peak_strain"] == pytest.approx(F / EA, rel=5e-4)
    assert r["limit_force"] == 12e3


def test_climbing_fall_rope_mass_raises_the_peak_a_little():
    """The catalogue's rope (62 g/m, EA 9.2 kN): the peak is above the massless formula's by a
    fraction of the order of the rope-to-mass ratio (2e-3 here), not more."""
    r = climbing_fall(N=10, tol=1e-7)
    assert r["mass_ratio"] == pytest.approx(0.062 * 2.6 / 80.0, rel=1e-12)
    rel = r["peak_force"] / r["formula_force"] - 1.0
    assert 0.0 < rel < r["mass_ratio"]
