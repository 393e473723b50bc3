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
    answer's two graded levels ([(h, where), (h, where)]) for the stand-in, or None. Where a peak has no
    shipped limit the stand-in is the larger of the ideal on those graded links, extrapolated, and on the
    uniform links (both short of the limit where the ideal's peaks grow with its links; graded links cut for a
    line's bending length can fall far short: the bullwhip at chi 0.04, 1025 N on 134/248 graded links, 1168 N
    on 100 uniform), its error unknown (NaN). ``info``: ``what`` ("limit"), ``source`` per peak ("limit",
    "graded" or "uniform"), ``relative_error`` per peak, ``why`` (per stand-in peak: why no limit),
    ``uniform``, ``links`` (the graded stand-in's, when run) and ``method``."""
    from ._validate import SnappingInputError
    from .table.limits import CHIS, ideal_limit

    try:
        lim = ideal_limit(runs.chi)
        none = "the ideal's peak has no continuum limit here (it grows with the links)"
    except SnappingInputError:  # (outside the shipped separations)
        lim = {q: None for q in QUANTITIES}
        none = f"no shipped limit: chi outside [{CHIS[0]:g}, {CHIS[-1]:g}]"
    graded = runs.ideal_on(links) if links and any(lim[q] is None for q in QUANTITIES) else None
    ideal, err, source, why = {}, {}, {}, {}
    for q in QUANTITIES:
        if lim[q] is not None:
            ideal[q], err[q], source[q] = lim[q][0], lim[q][1], "limit"
            continue
        why[q] = none + ": a stand-in, likely short of it"
        if graded is not None and graded["extrapolated"][q] > uniform[q]:
            ideal[q], err[q], source[q] = graded["extrapolated"][q], math.nan, "graded"
        else:
            ideal[q], err[q], source[q] = uniform[q], math.nan, "uniform"
    kinds = sorted(set(source.values()))
    method = ("continuum limit (snapping.table.limits)" if kinds == ["limit"] else
              "/".join({"limit": "continuum limit", "graded": "graded stand-in",
                        "uniform": uniform["method"] + " on uniform links"}[k] for k in kinds))
    info = {"what": "limit", "source": source, "relative_error": err, "why": why, "uniform": uniform,
            "links": graded["links"] if graded is not None else None, "method": method}
    return {**ideal, "method": method}, info
