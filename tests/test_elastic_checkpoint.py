"""Checkpoints of extensible-line runs (``solve(..., checkpoint=, checkpoint_every=, resume=)``,
methods rodas4 and rodas4-links): a run interrupted after K chunks (by the test hook, or by a
real SIGINT sent to this process) and resumed from its file ends with the same Dataset (every
variable), peaks and final state as the run that was never interrupted, bit for bit (the
reference is that run, not the resumed code's output); a file with a wrong digest, or resumed
with another elastic line, is refused by name."""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest
import xarray as xr

from snapping._validate import SnappingInputError
from snapping.simulate import elastic_checkpoint as ECK
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.errors import RunInterrupted
from snapping.simulate.problem import Links, Problem

KW = dict(tol=1e-6, snapshot_times=(0.1, 0.5))


def _line():
    return Problem.catenary(0.25, links=Links.uniform(12, lumping="shared")), Elastic.from_wave_speed(20.0)


@pytest.fixture(autouse=True)
def _no_hook():
    yield
    ECK._chunk_hook = None


def _interrupt_after(k, real=False):
    n = [0]

    def hook(run):
        n[0] += 1
        if n[0] == k:
            if real:
                os.kill(os.getpid(), signal.SIGINT)  # (the handler notes it; the loop then stops)
                return None
            return signal.SIGINT
        return None

    ECK._chunk_hook = hook


def _same(a, b):
    assert set(a.variables) == set(b.variables)
    for k in a.variables:
        assert np.array_equal(a[k].values, b[k].values), k
    for k in a.attrs:
        if k != "wall_time":
            assert str(a.attrs[k]) == str(b.attrs[k]), k


@pytest.mark.parametrize("method,k,real", [("rodas4", 4, False), ("rodas4-links", 3, True)])
def test_interrupted_and_resumed_equals_uninterrupted(tmp_path, method, k, real):
    P, E = _line()
    ref = solve(P, E, method=method, **KW)
    assert ref.dataset.attrs["status"] == "completed"
    p = tmp_path / "ck.nc"
    _interrupt_after(k, real)
    with pytest.raises(RunInterrupted) as exc:
        solve(P, E, method=method, checkpoint=p, **KW)
    ECK._chunk_hook = None
    ds = exc.value.dataset
    assert exc.value.path == str(p) and exc.value.signum == signal.SIGINT
    assert ds.attrs["status"] == "interrupted" and 0.1 < ds.attrs["t_final"] < ref.dataset.attrs["t_final"]
    # the record so far is the reference's first steps
    n = ds.sizes["step"]
    assert np.array_equal(ds["t"].values, ref.dataset["t"].values[:n])
    assert np.array_equal(ds["v_max"].values, ref.dataset["v_max"].values[:n])
    r = solve(P, E, method=method, resume=p, **KW)
    assert r.peaks == ref.peaks
    assert np.array_equal(r.state, ref.state)
    _same(ref.dataset, r.dataset)


def test_periodic_checkpoint_resumes_and_default_run_unchanged(tmp_path):
    P, E = _line()
    ref = solve(P, E, method="rodas4", **KW)
    p = tmp_path / "ck.nc"
    seen = []

    def hook(run):  # keep the checkpoint written after the 3rd chunk
        seen.append(1)
        if len(seen) == 4:
            os.replace(p, tmp_path / "third.nc")

    ECK._chunk_hook = hook
    done = solve(P, E, method="rodas4", checkpoint=p, checkpoint_every=0.0, **KW)
    ECK._chunk_hook = None
    _same(ref.dataset, done.dataset)  # checkpointing does not change the run
    third = xr.load_dataset(tmp_path / "third.nc")
    assert third.attrs["status"] == "checkpoint"
    r = solve(P, E, method="rodas4", resume=tmp_path / "third.nc", **KW)
    _same(ref.dataset, r.dataset)


def test_refused_files_and_inputs(tmp_path):
    P, E = _line()
    p = tmp_path / "ck.nc"
    _interrupt_after(2)
    with pytest.raises(RunInterrupted):
        solve(P, E, method="rodas4", checkpoint=p, **KW)
    ECK._chunk_hook = None
    with pytest.raises(SnappingInputError, match="stiffness|elastic"):
        solve(P, Elastic.from_wave_speed(21.0), method="rodas4", resume=p, **KW)
    with pytest.raises(SnappingInputError, match="tol"):
        solve(P, E, method="rodas4", resume=p, tol=1e-7, snapshot_times=(0.1, 0.5))
    with pytest.raises(SnappingInputError, match="method"):
        solve(P, E, method="radau", resume=p, **KW)
    ds = xr.load_dataset(p)
    ds["ckpt_sctl"].values[3] *= 1.5  # the running peak: an edited state
    bad = tmp_path / "bad.nc"
    ds.to_netcdf(bad)
    with pytest.raises(SnappingInputError, match="bad.nc.*integrity"):
        solve(P, E, method="rodas4", resume=bad, **KW)
    with pytest.raises(SnappingInputError, match="checkpoint"):
        solve(P, E, method="rodas4", checkpoint_every=1.0, **KW)
    with pytest.raises(SnappingInputError, match="exists"):
        solve(P, E, method="rodas4", checkpoint=p, **KW)
