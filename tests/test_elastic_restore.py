"""The state of a compiled RODAS4 elastic run (``RodasRun.state``/``restore``, the base an elastic
checkpoint needs): a run stopped at a return of its loop, its arrays put into a fresh run built
from the same line, continues exactly as the run that was not stopped: the same record, final
state, controls and refined peaks, bit for bit. The reference is the run not stopped, not the
restored code's own output."""

from __future__ import annotations

import numpy as np
import pytest

from snapping.simulate import elastic_advance as EA
from snapping.simulate import elastic_refine as ERF
from snapping.simulate import elastic_solve as S
from snapping.simulate.elastic import Elastic
from snapping.simulate.elastic_links_rodas import LinksStepper
from snapping.simulate.elastic_model import ElasticLine
from snapping.simulate.elastic_rodas import RodasStepper
from snapping.simulate.problem import Links, PinMotion, Problem


def _make(method, pin=None):
    kw = {} if pin is None else {"pin": pin}
    p = Problem.catenary(0.25, links=Links.uniform(12, lumping="shared"), **kw)
    line = ElasticLine(p, Elastic.from_wave_speed(20.0, damping=1e-3))
    z0 = line.start("stretched")
    st = (RodasStepper if method == "rodas4" else LinksStepper)(line, 0.0, z0, 10.0, 1e-6)
    mm0 = line.measure(0.0, z0)
    row = S._record(line, 0.0, z0, 0.0, mm0)
    E0, U0 = row[S.STEP_NAMES.index("energy")], row[S.STEP_NAMES.index("elastic_energy")]
    floor = S.speed_floor(U0, float(np.min(line.m)), 0.5)
    return (EA.RodasRun if method == "rodas4" else EA.LinksRun)(
        st, mm0, t_end_given=False, stop_fraction=0.5, floor=floor, E0=E0, U0=U0, max_rhs=50_000_000,
        energy_fail=S.ENERGY_ERROR_FAIL)


def _to_end(run, rows, calls=None):
    out, n = [], 0
    while calls is None or n < calls:
        code = run.advance(np.inf, rows)
        out.append(run.drain())
        n += 1
        if code not in (EA.R_BUFFER, EA.R_SNAPSHOT):
            return np.concatenate(out), code
    return np.concatenate(out), None


def _steps(run, k):
    """Take exactly ``k`` steps (not the last)."""
    while k > 0:
        rows = min(k, run.rec.shape[0])
        assert run.advance(np.inf, rows) == EA.R_BUFFER
        k -= len(run.drain())


@pytest.mark.parametrize("method,pin", [("rodas4", None), ("rodas4-links", None),
                                        ("rodas4", PinMotion.flick((0.5, 0.0), 0.4))])
def test_restored_run_continues_bit_for_bit(method, pin):
    a = _make(method, pin)
    head, code = _to_end(a, 37, calls=9)  # stopped at the 9th return (333 steps)
    assert code is None
    saved = a.state()
    tail_a, code_a = _to_end(a, 37)
    b = _make(method, pin)
    b.restore(saved)
    tail_b, code_b = _to_end(b, 37)
    assert code_a == code_b == EA.R_SNAP and len(tail_a) > 1000
    assert np.array_equal(tail_a, tail_b)
    assert np.array_equal(a.st.y, b.st.y) and np.array_equal(a.st.ctl, b.st.ctl, equal_nan=True)
    assert np.array_equal(a.sctl, b.sctl, equal_nan=True) and np.array_equal(a.peak_z, b.peak_z)
    ra, rb = ERF.refine(a, S.PEAK_SAMPLES, S.PEAK_RESTEP), ERF.refine(b, S.PEAK_SAMPLES, S.PEAK_RESTEP)
    assert ra == rb


@pytest.mark.parametrize("method", ["rodas4", "rodas4-links"])
def test_restored_after_the_peaks_refines_them_bit_for_bit(method):
    """Stopped 3 steps before the stop rule ends the run: the peaks' kept steps (their dense
    output guides the refinement) were all taken before the stop, and come from the state."""
    ref = _make(method)
    total = len(_to_end(ref, None)[0])
    a = _make(method)
    _steps(a, total - 3)
    b = _make(method)
    b.restore(a.state())
    tail_a, tail_b = _to_end(a, None), _to_end(b, None)
    assert tail_a[1] == tail_b[1] == EA.R_SNAP and len(tail_a[0]) == 3 and np.array_equal(tail_a[0], tail_b[0])
    assert a.best[0, 1] < tail_a[0][0, 0]  # (the v peak was before the stop)
    peaks = [ERF.refine(r, S.PEAK_SAMPLES, S.PEAK_RESTEP) for r in (ref, a, b)]
    assert peaks[0] == peaks[1] == peaks[2]


def test_a_fresh_run_is_not_the_stopped_one():
    """(The check above can fail: without the restore the continuation differs.)"""
    a = _make("rodas4")
    _to_end(a, 37, calls=9)
    tail_a, _ = _to_end(a, 37)
    b = _make("rodas4")
    b.restore({**a.state(), "stepper_ctl": _make("rodas4").st.ctl.copy()})  # the controller's state not restored
    tail_b, _ = _to_end(b, 37)
    assert len(tail_a) != len(tail_b) or not np.array_equal(tail_a, tail_b)


def test_restore_refuses_a_state_of_another_run():
    a = _make("rodas4")
    s = a.state()
    with pytest.raises(ValueError, match="expected the arrays"):
        a.restore({k: v for k, v in s.items() if k != "sctl"})
    with pytest.raises(ValueError, match="shape"):
        a.restore({**s, "stepper_y": np.zeros(3)})
    with pytest.raises(ValueError, match="expected the arrays"):
        _make("rodas4-links").restore(s)  # (the link run's state names its link state)
