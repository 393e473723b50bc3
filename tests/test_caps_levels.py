"""Escalated graded levels of design answers (snapping.caps_runs.graded_levels, observed_order,
grading_for; snapping.caps._answer; issue 24). The levels are synthetic -- f = f* + c h^p with h
halving, whose order, extrapolation and error estimate are known in closed form -- run by a cheap
fake runner; the grading rule's full run on 2N links is checked on fake runs of given curvature
peaks and once on the fly line itself (100 and 200 uniform links). Small: ~3 s."""

from __future__ import annotations

import math

import pytest

from snapping import caps, caps_runs

Q = ("v_peak", "a_peak", "sigma_peak")


def _levels(c: dict, p: float = 2.0, exact: dict | None = None, h0: float = 1.0):
    """A fake runner: level k's peak q is exact[q] + c[q] (h0 / 2^k)^p; it records the levels run."""
    exact = exact or {q: 1.0 for q in c}
    calls = []

    def run_level(k):
        calls.append(k)
        return {q: exact[q] + c[q] * (h0 * 0.5 ** k) ** p for q in c}
    return run_level, calls


@pytest.mark.parametrize("p, ratio", [(1.0, 2.0), (1.5, 2.0), (2.0, 2.0), (3.0, 2.0), (2.0, 3.0)])
def test_observed_order_of_a_known_law(p, ratio):
    f = [5.0 - 0.7 * (0.3 / ratio ** k) ** p for k in range(3)]
    assert caps_runs.observed_order(*f, ratio=ratio) == pytest.approx(p, rel=1e-9)


def test_observed_order_is_nan_out_of_the_asymptotic_range():
    assert math.isnan(caps_runs.observed_order(1.0, 1.2, 1.1))  # the differences change sign
    assert math.isnan(caps_runs.observed_order(1.0, 1.0, 1.1))  # one vanishes
    assert caps_runs.observed_order(1.0, 1.1, 1.3) == pytest.approx(-1.0)  # diverging: a negative order


def test_escalation_stops_within_one_percent():
    # c h0^2 = 0.5 at order 2: the correction of levels (k-1, k) is (f_k - f_{k-1})/3 = c h0^2 4^-k exactly,
    # over f* = 1: 12.5%, 3.1%, 0.78% -> the pair (2, 3), four levels run
    run_level, calls = _levels({"v_peak": 0.01, "a_peak": -0.5, "sigma_peak": 0.02})
    g = caps_runs.graded_levels(run_level, lambda k: 100 * 2 ** k, within=0.01, quantities=Q)
    assert calls == [0, 1, 2, 3] and g["pair"] == (2, 3) and g["stopped"] == "within"
    assert g["relative_error"]["a_peak"] == pytest.approx(0.5 / 64, rel=1e-9)
    assert g["relative_error"]["v_peak"] == pytest.approx(0.01 / 64, rel=1e-9)
    for q in Q:  # order 2 exactly: the extrapolation is the exact value
        assert g["extrapolated"][q] == pytest.approx(1.0, abs=1e-12)
        assert g["observed_order"][q] == pytest.approx(2.0, rel=1e-9)


def test_escalation_needs_every_peak_within():
    # only the speed is slow (c = 0.06: 1.5% on levels 0-1, 0.375% on 1-2): one more level for it alone
    run_level, calls = _levels({"v_peak": 0.06, "a_peak": 1e-4, "sigma_peak": 1e-4})
    g = caps_runs.graded_levels(run_level, lambda k: 100 * 2 ** k, within=0.01, quantities=Q)
    assert calls == [0, 1, 2] and g["pair"] == (1, 2) and g["stopped"] == "within"
    # every peak within on the first two: no escalation, no observed order
    run_level, calls = _levels({q: 1e-3 for q in Q})
    g = caps_runs.graded_levels(run_level, lambda k: 100 * 2 ** k, within=0.01, quantities=Q)
    assert calls == [0, 1] and g["pair"] == (0, 1) and g["observed_order"] is None and g["stopped"] == "within"


def test_escalation_stops_at_the_links_cap():
    # a slow first-order peak (never within at order 2 before the cap); links 545, 1090, 2180, 4360: level 3
    # would pass 2500, so levels 0-2 are run and the last two extrapolated, with the reason
    run_level, calls = _levels({"v_peak": 0.0, "a_peak": 0.0, "sigma_peak": 0.8}, p=1.0)
    g = caps_runs.graded_levels(run_level, lambda k: 545 * 2 ** k, within=0.01, max_links=2500, quantities=Q)
    assert calls == [0, 1, 2] and g["pair"] == (1, 2) and g["stopped"] == "max_links"
    # order-2 correction of 1 + 0.8 h (h = 1/2, 1/4): (0.2 - 0.4)/3, over 1.2 - 0.2/3
    e = (0.4 - 0.2) / 3.0
    assert g["error"]["sigma_peak"] == pytest.approx(e, rel=1e-9)
    assert g["relative_error"]["sigma_peak"] == pytest.approx(e / (1.2 - e), rel=1e-9)
    assert g["observed_order"]["sigma_peak"] == pytest.approx(1.0, rel=1e-9)
    assert "level 3 would need 4360 links (> 2500)" in g["why"]


class _FakeRuns:
    """The runs of an answer, faked: uniform runs give kappa_peak from ``kappa`` ({(on, N): value}),
    peaks 1; graded levels from ``run_level``."""

    def __init__(self, sp, chi, kappa=None, run_level=None):
        self.sp, self.chi, self.tol, self.damping, self.log = sp, chi, 1e-6, 1.0, []
        self.kappa, self.run_level = kappa or {}, run_level

    ideal_on = caps_runs.Runs.ideal_on  # (the ideal on graded links: this get's, 1 on every level)
    limit = False

    def get(self, on, N, h=None, where=""):
        self.log.append((tuple(on), N) + ((where,) if where else ()))
        return {"v_peak": 1.0, "a_peak": 1.0, "sigma_peak": 1.0, "method": "dop853",
                "kappa_peak": self.kappa.get((tuple(on), N), 0.0)}

    def graded(self, on, k):
        self.log.append((tuple(on), f"graded {k}"))
        return {**self.run_level(k), "method": "rodas4", "links": caps_runs.graded_h(self.chi, self.lb, k).size}


def test_answer_escalates_and_says_why():
    sp = caps.spec("nylon-monofilament")
    run_level, calls = _levels({"v_peak": 0.01, "a_peak": 0.2, "sigma_peak": 0.02}, exact={q: 0.5 for q in Q})
    runs = _FakeRuns(sp, 0.25, run_level=run_level)
    runs.lb = caps_runs.bending_length(sp)
    r = caps._answer(runs, 100, "sigma_peak", False, False, graded=True)
    g = r["graded"]
    # relative: c 4^-k / 0.5 -> a_peak 10%, 2.5%, 0.625%: pair (2, 3); levels 545, 1072, 2127 ... but 4236 > 2500
    links = [caps_runs.graded_h(0.25, runs.lb, k).size for k in range(4)]
    assert links[:3] == [545, 1072, 2127] and links[3] > 2500
    assert calls == [0, 1, 2] and g["levels"] == links[:3] and g["pair"] == (1, 2)
    assert g["stopped"] == "max_links" and g["within"] is False
    assert g["relative_error"]["a_peak"] == pytest.approx(0.2 / 16 / 0.5, rel=1e-9)
    assert g["observed_order"]["sigma_peak"] == pytest.approx(2.0, rel=1e-9)
    # the real tension: the extrapolation (exact: 0.5) in newtons, M g
    assert r["real"]["sigma_peak"] == pytest.approx(0.5 * sp.mass * sp.g, rel=1e-12)
    assert r["resolution"]["sigma_peak"] == pytest.approx((0.02 / 16 - 0.02 / 4) / (0.5 + 0.02 / 16), rel=1e-9)


def test_grading_rule_runs_the_full_model_on_2N_when_the_bending_length_is_under_a_link():
    sp = caps.spec("fly-line")
    on = tuple(m for m in caps.MECHANISMS[:-1] if sp.has(m))
    bare = tuple(m for m in on if m != "bending")
    lb = caps_runs.bending_length(sp)
    assert lb * 100 < 1.0 < lb * 1000  # 0.11 links at N = 100, 1.1 at 1000
    # drag alone's fold narrows (0.45 -> 0.26 per link); the full run's does not (0.59 -> 0.76): graded
    k = {(bare, 100): 0.45 * 100, (bare, 200): 0.26 * 200, (on, 100): 0.59 * 100, (on, 200): 0.76 * 200}
    runs = _FakeRuns(sp, 0.25, k)
    g = caps_runs.grading_for(runs, 100, list(on))
    assert g["used"] and g["collapse_run"] == "with bending" and g["halved"] == pytest.approx(0.76)
    assert runs.log == [(bare, 100), (on, 100), (bare, 200), (on, 200)]  # the full run on N before bare on 2N
    # the full run's fold narrows too (0.59 -> 0.40): uniform links
    runs = _FakeRuns(sp, 0.25, {**k, (on, 200): 0.40 * 200})
    assert not caps_runs.grading_for(runs, 100, list(on))["used"]
    # the bending length over a link (N = 1000: 1.1 links): no full run on 2N, uniform links
    k = {(bare, 1000): 0.45 * 1000, (bare, 2000): 0.26 * 2000, (on, 1000): 0.59 * 1000, (on, 2000): 0.76 * 2000}
    runs = _FakeRuns(sp, 0.25, k)
    assert not caps_runs.grading_for(runs, 1000, list(on))["used"]
    assert runs.log == [(bare, 1000), (on, 1000), (bare, 2000)]


def test_fly_line_graded_at_100_links():
    # the fly line's own runs at chi 0.25: its full run's fold on 100 and 200 links does not narrow
    sp = caps.spec("fly-line")
    runs = caps_runs.Runs(sp, 0.25, 1e-6, caps_runs.STIFF_TOL, caps_runs.GRID_DAMPING)
    on = [m for m in caps.MECHANISMS[:-1] if sp.has(m)]
    g = caps_runs.grading_for(runs, 100, on)
    kf = [runs.get(tuple(on), n)["kappa_peak"] / n for n in (100, 200)]
    assert kf[0] < math.pi / 2 and kf[1] >= kf[0]
    assert g["used"] and g["collapse_run"] == "with bending"


def test_escalation_runs_a_level_up_to_4000_links():
    # levels 1 + 0.1 4^-k (order 2): the estimates (Richardson's corrections) 2.5% on levels 0-1, 0.625% on
    # 1-2; with the links
    # 491 2^k the third level (1964) is run; with 3810 links for level 2 too (the fly line's level 3 at
    # chi 0.1 is 3810), it is run; 4236 (the nylon line's level 3 at chi 0.25) is not
    def run_level(k):
        calls.append(k)
        return {q: 1.0 + 0.1 * 4.0 ** -k for q in Q}
    for links, ran in ((3810, [0, 1, 2]), (4001, [0, 1])):
        calls = []
        g = caps_runs.graded_levels(run_level, lambda k: 491 if k == 0 else (965 if k == 1 else links),
                                    within=0.01, quantities=Q)
        assert calls == ran
        assert g["stopped"] == ("within" if links <= 4000 else "max_links")
