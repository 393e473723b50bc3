"""Benchmark: the stretching study's cells by node RODAS4 and by RODAS4 in link coordinates (issue 24).

For each cell (chi, c) of the regime study (``snapping.regimes.cell_problem``) and each fold level K
(``level_parameters(8, 0.5, first=-4)``: K = -4, -3, -2 are the shipped study's levels, -1 ... 2 the
other scans' 1% levels), from the matched start, the stop rule armed at ``STRETCH_STOP_FLOOR``, at the
study's tolerance (``stretch_tol(TOL, c)``), capped at ``--max-rhs`` evaluations:

* ``node z4``: the study's run (``method="rodas4"``, grid damping 4);
* ``links z4``: ``method="rodas4-links"``, the same grid damping;
* ``links z0``: ``method="rodas4-links"``, undamped;
* ``ref z4`` / ``ref z0``: ``rodas4-links`` at ``--ref-tol`` (the reference of each damping).

Per run: v, a and sigma peaks, evaluations, steps, CPU seconds (``time.process_time``), status; the
peaks' relative differences to the reference of the same damping. Results are appended to ``--out``
(JSON lines; a rerun skips the runs already there), ``--table`` reprints the table from it.

Usage::

    PYTHONPATH=src python benchmarks/stretch_links.py --chi 0.5 0.3 0.1 --c 442 38.5 7.52 --levels -4 -3 -2 \\
        --out benchmarks/results/stretch_links.jsonl
    PYTHONPATH=src python benchmarks/stretch_links.py --table --out benchmarks/results/stretch_links.jsonl
    PYTHONPATH=src python benchmarks/stretch_links.py --summary    # per cell over levels -4, -3, -2
    PYTHONPATH=src python benchmarks/stretch_links.py --chi 0.5 0.1 --c 442 38.5 7.52 --levels -1 0 1 2 \
        --runs "links z4" --max-rhs 100000                         # the 1% levels
    PYTHONPATH=src python benchmarks/stretch_links.py --tol 1e-7 --chi 0.5 --c 196 87 442 1000 --levels 2 \
        --runs "links z4" --max-rhs 100000 --out benchmarks/results/stretch_links_tol1e-7.jsonl

CPU times are noisy on a shared machine: the load average is stored with each run.
"""

from __future__ import annotations

import argparse
import json
import os
import time

from snapping.continuum import level_parameters
from snapping.regimes import cell_problem
from snapping.regimes_spec import STRETCH_DAMPING, STRETCH_MAX_RHS, STRETCH_STOP_FLOOR, stretch_tol
from snapping.simulate.elastic import Elastic, solve

KEYS = ("v_peak", "a_peak", "sigma_peak")
RUNS = {  # name -> (method, grid damping, reference?)
    "node z4": ("rodas4", STRETCH_DAMPING, False),
    "links z4": ("rodas4-links", STRETCH_DAMPING, False),
    "links z0": ("rodas4-links", 0.0, False),
    "ref z4": ("rodas4-links", STRETCH_DAMPING, True),
    "ref z0": ("rodas4-links", 0.0, True),
}


def one(chi, c, k, name, tol, ref_tol, max_rhs):
    method, zeta, is_ref = RUNS[name]
    lv = level_parameters(8, 0.5, first=-4)[k + 4]
    p = cell_problem(chi, "stretching", 1.0 / c, lv)
    t0 = time.process_time()
    ds = solve(p, Elastic.from_wave_speed(c, grid_damping=zeta), tol=ref_tol if is_ref else stretch_tol(tol, c),
               method=method, stop_floor=STRETCH_STOP_FLOOR, start="matched", max_rhs=max_rhs).dataset
    cpu = time.process_time() - t0
    a = ds.attrs
    return {"chi": chi, "c": c, "k": k, "run": name, "N": int(p.links.N), "tol": ref_tol if is_ref else stretch_tol(tol, c),
            **{q: float(a[q]) for q in KEYS}, "n_rhs": int(a["n_rhs"]), "n_steps": int(a["n_steps"]),
            "cpu": cpu, "status": str(a["status"]), "stop_reason": str(a.get("stop_reason", "")), "peak_note": str(a.get("peak_note", "")),
            "load": os.getloadavg()[0]}


def table(rows):
    by = {(r["chi"], r["c"], r["k"], r["run"]): r for r in rows}
    cells = sorted({(r["chi"], r["c"], r["k"]) for r in rows}, key=lambda x: (-x[0], -x[1], x[2]))
    print("| chi | c | K | N | run | evaluations | steps | CPU s | v_peak | dv/v | da/a | dsigma/sigma | status |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for cell in cells:
        for name in ("node z4", "links z4", "links z0", "ref z4", "ref z0"):
            r = by.get(cell + (name,))
            if r is None:
                continue
            ref = by.get(cell + ("ref z0" if name.endswith("z0") else "ref z4",))
            if ref is not None and not name.startswith("ref") and r["status"] == "completed":
                d = " | ".join(f"{r[q] / ref[q] - 1:+.1e}" for q in KEYS)
            else:
                d = "- | - | -"
            print(f"| {cell[0]:g} | {cell[1]:g} | {cell[2]} | {r['N']} | {name} | {r['n_rhs']} | {r['n_steps']} | "
                  f"{r['cpu']:.2f} | {r['v_peak']:.6f} | {d} | {r['status']} |")
    # node z4 vs links z4 (same damping), and damped vs undamped links
    print()
    print("| chi | c | K | CPU node z4 / links z4 / links z0 | links z4 vs node z4: dv, da, dsigma | links z0 vs links z4: dv, dsigma |")
    print("|---|---|---|---|---|---|")
    for cell in cells:
        n, l4, l0 = (by.get(cell + (x,)) for x in ("node z4", "links z4", "links z0"))
        if n is None or l4 is None or l0 is None:
            continue
        if n["status"] != "completed":
            print(f"| {cell[0]:g} | {cell[1]:g} | {cell[2]} | {n['cpu']:.2f} / {l4['cpu']:.2f} / {l0['cpu']:.2f} | "
                  f"node {n['status']} ({n['n_rhs']} evaluations) | "
                  + ", ".join(f"{l0[q] / l4[q] - 1:+.1e}" for q in ("v_peak", "sigma_peak")) + " |")
            continue
        print(f"| {cell[0]:g} | {cell[1]:g} | {cell[2]} | {n['cpu']:.2f} / {l4['cpu']:.2f} / {l0['cpu']:.2f} | "
              + ", ".join(f"{l4[q] / n[q] - 1:+.1e}" for q in KEYS) + " | "
              + ", ".join(f"{l0[q] / l4[q] - 1:+.1e}" for q in ("v_peak", "sigma_peak")) + " |")
    for name in ("node z4", "links z4", "links z0"):
        rs = [by[cl + (name,)] for cl in cells if all(cl + (x,) in by for x in ("node z4", "links z4", "links z0"))]
        if rs:
            print(f"{name}: {len(rs)} runs (the cells with all three), {sum(r['cpu'] for r in rs):.1f} s CPU, "
                  f"{sum(r['n_rhs'] for r in rs)} evaluations, {sum(r['status'] != 'completed' for r in rs)} failed")
    loads = [r["load"] for r in rows]
    print(f"\n{len(rows)} runs, {sum(r['cpu'] for r in rows):.0f} s CPU, load {min(loads):.1f}-{max(loads):.1f}")


def summary(rows, levels=(-4, -3, -2)):
    """Per cell (chi, c) over ``levels``: summed CPU and evaluations of each method, the worst peak
    differences to the reference of the same damping, and the grid damping's effect on v_peak."""
    by = {(r["chi"], r["c"], r["k"], r["run"]): r for r in rows}
    cells = sorted({(r["chi"], r["c"]) for r in rows}, key=lambda x: (-x[0], -x[1]))
    print(f"levels {list(levels)}")
    print("| chi | c | CPU s node z4 / links z4 / links z0 | evaluations node z4 / links z4 / links z0 | "
          "worst peak error (v, a, sigma) node z4 | links z4 | links z0 | v_peak z0 / z4 - 1 |")
    print("|---|---|---|---|---|---|---|---|")
    for chi, c in cells:
        if not all((chi, c, k, n) in by for k in levels for n in RUNS):
            continue
        cpu = [sum(by[(chi, c, k, n)]["cpu"] for k in levels) for n in ("node z4", "links z4", "links z0")]
        ev = [sum(by[(chi, c, k, n)]["n_rhs"] for k in levels) for n in ("node z4", "links z4", "links z0")]
        worst = []
        for n, ref in (("node z4", "ref z4"), ("links z4", "ref z4"), ("links z0", "ref z0")):
            rs = [(by[(chi, c, k, n)], by[(chi, c, k, ref)]) for k in levels]
            nf = sum(r["status"] != "completed" for r, _ in rs)
            w = [max(abs(r[q] / f[q] - 1) for r, f in rs if r["status"] == "completed") if nf < len(rs) else float("nan")
                 for q in KEYS]
            worst.append(", ".join(f"{x:.0e}" for x in w) + (f" ({nf} failed)" if nf else ""))
        dz = [by[(chi, c, k, "links z0")]["v_peak"] / by[(chi, c, k, "links z4")]["v_peak"] - 1 for k in levels]
        print(f"| {chi:g} | {c:g} | {cpu[0]:.2f} / {cpu[1]:.2f} / {cpu[2]:.2f} | {ev[0]} / {ev[1]} / {ev[2]} | "
              f"{worst[0]} | {worst[1]} | {worst[2]} | " + ", ".join(f"{x:+.1e}" for x in dz) + " |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chi", type=float, nargs="+", default=[0.5, 0.3, 0.1])
    ap.add_argument("--c", type=float, nargs="+", default=[442.0, 38.5, 7.52])
    ap.add_argument("--levels", type=int, nargs="+", default=[-4, -3, -2])
    ap.add_argument("--runs", nargs="+", default=list(RUNS), choices=list(RUNS))
    ap.add_argument("--tol", type=float, default=1e-6, help="the study's tolerance")
    ap.add_argument("--ref-tol", type=float, default=1e-8)
    ap.add_argument("--max-rhs", type=int, default=STRETCH_MAX_RHS)
    ap.add_argument("--out", default="benchmarks/results/stretch_links.jsonl")
    ap.add_argument("--table", action="store_true")
    ap.add_argument("--summary", action="store_true", help="per cell over the study's levels -4, -3, -2")
    a = ap.parse_args(argv)
    rows = []
    if os.path.exists(a.out):
        with open(a.out) as f:
            rows = [json.loads(line) for line in f if line.strip()]
    if a.table or a.summary:
        table(rows) if a.table else summary(rows)
        return
    done = {(r["chi"], r["c"], r["k"], r["run"]) for r in rows}
    small = cell_problem(0.5, "stretching", 0.1, {"n_links": 4, "frac": 0.25})  # (compile)
    for m in ("rodas4", "rodas4-links"):
        solve(small, Elastic.from_wave_speed(10.0, grid_damping=1.0), tol=1e-5, method=m, stop_floor=1.0,
              start="matched")
    for chi in a.chi:
        for c in a.c:
            for k in a.levels:
                for name in a.runs:
                    if (chi, c, k, name) in done:
                        continue
                    r = one(chi, c, k, name, a.tol, a.ref_tol, a.max_rhs)
                    print(json.dumps(r), flush=True)
                    with open(a.out, "a") as f:
                        f.write(json.dumps(r) + "\n")


if __name__ == "__main__":
    main()
