"""Benchmark: the full stretching scan (4 chi x 8 c, the 1% levels) by ``rodas4-links``, in ONE process (issue 24).

``regimes("stretching", [0.1, 0.2, 0.3, 0.5], geomspace(1e-3, 0.3, 8), accuracy="medium", tol=1e-6,
method="rodas4-links")``: fold levels -1 ... 2 (the other mechanisms' 1% levels), the study's tolerance
(1e-6, tighter above c = 450: ``stretch_tol``), grid damping 4, matched start, the tip links floored at
``STRETCH_TIP_TIME * c`` (``regimes_spec.stretch_tip_floor``). Measures the process's CPU time
(``time.process_time``: one process, no workers) and samples the load; writes the study to ``--out``
(resumable: a rerun computes only the runs missing; its a_peak, sigma_peak are the runs' snap peaks,
``a_peak_snap``/``sigma_peak_snap``, since branch snappeaks: ``results/stretch_scan_snap.json``) and a JSON summary beside it (``.json``), with
per-run CPU split by c, chi and level (what dominates) and the cells not converged / not within 1%.
Since branch stretch1pct: escalated (``regimes(escalate=STRETCH_ESCALATE, extra_levels=STRETCH_EXTRA_LEVELS)``:
a cell whose v, a or sigma bar is over 1% runs fold level 3 too, :mod:`snapping.regimes_escalate`), the taut
snap's tension kept beside (``sigma_peak_taut``, ``regimes_spec.STRETCH_EXTRA_PEAKS``):
``results/stretch_scan_esc.json``.

Usage::

    PYTHONPATH=src python benchmarks/stretch_scan.py --out benchmarks/results/stretch_scan_links.nc
    PYTHONPATH=src python benchmarks/stretch_scan.py --out benchmarks/results/stretch_scan_links.nc --report
"""

from __future__ import annotations

import argparse
import json
import os
import threading
import time

import numpy as np

CHIS = [0.1, 0.2, 0.3, 0.5]
NUMBERS = list(np.geomspace(1e-3, 0.3, 8))


def report(ds, extra=None):
    out = dict(extra or {})
    cpu = ds["cpu_time_level"].values
    icpu = ds["cpu_time_ideal_level"].values
    out["cpu_runs_s"] = float(np.nansum(cpu) + np.nansum(icpu))
    out["cpu_elastic_s"], out["cpu_ideal_s"] = float(np.nansum(cpu)), float(np.nansum(icpu))
    cs = 1.0 / ds.number.values
    out["cpu_by_c"] = {f"{c:.4g}": float(np.nansum(cpu[:, j])) for j, c in enumerate(cs)}
    out["cpu_by_chi"] = {f"{x:g}": float(np.nansum(cpu[i]) + np.nansum(icpu[i])) for i, x in enumerate(ds.chi.values)}
    out["cpu_by_level"] = {str(k): float(np.nansum(cpu[:, :, k]) + np.nansum(icpu[:, k])) for k in range(cpu.shape[2])}
    for q in ("v_peak", "a_peak", "sigma_peak") + (("sigma_peak_taut",) if "sigma_peak_taut" in ds else ()):
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = np.abs(ds[f"{q}_error"].values / ds[q].values)
        out[f"{q}_cells_within_1pct"] = int((rel <= 0.01).sum())
        out[f"{q}_median_rel_error"] = float(np.nanmedian(rel))
    out["n_rhs"] = float(np.nansum(ds["n_rhs_level"].values) + np.nansum(ds["n_rhs_ideal_level"].values))
    base = int(ds.attrs["levels"])
    out["runs_missing"] = int(np.isnan(ds["v_peak_level"].values[:, :, :base]).sum()
                              + np.isnan(ds["v_peak_ideal_level"].values[:, :base]).sum())
    out["runs"] = int(np.isfinite(ds["v_peak_level"].values).sum() + np.isfinite(ds["v_peak_ideal_level"].values).sum())
    cells = []
    for i, x in enumerate(ds.chi.values):
        for j, c in enumerate(cs):
            r = {q: float(ds[q].values[i, j]) for q in ("v_peak", "v_peak_error", "v_peak_order", "v_peak_ratio",
                                                         "v_peak_ratio_error", "a_peak", "a_peak_error",
                                                         "sigma_peak", "sigma_peak_error")}
            r.update(chi=float(x), c=float(c), converged=int(ds["converged"].values[i, j]),
                     levels=[float(v) for v in ds["v_peak_level"].values[i, j]],
                     n_links=[float(v) for v in ds["n_links_level"].values[i, j]],
                     cpu=[float(v) for v in cpu[i, j]])
            for q in ("v_peak", "a_peak", "sigma_peak"):
                r[f"{q}_rel_error"] = abs(r[f"{q}_error"] / r[q]) if r[q] else float("nan")
            cells.append(r)
    out["cells"] = cells
    out["ideal"] = {f"{x:g}": {"v_peak": float(ds["v_peak_ideal"].values[i]), "error": float(ds["v_peak_ideal_error"].values[i]),
                               "levels": [float(v) for v in ds["v_peak_ideal_level"].values[i]]}
                    for i, x in enumerate(ds.chi.values)}
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="benchmarks/results/stretch_scan_links.nc")
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--report", action="store_true", help="summarize the study file only")
    a = ap.parse_args()
    from snapping.regimes import load_study, regimes
    from snapping.regimes_spec import STRETCH_ESCALATE, STRETCH_EXTRA_LEVELS

    js = os.path.splitext(a.out)[0] + ".json"
    if a.report:
        print(json.dumps(report(load_study(a.out)), indent=1))
        return
    loads, stop = [], threading.Event()

    def sample():
        while not stop.wait(30.0):
            loads.append(os.getloadavg()[0])

    th = threading.Thread(target=sample, daemon=True)
    th.start()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    err = None
    try:
        ds = regimes("stretching", CHIS, NUMBERS, accuracy="medium", tol=a.tol, method="rodas4-links", out=a.out,
                     progress=False, escalate=STRETCH_ESCALATE, extra_levels=STRETCH_EXTRA_LEVELS)
    except RuntimeError as exc:  # some runs failed: the study file keeps the others
        err = str(exc)
        ds = load_study(a.out)
    stop.set()
    extra = {"cpu_process_s": time.process_time() - cpu0, "wall_s": time.perf_counter() - wall0,
             "load_min": min(loads, default=float("nan")), "load_max": max(loads, default=float("nan")),
             "load_mean": float(np.mean(loads)) if loads else float("nan"), "error": err, "tol": a.tol}
    out = report(ds, extra)
    with open(js, "w") as f:
        json.dump(out, f, indent=1)
    print(json.dumps({k: v for k, v in out.items() if k != "cells"}, indent=1))


if __name__ == "__main__":
    main()
