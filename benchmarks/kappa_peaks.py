"""The curvature peak of the regime studies' runs (issue 24, branch kappa; docs/guide/regimes.md,
"The curvature peak").

    python benchmarks/kappa_peaks.py cells ideal:0.3:0:3 drag:0.5:0.193:3 end-mass:0.1:1.93e-6:4
        each cell MECH:CHI:NUMBER:LEVELS (ideal: number 0) run by the study's worker on its first LEVELS
        fold levels: kappa_peak and kappa_peak_approach per level, limit +- error bar and order
        (the study's extrapolation)
    python benchmarks/kappa_peaks.py maxima ideal:0.3:0:4
        the local maxima in time of the record's kappa_max (above half its largest): time from the
        speed peak, joint (links from the free end), v_max over the peak speed
"""

from __future__ import annotations

import sys
import time

import numpy as np


def _spec(spec):
    mech, chi, num, nl = spec.split(":")
    return (None if mech == "ideal" else mech), float(chi), float(num), int(nl)


def cells(specs):
    from snapping.regimes import _levels, _run_task
    from snapping.regimes_escalate import extrapolate_prefix

    levels = _levels("fold", {"levels": 6, "first": -1, "n0": 0}, 0.5)
    res = np.array([p["frac"] for p in levels])
    for spec in specs:
        mech, chi, num, nl = _spec(spec)
        rows = [_run_task(chi, mech, num, levels[k], 1e-7) for k in range(nl)]
        print(f"{mech or 'ideal'} chi {chi:g} number {num:g}: cpu {sum(r['cpu_time'] for r in rows):.1f} s")
        for q in ("kappa_peak", "kappa_peak_approach"):
            v = np.array([r[q] for r in rows])
            e = extrapolate_prefix(res[:nl], v, nl)
            tail = f" -> {e['limit']:.2f} +- {100 * e['error'] / abs(e['limit']):.2f}% order {e['order']:.2f}" if e else ""
            print(f"   {q:20s} " + ", ".join(f"{x:.2f}" for x in v) + tail, flush=True)


def maxima(specs):
    from snapping.regimes import _levels, cell_problem
    from snapping.simulate import run

    levels = _levels("fold", {"levels": 6, "first": -1, "n0": 0}, 0.5)
    for spec in specs:
        mech, chi, num, nl = _spec(spec)
        for k in range(nl):
            p = cell_problem(chi, mech, num, levels[k])
            c = time.process_time()
            ds = run(problem=p, method="rodas4" if mech == "bending" else "fast", tol=1e-7, progress=False).dataset
            a = ds.attrs
            kk, t, v = ds.kappa_max.values, ds.t.values, ds.v_max.values
            joint = np.rint((1.0 - ds.s_kappa_max.values) / p.links.h[0]).astype(int)  # (exact for joint 1)
            print(f"{mech or 'ideal'} chi {chi:g} number {num:g} level {k} ({p.links.N} links, {time.process_time() - c:.1f} s): "
                  f"kappa_peak {a['kappa_peak']:.2f}, kappa_peak_approach {a['kappa_peak_approach']:.2f} "
                  f"at t_snap_v {a['t_kappa_peak_approach'] - a['t_snap_v']:+.2e}")
            for j in range(1, kk.size - 1):
                if kk[j] >= kk[j - 1] and kk[j] >= kk[j + 1] and kk[j] > 0.5 * kk.max():
                    print(f"   kappa_max {kk[j]:9.2f}  t - t_snap_v {t[j] - a['t_snap_v']:+.2e}  joint ~{joint[j]}  "
                          f"v/v_peak {v[j] / a['v_peak']:.3f}", flush=True)


if __name__ == "__main__":
    {"cells": cells, "maxima": maxima}[sys.argv[1]](sys.argv[2:])
