"""SIGINT outside a run's step loop (``snapping simulate``; branch ``clidrag``): before the first
step (under the -o lock, while a resumed run or checkpoint is read) and after the run (while it
writes or prints). A real SIGINT is raised in this process (signal.raise_signal, Python's own
handler) at a chosen call on that path. Each time: exit 130, nothing lost or overwritten (an
existing -o, a rigid checkpoint or an extensible-line checkpoint keeps its bytes; a finished run's
file is whole and complete), no lock or temporary left, and one line that says what each file
holds and what to do, whose advice works (the printed or the same command completes the run)."""

from __future__ import annotations

import os
import shlex
import signal

import pytest
import xarray as xr

from snapping import _files
from snapping.cli import main
from snapping.cli import simulate as cli_simulate
from snapping.simulate import driver, resuming
from snapping.simulate import elastic_checkpoint as ECK

RIGID = ["simulate", "--chi", "0.3", "--N", "12", "--t-end", "0.2", "--no-progress"]
ELASTIC = ["simulate", "--chi", "0.25", "--N", "12", "--stretching", "20", "--method", "rodas4", "--no-progress"]


@pytest.fixture(autouse=True)
def sigint_raises():
    """Python's SIGINT handler (a test run in the background inherits SIGINT ignored)."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


def _sigint_at(monkeypatch, owner, name, k=1, when=lambda *a, **kw: True):
    """``owner.name`` raising a real SIGINT at its k-th call that ``when`` accepts, before it runs."""
    real = getattr(owner, name)
    calls = [0]

    def wrapped(*a, **kw):
        if when(*a, **kw):
            calls[0] += 1
            if calls[0] == k:
                signal.raise_signal(signal.SIGINT)  # (KeyboardInterrupt here, or noted by a run's handler)
        return real(*a, **kw)

    monkeypatch.setattr(owner, name, wrapped)
    return calls


def _interrupted(argv, capsys) -> str:
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == 130, err
    line = err.strip().splitlines()[-1]
    assert line.startswith("snapping simulate: interrupted by SIGINT "), line
    return line


def _only(d, *names):
    assert sorted(os.listdir(d)) == sorted(names)  # (no lock, no temporary left)


def test_before_the_first_step_under_the_lock_nothing_written(tmp_path, monkeypatch, capsys):
    out = tmp_path / "run.nc"
    _sigint_at(monkeypatch, driver, "check_writable", k=2)  # (the 2nd check: under -o's lock)
    line = _interrupted([*RIGID, "-o", str(out)], capsys)
    assert "before the run's first step: nothing was written" in line and "run the command again" in line, line
    _only(tmp_path)


def test_overwrite_before_the_first_step_keeps_the_file(tmp_path, monkeypatch, capsys):
    out = tmp_path / "run.nc"
    assert main([*RIGID, "-o", str(out)]) == 0
    before = out.read_bytes()
    _sigint_at(monkeypatch, driver, "check_writable", k=2)
    line = _interrupted([*RIGID, "--t-end", "0.1", "-o", str(out), "--overwrite"], capsys)
    assert f"{out} is unchanged" in line and "run the command again" in line, line
    assert out.read_bytes() == before
    _only(tmp_path, "run.nc")


@pytest.mark.parametrize("overwrite", [False, True])
def test_after_the_run_the_file_holds_it(tmp_path, monkeypatch, capsys, overwrite):
    out = tmp_path / "run.nc"
    if overwrite:
        assert main([*RIGID, "--t-end", "0.1", "-o", str(out)]) == 0
    _sigint_at(monkeypatch, cli_simulate, "print_table")
    line = _interrupted([*RIGID, "-o", str(out), *(["--overwrite"] if overwrite else [])], capsys)
    assert f"after the run: {out} holds the run this command wrote" in line, line
    ds = xr.load_dataset(out)
    assert ds.attrs["status"] == "completed" and float(ds.attrs["t_final"]) == 0.2
    _only(tmp_path, "run.nc")


def test_resume_interrupted_before_its_first_step_keeps_the_checkpoint(tmp_path, monkeypatch, capsys):
    ck = tmp_path / "ck.nc"
    monkeypatch.setattr(driver, "_chunk_hook", lambda eng: int(signal.SIGINT))  # (the loop's own interruption)
    assert main([*RIGID, "--t-end", "2", "-o", str(ck)]) == 130
    monkeypatch.setattr(driver, "_chunk_hook", None)
    capsys.readouterr()
    before = ck.read_bytes()
    assert xr.load_dataset(ck).attrs["status"] == "interrupted"
    _sigint_at(monkeypatch, resuming, "_open_checkpoint")
    line = _interrupted(["simulate", "--resume", str(ck), "--no-progress"], capsys)
    assert f"its checkpoint {ck} is unchanged" in line and "run the same command again" in line, line
    assert ck.read_bytes() == before
    _only(tmp_path, "ck.nc")
    monkeypatch.undo()
    assert main(["simulate", "--resume", str(ck), "--no-progress"]) == 0  # (the advice works)
    assert xr.load_dataset(ck).attrs["status"] == "completed"
    capsys.readouterr()


@pytest.fixture
def elastic_checkpoint(tmp_path, monkeypatch, capsys):
    ck = tmp_path / "ck.nc"
    monkeypatch.setattr(ECK, "_chunk_hook", lambda run: int(signal.SIGINT))
    assert main([*ELASTIC, "--checkpoint", str(ck)]) == 130
    monkeypatch.setattr(ECK, "_chunk_hook", None)
    capsys.readouterr()
    return ck


def test_elastic_resume_interrupted_before_its_loop_prints_the_command(elastic_checkpoint, tmp_path, monkeypatch,
                                                                       capsys):
    ck, out = elastic_checkpoint, tmp_path / "run.nc"
    before = ck.read_bytes()
    _sigint_at(monkeypatch, ECK, "read")
    line = _interrupted([*ELASTIC, f"--checkpoint={ck}", "--res", "-o", str(out)], capsys)
    assert "nothing was written" in line and f"its checkpoint {ck} is kept as last saved" in line, line
    assert ck.read_bytes() == before and not out.exists()
    cmd = shlex.split(line.split("continue with: ", 1)[1])
    assert cmd[0] == "snapping" and cmd[-3:] == ["--checkpoint", str(ck), "--resume"], cmd
    monkeypatch.undo()
    assert main(cmd[1:]) == 0  # (the printed command completes it)
    assert xr.load_dataset(out).attrs["status"] == "completed"
    capsys.readouterr()


def test_elastic_sigint_while_writing_o_is_held_until_it_is_whole(elastic_checkpoint, tmp_path, monkeypatch,
                                                                   capsys):
    """The finished extensible-line run's -o write: SIGINT in it is acted on once the file is whole
    (before: the KeyboardInterrupt cut the write, and the finished run was lost)."""
    ck, out = elastic_checkpoint, tmp_path / "run.nc"
    _sigint_at(monkeypatch, _files, "write_atomic", when=lambda path, *a, **kw: str(path) == str(out))
    line = _interrupted([*ELASTIC, "--checkpoint", str(ck), "--resume", "-o", str(out)], capsys)
    assert f"{out} holds the finished run" in line, line
    ds = xr.load_dataset(out)
    assert ds.attrs["status"] == "completed"
    assert not any(n.endswith(".part") or n.endswith(".lock") for n in os.listdir(tmp_path))


# --- lead: a signal the run noted after its loop's last poll (while its -o was written) ---

@pytest.mark.parametrize("signame", ["SIGINT", "SIGTERM"])
def test_rigid_signal_while_the_finished_run_is_written_is_acted_on_once_it_is_whole(tmp_path, monkeypatch, capsys,
                                                                                      signame):
    """The rigid run's handlers note SIGINT/SIGTERM until the finished run's file is written; one
    that came then was dropped (exit 0, as if never sent). Now: the file whole and complete, then
    exit 130/143 with the words for a signal after the run."""
    out, sig = tmp_path / "run.nc", getattr(signal, signame)
    real = driver.save

    def save(ds, path, **kw):
        if ds.attrs["status"] == "completed":
            signal.raise_signal(sig)  # (noted by the run's handler, still in place)
        return real(ds, path, **kw)

    monkeypatch.setattr(driver, "save", save)
    rc = main([*RIGID, "-o", str(out)])
    err = capsys.readouterr().err
    assert rc == 128 + int(sig), err
    verb = "interrupted by SIGINT" if signame == "SIGINT" else "terminated by SIGTERM"
    line = err.strip().splitlines()[-1]
    assert line.startswith(f"snapping simulate: {verb} after the run: {out} holds the run this command wrote"), line
    ds = xr.load_dataset(out)
    assert ds.attrs["status"] == "completed" and float(ds.attrs["t_final"]) == 0.2
    _only(tmp_path, "run.nc")


def test_library_run_raises_a_late_sigint_after_saving(tmp_path, monkeypatch):
    """simulate.run: SIGINT while the completed run is saved -> KeyboardInterrupt after the save."""
    from snapping import simulate

    out, real = tmp_path / "r.nc", driver.save
    monkeypatch.setattr(driver, "save", lambda ds, path, **kw: (signal.raise_signal(signal.SIGINT), real(ds, path, **kw))[1])
    with pytest.raises(KeyboardInterrupt):
        simulate.run(0.3, 12, t_end=0.2, output=str(out), progress=False)
    assert xr.load_dataset(out).attrs["status"] == "completed"


def test_signals_block_raises_a_noted_signal_nothing_acted_on():
    """ECK.Signals (the extensible line's loop and its -o write): a signal noted in a block that
    ends normally is raised on exit, after the handlers are put back; one the block acted on (it
    raised) is not raised again."""
    with pytest.raises(KeyboardInterrupt) as e:
        with ECK.Signals() as s:
            signal.raise_signal(signal.SIGINT)
            assert s.signum == signal.SIGINT  # (noted, not raised, inside)
    assert type(e.value) is KeyboardInterrupt and signal.getsignal(signal.SIGINT) is signal.default_int_handler
    with pytest.raises(ValueError):  # (acted on: only the block's own exception)
        with ECK.Signals():
            signal.raise_signal(signal.SIGINT)
            raise ValueError("acted on")
    with ECK.Signals() as s:  # (none noted: nothing raised)
        pass
    assert s.signum is None
