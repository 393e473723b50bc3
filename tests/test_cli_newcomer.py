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
