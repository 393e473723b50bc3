"""The elastic line's kappa_peak_approach on accepted steps against the peak between them (branch stretchapp).

For stretching-study cells (the shipped study's key: links, tolerance, method, start), one run gives
``kappa_peak_approach`` on the accepted steps (:func:`snapping.simulate.elastic_approach.approach_peak` of its
records) and located between them (the run's attribute); the same run again with ``--samples`` snapshots
spread over the two steps around the steps' best (states integrated from the step's
start by the run's own method, not interpolated: ``elastic_solve._snapshot``; the steps are unchanged)
gives the interior curvature between the steps, computed here from the snapshot's node positions (turning
angle over the mean rest length, joints >= KAPPA_TIP_JOINTS from the free end), where v_max is at its
running maximum. Prints the relative shortfall of the steps' value and of the located one.

    PYTHONPATH=src python benchmarks/stretch_kappa_approach.py --cells 0.1:0.0588 0.2:0.0051 --levels 0 3

``--graft OLD NEW OUT``: the shipped file made from a fresh study NEW (``bench_regimes.py --study stretching
--out NEW``; its cells bit for bit OLD's, with kappa_peak_approach) and the shipped OLD: OLD's ideal runs kept
(every variable OLD has, bit for bit: they were run by older chain code, 1e-9 from today's runs, and OLD's
chi 0.5 ran a fifth ideal level that a fresh study does not ask for), NEW's ideal kappa_peak_approach levels,
and the ideal levels OLD ran and NEW did not run now (their kappa_peak_approach only); the limits recomputed.
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
    acc["levels"] += acc.get("extra_levels", 0)  # (the escalated levels too)
    lev = R._levels(R.MECHANISMS["stretching"][1], acc, 0.5)[level]
    p = R.cell_problem(chi, "stretching", number, lev, damping=key["damping"], method=key["elastic_method"])
    return solve(p, Elastic.from_wave_speed(1.0 / number, grid_damping=key["damping"]),
                 tol=stretch_tol(key["tol"], 1.0 / number), method=key["elastic_method"], stop_floor=STRETCH_STOP_FLOOR,
                 start=key["elastic_start"], max_rhs=STRETCH_MAX_RHS_LINKS, snapshot_times=snapshot_times).dataset


def between_steps(chi, number, level, samples=40):
    """(steps' value, the largest between the steps, its time, the steps' time, links, the located value)."""
    from snapping.simulate.elastic_approach import approach_peak

    ds = cell_run(chi, number, level)
    t = ds.t.values
    st = approach_peak(t, ds.v_max.values, ds.kappa_max_interior.values)
    i = int(np.flatnonzero(t == st["t_kappa_peak_approach"])[0])
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
    return (st["kappa_peak_approach"], best, tb, st["t_kappa_peak_approach"], int(ds.sizes["link"]),
            float(ds.attrs["kappa_peak_approach"]))


def graft(old_path, new_path, out):
    import os

    from snapping import regimes as R
    from snapping.sweep_files import atomic_to_netcdf

    old, new = R.load_study(old_path), R.load_study(new_path)
    if old.attrs["regimes_study"] != new.attrs["regimes_study"] or os.path.lexists(out):
        raise SystemExit("--graft: OLD and NEW must be the same study, and OUT a new file")
    key = json.loads(old.attrs["regimes_study"])
    acc = {k: v for k, v in key.items() if k not in ("mechanism", "chi", "number", "ratio")}
    acc["levels"] += acc.get("extra_levels", 0)
    ideal_p = R._levels("fold", acc, 0.5)
    ds = new.copy(deep=True)
    for name in old.data_vars:
        if name.endswith("_ideal_level"):
            ds[name].values[...] = old[name].values
    q = ds["kappa_peak_approach_ideal_level"].values
    cpu = time.process_time()
    for i, chi in enumerate(ds.chi.values):
        for k in range(ds.sizes["level"]):
            if np.isfinite(old.v_peak_ideal_level.values[i, k]) and not np.isfinite(q[i, k]):
                row = R._run_task(float(chi), None, 0.0, ideal_p[k], key["tol"])
                q[i, k] = row["kappa_peak_approach"]
                print(f"ideal chi {chi:g} level {k}: kappa_peak_approach {q[i, k]:.10g} (v_peak {row['v_peak']:.12g}, "
                      f"OLD's {old.v_peak_ideal_level.values[i, k]:.12g})", flush=True)
    q[~np.isfinite(old.v_peak_ideal_level.values)] = np.nan
    atomic_to_netcdf(R._finish(ds), out)
    print(f"{out}: NEW's cells, OLD's ideal runs, the ideal's kappa_peak_approach ({time.process_time() - cpu:.1f} s CPU)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", nargs="+", default=["0.1:0.0588", "0.2:0.0051", "0.5:0.3"])
    ap.add_argument("--levels", nargs="+", type=int, default=[0])
    ap.add_argument("--samples", type=int, default=40)
    ap.add_argument("--graft", nargs=3, default=None, metavar=("OLD", "NEW", "OUT"))
    a = ap.parse_args()
    if a.graft:
        return graft(*a.graft)
    from snapping import regimes as R

    old = R.bundled_study("stretching")
    for cell in a.cells:
        chi, num = (float(x) for x in cell.split(":"))
        num = float(old.number.values[np.argmin(abs(np.log(old.number.values / num)))])
        for lev in a.levels:
            cpu = time.process_time()
            k_step, k_dense, t_dense, t_step, n, k_loc = between_steps(chi, num, lev, a.samples)
            print(f"chi {chi:g} number {num:.4g} level {lev} ({n} links): steps {k_step:.8g} at t {t_step:.8f}, "
                  f"between {k_dense:.8g} at t {t_dense:.8f}: shortfall {1 - k_step / k_dense:+.2e}; located "
                  f"{k_loc:.8g}: {1 - k_loc / k_dense:+.2e} "
                  f"({time.process_time() - cpu:.1f} s CPU)", flush=True)


if __name__ == "__main__":
    main()
