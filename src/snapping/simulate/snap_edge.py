"""The snap window's exact end (issue 24, branch window): the time after the speed peak at which
v_max falls to ``SNAP_FRACTION`` (0.9) of the run's peak speed, located on the integrator's own
states, and the measures there.

:mod:`snapping.simulate.snap_window` ends the snap on a recorded step: the first step after the
speed peak below 0.9 of it. Where the tension still rises steeply there (soft lines: the line is
still being pulled straight while the tip slows), the largest tension of the window is its value
at the window's end, and a recorded step overshoots the exact end by whatever part of a step lies
beyond it. Measured (chi 0.3, c 442.7, fold level -1, 279 links, tol 1e-6, ``rodas4-links``): the
window's last step ends at t 1.16768538 with sigma_max 19.0827; v_max falls to 0.9 v_peak at
t 1.16763641, where sigma_max is 18.8559 (the step overshoots by 1.2%); which part of a step lies
beyond the edge changes from level to level, so the stored value jittered between levels (shipped:
18.93, 19.21, 18.62, 19.09, 18.75) and its error bar missed 1%.

:func:`window_edge` finds the edge: the recorded step ``k`` in which v_max first falls below
``fraction * v_peak`` after the recorded peak (``v_peak`` the run's refined peak speed), the state
at its start by integrating the recorded steps again from the recorded peak's state (each from its
start to its end in one call of the run's method and tolerance, as the peaks' refinement does,
``restep``), then the root of ``v_max(t) - fraction v_peak`` in ``(t[k-1], t[k])`` on the states
integrated from the step's start to ``t`` (the Illinois false position: bracketing, superlinear).
The states are the integrator's (a RODAS4 step of order 4 from the step's start), not its dense
output (of order 3, whose error along the links the tension and the acceleration multiply by up to
``2 c^2 N^2``: :class:`snapping.simulate.elastic_solve._Peaks`). The edge's measures (v, a, sigma,
kappa, ...) are those of that state.
"""

from __future__ import annotations

import numpy as np

__all__ = ["window_edge", "EDGE_XTOL", "EDGE_ULPS", "EDGE_VTOL", "EDGE_MAXITER"]

#: the edge's time is located to this fraction of its step (the measures' error from it is this
#: times their change over the step: 1e-10 of sigma's rise over the step, 3e-12 of sigma at chi 0.3,
#: c 442.7), and never to less than ``EDGE_ULPS`` spacings of the floats at the edge's time (a step
#: of 1e-4 at t ~ 1 would ask for less than one: the search would run to ``EDGE_MAXITER``)
EDGE_XTOL = 1e-10
EDGE_ULPS = 8
#: ... or until v_max is within this fraction of the threshold (1e-12: the edge's time then errs by
#: 1e-12 v / |dv/dt|, 1e-15 of the step at chi 0.3, c 442.7; the false position's last trials, once
#: the bracket's far end no longer moves, would otherwise bisect down to the time tolerance)
EDGE_VTOL = 1e-12
#: at most this many integrations to the trial times (the Illinois method takes 5-10)
EDGE_MAXITER = 60


def _illinois(g, a: float, b: float, ga: float, gb: float, xtol: float, ftol: float, maxiter: int):
    """A root of ``g`` in ``[a, b]`` with ``ga = g(a) >= 0 > gb = g(b)`` (the Illinois false position):
    (t, its trial's payload) with ``|g(t)| <= ftol``, else the bracket's left end once ``|b - a| <= xtol``
    (``g >= 0`` there); ``g`` returns (value, payload) or None (the integration failed: then None)."""
    pa = None
    side = 0
    for _ in range(maxiter):
        if b - a <= xtol:
            break
        x = b - gb * (b - a) / (gb - ga)
        if not (a < x < b):
            x = 0.5 * (a + b)
        got = g(x)
        if got is None:
            return None
        gx, px = got
        if abs(gx) <= ftol:
            return x, px
        if gx > 0.0:
            a, ga, pa = x, gx, px
            if side == 1:
                gb *= 0.5
            side = 1
        else:
            b, gb = x, gx
            if side == -1:
                ga *= 0.5
            side = -1
    return a, pa


def window_edge(t, v, peak_state, v_peak: float, restep, measure, fraction: float):
    """The snap window's exact end, or None where the records never fall below ``fraction * v_peak``
    after the recorded peak (the window is the run's: no edge) or an integration fails.

    ``t``, ``v``: the recorded times and v_max; ``peak_state``: ``(t_p, z_p)``, the recorded peak's
    time (one of ``t``) and state; ``v_peak``: the run's (refined) peak speed; ``restep(t0, y0, t1)``
    the state at ``t1`` integrated from ``(t0, y0)`` by the run's method and tolerance (None if it
    fails); ``measure(t, z)`` the measures (``ElasticLine.measure``: v_max first).

    Returns ``(t_edge, k, mm)``: the edge's time, the recorded step it lies in (``t[k-1] < t_edge <=
    t[k]``; every record before ``k`` is inside the window) and the measures of the state there."""
    t = np.asarray(t, dtype=float)
    v = np.asarray(v, dtype=float)
    thr = fraction * float(v_peak)
    t_p, z = float(peak_state[0]), peak_state[1]
    ip = int(np.searchsorted(t, t_p, side="left"))
    if ip >= t.size or t[ip] != t_p:
        return None
    below = np.flatnonzero(v[ip + 1:] < thr)
    if below.size == 0:
        return None
    k = ip + 1 + int(below[0])
    for j in range(ip + 1, k):  # (the recorded steps from the peak to the edge's step, again)
        z = restep(t[j - 1], z, t[j])
        if z is None:
            return None
    t0, z0 = t[k - 1], z
    m0 = measure(t0, z0)
    if m0[0] < thr:  # (round-off: the replayed state is already below: the edge is the step's start)
        return t0, k, m0

    def g(x):
        zx = restep(t0, z0, x)
        if zx is None:
            return None
        mx = measure(x, zx)
        return mx[0] - thr, mx

    end = g(t[k])
    if end is None:
        return None
    if end[0] >= 0.0:  # (round-off: the replayed end is not below: the edge is the step's end)
        return float(t[k]), k, end[1]
    got = _illinois(g, float(t0), float(t[k]), float(m0[0] - thr), float(end[0]),
                    max(EDGE_XTOL * float(t[k] - t0), EDGE_ULPS * float(np.spacing(abs(t[k])))), EDGE_VTOL * thr,
                    EDGE_MAXITER)
    if got is None:
        return None
    te, mm = got
    return float(te), k, (m0 if mm is None else mm)
