"""A command never writes netCDF under a name that says another format.

``snapping simulate ... -o x.txt`` wrote a netCDF4 run file named x.txt. Every command that
writes a netCDF file (simulate, in the plane, in space, elastic, resumed; regimes' study;
``python -m snapping.table.build``'s table) now refuses, before any work, an output whose
suffix is not .nc, .nc4 or .netcdf, naming the option, the value and the accepted suffixes
(exit status 2, one line, no file written). Figures (plot, fit/converge/regimes/design
``--plot``) and animations already refused a suffix that is not theirs; sweep, converge and
reproduce write into a directory.
"""

from __future__ import annotations

import os

import pytest

from snapping._files import NETCDF_SUFFIXES, netcdf_suffix
from snapping._validate import SnappingInputError
from snapping.cli import main

ACCEPTED = ("run.nc", "run.nc4", "run.netcdf", "RUN.NC", "a.b.nc")
REFUSED = ("run.txt", "run", "run.csv", "run.nc.txt", "run.h5", "run.ncx")


@pytest.mark.parametrize("name", ACCEPTED)
def test_netcdf_suffixes_are_accepted(name):
    assert netcdf_suffix(name) == name


@pytest.mark.parametrize("name", REFUSED)
def test_other_suffixes_are_refused_naming_option_value_and_suffixes(name):
    with pytest.raises(SnappingInputError) as info:
        netcdf_suffix(name, name="--output")
    msg = str(info.value)
    assert msg.startswith(f"--output={name!r} ") and all(s in msg for s in NETCDF_SUFFIXES), msg
    assert ("has no suffix" in msg) if "." not in name else (os.path.splitext(name)[1] in msg)


def _cli(argv, capsys):
    status = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    return status, err


@pytest.mark.parametrize("argv", [
    ["simulate", "--chi", "0.3", "--N", "4", "-o", "{d}/x.txt"],
    ["simulate", "--chi", "0.3", "--N", "4", "--method", "dop853", "--output", "{d}/x.TXT"],
    ["simulate", "--chi", "0.3", "--N", "4", "--stretching", "300", "-o", "{d}/x.txt"],  # the elastic line
    ["simulate", "--chi", "0.3", "--N", "4", "--dims", "3", "-o", "{d}/x.txt"],  # the chain in space
    ["simulate", "--resume", "{d}/missing.nc", "-o", "{d}/x.txt"],
    ["simulate", "--chi", "0.3", "--N", "4", "-o", "{d}/x"],
    ["regimes", "--mechanism", "drag", "--chi", "0.3", "--numbers", "1", "-o", "{d}/x.txt"],
])
def test_commands_refuse_a_netcdf_output_under_another_suffix(argv, tmp_path, capsys):
    argv = [a.format(d=tmp_path) for a in argv]
    status, err = _cli(argv, capsys)
    assert status == 2 and len(err) == 1, err
    assert "--output=" in err[0] and argv[-1] in err[0] and ".nc, .nc4 or .netcdf" in err[0], err
    assert list(tmp_path.iterdir()) == []  # nothing written, nothing started


@pytest.mark.parametrize("kind", ["device", "directory"])
def test_a_path_that_is_not_a_file_is_named_as_such_first(kind, tmp_path, capsys):
    """A directory or device given to -o is refused as what it is (check_output's words), the
    suffix aside: it is never replaced whatever its name."""
    p = "/dev/null" if kind == "device" else str(tmp_path / "adir")
    if kind == "directory":
        os.mkdir(p)
    assert netcdf_suffix(p) == p
    status, err = _cli(["simulate", "--chi", "0.3", "--N", "4", "-o", p, "--overwrite"], capsys)
    assert status == 2 and len(err) == 1 and ("regular file" in err[0] or "directory" in err[0]), err
    assert "suffix" not in err[0]


def test_table_build_refuses_before_any_run(tmp_path, capsys):
    from snapping.table.build import main as build_main

    with pytest.raises(SystemExit) as info:
        build_main(["--assemble-only", "--ledger", str(tmp_path / "none.jsonl"), "-o", str(tmp_path / "t.csv")])
    assert info.value.code == 2
    assert "--output=" in capsys.readouterr().err and list(tmp_path.iterdir()) == []


def test_a_netcdf_suffix_still_writes_the_run(tmp_path, capsys):
    from snapping.simulate import load_run

    out = tmp_path / "r.nc4"
    status, err = _cli(["simulate", "--chi", "0.5", "--N", "4", "--t-end", "0.01", "-o", str(out)], capsys)
    assert status == 0, err
    assert int(load_run(str(out)).attrs["N"]) == 4
