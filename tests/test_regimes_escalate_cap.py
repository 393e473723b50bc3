"""The escalation's cost cap (branch dragesc, issue 24): ``regimes(..., escalate_max_rhs=)``.

A cell whose error bars are over the target but whose last level took more right-hand-side
evaluations than the cap is left at its levels (the drag study's heavy-drag cells: a crumpled,
compressed tail whose peaks grow with the links, 3-4 million evaluations at level 2) and marked
``escalation_capped``; every other cell escalates as without the cap. The runs are closed-form level
sequences (no integration): which cells escalate is worked out by hand below.
"""

import math

import numpy as np
import pytest

from snapping import regimes as R
from snapping import regimes_escalate as X
from snapping._validate import SnappingInputError
from snapping.continuum import QUANTITIES

HEAVY = 5000  # the evaluations of every run of the heavy cell (chi 0.1, number 0.1); the others' 10


def _values(chi, number, frac):
    """v converges at order 2 everywhere (bars << 1%); a of the cell (0.1, 0.1) alternates about 100
    (+-0.5 frac: no order, its bar the spread, ~2%: over 1%, escalates when allowed); sigma of the
    cell (0.5, 0.1) converges at order 1/2 from far (5 (1 - 3 f^0.5): bar over 1%, escalates)."""
    v = 10.0 - 5.0 * frac**2
    k = round(math.log2(frac / 0.32))
    a = 100.0 * (1 + 0.5 * frac * (-1) ** k) if (chi, number) == (0.1, 0.1) else 100.0 * (1 - frac**2)
    s = 5.0 * (1 - 3 * frac**0.5) if (chi, number) == (0.5, 0.1) else 5.0 * (1 - frac**2)
    return {**{q: v for q in QUANTITIES}, "a_peak": a, "sigma_peak": s}


@pytest.fixture()
def fake(monkeypatch):
    calls = []

    def task(chi, mechanism, number, level, tol, *a, **k):
        n = number if mechanism else 0.0
        calls.append((chi, n, level["frac"]))
        return {**_values(chi, n, level["frac"]), "n_links": int(1 / level["frac"]),
                "n_rhs": HEAVY if (chi, n) == (0.1, 0.1) else 10, "cpu_time": 0.0}

    monkeypatch.setattr(R, "_run_task", task)
    monkeypatch.setattr(R, "cell_problem", lambda *a, **k: None)
    return calls


def _study(**kw):
    return R.regimes("end-mass", [0.1, 0.5], [0.01, 0.1], levels=4, first=-3, progress=False, escalate=0.01,
                     extra_levels=1, **kw)


def test_the_cap_leaves_the_costly_cell_and_escalates_the_others(fake):
    ds = _study(escalate_max_rhs=1000)
    run = ds.levels_run.values  # rows chi 0.1, 0.5; columns number 0.01, 0.1
    assert run.tolist() == [[4, 4], [4, 5]]  # the heavy cell (0.1, 0.1) stays at 4 levels; (0.5, 0.1) escalates
    assert ds.escalation_capped.values.tolist() == [[0, 1], [0, 0]]
    assert ds.levels_run_ideal.values.tolist() == [4, 5]  # chi 0.1: no cell escalated, its own bars are fine
    assert len(fake) == 2 * 3 * 4 + 2  # the base levels, then (0.5, 0.1) and the ideal at chi 0.5
    assert (0.1, 0.1, 0.02) not in fake
    # the capped cell is not within the target (it is reported, not converged): its a bar is over 1%
    assert abs(float(ds.a_peak_error.sel(chi=0.1, number=0.1))) > 0.01 * float(ds.a_peak.sel(chi=0.1, number=0.1))
    assert ds.attrs["status"] == "complete"  # nothing owed: the cap's cells are not pending
    assert '"escalate_max_rhs": 1000' in ds.attrs["regimes_study"]


def test_a_cell_at_the_cap_itself_escalates(fake):
    ds = _study(escalate_max_rhs=HEAVY)  # (more than the cap: not escalated; as many: escalated)
    assert ds.levels_run.values.tolist() == [[4, 5], [4, 5]]
    assert ds.escalation_capped.values.tolist() == [[0, 0], [0, 0]]


def test_without_the_cap_every_cell_over_the_target_escalates(fake):
    ds = _study()
    assert ds.levels_run.values.tolist() == [[4, 5], [4, 5]]
    assert "escalation_capped" not in ds and "escalate_max_rhs" not in ds.attrs["regimes_study"]
    capped = _study(escalate_max_rhs=1000)
    for q in ("v_peak", "a_peak", "sigma_peak"):  # the cells the cap does not touch: the same limits
        for chi, n in ((0.1, 0.01), (0.5, 0.01), (0.5, 0.1)):
            assert float(capped[q].sel(chi=chi, number=n)) == float(ds[q].sel(chi=chi, number=n))


def test_too_costly_reads_the_last_level_done():
    assert X.too_costly([10.0, 20.0, 2000.0, np.nan], 1000)
    assert not X.too_costly([2000.0, 20.0, np.nan, np.nan], 1000)  # (the last done level decides)
    assert not X.too_costly([np.nan, np.nan], 1000) and not X.too_costly([5e9], None)


@pytest.mark.parametrize("kw", [{"escalate_max_rhs": 1000}, {"escalate": 0.01, "escalate_max_rhs": 0},
                                {"escalate": 0.01, "escalate_max_rhs": 2.5}])
def test_bad_cap_is_refused(kw):
    with pytest.raises(SnappingInputError) as e:
        R.regimes("end-mass", [0.1], [0.1], progress=False, **kw)
    assert "escalate" in str(e.value)
