"""Escalation of a regime study's levels: a cell whose error bar is over the target runs one more
(finer) level (issue 24, branch stretch1pct).

A study run with ``regimes(..., escalate=target, extra_levels=m)`` holds ``levels + m`` levels; every
cell runs the first ``levels`` (the base), and a cell whose continuum extrapolation
(:func:`snapping.continuum.extrapolate` over the levels it has) leaves the error bar of v_peak,
a_peak or sigma_peak above ``target`` of its limit runs the next level, until it is within the
target or has all ``levels + m``. The ideal chain at a chi runs a level when any of its cells does
(the same-links ratio needs both on the same links) or when its own bars are over the target. A
cell's row holds its levels as a prefix of the level dimension (NaN after): :func:`prefix`.

Why (measured, docs/guide/regimes.md "Escalated levels"): at chi = 0.1 the ideal chain's own
a_peak is only +-2.0% on the stretching study's four levels (453,413, 582,569, 633,683, 648,205:
orders 1.3, 1.8, the first level pre-asymptotic), so every stiff cell there is too; one level more
settles them, and costs the cells that are already within 1% nothing.

>>> import numpy as np
>>> prefix(np.array([1.0, 2.0, np.nan, 4.0]))
2
"""

from __future__ import annotations

import math

import numpy as np

from . import _validate as V
from .continuum import extrapolate

__all__ = ["ESCALATE_QUANTITIES", "prefix", "extrapolate_prefix", "over_target", "integration_rhs", "too_costly",
           "pending", "next_round", "mark_levels_run"]

#: the peaks whose error bars decide an escalation
ESCALATE_QUANTITIES = ("v_peak", "a_peak", "sigma_peak")


def prefix(row) -> int:
    """The number of leading finite values of ``row`` (the levels a cell has run)."""
    ok = np.isfinite(np.asarray(row, dtype=float))
    bad = np.flatnonzero(~ok)
    return int(ok.size if bad.size == 0 else bad[0])


def extrapolate_prefix(res, row, base: int):
    """:func:`snapping.continuum.extrapolate` over the leading finite levels of ``row`` (resolutions
    ``res``), or None where fewer than ``base`` are done."""
    n = prefix(row)
    if n < base:
        return None
    return extrapolate(np.asarray(res, dtype=float)[:n], np.asarray(row, dtype=float)[:n])


def over_target(res, rows: dict, base: int, target: float) -> bool:
    """Whether any of ``rows`` ({quantity: levels}) has, over its done levels, an error bar above
    ``target`` times its limit (a zero or non-finite limit counts as over)."""
    for q in ESCALATE_QUANTITIES:
        if q not in rows:
            continue
        e = extrapolate_prefix(res, rows[q], base)
        if e is None:
            return False
        lim, err = e["limit"], e["error"]
        if not (math.isfinite(lim) and math.isfinite(err) and lim != 0.0 and abs(err) <= target * abs(lim)):
            return True
    return False


def integration_rhs(n_rhs_row, approach_row=None) -> np.ndarray:
    """A cell's evaluations per level less those that located its fifth peak, kappa_peak_approach
    (``approach_row``, the study's ``n_rhs_approach_level``; None or NaN: none known, nothing taken off).

    What the cost cap judges (branch emkappa): the integration's own cost, the work it judged before
    the fifth peak existed. Locating that peak on the dense output adds evaluations (+0.2% median, up to
    +15% on a crumpled heavy-drag cell) that say nothing about what the next level's integration will
    cost; counted, they moved end mass chi 0.1 M 0.0072 (588,503 at its fourth level) over the 600,000
    cap, so a study measuring one more peak ran one level fewer. Less them, every run's count is the one
    it had before, to the evaluation (:mod:`snapping.simulate.dense_peaks`), and the cap decides as before.

    >>> integration_rhs([600_100.0, float("nan")], [200.0, float("nan")]).tolist()
    [599900.0, nan]
    >>> integration_rhs([5.0], [float("nan")]).tolist(), integration_rhs([5.0]).tolist()
    ([5.0], [5.0])
    """
    row = np.asarray(n_rhs_row, dtype=float)
    if approach_row is None:
        return row
    extra = np.asarray(approach_row, dtype=float)
    return row - np.where(np.isfinite(extra), extra, 0.0)


def too_costly(n_rhs_row, max_rhs, approach_row=None) -> bool:
    """Whether a cell's last done level (the leading finite values of ``n_rhs_row``) took more than
    ``max_rhs`` right-hand-side evaluations in its integration (less ``approach_row``'s, those that
    located kappa_peak_approach: :func:`integration_rhs`): its next level (twice the links at least) is
    not run. ``max_rhs`` None: no cap (False).

    >>> too_costly([1e4, 3e5, 4e6, float("nan")], 1e6), too_costly([1e4, 3e5], 1e6), too_costly([4e6], None)
    (True, False, False)
    >>> too_costly([600_100.0], 600_000), too_costly([600_100.0], 600_000, [200.0])
    (True, False)
    """
    if max_rhs is None:
        return False
    row = integration_rhs(n_rhs_row, approach_row)
    n = prefix(row)
    return bool(n > 0 and row[n - 1] > max_rhs)


def _cell_costly(ds, i, j, max_rhs) -> bool:
    """:func:`too_costly` for cell (i, j) of study ``ds`` (its ``n_rhs_approach_level`` where it has one)."""
    extra = ds["n_rhs_approach_level"].values[i, j] if "n_rhs_approach_level" in ds else None
    return too_costly(ds["n_rhs_level"].values[i, j], max_rhs, extra)


def pending(ds, target: float, base: int, max_rhs=None) -> list[tuple]:
    """The runs an escalating study still owes: ``(chi index, number index or None for the ideal,
    level index)``, each the next level of a cell (or ideal) whose base levels are all done.
    ``max_rhs``: a cell whose last level took more evaluations is not escalated (:func:`too_costly`)."""
    nl = ds.sizes["level"]
    res = ds.resolution.values
    out = []
    for i in range(ds.sizes["chi"]):
        want = 0
        for j in range(ds.sizes["number"]):
            n = prefix(ds["v_peak_level"].values[i, j])
            if n < base:
                continue
            rows = {q: ds[f"{q}_level"].values[i, j] for q in ESCALATE_QUANTITIES}
            if (n < nl and over_target(res, rows, base, target)
                    and not (max_rhs is not None and _cell_costly(ds, i, j, max_rhs))):
                out.append((i, j, n))
                n += 1
            want = max(want, n)
        n = prefix(ds["v_peak_ideal_level"].values[i])
        if base <= n < nl:
            rows = {q: ds[f"{q}_ideal_level"].values[i] for q in ESCALATE_QUANTITIES}
            if n < want or over_target(ds.resolution_ideal.values, rows, base, target):
                out.append((i, None, n))
    return out


def next_round(ds, target: float, base: int, tried: set, max_rhs=None) -> list[tuple]:
    """The runs of the next round of escalation: :func:`pending` less those in ``tried`` (a failed
    run leaves its level owed; it is not tried again in the same call), added to ``tried``."""
    more = [m for m in pending(ds, target, base, max_rhs) if m not in tried]
    tried.update(more)
    return more


def mark_levels_run(ds, base: int) -> bool:
    """Add an escalating study's ``levels_run`` (chi, number) and ``levels_run_ideal`` (chi): the
    levels each cell and each ideal ran; returns whether any run is still owed (:func:`pending`)."""
    ds["levels_run"] = (("chi", "number"), np.array([[prefix(r) for r in rows] for rows in ds["v_peak_level"].values],
                                                    dtype=np.int8),
                        {"long_name": "levels the cell ran (the base, plus those its error bars asked for)"})
    ds["levels_run_ideal"] = ("chi", np.array([prefix(r) for r in ds["v_peak_ideal_level"].values], dtype=np.int8))
    max_rhs = ds.attrs.get("escalate_max_rhs")
    if max_rhs is not None:  # the cells over the target that the cap left at their levels (their cost)
        target, res, nl = float(ds.attrs["escalate"]), ds.resolution.values, ds.sizes["level"]

        def capped(i, j):
            n = prefix(ds["v_peak_level"].values[i, j])
            rows = {q: ds[f"{q}_level"].values[i, j] for q in ESCALATE_QUANTITIES}
            return (base <= n < nl and _cell_costly(ds, i, j, max_rhs)
                    and over_target(res, rows, base, target))

        ds["escalation_capped"] = (("chi", "number"), np.array(
            [[capped(i, j) for j in range(ds.sizes["number"])] for i in range(ds.sizes["chi"])], dtype=np.int8),
            {"long_name": f"1: the cell's error bars are over the target but its last level took more than "
                          f"{int(max_rhs)} evaluations: not escalated (not converged to the target)"})
    return bool(pending(ds, float(ds.attrs["escalate"]), base, max_rhs))


def settings(escalate, extra_levels, escalate_max_rhs) -> dict:
    """The escalation's entries of a study's key (validated; none without ``escalate``).

    >>> settings(0.01, None, None)
    {'escalate': 0.01, 'extra_levels': 1}
    >>> settings(None, None, None)
    {}
    """
    if escalate is None:
        given = [f"{k}={v!r}" for k, v in (("extra_levels", extra_levels), ("escalate_max_rhs", escalate_max_rhs))
                 if v is not None]
        if given:
            raise V.SnappingInputError(f"{', '.join(given)}: give {'it' if len(given) == 1 else 'them'} with escalate "
                                       f"(the error bar that asks for more levels)")
        return {}
    out = {"escalate": V.open_interval("escalate", escalate, 0.0, 1.0),
           "extra_levels": V.integer("extra_levels", 1 if extra_levels is None else extra_levels, 1, 4)}
    if escalate_max_rhs is not None:
        out["escalate_max_rhs"] = V.integer("escalate_max_rhs", escalate_max_rhs, 1)
    return out
