"""The ideal chain's continuum limits against the end separation: shipped, interpolated.

The ideal chain's peaks grow with its links (the paper's point); its continuum limit (the string's, finite at
every chi: :mod:`snapping.continuum`) is what a real line's answer is measured against (issue 24: the crossover
is where a peak falls 10% below it). Computing it costs 1-100 s of CPU per chi (the fold-following levels of
2140-33759 links at chi 0.05), more than a design answer's budget, so the limits at :data:`CHIS` are shipped
in ``snapping/data/ideal_limits.nc``, built by :func:`build` (``python -m snapping.table.limits``: each chi
:func:`snapping.continuum.converge` with ``levels=5, first=-1``, its limit and error bar per peak, 318 s of CPU
in all; relative bars 6e-4 (v), 3e-3 (a), 4e-3 (T) at chi 0.05; from chi 0.2 v and T under 1e-4, a 4e-4; the command, CPU
time and machine in the file's attributes). They agree with the regime studies' ideal limits, computed on their
own levels (v 32.970, 14.8208, 8.9642, 4.5340 at chi 0.1-0.5; ``tests/test_ideal_limits.py``).

:func:`ideal_limit` interpolates them: a cubic spline (scipy's ``CubicSpline``, not-a-knot) of log(limit) in
log(chi), exact at the nodes; its error bar, between nodes, the larger of the two neighbouring nodes' error bars
plus the interpolation's own error (the leave-one-out error at those nodes: the spline through the other
nodes, an overestimate for a smooth peak; where fewer than five converged nodes surround it, a flat 10%). A
peak that does not converge over the levels at a node (the
acceleration at large chi: the ideal chain's grows without limit with its links there) has no limit there, nor
in the intervals beside it: None, said.

Nondimensional: speed sqrt(g L), acceleration g, tension M g.

>>> x = ideal_limit(0.1)
>>> round(x["v_peak"][0], 1), x["v_peak"][1] < 0.01
(33.0, True)
"""

from __future__ import annotations

import functools
import json
import math
import os
import platform
import time
from pathlib import Path

import numpy as np

from .. import _validate as V

__all__ = ["CHIS", "LIMITS_FILE", "LIMIT_QUANTITIES", "build", "ideal_limit", "load_limits"]

#: the separations of the shipped limits
CHIS = (0.05, 0.06, 0.07, 0.08, 0.09, 0.1, 0.12, 0.14, 0.17, 0.2, 0.25, 0.3, 0.35, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9)
#: the shipped file
LIMITS_FILE = Path(__file__).resolve().parent.parent / "data" / "ideal_limits.nc"
#: the peaks whose limits are shipped
LIMIT_QUANTITIES = ("v_peak", "a_peak", "sigma_peak")
#: the levels of each chi's study (:func:`snapping.continuum.converge`): 5 from ``first = -1`` (33759 links at chi
#: 0.05; 318 s of CPU for all of :data:`CHIS`)
LEVELS, FIRST = 5, -1


def build(chis=CHIS, *, levels: int = LEVELS, first: int = FIRST, progress: bool = True):
    """The limits at ``chis`` (an xarray Dataset: ``<q>_limit``, ``<q>_error``, ``<q>_order`` over chi, NaN
    limit where the peak does not converge over the levels; ``links`` of the finest level, ``cpu_s``)."""
    import xarray as xr

    from ..continuum import converge

    rows = []
    c0 = time.process_time()
    for chi in chis:
        t = time.process_time()
        ds = converge(float(chi), levels=levels, first=first).dataset
        row = {"links": int(ds["n_links"].values[-1]), "cpu_s": time.process_time() - t}
        for q in LIMIT_QUANTITIES:
            finest, err = float(ds[q].values[-1]), float(ds.attrs[f"{q}_error"])
            row[q] = (_accepted(float(ds.attrs[f"{q}_limit"]), float(ds.attrs[f"{q}_order"]), int(ds.attrs[f"{q}_digits"]),
                                finest, err), err, float(ds.attrs[f"{q}_order"]), finest)
        rows.append(row)
        if progress:
            print(f"chi {chi:g}: {row['links']} links, {row['cpu_s']:.1f} s, " + ", ".join(
                f"{q} {row[q][0]:.6g} +- {row[q][1]:.2g}" for q in LIMIT_QUANTITIES), flush=True)
    data = {"links": ("chi", np.array([r["links"] for r in rows])), "cpu_s": ("chi", np.array([r["cpu_s"] for r in rows]))}
    for q in LIMIT_QUANTITIES:
        for i, what in enumerate(("limit", "error", "order", "finest")):
            data[f"{q}_{what}"] = ("chi", np.array([r[q][i] for r in rows]))
    return xr.Dataset(data, coords={"chi": np.asarray(chis, dtype=float)},
                      attrs={"title": "snapping: the ideal chain's continuum limits against chi",
                             "method": f"snapping.continuum.converge(chi, levels={levels}, first={first})",
                             "command": "python -m snapping.table.limits", "cpu_s_total": time.process_time() - c0,
                             "machine": f"{platform.machine()} {os.cpu_count()} cores, Python {platform.python_version()}",
                             "built": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())})


#: levels that agree this closely (the last difference over the finest level) are converged without an order
SETTLED = 1e-4


def _accepted(limit: float, order: float, digits: int, finest: float, error: float) -> float:
    """A study's limit of a peak, or NaN where it has none: the extrapolation where it converges (a finite
    observed order), the finest level where the levels agree within :data:`SETTLED` though their differences
    are at rounding and give no order (the speed at chi 0.8: 9.7e-6 of 2.36), else NaN (the acceleration at
    chi 0.9, growing with the links: 27, 43, 70, 118 on 185-1060 links)."""
    if math.isfinite(order) and digits > 0:
        return limit
    if math.isfinite(error) and abs(error) <= SETTLED * abs(finest):
        return finest
    return math.nan


@functools.lru_cache(maxsize=1)
def load_limits(path: str | None = None) -> dict:
    """The shipped limits as arrays: ``chi`` and, per peak, ``limit`` and ``error``."""
    import xarray as xr

    with xr.open_dataset(path or LIMITS_FILE) as ds:
        out = {"chi": ds["chi"].values.astype(float), "attrs": dict(ds.attrs)}
        for q in LIMIT_QUANTITIES:
            out[q] = {"limit": ds[f"{q}_limit"].values.astype(float), "error": ds[f"{q}_error"].values.astype(float)}
    return out


def _spline(x, y, at: float) -> float:
    from scipy.interpolate import CubicSpline

    return float(np.exp(CubicSpline(x, np.log(y))(at)))


def _leave_one_out(x, y, i: int) -> float:
    """The relative error at node ``i`` of the spline through the other nodes (0 at an end: no neighbour)."""
    if i == 0 or i == len(x) - 1:
        return 0.0
    keep = np.arange(len(x)) != i
    return abs(_spline(x[keep], y[keep], x[i]) / y[i] - 1.0)


def ideal_limit(chi: float) -> dict:
    """The ideal chain's continuum limit at ``chi`` (in [0.05, 0.9], the shipped range), per peak
    (:data:`LIMIT_QUANTITIES`): (limit, relative error bar), or None where the peak has no limit there (it
    does not converge at a neighbouring node). See the module's text."""
    t = load_limits()
    chis = t["chi"]
    chi = V.real("chi", chi)
    if not (chis[0] <= chi <= chis[-1]):
        raise V.SnappingInputError(f"chi={chi!r} is out of range: the shipped ideal limits cover [{chis[0]:g}, "
                                   f"{chis[-1]:g}]")
    x = np.log(chis)
    j = int(np.searchsorted(chis, chi))
    out = {}
    for q in LIMIT_QUANTITIES:
        y, err = t[q]["limit"], t[q]["error"]
        if j < len(chis) and chis[j] == chi:  # a node: its own limit
            out[q] = None if not np.isfinite(y[j]) else (float(y[j]), float(err[j] / y[j]))
            continue
        lo, hi = j - 1, j
        if not (np.isfinite(y[lo]) and np.isfinite(y[hi])):
            out[q] = None
            continue
        ok = np.isfinite(y)  # the spline through the converged nodes of the run of them around chi
        a, b = lo, hi
        while a > 0 and ok[a - 1]:
            a -= 1
        while b < len(chis) - 1 and ok[b + 1]:
            b += 1
        xs, ys = x[a:b + 1], y[a:b + 1]
        if len(xs) < 4:  # too few for a cubic: linear in log-log
            v = float(np.exp(np.interp(math.log(chi), xs, np.log(ys))))
        else:
            v = _spline(xs, ys, math.log(chi))
        interp = max(_leave_one_out(xs, ys, lo - a), _leave_one_out(xs, ys, hi - a)) if len(xs) >= 5 else 0.1
        out[q] = (v, max(err[lo] / y[lo], err[hi] / y[hi]) + interp)
    return out


def main(argv=None) -> int:
    import argparse

    p = argparse.ArgumentParser(prog="python -m snapping.table.limits", description=build.__doc__)
    p.add_argument("--output", default=str(LIMITS_FILE), help="the netCDF file to write (default: the shipped one)")
    p.add_argument("--chis", nargs="+", type=float, default=list(CHIS))
    a = p.parse_args(argv)
    ds = build(a.chis)
    ds.attrs["command"] = "python -m snapping.table.limits " + " ".join(argv or [])
    tmp = Path(a.output).with_suffix(".partial.nc")
    ds.to_netcdf(tmp)
    os.replace(tmp, a.output)
    print(json.dumps({"written": a.output, "cpu_s": ds.attrs["cpu_s_total"]}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
