"""The elastic line's kappa_peak_approach on accepted steps against the peak between them (branch stretchapp).

For stretching-study cells (the shipped study's key: links, tolerance, method, start), one run gives
``kappa_peak_approach`` on the accepted steps (:mod:`snapping.simulate.elastic_approach`); the same run
again with ``--samples`` snapshots spread over the two steps around it (states integrated from the step's
start by the run's own method, not interpolated: ``elastic_solve._snapshot``; the steps are unchanged)
gives the interior curvature between the steps, computed here from the snapshot's node positions (turning
angle over the mean rest length, joints >= KAPPA_TIP_JOINTS from the free end), where v_max is at its
running maximum. Prints the relative shortfall of the steps' value.

    PYTHONPATH=src python benchmarks/stretch_kappa_approach.py --cells 0.1:0.0588 0.2:0.0051 --levels 0 3
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np


def interior_kappa(x, y, h, tip=8):
    """max over nodes i >= tip (1..N-1) of the turning angle at node i over (h_{i-1} + h_i)/2: numpy, by hand."""
    dx, dy = np.diff(x), np.diff(y)
    cr = dx[:-1] * dy[1:] - dy[:-1] * dx[1:]
    dt = dx[:-1] * dx[1:] + dy[:-1] * dy[1:]
    k = np.arctan2(np.abs(cr), dt) / (0.5 * (h[:-1] + h[1:]))  # node i = 1..N-1
    return float(np.max(k[tip - 1:])) if k.size >= tip else np.nan


def cell_run(chi, number, level, snapshot_times=()):
    from snapping import regimes as R
    from snapping.regimes_spec import STRETCH_MAX_RHS_LINKS, STRETCH_STOP_FLOOR
    from snapping.simulate.elastic import Elastic, solve
    from snapping.regimes import stretch_tol

    old = R.bundled_study("stretching")
    key = json.loads(old.attrs["regimes_study"])
    acc = {k: v for k, v in key.items() if k not in ("mechanism", "chi", "number", "ratio")}
    lev = R._levels(R.MECHANISMS["stretching"][1], acc, 0.5)[level]
    p = R.cell_problem(chi, "stretching", number, lev, damping=key["damping"], method=key["elastic_method"])
    return solve(p, Elastic.from_wave_speed(1.0 / number, grid_damping=key["damping"]),
                 tol=stretch_tol(key["tol"], 1.0 / number), method=key["elastic_method"], stop_floor=STRETCH_STOP_FLOOR,
                 start=key["elastic_start"], max_rhs=STRETCH_MAX_RHS_LINKS, snapshot_times=snapshot_times).dataset


def between_steps(chi, number, level, samples=40):
    """(steps' value, the largest between the steps, its time, the run's t_kappa_peak_approach, links)."""
    ds = cell_run(chi, number, level)
    t = ds.t.values
    i = int(np.searchsorted(t, ds.attrs["t_kappa_peak_approach"]))
    lo, hi = t[max(i - 1, 0)], t[min(i + 1, t.size - 1)]
    ts = np.linspace(lo, hi, samples + 1)[1:-1]
    d2 = cell_run(chi, number, level, snapshot_times=ts)
    h = d2.link_length.values
    vrun = float(np.max(ds.v_max.values[:max(i - 1, 0) + 1]))  # the running peak at the interval's start
    best, tb = -np.inf, np.nan
    for k, tk in enumerate(d2.t_snapshot.values):
        if d2.snapshot_kind.values[k] != "requested":
            continue
        v = float(np.max(d2.speed.values[k]))
        vrun = max(vrun, v)
        if v < vrun:
            continue
        q = interior_kappa(d2.x.values[k], d2.y.values[k], h)
        if q > best:
            best, tb = q, float(tk)
    return float(ds.attrs["kappa_peak_approach"]), best, tb, float(ds.attrs["t_kappa_peak_approach"]), int(ds.sizes["link"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", nargs="+", default=["0.1:0.0588", "0.2:0.0051", "0.5:0.3"])
    ap.add_argument("--levels", nargs="+", type=int, default=[0])
    ap.add_argument("--samples", type=int, default=40)
    a = ap.parse_args()
    from snapping import regimes as R

    old = R.bundled_study("stretching")
    for cell in a.cells:
        chi, num = (float(x) for x in cell.split(":"))
        num = float(old.number.values[np.argmin(abs(np.log(old.number.values / num)))])
        for lev in a.levels:
            cpu = time.process_time()
            k_step, k_dense, t_dense, t_step, n = between_steps(chi, num, lev, a.samples)
            print(f"chi {chi:g} number {num:.4g} level {lev} ({n} links): steps {k_step:.8g} at t {t_step:.8f}, "
                  f"between {k_dense:.8g} at t {t_dense:.8f}: shortfall {1 - k_step / k_dense:+.2e} "
                  f"({time.process_time() - cpu:.1f} s CPU)", flush=True)


if __name__ == "__main__":
    main()
