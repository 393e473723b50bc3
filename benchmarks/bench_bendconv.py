"""Is the peak rise of a slightly stiff line real? N-convergence of the small-beta bending cells (issue 24).

The shipped bending study (``src/snapping/data/regimes/bending.nc``, 3 fold-graded levels,
frac 0.08-0.02) found the peak *raised* by a small stiffness at chi 0.1 and 0.2. At those
levels the rod's bending length at the fold, ``l_B = sqrt(beta / T)`` with T the ideal
chain's peak tension (its fold's tension scale, the study's ``sigma_peak_ideal``), can be
shorter than the links there: the levels may sit where bending acts at the link scale.

This script runs the same cells (:func:`snapping.regimes.cell_problem`, RODAS4, grid damping
1, the study's tolerance) at more fold-graded levels (``frac = 0.04 * 2**-k``), and the
ideal chain at the same levels, and prints per cell: each level's v_peak, its link length
at the fold ``h_fold`` (the link at arclength ``1/kappa_ideal`` from the free end: the
ideal fold's radius at the snap), ``l_B / h_fold``, the successive differences and the
Richardson extrapolation over the last three levels. Results are kept in a JSON file
(``--out``) and reused: rerunning resumes.

Usage::

    python benchmarks/bench_bendconv.py --chi 0.2 --beta 1e-8 7.2e-8 5.18e-7 3.73e-6 --k -1 0 1 2 3
    python benchmarks/bench_bendconv.py --table                # what is done so far
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "results", "bendconv.json")


def level(k: int) -> dict:
    from snapping.continuum import level_parameters

    return level_parameters(1, 0.5, first=k)[0]


def h_fold(chi: float, beta: float, k: int, kappa_ideal: float) -> float:
    """The link length at arclength 1/kappa_ideal from the free end at level k."""
    from snapping.regimes import cell_problem

    h = cell_problem(chi, "bending" if beta > 0 else None, beta, level(k), damping=1.0).links.h
    x = np.concatenate([[0.0], np.cumsum(h)])  # free end first (index 0)
    i = int(np.searchsorted(x, 1.0 / kappa_ideal)) - 1
    return float(h[max(0, min(i, h.size - 1))])


def load(path):
    return json.load(open(path)) if os.path.isfile(path) else {}


#: the study's tolerance (bending.nc's ``tol``): runs at another tolerance carry it in their key
TOL = 1e-7


def run(chi, beta, k, path, tol=TOL):
    from snapping.regimes import _run_task

    db = load(path)
    key = f"{chi:g} {beta:g} {k}" + ("" if tol == TOL else f" tol={tol:g}")
    if key in db:
        return db[key]
    t = time.time()
    row = _run_task(chi, "bending" if beta > 0 else None, beta, level(k), tol, 1.0)
    row["wall"] = time.time() - t
    row["load"] = os.getloadavg()[0]
    row["tol"] = tol
    db = load(path)
    db[key] = row
    tmp = path + ".tmp"
    json.dump(db, open(tmp, "w"), indent=1)
    os.replace(tmp, path)
    print(f"chi={chi:g} beta={beta:g} k={k}: v_peak={row['v_peak']:.6g} N={row['n_links']} "
          f"tol={tol:g} rhs={row['n_rhs']} cpu={row['cpu_time']:.1f}s load={row['load']:.1f}", flush=True)
    return row


def table(path):
    from snapping.continuum import extrapolate

    everything = load(path)
    db = {k: r for k, r in everything.items() if len(k.split()) == 3}  # the study's tolerance
    cells = sorted({(float(c), float(b)) for c, b, _ in (k.split() for k in db)})
    for chi, beta in cells:
        ks = sorted(int(k.split()[2]) for k in db if k.split()[:2] == [f"{chi:g}", f"{beta:g}"])
        ideal = [db.get(f"{chi:g} 0 {k}") for k in range(min(ks), max(ks) + 1)]
        kap = max((r["kappa_peak"] for r in ideal if r), default=float("nan"))
        sig = max((r["sigma_peak"] for r in ideal if r), default=float("nan"))
        print(f"chi={chi:g} beta={beta:g}" + ("" if beta == 0 else
              f"  l_B=sqrt(beta/T_ideal)={math.sqrt(beta / sig):.3g} (T={sig:.4g}), fold radius 1/kappa={1 / kap:.3g}"))
        print(f"  {'k':>3} {'frac':>8} {'N':>6} {'h_fold':>9} {'l_B/h':>6} {'v_peak':>10} {'diff':>9} "
              f"{'ideal':>9} {'ratio':>7} {'rhs':>8} {'cpu s':>7}")
        prev = None
        vs, fr = [], []
        for k in range(min(ks), max(ks) + 1):
            r = db.get(f"{chi:g} {beta:g} {k}")
            if r is None:
                prev = None
                vs, fr = [], []
                continue
            hf = h_fold(chi, beta, k, kap)
            lb = math.sqrt(beta / sig) / hf if beta > 0 else float("nan")
            idl = db.get(f"{chi:g} 0 {k}")
            iv = idl["v_peak"] if idl else float("nan")
            d = r["v_peak"] - prev if prev is not None else float("nan")
            print(f"  {k:3d} {level(k)['frac']:8.4g} {r['n_links']:6d} {hf:9.3g} {lb:6.2f} {r['v_peak']:10.6g} "
                  f"{d:+9.3g} {iv:9.5g} {r['v_peak'] / iv:7.4f} {r['n_rhs']:8d} {r['cpu_time']:7.1f}")
            prev = r["v_peak"]
            vs.append(r["v_peak"])
            fr.append(level(k)["frac"])
        if len(vs) >= 3:
            e = extrapolate(fr[-3:], vs[-3:])
            print(f"  last 3 levels: limit {e['limit']:.5g} +- {e['error']:.2g}, order {e['order']:.2f}, "
                  f"converging {e['converging']}")
    other = {k: r for k, r in everything.items() if len(k.split()) != 3}
    if other:
        print("at other tolerances (beside the study's run of the same cell and level, where there is one):")
    for key, r in sorted(other.items()):
        same = db.get(" ".join(key.split()[:3]))
        print(f"  {key}: v_peak {r['v_peak']:.6g} (study's tol: {same['v_peak'] if same else float('nan'):.6g}) "
              f"N {r['n_links']} rhs {r['n_rhs']} cpu {r['cpu_time']:.1f} s")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chi", type=float, nargs="*", default=[])
    ap.add_argument("--beta", type=float, nargs="*", default=[])
    ap.add_argument("--k", type=int, nargs="*", default=[], help="levels: frac = 0.04 * 2**-k")
    ap.add_argument("--out", default=OUT)
    ap.add_argument("--tol", type=float, default=TOL, help="RODAS4's tolerance (default the study's; another one "
                    "is kept under its own key, ' tol=X', which --table lists apart and --extend never seeds)")
    ap.add_argument("--table", action="store_true")
    a = ap.parse_args(argv)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    for k in a.k:  # level by level: the coarse levels of every cell first
        for chi in a.chi:
            for beta in [0.0] + list(a.beta):
                run(chi, beta, k, a.out, a.tol if beta else TOL)  # the ideal (DOP853) at the study's
    if a.table or not a.k:
        table(a.out)


if __name__ == "__main__":
    main()
