"""The snap's peaks of an elastic run (issue 24, branch snappeaks): :mod:`snapping.simulate.snap_window`.

* the window on synthetic records with a closed-form speed bump v = exp(-(t - 1)^2 / (2 s^2)):
  it ends at the first step with |t - 1| > s sqrt(2 ln(1/0.9)) after the peak, so a spike
  planted after that (the slack fold / recoil) is excluded and one planted inside it (before the
  speed peak, or after it while v > 0.9) is included;
* a run peak inside the window is returned as is (the refined value), one outside is replaced
  by the window's largest record;
* stiff limit: an elastic line of c = 10^4 sqrt(gL) on fold level -4 has snap peaks equal to the
  inextensible chain's (fast method) peaks on the same links to 1e-4 (the run's own peaks too);
  the ideal chain's own peaks lie inside its snap window (fold level -2 at chi 0.1, -4 at 0.3, 0.5);
* the schema's new names are in the run's attributes, and the stretching study keeps the snap's peaks;
* the taut snap (branch stretch1pct): on the same bump with a slack-link count planted by hand, its
  window ends at the first slack step at or after the speed peak (the run's end if none; never before
  the 0.9 window; slack before the peak ignored), so a tension turning point after the 0.9 window and
  before the slack is kept and a recoil spike after the slack excluded; on real runs, a soft line
  whose tension peaks before any slack link has ``sigma_peak_taut`` = the run's ``sigma_peak`` (> the
  0.9 window's) and a stiff one (c = 10^4) the inextensible chain's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping import regimes as R
from snapping import regimes_spec as S
from snapping import schema
from snapping.continuum import level_parameters
from snapping.simulate import run
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.snap_window import SNAP_FRACTION, snap_end, snap_peaks, taut_end, taut_peaks

S_W = 0.01  # the bump's width
T = np.linspace(0.9, 1.1, 2001)  # step 1e-4
V = np.exp(-((T - 1.0) ** 2) / (2 * S_W**2))
HALF = S_W * math.sqrt(2 * math.log(1 / 0.9))  # v = 0.9 at 1 +- HALF (closed form)
I_END = int(np.flatnonzero(T > 1.0 + HALF)[0])  # first step past it, by hand


def _a():
    return 100.0 * V**2  # an acceleration peaking with the speed


def test_window_ends_where_the_speed_falls_below_nine_tenths():
    assert SNAP_FRACTION == 0.9
    assert snap_end(T, V, 1.0) == I_END
    assert T[I_END] == pytest.approx(1.0 + HALF, abs=1.1e-4)
    # the speed never falls that far: the whole run
    assert snap_end(T[:1000], V[:1000], 0.999) == 999 and snap_end(T, V, float("nan")) == T.size - 1


def test_post_snap_spike_is_excluded():
    a = _a()
    j = I_END + 200  # in the recoil, v ~ 0.1
    a[j] = 1e4
    out = snap_peaks(T, V, {"a": a}, {"a": (1e4 * 1.01, T[j])}, 1.0)  # the run's refined peak: the spike
    assert out["a"] == pytest.approx(100.0, rel=1e-12)  # the bump's own maximum (v = 1 at t = 1 exactly)
    assert out["t_snap_end"] == T[I_END]
    a[I_END + 1] = 1e4  # one step past the window: still out
    assert snap_peaks(T, V, {"a": a}, {"a": (1e4, T[j])}, 1.0)["a"] == pytest.approx(100.0, rel=1e-12)


@pytest.mark.parametrize("where", ["before", "after", "last"])
def test_spike_inside_the_snap_is_included(where):
    a = _a()
    # before the speed peak / after it with v >= 0.9 / the window's last step (the first below 0.9)
    j = {"before": 900, "after": I_END - 1, "last": I_END}[where]
    assert V[j] >= 0.9 or T[j] < 1.0 or j == I_END
    a[j] = 5e3
    a[I_END + 300] = 1e4  # and a bigger one after the snap, which is the run's peak
    out = snap_peaks(T, V, {"a": a}, {"a": (1e4, T[I_END + 300])}, 1.0)
    assert out["a"] == 5e3


def test_run_peak_inside_the_window_is_kept_as_refined():
    a = _a()
    out = snap_peaks(T, V, {"a": a, "sigma": a / 10}, {"a": (123.456, 1.0001), "sigma": (12.5, T[I_END])}, 1.0)
    assert out["a"] == 123.456 and out["sigma"] == 12.5  # (not the records' 100 and 10)


LEVEL = level_parameters(8, 0.5, first=-4)[0]  # fold level -4 (the coarsest): 60-75 links


@pytest.mark.parametrize("chi", [0.3, 0.5])
def test_stiff_line_snap_peaks_are_the_inextensible_chains(chi):
    c = 1.0e4
    p = R.cell_problem(chi, "stretching", 1.0 / c, LEVEL, method="rodas4-links")
    ideal = run(p, method="fast", tol=1e-8, progress=False).dataset.attrs  # the same links, inextensible
    a = solve(p, Elastic.from_wave_speed(c, grid_damping=S.STRETCH_DAMPING), tol=S.stretch_tol(1e-6, c),
              method="rodas4-links", stop_floor=S.STRETCH_STOP_FLOOR, start="matched").dataset.attrs
    assert a["status"] == "completed" and a["snap_reached"] == 1
    for q in ("a_peak", "sigma_peak"):
        assert a[f"{q}_snap"] == pytest.approx(ideal[q], rel=3e-4)
        assert a[f"{q}_snap"] == a[q]  # stiff: the run's peaks are the snap's
    assert a["sigma_peak_taut"] == a["sigma_peak"] and a["t_taut_end"] >= a["t_snap_end"]
    assert a["t_snap_v"] < a["t_snap_end"] < a["t_final"]


@pytest.mark.parametrize("chi,k", [(0.1, -2), (0.3, -4), (0.5, -4)])
def test_ideal_chains_peaks_lie_in_its_snap(chi, k):
    # (the tension peak follows the speed peak, by less as the fold is resolved: at chi 0.1 the
    # speed there is 0.65 / 0.81 / 0.97 / 0.991 of its peak at fold levels -4 / -3 / -2 / -1, so
    # the coarsest chi 0.1 levels are left out; the study's levels start at -1)
    level = level_parameters(8, 0.5, first=-4)[k + 4]
    ds = run(R.cell_problem(chi, None, 0.0, level), method="fast", tol=1e-6, progress=False).dataset
    a = ds.attrs
    out = snap_peaks(ds.t.values, ds.v_max.values, {"a": ds.a_max.values, "sigma": ds.sigma_max.values},
                     {"a": (a["a_peak"], a["t_snap_a"]), "sigma": (a["sigma_peak"], a["t_snap_sigma"])}, a["t_snap_v"])
    assert out["a"] == a["a_peak"] and out["sigma"] == a["sigma_peak"]
    assert out["t_snap_end"] < ds.t.values[-1]  # and the window is shorter than the run


def test_schema_names_and_the_study_keeps_the_snap(monkeypatch):
    for k in ("a_peak_snap", "sigma_peak_snap", "t_snap_end", "sigma_peak_taut", "t_taut_end"):
        assert k in schema.ELASTIC_RESULT_ATTRS
    for k in ("a_peak", "sigma_peak", "v_peak"):  # unchanged, still there
        assert k in schema.RESULT_ATTRS
    import types

    import snapping.simulate.elastic as E

    attrs = {"status": "completed", "v_peak": 2.0, "a_peak": 50.0, "sigma_peak": 9.0, "kappa_peak": float("nan"),
             "t_snap_v": 1.1, "a_peak_snap": 30.0, "sigma_peak_snap": 4.0, "sigma_peak_taut": 6.0, "n_rhs": 7}
    monkeypatch.setattr(E, "solve", lambda *a, **k: types.SimpleNamespace(dataset=types.SimpleNamespace(attrs=attrs)))
    row = R._run_task(0.5, "stretching", 0.01, {"n_links": 4, "frac": 0.25}, 1e-6)
    # the acceleration and tension over the snap; the taut snap's tension beside (regimes_spec.STRETCH_EXTRA_PEAKS)
    assert (row["v_peak"], row["a_peak"], row["sigma_peak"], row["sigma_peak_taut"]) == (2.0, 30.0, 4.0, 6.0)
    ideal = R._run_task(0.5, None, 0.0, {"n_links": 4, "frac": 0.25}, 1e-6)
    assert "sigma_peak_taut" not in ideal  # (a study of another mechanism: no taut column)
    key = R._study_key("stretching", [0.5], [0.1], {"peaks": "snap"}, 0.5)
    monkeypatch.setattr(R, "_run_task", lambda *a, **k: {**{q: 1.0 for q in R.QUANTITIES}, "n_links": 1, "n_rhs": 1,
                                                         "cpu_time": 0.0})
    ds = R.regimes("stretching", [0.5], [0.1], levels=2, first=-4, progress=False)
    assert '"peaks": "snap"' in ds.attrs["regimes_study"] and key != R._study_key("stretching", [0.5], [0.1], {}, 0.5)
    dr = R.regimes("drag", [0.5], [0.1], levels=2, first=-4, progress=False)
    assert "peaks" not in dr.attrs["regimes_study"]


# --- the taut snap (branch stretch1pct) ---

J_SLACK = I_END + 250  # the first slack step after the peak, planted (v there ~ 0.01)


def _sigma():
    """A tension rising through the 0.9 window (0.39 of its peak at its end) to a turning point at
    t = 1 + 4 HALF (v ~ 0.18 there), between the window's end and the planted slack."""
    return 10.0 * np.exp(-((T - 1.0 - 4 * HALF) ** 2) / (2 * S_W**2))


def _slack():
    ns = np.zeros(T.size, dtype=int)
    ns[J_SLACK:] = 3
    return ns


def test_taut_window_ends_at_the_first_slack_after_the_peak():
    j_turn = int(np.argmax(_sigma()))
    assert I_END < j_turn < J_SLACK  # (the setting: the turning point is after the 0.9 window, before the slack)
    ns = _slack()
    assert taut_end(T, V, ns, 1.0) == J_SLACK
    assert taut_end(T, V, np.zeros(T.size, dtype=int), 1.0) == T.size - 1  # no slack: the whole run
    ns[300] = 5  # a slack link before the speed peak (t = 0.93): ignored
    assert taut_end(T, V, ns, 1.0) == J_SLACK
    early = np.zeros(T.size, dtype=int)
    early[I_END - 20:] = 1  # slack before the 0.9 window ends: that window's end
    assert taut_end(T, V, early, 1.0) == I_END
    assert taut_end(T, V, ns, float("nan")) == snap_end(T, V, float("nan"))
    with pytest.raises(ValueError):
        taut_end(T, V, ns[:-1], 1.0)


def test_taut_peak_keeps_the_turning_point_and_drops_the_recoil():
    sig = _sigma()
    j_turn = int(np.argmax(sig))
    sig[J_SLACK + 1] = 50.0  # the recoil after the slack: the run's peak
    out = taut_peaks(T, V, _slack(), {"sigma": sig}, {"sigma": (50.5, T[J_SLACK + 1])}, 1.0)
    assert out["sigma"] == pytest.approx(10.0, rel=1e-5) and out["t_taut_end"] == T[J_SLACK]
    assert T[j_turn] == pytest.approx(1.0 + 4 * HALF, abs=1e-4)
    # the 0.9 window cuts the same tension at its edge (the value at its last step, rising)
    snap = snap_peaks(T, V, {"sigma": sig}, {"sigma": (50.5, T[J_SLACK + 1])}, 1.0)["sigma"]
    assert snap == pytest.approx(sig[I_END], rel=1e-12) and snap < 0.5 * out["sigma"]
    sig[J_SLACK] = 20.0  # on the window's last step (the first slack step): included
    assert taut_peaks(T, V, _slack(), {"sigma": sig}, {"sigma": (50.5, T[J_SLACK + 1])}, 1.0)["sigma"] == 20.0
    # a refined run peak inside the window is returned as is
    assert taut_peaks(T, V, _slack(), {"sigma": sig}, {"sigma": (10.01, T[j_turn])}, 1.0)["sigma"] == 10.01


def test_soft_line_tension_peak_before_the_slack_is_the_taut_snaps():
    """chi 0.5, c = 38.4, fold level -4: the tension peaks (at the held end, the snap's wave) after
    the 0.9 window and before any link goes slack (measured at level -1: +2.5e-2 after the speed
    peak, the first slack at +6.6e-2): the taut snap's tension is the run's, 12% above the 0.9
    window's; the window's end is the first recorded slack step (at or after t_first_slack)."""
    c = 38.41511522329253
    p = R.cell_problem(0.5, "stretching", 1.0 / c, LEVEL, method="rodas4-links")
    ds = solve(p, Elastic.from_wave_speed(c, grid_damping=S.STRETCH_DAMPING), tol=S.stretch_tol(1e-6, c),
               method="rodas4-links", stop_floor=S.STRETCH_STOP_FLOOR, start="matched").dataset
    a = ds.attrs
    assert a["status"] == "completed"
    assert a["t_snap_v"] < a["t_snap_end"] < a["t_snap_sigma"] <= a["t_taut_end"]
    assert a["sigma_peak_taut"] == a["sigma_peak"] and a["sigma_peak_snap"] < 0.9 * a["sigma_peak"]  # (5.016, 5.707)
    t, ns = ds.t.values, ds.n_slack.values
    after = np.flatnonzero((t >= a["t_snap_v"]) & (ns > 0))
    assert a["t_taut_end"] == (t[after[0]] if after.size else t[-1])
    if after.size:
        assert a["t_taut_end"] >= a["t_first_slack"]
