"""The Richardson limit of a cell's levels computed by hand, independently of snapping.continuum and
snapping.regimes (the expected values of the tests that read the shipped regime studies)."""

import math

import numpy as np


def richardson(q):
    """Four or more levels halving (the levels a cell ran: an escalated cell's five, NaN after), by
    hand: the Richardson limit of the last three (order p = log2(d1/d2), limit q3 + d2/(2^p - 1)), its
    error bar max(|limit - the three before's limit|, |correction|/10); where the last three do not
    converge monotonically, the finest level, its bar their spread."""
    q = np.asarray(q, dtype=float)
    q = q[:int(np.isfinite(q).cumprod().sum())]
    assert q.size >= 4
    d = np.diff(q)
    ests = []
    for k in (q.size - 2, q.size - 1):
        d1, d2 = d[k - 2], d[k - 1]
        ok = d1 != 0 and d2 != 0 and np.sign(d1) == np.sign(d2) and abs(d2) < abs(d1)
        ests.append(q[k] + d2 / (2 ** math.log2(d1 / d2) - 1) if ok else None)
    if ests[1] is None:
        return q[-1], float(np.ptp(q[-3:]))
    err = abs(ests[1] - q[-1]) if ests[0] is None else max(abs(ests[1] - ests[0]), 0.1 * abs(ests[1] - q[-1]))
    return ests[1], err
