"""Escalated levels of a regime study (branch stretch1pct, issue 24): :mod:`snapping.regimes_escalate`.

The runs are replaced by closed-form level sequences (no integration), so what is checked is the
study's bookkeeping: which cells run the extra level (an error bar over the target in v, a or
sigma, worked out by hand below), that the ideal at that chi runs it too (the same-links ratio),
that each limit is the hand Richardson extrapolation of the levels the cell ran, that a resumed
study runs nothing, that a study without ``escalate`` is what it was, and the input checks.
"""

import math

import numpy as np
import pytest

from snapping import regimes as R
from snapping import regimes_escalate as X
from snapping._validate import SnappingInputError
from snapping.continuum import QUANTITIES


def _values(chi, number, frac):
    """Closed-form peaks of one run at fold fraction ``frac`` (0.32 ... 0.02: fold levels -3 ... 0, + 1).
    v converges at order 2 everywhere; a of the cell (chi 0.1, number 0.1) alternates about 100
    (+-0.5 frac / 0.01 %, no order: its bar is the spread of the last three, 2.5%-ish: escalates);
    sigma of the cell (0.5, 0.1) converges at order 1 from far (3f^0.5 correction: orders drift,
    bar over 1%: escalates); the ideal at chi 0.5 has a sigma bar over 1% of its own."""
    v = 10.0 - 5.0 * frac**2
    k = round(math.log2(frac / 0.32))
    a = 100.0 * (1 + 0.5 * frac * (-1) ** k) if (chi, number) == (0.1, 0.1) else 100.0 * (1 - frac**2)
    if (chi, number) == (0.5, 0.1):
        s = 5.0 * (1 - 3 * frac**0.5)
    elif (chi, number) == (0.5, 0.0):
        s = 4.0 * (1 - 2 * frac**0.5)
    else:
        s = 5.0 * (1 - frac**2)
    return {**{q: v for q in QUANTITIES}, "a_peak": a, "sigma_peak": s}


@pytest.fixture()
def fake(monkeypatch):
    calls = []

    def task(chi, mechanism, number, level, tol, *a, **k):
        calls.append((chi, number if mechanism else 0.0, level["frac"]))
        return {**_values(chi, number if mechanism else 0.0, level["frac"]), "n_links": int(1 / level["frac"]),
                "n_rhs": 1, "cpu_time": 0.0}

    monkeypatch.setattr(R, "_run_task", task)
    monkeypatch.setattr(R, "cell_problem", lambda *a, **k: None)  # (the up-front check of the runs' problems: not run)
    return calls


def _richardson_last3(q):
    """The limit of the last three of ``q`` (fractions halving) by hand, and the bar as
    :func:`snapping.continuum.extrapolate` states it: max(|limit - the previous three's limit|,
    |correction| / 10); None where the last three do not converge monotonically."""
    def est(x):
        d1, d2 = x[1] - x[0], x[2] - x[1]
        if d1 == 0 or d2 == 0 or np.sign(d1) != np.sign(d2) or abs(d2) >= abs(d1):
            return None
        return x[2] + d2 / (abs(d1 / d2) - 1)  # 2^p = d1/d2
    e1, e0 = est(q[-3:]), est(q[-4:-1])
    if e1 is None:
        return None
    return e1, (abs(e1 - q[-1]) if e0 is None else max(abs(e1 - e0), 0.1 * abs(e1 - q[-1])))


def test_cells_over_the_target_run_one_more_level(fake):
    ds = R.regimes("end-mass", [0.1, 0.5], [0.01, 0.1], levels=4, first=-3, progress=False, escalate=0.01,
                   extra_levels=1)
    assert ds.sizes["level"] == 5 and ds.attrs["status"] == "complete"
    np.testing.assert_allclose(ds.resolution.values, [0.32, 0.16, 0.08, 0.04, 0.02])
    # by hand: (0.1, 0.1)'s a alternates (bar 2 x 0.5% spread), (0.5, 0.1)'s sigma converges at order 1/2
    # (bar >> 1%): both escalate, and so do the ideals at chi 0.1 (a cell did) and 0.5 (a cell did; its own
    # sigma bar is over 1% too); (0.1, 0.01) and (0.5, 0.01) converge at order 2 (bars 1e-4): they do not
    np.testing.assert_array_equal(ds.levels_run.values, [[4, 5], [4, 5]])
    np.testing.assert_array_equal(ds.levels_run_ideal.values, [5, 5])
    assert len(fake) == 2 * 3 * 4 + 4
    assert sorted(c for c in fake if c[2] == 0.02) == [(0.1, 0.0, 0.02), (0.1, 0.1, 0.02), (0.5, 0.0, 0.02),
                                                     (0.5, 0.1, 0.02)]
    fr = [0.32, 0.16, 0.08, 0.04, 0.02]
    # the escalated cell's sigma: the Richardson limit of its five levels (last three), by hand
    q = [_values(0.5, 0.1, f)["sigma_peak"] for f in fr]
    lim, err = _richardson_last3(q)
    assert float(ds.sigma_peak.sel(chi=0.5, number=0.1)) == pytest.approx(lim, rel=1e-12)
    assert float(ds.sigma_peak_error.sel(chi=0.5, number=0.1)) == pytest.approx(err, rel=1e-9)
    # the alternating a: no order over the last three: the finest level, its bar their spread
    q = [_values(0.1, 0.1, f)["a_peak"] for f in fr]
    assert float(ds.a_peak.sel(chi=0.1, number=0.1)) == q[-1]
    assert float(ds.a_peak_error.sel(chi=0.1, number=0.1)) == pytest.approx(np.ptp(q[-3:]), rel=1e-12)
    # a cell that stayed on four levels: its extrapolation over those four (level 4 NaN, not used)
    assert np.isnan(ds.v_peak_level.sel(chi=0.1, number=0.01).values[4])
    q = [_values(0.1, 0.01, f)["v_peak"] for f in fr[:4]]
    assert float(ds.v_peak.sel(chi=0.1, number=0.01)) == pytest.approx(_richardson_last3(q)[0], rel=1e-12)


def test_a_study_without_escalate_is_unchanged(fake):
    ds = R.regimes("end-mass", [0.1, 0.5], [0.01, 0.1], levels=4, first=-3, progress=False)
    assert ds.sizes["level"] == 4 and "levels_run" not in ds and len(fake) == 2 * 3 * 4
    assert "escalate" not in ds.attrs["regimes_study"] and "extra_levels" not in ds.attrs
    esc = R.regimes("end-mass", [0.1, 0.5], [0.01, 0.1], levels=4, first=-3, progress=False, escalate=0.01)
    assert esc.attrs["regimes_study"] != ds.attrs["regimes_study"] and esc.attrs["extra_levels"] == 1
    # the cells that did not escalate have the same limits as the unescalated study's
    assert float(esc.v_peak.sel(chi=0.1, number=0.01)) == float(ds.v_peak.sel(chi=0.1, number=0.01))


def test_resume_runs_nothing(fake, tmp_path):
    out = str(tmp_path / "s.nc")
    a = R.regimes("end-mass", [0.1], [0.1], levels=4, first=-3, progress=False, escalate=0.01, out=out)
    n = len(fake)
    assert n == 10 and int(a.levels_run.values[0, 0]) == 5  # (the cell escalates: its a alternates)
    b = R.regimes("end-mass", [0.1], [0.1], levels=4, first=-3, progress=False, escalate=0.01, out=out)
    assert len(fake) == n and b.attrs["status"] == "complete"
    np.testing.assert_array_equal(a.sigma_peak.values, b.sigma_peak.values)


def test_pending_needs_the_base_levels_and_stops_at_the_last():
    import xarray as xr

    lv = np.full((1, 1, 3), np.nan)
    lv[0, 0, :2] = [1.0, 2.0]  # two of a base of 2, the third level open; the bar |2 - 1| is 50%
    ideal = np.array([[1.0, 1.0, np.nan]])
    ds = xr.Dataset({f"{q}_level": (("chi", "number", "level"), lv) for q in X.ESCALATE_QUANTITIES}
                    | {f"{q}_ideal_level": (("chi", "level"), ideal) for q in X.ESCALATE_QUANTITIES}
                    | {"resolution": ("level", [0.4, 0.2, 0.1]), "resolution_ideal": ("level", [0.4, 0.2, 0.1])})
    assert X.pending(ds, 0.01, 2) == [(0, 0, 2), (0, None, 2)]  # the cell, and the ideal for its links
    assert X.pending(ds, 0.01, 3) == []  # its base not done yet: nothing decided
    assert X.pending(ds, 0.6, 2) == []  # within the target (and the ideal's spread 0)
    for q in X.ESCALATE_QUANTITIES:
        ds[f"{q}_level"].values[0, 0, 2] = 2.5
    assert X.pending(ds, 0.01, 2) == [(0, None, 2)]  # all levels run: no more; the ideal still owed
    assert X.prefix([np.nan, 1.0]) == 0 and X.prefix([1.0, 2.0]) == 2


@pytest.mark.parametrize("kw", [{"escalate": 0.0}, {"escalate": 1.5}, {"escalate": 0.01, "extra_levels": 0},
                                {"escalate": 0.01, "extra_levels": 5}, {"extra_levels": 1}])
def test_bad_escalation_refused(kw, fake):
    with pytest.raises(SnappingInputError) as e:
        R.regimes("end-mass", [0.5], [0.1], levels=4, first=-3, progress=False, **kw)
    assert ("escalate" if "escalate" in kw and kw.get("extra_levels", 1) in (1,) else "extra_levels") in str(e.value)
    assert fake == []


def test_a_failed_escalated_run_is_reported_not_retried(monkeypatch):
    # every run of the extra level (fraction 0.02) raises: the study must end, naming the failures
    # (the four escalated runs of the first test, each tried once), and keep the base levels' limits
    calls = []

    def task(chi, mechanism, number, level, tol, *a, **k):
        calls.append((chi, number if mechanism else 0.0, level["frac"]))
        if len(calls) > 100:  # (a BaseException: not caught as the run's failure)
            pytest.fail("the failed escalated runs are tried again and again")
        if level["frac"] == 0.02:
            raise ValueError("planted failure")
        return {**_values(chi, number if mechanism else 0.0, level["frac"]), "n_links": int(1 / level["frac"]),
                "n_rhs": 1, "cpu_time": 0.0}

    monkeypatch.setattr(R, "_run_task", task)
    monkeypatch.setattr(R, "cell_problem", lambda *a, **k: None)
    with pytest.raises(RuntimeError, match="4 run\\(s\\) of the study failed.*planted failure"):
        R.regimes("end-mass", [0.1, 0.5], [0.01, 0.1], levels=4, first=-3, progress=False, escalate=0.01,
                  extra_levels=1)
    assert len(calls) == 2 * 3 * 4 + 4 and sum(c[2] == 0.02 for c in calls) == 4
