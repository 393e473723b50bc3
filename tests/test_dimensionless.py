"""The nondimensional numbers of a real line (issue 24, item 1: snapping.dimensionless), each
against a hand computation from the SI values of a concrete line, by formulas other than the
code's (material constants instead of EI, EA and lambda), and printed by the commands that
take the physical parameters."""

from __future__ import annotations

import argparse
import json
import math

import pytest

from snapping import dimensionless as D
from snapping._validate import SnappingInputError
from snapping.cli import main
from snapping.cli._common import _dimensionless
from snapping.units import Scales

# A 1 m steel wire, solid, 2 mm across (E = 200 GPa, rho = 7850 kg/m^3), a 10 g end mass, 50
# links, in air (rho_air = 1.2 kg/m^3, C_n = 1.2, C_t = 0.01), g = 9.81.
E, RHO, DIAM, L, G = 200e9, 7850.0, 2e-3, 1.0, 9.81
AREA = math.pi * DIAM**2 / 4
LAM = RHO * AREA                         # kg/m
MASS = LAM * L
EI = E * math.pi * DIAM**4 / 64          # N m^2
EA = E * AREA                            # N


@pytest.fixture(scope="module")
def steel():
    return D.line_numbers(L, MASS, G, N=50, ei=EI, ea=EA, diameter=DIAM, air_density=1.2, cd_normal=1.2,
                          cd_tangential=0.01, end_mass=0.01)


def test_each_number_of_a_steel_wire(steel):
    # bending: EI/(lambda g L^3) = E I/(rho A g L^3) with I/A = d^2/16
    assert steel["beta"] == pytest.approx(E * DIAM**2 / (16.0 * RHO * G * L**3), rel=1e-12)
    # stretching: the bar wave speed sqrt(E/rho) (5048 m/s, no area) over sqrt(g L)
    assert steel["stretching"] == pytest.approx(math.sqrt(E / RHO) / math.sqrt(G * L), rel=1e-12)
    assert math.sqrt(E / RHO) == pytest.approx(5047.5, abs=0.1)
    # drag: 0.5 rho_air C d L / lambda = 0.5 rho_air C L / (rho pi d / 4)
    assert steel["drag_normal"] == pytest.approx(0.5 * 1.2 * 1.2 * L * 4.0 / (RHO * math.pi * DIAM), rel=1e-12)
    assert steel["drag_tangential"] == pytest.approx(0.5 * 1.2 * 0.01 * L * 4.0 / (RHO * DIAM), rel=1e-12)
    # end mass over the line's mass (24.66 g), and the links
    assert steel["end_mass"] == pytest.approx(0.01 / (RHO * math.pi * 1e-6), rel=1e-12)
    assert steel["link_scale"] == 0.02
    assert list(steel) == list(D.NUMBERS)  # one per mechanism, in the table's order


def test_numbers_scale_as_their_definitions():
    """Twice the length: beta / 8 (EI/lambda g L^3 at fixed lambda), stretching / sqrt(2), drag x 2."""
    a = D.line_numbers(1.0, 0.5, ei=1e-3, ea=1e4, diameter=1e-3)
    b = D.line_numbers(2.0, 1.0, ei=1e-3, ea=1e4, diameter=1e-3)
    assert b["beta"] == pytest.approx(a["beta"] / 8, rel=1e-14)
    assert b["stretching"] == pytest.approx(a["stretching"] / math.sqrt(2), rel=1e-14)
    assert b["drag_normal"] == pytest.approx(2 * a["drag_normal"], rel=1e-14)
    assert "link_scale" not in a and a["end_mass"] == 0.0
    assert D.line_numbers(1.0, 0.5, N=[10, 40])["link_scale"] == (0.1, 0.025)
    assert "end_mass" not in D.line_numbers(1.0, 0.5, end_mass=None)
    assert D.line_numbers(2.0, 0.5, end_mass=0.125)["end_mass"] == 0.25  # M_end / (lambda L) = M_end / M


@pytest.mark.parametrize("kw, name", [({"ea": 0.0}, "ea="), ({"ea": math.inf}, "ea="), ({"ea": -5.0}, "ea="),
                                      ({"end_mass": -1.0}, "end_mass="), ({"N": 0}, "N="), ({"N": 2.5}, "N="),
                                      ({"ei": -1.0}, "ei")])
def test_bad_values_are_named(kw, name):
    with pytest.raises(SnappingInputError, match=name):
        D.line_numbers(1.0, 0.5, **kw)


def test_the_cli_helper_takes_ea_and_nondimensional_body_options():
    """--ea (the elastic model's option, where a command has it) and --bending given as a number."""
    args = argparse.Namespace(ea=EA, bending=0.25)
    n = _dimensionless(Scales(L, MASS, G), args, N=50, tip_mass=0.5)
    assert n["stretching"] == pytest.approx(math.sqrt(E / RHO / (G * L)), rel=1e-12)
    assert n["beta"] == 0.25 and n["end_mass"] == pytest.approx(0.5, rel=1e-15) and n["link_scale"] == 0.02
    assert _dimensionless(None, args) is None


def _block(out: str) -> dict:
    """The rows of the printed block "Dimensionless numbers" as {name: value text}."""
    assert out.count("Dimensionless numbers") == 1
    rows = {}
    for line in out.split("Dimensionless numbers")[1].splitlines()[2:]:
        if not line.startswith("  ") or line.startswith("   "):
            break
        name, value = line.split()[:2]
        rows[name] = value.rstrip(",")
    return rows


def test_simulate_prints_the_block(capsys):
    assert main(["simulate", "--chi", "0.5", "--N", "8", "--length", str(L), "--mass", repr(MASS),
                 "--ei", repr(EI), "--diameter", repr(DIAM), "--tip-mass", "0.2", "--no-progress"]) == 0
    rows = _block(capsys.readouterr().out)
    assert float(rows["beta"]) == pytest.approx(E * DIAM**2 / (16.0 * RHO * 9.81), rel=1e-5)  # (6 digits printed)
    assert float(rows["drag_normal"]) == pytest.approx(0.5 * 1.2 * 1.2 * 4.0 / (RHO * math.pi * DIAM), rel=1e-5)
    assert float(rows["end_mass"]) == 0.2 and float(rows["link_scale"]) == 0.125
    assert main(["simulate", "--chi", "0.5", "--N", "8", "--no-progress"]) == 0
    assert "Dimensionless numbers" not in capsys.readouterr().out  # no physical parameters, no block


def test_estimate_design_and_sweep_print_it(capsys, tmp_path):
    assert main(["estimate", "--chi", "0.25", "--links", "100", "--length", "2", "--mass", "0.05"]) == 0
    rows = _block(capsys.readouterr().out)
    assert rows == {"end_mass": "0", "link_scale": "0.01"}
    assert main(["estimate", "--chi", "0.25", "--links", "100", "--length", "2", "--mass", "0.05", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["dimensionless_numbers"] == {"end_mass": 0.0, "link_scale": 0.01}
    assert main(["design", "--max-tension", "20", "--length", "2", "--mass", "0.05", "--links", "100",
                 "--tip-mass", "0.1"]) == 0
    assert _block(capsys.readouterr().out) == {"end_mass": "0.1", "link_scale": "0.01"}
    assert main(["sweep", "--chi", "0.5", "--N", "8,16", "--output", str(tmp_path / "sw"), "--length", "1",
                 "--mass", "0.5", "--bending", "0.001"]) == 0
    assert _block(capsys.readouterr().out) == {"beta": "0.001", "end_mass": "0", "link_scale": "0.125"}
    assert main(["converge", "--chi", "0.25", "--levels", "3", "--first", "-1", "--length", "1", "--mass", "0.5"]) == 0
    out = capsys.readouterr().out
    assert _block(out) == {"link_scale": "8e-06"}  # the graded levels' smallest links h_min/L
    assert "8e-06, 4e-06, 2e-06" in out
