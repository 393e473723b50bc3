"""``snapping simulate --drag-jacobian {banded,correct}`` (branch ``clidrag``): the CLI's flag for
``simulate.run(..., method="rodas4", drag_jacobian=...)``. A run with ``correct`` is the library's
corrected run (recorded in the file and the summary; fewer steps than the banded run on a line with
drag), ``banded`` is the default run bit for bit; where the correction cannot apply (an explicit
method without stage solves, a 3D run, the extensible line, fast on the paper's chain) it is refused
naming the option, its value and the choices, with nothing written; an interrupted corrected run,
continued by ``--resume RUN.nc`` alone, is the uninterrupted corrected run bit for bit (the option
travels in the file), and ``--resume`` with the other value is refused by name."""

from __future__ import annotations

import json
import signal

import numpy as np
import pytest
import xarray as xr

from snapping.cli import main
from snapping.simulate import driver
from snapping.simulate import rk as R
from snapping.simulate.methods import rodas4 as RO

BODY = ["--chi", "0.3", "--N", "10", "--bending", "1e-3", "--drag-normal", "2", "--drag-tangential", "0.2",
        "--t-end", "0.3", "--no-progress"]


def _load(p):
    return xr.load_dataset(p)


def _same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return np.array_equal(a, b, equal_nan=a.dtype.kind in "fc" and b.dtype.kind in "fc")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("dj")
    out = {}
    for name, extra in (("default", []), ("banded", ["--drag-jacobian", "banded"]),
                        ("correct", ["--drag-jacobian", "correct"])):
        p = d / f"{name}.nc"
        assert main(["simulate", *BODY, "--method", "rodas4", *extra, "-o", str(p)]) == 0
        out[name] = _load(p)
    return out


def test_correct_is_recorded_and_differs_banded_is_the_default_bit_for_bit(runs):
    c, b, dflt = runs["correct"], runs["banded"], runs["default"]
    assert c.attrs["drag_jacobian"] == "correct" and c.attrs["method"] == "rodas4"
    assert "drag_jacobian" not in b.attrs and "drag_jacobian" not in dflt.attrs  # (the default is not written)
    for k in dflt.variables:
        assert _same(b[k].values, dflt[k].values), k
    # the correction changes the steps: far fewer on this drag-dominated line (measured 21 vs ~100)
    assert int(c.attrs["n_steps"]) < int(b.attrs["n_steps"])
    # ... for the same motion: the two runs agree at t_end to their tolerance
    assert abs(float(c.v_max[-1]) - float(b.v_max[-1])) < 1e-3 * float(b.v_max[-1])


def test_summary_names_the_correction(capsys):
    assert main(["simulate", *BODY, "--method", "stiff", "--drag-jacobian", "correct", "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["drag_jacobian"] == "correct" and s["method"] == "rodas4"
    assert main(["simulate", *BODY, "--method", "stiff", "--json"]) == 0
    assert "drag_jacobian" not in json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("extra, why", [
    (["--method", "dop853"], "--method dop853"),
    (["--method", "euler-richardson"], "--method euler-richardson"),
    (["--dims", "3"], "3D run"),
])
def test_refused_where_it_cannot_apply(extra, why, tmp_path, capsys):
    out = tmp_path / "run.nc"
    argv = ["simulate", "--chi", "0.3", "--N", "8", "--drag-jacobian", "correct", *extra, "-o", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    for w in ("--drag-jacobian correct", why, "banded", "rodas4"):
        assert w in err, (w, err)
    assert not out.exists()


def test_refused_for_the_extensible_line_and_fast_without_a_body(tmp_path, capsys):
    out = tmp_path / "run.nc"
    assert main(["simulate", "--chi", "0.3", "--N", "8", "--stretching", "30", "--method", "rodas4",
                 "--drag-jacobian", "correct", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--drag-jacobian correct" in err and "extensible line" in err and "banded" in err
    # fast on the paper's chain (the library's own check, in the option's words)
    assert main(["simulate", "--chi", "0.3", "--N", "8", "--drag-jacobian", "correct", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--drag-jacobian" in err and "correct" in err and "rodas4" in err
    assert not out.exists()
    # banded, the default, is what every run does: accepted with any method
    assert main(["simulate", "--chi", "0.3", "--N", "8", "--t-end", "0.05", "--method", "dop853",
                 "--drag-jacobian", "banded", "--no-progress"]) == 0
    capsys.readouterr()


def test_bad_value_names_the_choices(capsys):
    with pytest.raises(SystemExit) as exc:  # (argparse's choices)
        main(["simulate", *BODY, "--method", "rodas4", "--drag-jacobian", "exact"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--drag-jacobian" in err and "'exact'" in err and "banded" in err and "correct" in err


def _stop_at_second_return(monkeypatch):
    """The rodas4 engine's compiled loop returning every 3 steps (small calls, the steps unchanged:
    test_rodas4), and SIGINT acted on at its 2nd return (driver._chunk_hook)."""
    monkeypatch.setattr(RO, "NODE_EVALS_PER_CALL", 40 * 10 * 3)
    real = RO.Engine.__init__

    def init(self, *a, **k):
        real(self, *a, **k)
        self.ctl[R.Q_STEPS_PER_CALL] = 3.0

    monkeypatch.setattr(RO.Engine, "__init__", init)
    calls = [0]

    def stop(eng):
        calls[0] += 1
        return int(signal.SIGINT) if calls[0] == 2 else None

    monkeypatch.setattr(driver, "_chunk_hook", stop)


def test_interrupted_corrected_run_resumes_corrected_bit_for_bit(runs, tmp_path, monkeypatch, capsys):
    _stop_at_second_return(monkeypatch)
    p = tmp_path / "run.nc"
    assert main(["simulate", *BODY, "--method", "rodas4", "--drag-jacobian", "correct", "-o", str(p)]) == 130
    err = capsys.readouterr().err
    assert f"resume with: snapping simulate --resume {p}" in err, err
    monkeypatch.setattr(driver, "_chunk_hook", None)
    ck = _load(p)
    assert ck.attrs["status"] == "interrupted" and ck.attrs["drag_jacobian"] == "correct"
    assert 0 < float(ck.attrs["t_final"]) < 0.3
    # --resume with the other value: refused by name, the checkpoint untouched
    before = p.read_bytes()
    assert main(["simulate", "--resume", str(p), "--drag-jacobian", "banded", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "--drag-jacobian" in err and "correct" in err and "banded" in err, err
    assert p.read_bytes() == before
    # the printed command: the corrected run, bit for bit (not the banded one)
    assert main(["simulate", "--resume", str(p), "--drag-jacobian", "correct", "--no-progress"]) == 0
    got, ref = _load(p), runs["correct"]
    assert got.attrs["status"] == "completed" and got.attrs["drag_jacobian"] == "correct"
    for k in ref.variables:
        assert _same(got[k].values, ref[k].values), k
    for k in ("n_steps", "n_rhs", "n_rejected", "t_snap_v", "v_peak"):
        if k in ref.attrs:
            assert str(got.attrs[k]) == str(ref.attrs[k]), k
    capsys.readouterr()


def test_resume_of_a_banded_run_accepts_banded(tmp_path, monkeypatch, capsys):
    _stop_at_second_return(monkeypatch)
    p = tmp_path / "run.nc"
    assert main(["simulate", *BODY, "--method", "rodas4", "-o", str(p)]) == 130
    monkeypatch.setattr(driver, "_chunk_hook", None)
    assert main(["simulate", "--resume", str(p), "--drag-jacobian", "correct", "--no-progress"]) == 2
    assert "--drag-jacobian" in capsys.readouterr().err
    assert main(["simulate", "--resume", str(p), "--drag-jacobian", "banded", "--no-progress"]) == 0
    assert _load(p).attrs["status"] == "completed"
    capsys.readouterr()
