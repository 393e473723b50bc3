"""The command an interrupted extensible-line run prints to continue it (``snapping simulate
--stretching ... --method rodas4 --checkpoint FILE``; branch ``clidrag``): built from the command
line as argparse parsed it, so every spelling argparse accepts of --checkpoint and --resume is
replaced (an abbreviation such as ``--res``, ``--checkpoint=FILE``, ``--resume=FILE``) and every
other option is kept, abbreviated or not (``--checkpoint-e`` is --checkpoint-every, not
--checkpoint). The printed command, run, continues the run to the same -o file, bit for bit, as the
uninterrupted run without any checkpoint (a different code path). SIGINT is delivered at a chosen
return of the compiled loop (elastic_checkpoint._chunk_hook), in this process."""

from __future__ import annotations

import shlex
import signal

import numpy as np
import pytest
import xarray as xr

from snapping.cli import main
from snapping.simulate import elastic_checkpoint as ECK

# (abbreviated options on purpose: argparse accepts unique prefixes)
RUN = ["simulate", "--chi", "0.25", "--N", "12", "--stretch", "20", "--meth", "rodas4", "--snapshot-t", "0.1,0.5",
       "--no-prog"]


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    ref = tmp_path_factory.mktemp("ref") / "ref.nc"
    assert main([*RUN, "-o", str(ref)]) == 0
    return xr.load_dataset(ref)


def _interrupt_at(monkeypatch, k):
    calls = [0]

    def hook(run):
        calls[0] += 1
        return int(signal.SIGINT) if calls[0] == k else None

    monkeypatch.setattr(ECK, "_chunk_hook", hook)


def _printed(capsys) -> list[str]:
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "resume with: " in err, err
    argv = shlex.split(err.split("resume with: ", 1)[1])
    assert argv[0] == "snapping"
    return argv[1:]


def _check_words(argv, ck):
    """One --checkpoint CK and one --resume (at the end), no other spelling of either."""
    assert argv[-3:] == ["--checkpoint", str(ck), "--resume"], argv
    for a in argv[:-3]:
        name = a.split("=", 1)[0]
        assert not (len(name) > 2 and ("--checkpoint".startswith(name) or "--resume".startswith(name))), (a, argv)
        assert not a.startswith(("--checkpoint=", "--resume=")), (a, argv)


def _same_run(path, reference):
    got = xr.load_dataset(path)
    assert got.attrs["status"] == "completed"
    assert set(got.variables) == set(reference.variables)
    for k in reference.variables:
        assert np.array_equal(got[k].values, reference[k].values), k
    for k in reference.attrs:
        if k != "wall_time":
            assert str(got.attrs[k]) == str(reference.attrs[k]), k


def test_equals_spelling_and_abbreviations(reference, tmp_path, monkeypatch, capsys):
    ck, out = tmp_path / "ck.nc", tmp_path / "run.nc"
    monkeypatch.chdir(tmp_path)
    _interrupt_at(monkeypatch, 1)
    assert main([*RUN, f"--checkpoint={ck}", "--checkpoint-e", "0", "-o", str(out)]) == 130
    argv = _printed(capsys)
    _check_words(argv, ck)
    assert "--checkpoint-every" in argv and argv[argv.index("--checkpoint-every") + 1] == "0.0"  # (kept)
    assert argv[argv.index("--stretching") + 1] == "20.0" and argv[argv.index("--method") + 1] == "rodas4"
    assert "-o" in argv or "--output" in argv
    assert not out.exists() and xr.load_dataset(ck).attrs["status"] == "interrupted"
    # the printed command, interrupted again, spelled the abbreviated way: --res
    _interrupt_at(monkeypatch, 1)
    i = argv.index("--resume")
    assert main([*argv[:i], "--res"]) == 130
    argv2 = _printed(capsys)
    _check_words(argv2, ck)
    assert argv2 == argv  # (the same command again)
    # --resume=FILE (no --checkpoint: further checkpoints go to the resumed file)
    _interrupt_at(monkeypatch, 1)
    j = argv.index("--checkpoint")
    assert main([*argv[:j], f"--resume={ck}"]) == 130
    _check_words(_printed(capsys), ck)
    # and run to its end: the uninterrupted run, bit for bit
    monkeypatch.setattr(ECK, "_chunk_hook", None)
    assert main(argv) == 0
    capsys.readouterr()
    _same_run(out, reference)


@pytest.mark.parametrize("spelled", [["--resu", "ck.nc"], ["--resume=ck.nc"], ["--res=ck.nc"],
                                     ["--checkpoint", "ck.nc", "--resum"], ["--checkpoint=ck.nc", "--resume"],
                                     ["--checkpoint", "old.nc", "--checkpoint=ck.nc"]])
def test_every_spelling_dropped_values_kept(spelled):
    """(No run: the command of a parsed command line.) --checkpoint/--resume however spelled are
    dropped with their values; a value that starts with '-' is kept as --option=VALUE (read back as
    a value, not an option); every other option typed is kept, none that was not."""
    from types import SimpleNamespace

    from snapping.cli import _elastic, build_parser

    argv = ["simulate", "--chi", "0.25", "--N", "12", "--stretching", "20", "--meth", "rodas4", "--supports",
            "-0.3,0.1", "--grid-d", "1", "--overw", "-o", "run.nc", *spelled]
    got = shlex.split(_elastic.resume_command(SimpleNamespace(_argv=argv), "ck.nc"))
    assert got[0] == "snapping"
    _check_words(got[1:], "ck.nc")
    assert "--supports=-0.3,0.1" in got and "--overwrite" in got and got[got.index("--grid-damping") + 1] == "1.0"
    assert "--checkpoint-every" not in got and "--json" not in got  # (not typed: not added)
    a, b = build_parser().parse_args(argv), build_parser().parse_args(got[1:])  # (the same options, parsed)
    for k in ("chi", "N", "stretching", "method", "supports", "grid_damping", "overwrite", "output"):
        assert getattr(a, k) == getattr(b, k), k
    assert b.checkpoint == "ck.nc" and b.resume is True
