"""The extensible line's progress bar (``elastic.solve(progress=...)``, ``snapping simulate
--stretching ...``): it moves while the run goes, ends at the run's end with its steps and
rejected steps, follows the rigid chain's display rules, and changes none of the run's numbers.

The expected values come from the run's Dataset, not from the bar: the bar's times are the
record's step times, its step count the record's ``n_steps``, its rejected steps the
factorisations less the accepted steps (RODAS4 factors once per attempt)."""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.cli import main
from snapping.simulate import elastic_progress as EP
from snapping.simulate import progress_lines
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem


def _problem(chi=0.25, N=12):
    return Problem.catenary(chi, links=Links.uniform(N, lumping="shared"))


class Recorder:
    """A bar that keeps every call (``open_bar``'s interface)."""

    def __init__(self, desc, *, progress, t_end=None, expected=None, initial=0.0, line_desc=None):
        self.desc, self.total, self.expected, self.n = desc, t_end, expected, float(initial)
        self.ts, self.posts, self.closed = [], [], False

    def update(self, dn):
        self.n += dn
        self.ts.append(self.n)

    def set_postfix_str(self, s, refresh=True):
        self.posts.append(s)

    def close(self):
        self.closed = True


@pytest.fixture
def recorded(monkeypatch):
    bars = []

    def opener(*a, **k):
        bars.append(Recorder(*a, **k))
        return bars[-1]

    monkeypatch.setattr(EP, "open_bar", opener)
    return bars


def _post(bar, key):
    return int(bar.posts[-1].split(f"{key}=")[1].split()[0])


def _same(d1, d2):
    """Two run Datasets equal bit for bit (but the wall time)."""
    a1 = {k: v for k, v in d1.attrs.items() if k != "wall_time"}
    a2 = {k: v for k, v in d2.attrs.items() if k != "wall_time"}
    assert a1.keys() == a2.keys()
    for k in a1:
        v1, v2 = a1[k], a2[k]
        assert (isinstance(v1, float) and np.isnan(v1) and np.isnan(v2)) or v1 == v2, k
    assert set(d1.variables) == set(d2.variables)
    for k in d1.variables:
        assert np.array_equal(d1[k].values, d2[k].values, equal_nan=d1[k].dtype.kind == "f"), k


@pytest.mark.parametrize("method", ["rodas4", "rodas4-links"])
def test_bar_moves_every_chunk_and_ends_at_t_end(method, recorded, monkeypatch):
    monkeypatch.setattr(EP, "CHUNK_SECONDS", 0.0)  # a return to Python after every step
    monkeypatch.setattr(EP, "FIRST_CHUNK", 1)
    ds = solve(_problem(), Elastic.from_wave_speed(20.0), t_end=0.3, tol=1e-6, method=method, progress=True).dataset
    (bar,) = recorded
    steps = int(ds.attrs["n_steps"])
    assert bar.closed and bar.total == 0.3 and bar.desc == f"extensible line N=12 ({method})"
    assert np.array_equal(bar.ts, ds.t.values[1:])  # one update per step, at each step's end
    assert bar.n == 0.3 == float(ds.t[-1])
    assert _post(bar, "steps") == steps
    assert _post(bar, "rejected") == int(ds.attrs["n_lu"]) - steps > 0


def test_bar_of_an_automatic_run_ends_at_the_snap(recorded):
    ds = solve(_problem(), Elastic.from_wave_speed(20.0), tol=1e-6, method="rodas4", progress=True).dataset
    (bar,) = recorded
    assert ds.attrs["stop_reason"] == "snap" and bar.closed and bar.total is None
    assert 1.1 < bar.expected < 1.2  # the rigid chain's estimated snap of chi = 0.25 (t* - chi^2/4 = 1.1825)
    assert bar.n == float(ds.t[-1]) and _post(bar, "steps") == int(ds.attrs["n_steps"])
    assert len(bar.ts) >= 2 and np.all(np.diff(bar.ts) > 0)


def test_bar_of_the_python_loop(recorded):
    ds = solve(_problem(N=8), Elastic.from_wave_speed(20.0), t_end=0.1, tol=1e-5, method="radau",
               progress=True).dataset
    (bar,) = recorded
    assert np.array_equal(bar.ts, ds.t.values[1:]) and _post(bar, "steps") == int(ds.attrs["n_steps"])
    assert "rejected" not in bar.posts[-1]  # (scipy's Radau does not count them)


@pytest.mark.parametrize("method,c,snaps", [("rodas4", 20.0, (0.4, 1.0)), ("rodas4-links", 60.0, (0.7,))])
def test_results_bit_for_bit_with_and_without_the_bar(method, c, snaps, monkeypatch):
    kw = dict(tol=1e-6, method=method, snapshot_times=snaps)
    r0 = solve(_problem(), Elastic.from_wave_speed(c), **kw)
    monkeypatch.setattr(EP, "CHUNK_SECONDS", 0.0)  # every step a return to Python
    monkeypatch.setattr(EP, "FIRST_CHUNK", 1)
    with contextlib.redirect_stderr(io.StringIO()):
        r1 = solve(_problem(), Elastic.from_wave_speed(c), progress=True, **kw)
    assert r0.dataset.attrs["stop_reason"] == "snap" and int(r0.dataset.attrs["n_steps"]) > 500
    _same(r0.dataset, r1.dataset)
    assert r0.peaks == r1.peaks and np.array_equal(r0.state, r1.state)


def test_tqdm_bar_text(capsys):
    ds = solve(_problem(), Elastic.from_wave_speed(20.0), t_end=0.3, tol=1e-6, method="rodas4", progress=True).dataset
    err = capsys.readouterr().err
    assert "extensible line N=12 (rodas4): t=0.30000/0.30000" in err
    assert f"steps={int(ds.attrs['n_steps'])} rejected={int(ds.attrs['n_lu']) - int(ds.attrs['n_steps'])}" in err
    solve(_problem(), Elastic.from_wave_speed(20.0), t_end=0.3, tol=1e-6, method="rodas4")  # default: no bar
    assert capsys.readouterr().err == ""


def test_progress_none_off_a_terminal_prints_lines(capsys, monkeypatch):
    monkeypatch.setattr(progress_lines, "EVERY", 0.0)
    solve(_problem(), Elastic.from_wave_speed(20.0), t_end=0.3, tol=1e-6, method="rodas4", progress=None)
    lines = capsys.readouterr().err.splitlines()
    assert lines and all(ln.startswith("extensible line N=12 (rodas4): ") for ln in lines)
    assert "stopped at t=0.3/0.3" in lines[-1] and "steps=" in lines[-1]


@pytest.mark.parametrize("bad", ["yes", 1, 0.5])
def test_bad_progress_is_refused(bad):
    with pytest.raises(SnappingInputError, match="progress="):
        solve(_problem(), Elastic.from_wave_speed(20.0), t_end=0.1, method="rodas4", progress=bad)


def test_chunks_aim_at_their_wall_time(monkeypatch):
    clock = [0.0]
    monkeypatch.setattr(EP.time, "perf_counter", lambda: clock[0])
    assert EP.Chunks(None, 4096).start() == 4096  # no bar: the whole buffer
    ch = EP.Chunks(object(), 4096)
    sizes = []
    for _ in range(5):
        rows = ch.start()
        sizes.append(rows)
        clock[0] += 1e-3 * rows  # 1 ms a step: 0.2 s is 200 steps
        ch.done(rows)
    assert sizes == [EP.FIRST_CHUNK, 4 * EP.FIRST_CHUNK, 200, 200, 200]
    clock[0] += 10.0  # one slow call: down to one step, not below
    ch.start()
    clock[0] += 50.0
    ch.done(1)
    assert ch.start() == 1


def test_cli_stretching_run_shows_progress_lines(capsys, monkeypatch):
    monkeypatch.setattr(progress_lines, "EVERY", 0.0)
    args = ["simulate", "--chi", "0.25", "--N", "12", "--stretching", "20", "--method", "rodas4", "--t-end", "0.3"]
    assert main(args) == 0
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("extensible line N=12 (rodas4)")]
    assert len(lines) >= 2 and "stopped at t=0.3/0.3" in lines[-1]
    assert main(args + ["--no-progress"]) == 0
    assert "extensible line" not in capsys.readouterr().err
