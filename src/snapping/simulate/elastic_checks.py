"""Whether an elastic run's acceleration and tension peaks are the line's or the integrator's
longitudinal ringing (issue 22), judged from the run's own per-step records.

A run can end ``completed`` with a_peak and sigma_peak that are ringing the integration put into
the line, with v_peak right and a small ``energy_drift``: chi = 0.25, N = 30, c = 3000, matched
start, undamped, RODAS4 at tol 1e-5 gives a_peak 5665 and sigma_peak 117 against 690 and 11.5 at
tol 1e-7, energy_drift 1.5e-5 (docs/guide/elastic.md, "The peak guard"). Three rules, each on the
fall before the snap (``t <= T_CUT t_snap_sigma``: the snap's own rise is fast and legitimately
rough):

* **ringing** (:func:`ringing_tension`): the largest tension's oscillation about its local level,
  over windows of two periods ``8 L / c`` of the slowest longitudinal mode (the quasi-static fall
  changes little in one); the median over the windows of half their range over their median.
  From the matched start the line's own ringing has a tension amplitude ``T''(0)/omega^2``, O(c^-2)
  (measured 0.001 at c = 3000, 0.011 at c = 300, N = 30); from a release (stretched, unstretched
  or a given initial state) the unloading wave's amplitude is at most the start's own tensions,
  0.35-0.42 measured converged, undamped. Limits: :data:`RING_MATCHED` and :data:`RING_RELEASE`.
* **slack** (:func:`slack_share`): the share of that time with a slack link, from the matched start
  whose links all start taut (the rigid chain's tensions, positive before the snap: none is slack
  in a converged run; 0.89-0.98 in the ringing runs measured). Limit :data:`SLACK_MAX`.
* **energy**: ``energy_drift`` above :data:`ENERGY_FLAG` of the line's energy scale (a tenth of the
  automatic run's failure threshold, which does not act on runs with ``t_end``).

:func:`peak_guard` returns (ringing measure, resolved, note). Not caught (measured): see the guide.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as V

#: the shortest link an ``initial`` state may have, relative to its rest length
MIN_LINK = 1e-9

__all__ = ["ringing_tension", "slack_share", "peak_guard", "initial_state", "MIN_LINK", "RING_MATCHED", "RING_RELEASE", "SLACK_MAX",
           "ENERGY_FLAG", "T_CUT", "MIN_WINDOWS"]

#: the rules look at t <= T_CUT * t_snap_sigma (the fall, before the snap's own rise)
T_CUT = 0.9
#: the ringing rule needs at least this many windows of 8 L / c before the cut (else: not judged;
#: at small c the ringing and the fall share one time scale, and the steps follow the motion)
MIN_WINDOWS = 10
#: the quantile over the windows that is the measure (0.5: the median; higher catches ringing that
#: grows late in the fall)
RING_QUANTILE = 0.5
#: steps a window needs to be counted
MIN_STEPS = 4
#: largest ringing measure from the matched start (fitted: converged runs 0.001-0.014 at N = 30, 100,
#: c = 300-3000; the ringing runs 0.38-3.7)
RING_MATCHED = 0.1
#: largest ringing measure from a release (fitted: the unloading wave's tension amplitude is at most
#: the start's tensions, relative amplitude <= 1, but undamped releases measure 0.35-0.42 converged
#: (N = 30, c = 300 tol 1e-5 to 1e-7, c = 3000 tol 1e-7; N = 100, c = 300 tol 1e-7) and 0.60 at c = 3000 tol 1e-6, whose
#: a_peak is 32% off: the margin is thin)
RING_RELEASE = 0.5
#: largest share of the fall with a slack link from the matched start (fitted: 0 in converged runs,
#: 0.85-0.999 in the ringing ones, N = 12 and 30)
SLACK_MAX = 0.1
#: energy_drift above this fraction of |E0| + |W| + U0 flags the run (ENERGY_ERROR_FAIL / 10)
ENERGY_FLAG = 0.01


def _cut(t, t_snap_sigma):
    t = np.asarray(t, dtype=float)
    tc = T_CUT * float(t_snap_sigma)
    return t, (tc if np.isfinite(tc) and tc > 0.0 else 0.0)


def ringing_tension(t, sigma_max, wave_speed: float, length: float, t_snap_sigma: float) -> float:
    """The median over windows of width ``8 length / wave_speed`` (t <= T_CUT t_snap_sigma) of the
    largest tension's half range over its median; NaN when fewer than MIN_WINDOWS windows.

    >>> t = np.linspace(0.0, 1.0, 20001)
    >>> round(ringing_tension(t, 1.0 + 0.5 * np.sin(2e4 * t), 3000.0, 1.0, 1.0), 2)
    0.5
    """
    t, tc = _cut(t, t_snap_sigma)
    s = np.asarray(sigma_max, dtype=float)
    W = 8.0 * float(length) / float(wave_speed)
    if not (W > 0.0 and np.isfinite(W)) or tc < MIN_WINDOWS * W:
        return float("nan")
    m = t <= tc
    k = np.floor(t[m] / W).astype(np.int64)
    s = s[m]
    edges = np.flatnonzero(np.diff(k)) + 1
    rel = []
    for part in np.split(s, edges):
        med = np.median(part)
        if part.size >= MIN_STEPS:
            half = 0.5 * (part.max() - part.min())
            rel.append(half / med if med > 0.0 else np.inf)
    if len(rel) < MIN_WINDOWS:
        return float("nan")
    return float(np.quantile(rel, RING_QUANTILE))


def slack_share(t, dt, n_slack, t_snap_sigma: float) -> float:
    """The share of ``[0, T_CUT t_snap_sigma]`` spent in steps that end with a slack link.

    >>> round(slack_share([0.0, 0.5, 1.0], [0.0, 0.5, 0.5], [0, 3, 0], 10.0 / 9.0), 3)
    0.5
    """
    t, tc = _cut(t, t_snap_sigma)
    if tc <= 0.0:
        return float("nan")
    m = (t <= tc) & (np.asarray(n_slack) > 0)
    return float(np.sum(np.asarray(dt, dtype=float)[m]) / tc)


def peak_guard(t, rec: dict, *, wave_speed: float, length: float, start: str, t_snap_sigma: float,
               energy_drift: float, energy_scale: float) -> tuple[float, bool, str]:
    """``(ringing measure, resolved, note)`` for a run's per-step records ``rec`` (arrays
    ``sigma_max``, ``dt``, ``n_slack``, ``sigma_min``, one a step, over times ``t``); ``start`` the
    run's start ("matched", "stretched", "unstretched", "initial"); the note names the rules broken
    ("" when resolved)."""
    ring = ringing_tension(t, rec["sigma_max"], wave_speed, length, t_snap_sigma)
    matched = start == "matched" and float(np.asarray(rec["sigma_min"])[0]) > 0.0
    notes = []
    limit = RING_MATCHED if matched else RING_RELEASE
    if np.isfinite(ring) and ring > limit:
        notes.append(f"ringing: tension oscillates {ring:.3g} of its level before the snap (limit {limit:g}; "
                     "a_peak/sigma_peak are the integrator's: tighten tol or add grid damping)")
    if matched:
        share = slack_share(t, rec["dt"], rec["n_slack"], t_snap_sigma)
        if np.isfinite(share) and share > SLACK_MAX:
            notes.append(f"slack: a link slack during {share:.3g} of the fall from the matched start (limit {SLACK_MAX:g})")
    if np.isfinite(energy_drift) and energy_drift > ENERGY_FLAG * energy_scale:
        notes.append(f"energy: drift {energy_drift:.3g} above {ENERGY_FLAG:g} of the energy scale {energy_scale:.3g}")
    return ring, not notes, "; ".join(notes)


def initial_state(line, start: str, initial):
    """:func:`snapping.simulate.elastic_solve.solve`'s state at t = 0: ``line.start(start)``, or the
    given node values ``initial = (x, y, vx, vy)`` checked (N + 1 finite values each, the held end's
    last; every link longer than ``MIN_LINK`` of its rest length: a link of zero length has no
    direction, its springs' and body's forces none)."""
    if initial is None:
        return line.start(start)
    try:
        x, y, vx, vy = (np.asarray(V.float_array(n, a), dtype=float).ravel() for n, a in
                        zip(("x", "y", "vx", "vy"), initial))
    except (TypeError, ValueError) as exc:
        if isinstance(exc, V.SnappingInputError):
            raise
        raise V.SnappingInputError("initial must be (x, y, vx, vy), N + 1 node values each") from None
    N = line.N
    p = line.pin_state(0.0)
    for name, a, pv in zip(("x", "y", "vx", "vy"), (x, y, vx, vy), p):
        if a.size != N + 1 or not np.all(np.isfinite(a)):
            raise V.SnappingInputError(f"initial {name}: expected {N + 1} finite node values; got {a.size}")
        if a[-1] != pv:
            raise V.SnappingInputError(f"initial {name}[N]={a[-1]!r} must be the held end's, {pv!r}, at t = 0")
    ln = np.hypot(np.diff(x), np.diff(y))
    short = np.flatnonzero(~(ln > MIN_LINK * line.h))
    if short.size:
        j = int(short[0])
        raise V.SnappingInputError(f"initial x, y: link {j} has length {ln[j]:.6g}; every link must be longer than "
                                   f"{MIN_LINK:g} of its rest length ({line.h[j]:.6g}): nodes {j} and {j + 1} coincide")
    return line.pack(x, y, vx, vy)
