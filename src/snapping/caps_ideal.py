"""The ideal chain beside a real line's answer (:mod:`snapping.caps`).

The ideal chain's peaks grow with its links; a real line's converge (its bending, drag, stretching hold its fold
above the links). So where the real answer is a limit -- links chosen until it settles (``N="auto"``, the
default), graded links extrapolated, the combined model on graded links -- the ideal beside it, and the
factor and the verdict, are the ideal chain's **continuum limit** at the same chi (:func:`snapping.table.limits.
ideal_limit`: shipped for chi in [0.05, 0.9], its error bar carried). Where no shipped limit exists for a peak
(chi outside that range, or the ideal's acceleration at large chi, which grows without limit), the ideal chain
on the answer's graded links extrapolated the same way stands in (:meth:`snapping.caps_runs.Runs.ideal_on`), or
else the ideal on the answer's uniform links; ``source`` says which per peak. On links the user gave (``N``),
and on a discrete chain's own links, the ideal is the chain on the same links, as before.

Measured (``benchmarks/bench_caps.py --answers ...``, docs/guide/caps.md): the climbing rope at chi 0.15 (real
1264 N) has the ideal on 100 uniform links at 958 N (factor 1.32: "none") but its limit at 1491 N (0.85:
capped); the bullwhip's graded links (133/247 at chi 0.05) would put the ideal at 509 N +- 7%, the limit is
1.62 kN: graded links cut for the real line's bending length do not resolve the ideal's fold.
"""

from __future__ import annotations

import math

from .caps_runs import QUANTITIES

__all__ = ["beside"]


def beside(runs, uniform: dict, links=None) -> tuple[dict, dict]:
    """The ideal (nondimensional peaks) that a limit answer of ``runs``' line compares with, and what it is:
    ``(ideal, info)``; ``uniform``: the ideal on the answer's uniform links (kept in ``info``), ``links``: the
    answer's two graded levels ([(h, where), (h, where)]) for the stand-in, or None. ``info``: ``what``
    ("limit"), ``source`` per peak ("limit", "graded" or "uniform"), ``relative_error`` per peak, ``uniform``,
    and ``links`` (the stand-in's, when run)."""
    from ._validate import SnappingInputError
    from .table.limits import ideal_limit

    try:
        lim = ideal_limit(runs.chi)
    except SnappingInputError:  # (outside the shipped separations)
        lim = {q: None for q in QUANTITIES}
    graded = runs.ideal_on(links) if links and any(lim[q] is None for q in QUANTITIES) else None
    ideal, err, source = {}, {}, {}
    for q in QUANTITIES:
        if lim[q] is not None:
            ideal[q], err[q], source[q] = lim[q][0], lim[q][1], "limit"
        elif graded is not None:
            ideal[q], err[q], source[q] = graded["extrapolated"][q], graded["relative_error"][q], "graded"
        else:
            ideal[q], err[q], source[q] = uniform[q], math.nan, "uniform"
    info = {"what": "limit", "source": source, "relative_error": err, "uniform": uniform,
            "links": graded["links"] if graded is not None else None}
    return {**ideal, "method": uniform["method"]}, info
