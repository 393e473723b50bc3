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


def _tol(key: str) -> float:
    return float(key.split()[3].split("=")[1]) if len(key.split()) > 3 else TOL


def bound(vs) -> str:
    """Where the levels' last two differences alternate in sign and shrink (ratio r < 1), the limit
    lies within ``|d_last| r / (1 - r)`` of the last level if they go on shrinking geometrically
    (the tail of an alternating geometric series); else nothing is claimed."""
    if len(vs) < 3:
        return ""
    d1, d2 = vs[-2] - vs[-3], vs[-1] - vs[-2]
    r = abs(d2 / d1) if d1 else float("inf")
    if d1 * d2 >= 0 or r >= 1:
        return ""
    tail = abs(d2) * r / (1 - r)
    return (f"; alternating (ratio {r:.2f}): limit {vs[-1]:.5g} +- {tail:.2g} if it goes on shrinking, "
            f"between the last two levels ({min(vs[-2:]):.5g}..{max(vs[-2:]):.5g}) if it goes on alternating")


def table(path):
    from snapping.continuum import extrapolate

    db = load(path)
    cells = sorted({(float(c), float(b)) for c, b, *_ in (k.split() for k in db)})
    tols = sorted({_tol(k) for k in db}, reverse=True)
    for chi, beta in cells:
        ideal = {int(k.split()[2]): r for k, r in db.items() if k.split()[:2] == [f"{chi:g}", "0"] and _tol(k) == TOL}
        kap = max((r["kappa_peak"] for r in ideal.values()), default=float("nan"))
        sig = max((r["sigma_peak"] for r in ideal.values()), default=float("nan"))
        ik = sorted(ideal)
        ilim = extrapolate([level(k)["frac"] for k in ik[-3:]], [ideal[k]["v_peak"] for k in ik[-3:]]) \
            if len(ik) >= 3 and ik[-1] - ik[-3] == 2 else None
        for tol in tols:
            cell = {TOL: {}, tol: {}}
            for k, r in db.items():
                if k.split()[:2] == [f"{chi:g}", f"{beta:g}"] and _tol(k) in cell:
                    cell[_tol(k)][int(k.split()[2])] = r
            rows = cell[tol]
            if not rows or (beta == 0 and tol != TOL):
                continue
            # a looser tolerance's levels continue the study's coarser ones (its tolerance error, measured
            # where both ran the same level, is far below the level differences of these cells)
            rows = {**{k: r for k, r in cell[TOL].items() if k < min(rows)}, **rows}
            print(f"chi={chi:g} beta={beta:g} tol={tol:g}" + ("" if beta == 0 else
                  f"  l_B=sqrt(beta/T_ideal)={math.sqrt(beta / sig):.3g} (T={sig:.4g}), fold radius 1/kappa={1 / kap:.3g}"))
            both = sorted(set(cell[TOL]) & set(cell[tol])) if tol != TOL else []
            if both:
                print("  tolerance error (same level at tol " + f"{tol:g} - at {TOL:g}): " + ", ".join(
                    f"k={k}: {cell[tol][k]['v_peak'] - cell[TOL][k]['v_peak']:+.2g}" for k in both))
            print(f"  {'k':>3} {'frac':>8} {'N':>6} {'h_fold':>9} {'l_B/h':>6} {'v_peak':>10} {'diff':>9} "
                  f"{'ideal':>9} {'ratio':>7} {'rhs':>8} {'cpu s':>7} {'tol':>6}")
            prev = None
            vs, fr = [], []
            for k in range(min(rows), max(rows) + 1):
                r = rows.get(k)
                if r is None:
                    prev = None
                    vs, fr = [], []
                    continue
                hf = h_fold(chi, beta, k, kap)
                lb = math.sqrt(beta / sig) / hf if beta > 0 else float("nan")
                iv = ideal[k]["v_peak"] if k in ideal else float("nan")
                d = r["v_peak"] - prev if prev is not None else float("nan")
                print(f"  {k:3d} {level(k)['frac']:8.4g} {r['n_links']:6d} {hf:9.3g} {lb:6.2f} {r['v_peak']:10.6g} "
                      f"{d:+9.3g} {iv:9.5g} {r['v_peak'] / iv:7.4f} {r['n_rhs']:8d} {r['cpu_time']:7.1f} "
                      f"{r.get('tol', TOL):6.0e}")
                prev = r["v_peak"]
                vs.append(r["v_peak"])
                fr.append(level(k)["frac"])
            if len(vs) >= 3:
                e = extrapolate(fr[-3:], vs[-3:])
                print(f"  last 3 levels: limit {e['limit']:.5g} +- {e['error']:.2g}, order {e['order']:.2f}, "
                      f"converging {e['converging']}" + bound(vs))
                if beta > 0 and ilim:
                    print(f"  over the ideal's limit {ilim['limit']:.5g} +- {ilim['error']:.2g}: finest level "
                          f"{vs[-1] / ilim['limit']:.4f}, last 3 levels' limit {e['limit'] / ilim['limit']:.4f}")


def check(paths) -> int:
    """Compare every run of ``paths`` at the study's tolerance with the shipped bending study's run
    of the same cell and level (``bending.nc``, level index k - first): peaks and evaluations must
    agree bit for bit. Returns the number of runs that differ."""
    from snapping.continuum import QUANTITIES
    from snapping.regimes import bundled_study

    ds = bundled_study("bending")
    first = int(ds.attrs["first"])
    same = differ = 0
    for path in paths:
        for key, r in load(path).items():
            if len(key.split()) != 3:
                continue
            chi, beta, k = float(key.split()[0]), float(key.split()[1]), int(key.split()[2])
            lv = k - first
            if chi not in ds.chi.values or not 0 <= lv < ds.sizes["level"] or (beta and beta not in ds.number.values):
                continue
            c = ds.sel(chi=chi).isel(level=lv)
            if beta:
                c = c.sel(number=beta)
            sfx = "_level" if beta else "_ideal_level"
            ok = all(float(c[q + sfx]) == r[q] for q in QUANTITIES + ("n_rhs", "n_links"))
            same, differ = same + ok, differ + (not ok)
            if not ok:
                print(f"  differs: {key} ({path})")
    print(f"bit for bit against bending.nc: {same} runs identical, {differ} differ")
    return differ


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chi", type=float, nargs="*", default=[])
    ap.add_argument("--beta", type=float, nargs="*", default=[])
    ap.add_argument("--k", type=int, nargs="*", default=[], help="levels: frac = 0.04 * 2**-k")
    ap.add_argument("--out", default=OUT)
    ap.add_argument("--tol", type=float, default=TOL, help="RODAS4's tolerance (default the study's; another one "
                    "is kept under its own key, ' tol=X', which --table lists apart and --extend never seeds)")
    ap.add_argument("--table", action="store_true")
    ap.add_argument("--check", nargs="*", default=None, metavar="JSON",
                    help="compare these files' runs at the study's tolerance with bending.nc's, bit for bit")
    a = ap.parse_args(argv)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    for k in a.k:  # level by level: the coarse levels of every cell first
        for chi in a.chi:
            for beta in [0.0] + list(a.beta):
                run(chi, beta, k, a.out, a.tol if beta else TOL)  # the ideal (DOP853) at the study's
    if a.check is not None:
        raise SystemExit(1 if check(a.check or [a.out]) else 0)
    if a.table or not a.k:
        table(a.out)


if __name__ == "__main__":
    main()
