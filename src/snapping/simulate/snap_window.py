"""The snap's own peaks of an extensible line's run (issue 24): acceleration and tension taken
over the snap, not over the whole run.

An elastic run (:func:`snapping.simulate.elastic.solve`) stops when v_max has fallen to
``stop_fraction`` (1/2) of its peak. Between the snap and that stop the line goes on: the fold
runs out, links go slack and the line recoils, and in soft lines (c a few to a few hundred
sqrt(g L)) the largest acceleration or tension of the run can come from that phase, at the
run's last steps (chi 0.3, c 442.7, fold level 1: v_max peaks at step 253 of 4702, a_max and
sigma_max at step 4685, ``benchmarks/stretch_peak_phase.py``). Such maxima depend on where the
run is stopped and are not the snap's.

**The snap** is the tip's whip: from the start until the speed has fallen back to
``SNAP_FRACTION`` (0.9) of its peak after the peak, i.e. while the fastest node moves within
10% of its peak speed. Why this window (measured, docs/guide/regimes.md "The snap's peaks"):

* the ideal (inextensible) chain's acceleration peak comes at or just before its speed peak
  and its tension peak just after it (chi 0.1/0.3/0.5 at the coarse study level: +1e-5,
  +1.2e-4, +7.9e-4 in t sqrt(g/L)), while its speed is still above 0.99 of the peak: a
  window that ended at the speed peak would cut the ideal's tension peak; one that ends at
  0.9 holds all three, so in the stiff limit the snap's peaks are the run's;
* the slack/recoil phase starts later: the first slack link of chi 0.3 c 442.7 (level -1)
  comes 5.8e-3 after the speed peak, when v_max is below 0.8 of its peak; the window ends
  at +1.2e-3.

In soft lines the tension keeps rising through the window (the line is still being pulled
straight when the tip has slowed by 10%), so ``sigma_peak_snap`` is then the largest tension
while the tip is within 10% of its peak speed: a value at the window's end, not a turning
point (documented, with its level convergence, in the guide).

**The taut snap** (branch stretch1pct, for the tension): the snap's window extended until the line
first goes slack after the speed peak (the first recorded step at or after it with a slack link; the
run's end if none), never shorter than the 0.9 window (:func:`taut_end`, ``sigma_peak_taut``,
``t_taut_end``). Why (measured, ``benchmarks/stretch_taut.py``, docs/guide/regimes.md "The taut
snap's tension"): in soft lines the tension peak is a turning point after the 0.9 window but before
any link goes slack, so the 0.9 window cut it at its edge (a value that moved with the level):
chi 0.1, c 7.53, fold level -1: 25.69 at the window's end, 27.75 at the turning point (v_max there
0.64 of its peak, no slack link in the whole run); chi 0.3, c 442.7: 18.93 at the window's end, the
tension wave's arrival at the held end 21.77 at +2.29e-3 = 1.01 L/c after the speed peak, the first
slack link at +5.87e-3 and the recoil's 24.4 after it (excluded).

**The snap without the release** (branch snapbend, the bending study): a line with bending stiffness
released from rest in its folded shape rings at the grid scale at once: the first step's acceleration is
the largest of the run, and it doubles with each fold level (chi 0.5, beta 0.01, fold levels -1 ... 2:
a_peak 96, 197, 395, 789 at t = 0, against the snap's 10.2 at t 0.97 while v_max rises to its 1.81 at
t 1.10), a mesh artefact of the start, not the snap. :func:`release_window` keeps the whip: the steps
while v_max is at least ``RELEASE_FRACTION`` (1/2) of its peak around the peak, from the last step
before the peak below it to the first after (the run's last step: the inextensible run stops there,
``stop_fraction`` 1/2). Why (measured, docs/guide/regimes.md "Bending"):

* the start: the release's spike dies out long before the tip is fast (chi 0.5, beta 0.01, level -1:
  a_max 96 at t = 0, 4.4 at t 3.5e-3 where v_max is 1.6% of its peak, the fall's ~2 from t 0.03, v_max
  5%), while the snap's acceleration and tension peaks come with the speed's (the ideal's within 1e-3 of
  the speed peak, v_max there above 0.99 of its peak);
* the end is the run's, not the elastic snap's 0.9: a stiff rod's peaks come after the speed's, while
  the tip slows (chi 0.1, beta 0.01, level -1: v_max peaks at t 0.866, the acceleration at t 1.056
  (17.70) and the tension at 1.060 (10.66), v_max there 0.80 and 0.79 of its peak: a 0.9 window cut both
  at its edge, 12.17 and 3.28). An inextensible line has no slack/recoil phase to exclude.

:func:`run_snap_peaks` applies it to a run Dataset (its ``t``, ``v_max``, ``a_max``, ``sigma_max`` and
the run's refined peaks). The curvature is not windowed: a bent line's largest curvature is its
start's (the rest shape's fold, a continuum quantity: bending bounds it) or the fall's, and over the
window its maximum would be the window's first value, not a turning point (chi 0.5, beta 0.01: 5.58 at
t ~ 0.2 against 4.74 at the window's start).

The snap's peaks are computed from the run's per-step records: where the run's refined peak
(``a_peak``, ``sigma_peak``) falls inside the window it is taken as is (so the snap's peaks
equal the run's whenever the run's peaks belong to the snap, bit for bit); otherwise the
largest recorded step value inside the window (step ends, not refined).

**The window's exact end** (branch window): an elastic run ends the 0.9 window where v_max falls to
0.9 of its (refined) peak, located on the integrator's states (:mod:`snapping.simulate.snap_edge`,
``t_snap_edge``), and ``snap_peaks(..., edge=)`` takes the records before that step and the value at
the edge, not the recorded step past it: where the tension still rises at the window's end, that
step overshot the edge by up to a step's rise (chi 0.3, c 442.7, fold level -1: 19.08 against 18.86),
a jitter between levels that kept two study cells over 1%. ``t_snap_end`` stays the recorded step.
The release window's start and the taut window's end (a slack link) stay recorded steps: the
former is not where any peak lies, the latter is taken at its end only where it is the 0.9 window's.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SNAP_FRACTION", "RELEASE_FRACTION", "snap_end", "snap_peaks", "taut_end", "taut_peaks", "release_start",
           "release_window", "run_snap_peaks"]

#: the snap lasts, after the speed peak, until v_max has fallen below this fraction of its peak
SNAP_FRACTION = 0.9
#: the snap without the release (:func:`release_window`) runs while v_max is at least this fraction of its
#: peak around the peak: from the last step before the peak below it to the first after
RELEASE_FRACTION = 0.5


def snap_end(t, v, t_peak, fraction: float = SNAP_FRACTION) -> int:
    """Index of the last recorded step of the snap: the first step after the speed peak (the
    first recorded time >= ``t_peak``) whose speed ``v`` is below ``fraction`` times the peak
    (the largest of ``v``); the last step if the speed never falls that far (the run's end)."""
    t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
    if t.size == 0:
        raise ValueError("no recorded steps")
    if not np.isfinite(t_peak):
        return t.size - 1
    ip = int(np.searchsorted(t, t_peak, side="left"))
    if ip >= t.size:
        return t.size - 1
    vp = max(float(np.max(v)), 0.0)
    below = np.flatnonzero(v[ip:] < fraction * vp)
    return t.size - 1 if below.size == 0 else ip + int(below[0])


def snap_peaks(t, v, cols: dict, run_peaks: dict, t_peak, fraction: float = SNAP_FRACTION, edge=None) -> dict:
    """The snap's peaks of the per-step records ``cols`` ({name: values per step}) given the
    run's refined peaks ``run_peaks`` ({name: (value, time)}) and the speed's peak time
    ``t_peak``: ``{name: value}`` plus ``"t_snap_end"`` (the window's last recorded time). A run peak
    whose time lies in the window is returned as is; else the window's largest record.

    ``edge``: the window's exact end (branch window, :func:`snapping.simulate.snap_edge.window_edge`):
    ``(t_edge, k, values)`` with ``values`` {name: the quantity at t_edge}; the window is then the
    records before step ``k`` and the edge itself (a run peak counts where its time is <= t_edge), and
    ``"t_snap_edge"`` is returned too (NaN without an edge)."""
    t = np.asarray(t, dtype=float)
    je = snap_end(t, v, t_peak, fraction)
    if edge is None:
        return {"t_snap_end": float(t[je]), "t_snap_edge": float("nan"), **_window_peaks(t, je, cols, run_peaks)}
    t_edge, k, vals = edge
    out = {"t_snap_end": float(t[je]), "t_snap_edge": float(t_edge)}
    for name, col in cols.items():
        val, tp = run_peaks[name]
        if np.isfinite(tp) and tp <= t_edge:
            out[name] = float(val)
        else:
            out[name] = max(float(np.max(np.asarray(col, dtype=float)[:k])), float(vals[name]))
    return out


def _window_peaks(t, je: int, cols: dict, run_peaks: dict, js: int = 0) -> dict:
    """The peaks over the recorded steps ``js ... je``: a run peak whose time is in it as is, else the
    largest record."""
    t_start, t_end = float(t[js]), float(t[je])
    out = {}
    for name, col in cols.items():
        val, tp = run_peaks[name]
        if np.isfinite(tp) and tp <= t_end and (js == 0 or tp >= t_start):
            out[name] = float(val)
        else:
            out[name] = float(np.max(np.asarray(col, dtype=float)[js:je + 1]))
    return out


def taut_end(t, v, n_slack, t_peak, fraction: float = SNAP_FRACTION) -> int:
    """Index of the last recorded step of the taut snap: the first step at or after the speed peak
    (the first recorded time >= ``t_peak``) with a slack link (``n_slack`` > 0), the run's last step if
    none, and never before :func:`snap_end` (the 0.9 window)."""
    t, ns = np.asarray(t, dtype=float), np.asarray(n_slack)
    je = snap_end(t, v, t_peak, fraction)
    if ns.shape != t.shape:
        raise ValueError("n_slack and t differ in length")
    if not np.isfinite(t_peak):
        return je
    ip = int(np.searchsorted(t, t_peak, side="left"))
    slack = np.flatnonzero(ns[ip:] > 0)
    jf = t.size - 1 if slack.size == 0 else ip + int(slack[0])
    return max(je, jf)


def taut_peaks(t, v, n_slack, cols: dict, run_peaks: dict, t_peak, fraction: float = SNAP_FRACTION) -> dict:
    """As :func:`snap_peaks`, over the taut snap (:func:`taut_end`): ``{name: value}`` plus
    ``"t_taut_end"``."""
    t = np.asarray(t, dtype=float)
    je = taut_end(t, v, n_slack, t_peak, fraction)
    return {"t_taut_end": float(t[je]), **_window_peaks(t, je, cols, run_peaks)}


def release_start(t, v, t_peak, fraction: float = RELEASE_FRACTION) -> int:
    """Index of the first recorded step of the snap without the release: the last step before the speed
    peak (before the first recorded time >= ``t_peak``) whose speed ``v`` is below ``fraction`` times the
    peak (the largest of ``v``, NaN ignored; searched no later than the recorded peak); 0 if none (or no
    peak time).

    >>> release_start([0, 1, 2, 3, 4, 5], [0.0, float("nan"), 0.4, 1.0, 0.6, 0.4], 3.0)
    2
    >>> release_start([0, 1, 2, 3], [0.0, 0.2, 1.0, 0.3], 9.0)   # (t_peak past the records)
    1
    """
    t, v = np.asarray(t, dtype=float), np.asarray(v, dtype=float)
    if t.size == 0:
        raise ValueError("no recorded steps")
    if not np.isfinite(t_peak):
        return 0
    if not np.any(np.isfinite(v)):
        return 0
    k = int(np.nanargmax(v))  # (the recorded peak: a t_peak past it, or past the records, does not move the start)
    ip = min(int(np.searchsorted(t, t_peak, side="left")), k + 1)
    below = np.flatnonzero(v[:ip] < fraction * max(float(v[k]), 0.0))
    return 0 if below.size == 0 else int(below[-1])


def release_window(t, v, cols: dict, run_peaks: dict, t_peak, fraction: float = RELEASE_FRACTION) -> dict:
    """As :func:`snap_peaks`, over the snap without the release: while v_max is at least ``fraction`` of
    its peak around the peak (:func:`release_start` ... :func:`snap_end` at ``fraction``; the run's end
    for a run stopped at half its peak speed): ``{name: value}`` plus ``"t_snap_start"`` and
    ``"t_snap_end"``. A run peak whose time lies in the window (both ends included) is returned as is;
    else the window's largest record."""
    t = np.asarray(t, dtype=float)
    js, je = release_start(t, v, t_peak, fraction), snap_end(t, v, t_peak, fraction)
    if je < js:  # (cannot happen: the start is before the speed peak, the end at or after it)
        raise ValueError("the window ends before it starts")
    return {"t_snap_start": float(t[js]), "t_snap_end": float(t[je]), **_window_peaks(t, je, cols, run_peaks, js)}


def run_snap_peaks(ds) -> dict:
    """The snap's ``a_peak`` and ``sigma_peak`` of a run Dataset (:func:`snapping.simulate.run`) without the
    release (:func:`release_window`), from its per-step ``t``, ``v_max``, ``a_max``, ``sigma_max`` and its
    refined peaks (``a_peak`` at ``t_snap_a``, ``sigma_peak`` at ``t_snap_sigma``, the speed's at
    ``t_snap_v``); plus ``t_snap_start``, ``t_snap_end``."""
    a = ds.attrs
    cols = {q: ds[f"{q}_max"].values for q in ("a", "sigma")}
    run_peaks = {q: (float(a[f"{q}_peak"]), float(a[f"t_snap_{q}"])) for q in ("a", "sigma")}
    w = release_window(ds["t"].values, ds["v_max"].values, cols, run_peaks, float(a["t_snap_v"]))
    return {"a_peak": w["a"], "sigma_peak": w["sigma"], "t_snap_start": w["t_snap_start"],
            "t_snap_end": w["t_snap_end"]}
