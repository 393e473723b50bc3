"""Where one of this project's elastic runs spends its CPU time (issue 22, the side-by-side table):
the compiled RODAS4 step loop against the fixed costs around it, on the peers' problem
(``elastic_common.py``: chi = 0.25, EA = c^2, the start given as ``initial``, as the table runs it).

Each run of ``elastic.solve(..., method="rodas4")`` is split, by timing wrappers (CPU time,
``time.process_time``) around its parts, into:

* ``setup``: the line (``ElasticLine``), the start's checks (``_initial``), the stepper
  (``RodasStepper``: its arrays, the first step's guess) and the compiled loop's buffers
  (``RodasRun``);
* ``loop``: the compiled step loop (``RodasRun.advance``: steps, records, peaks, stop rule);
* ``refine``: the peaks' refinement (``elastic_refine.refine``, compiled, or ``_Peaks.refine``
  with ``COMPILED_REFINE = False``: the dense output sampled, a few states integrated again from a
  step's start);
* ``dataset``: the xarray Dataset (``_dataset``);
* ``other``: the rest of ``solve`` (argument checks, the records' concatenation, the attrs).

Printed per (N, c, tol): the evaluations and steps, the smallest and median CPU time of each part
over ``--repeat`` runs, the loop's CPU per step and per evaluation, and the part of the run that
is not the loop. The same runs with a wrapper timing nothing (``--bare``) are the run's cost as
the table measures it (``elastic_common.run_project``).

Usage::

    python benchmarks/peers/elastic_overhead.py                       # N = 100, c = 30, tol 3e-5 and 3e-4
    python benchmarks/peers/elastic_overhead.py --N 100,400 --c 30,300 --tol 3e-5 --repeat 20
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import elastic_common as E  # noqa: E402

PARTS = ("setup", "loop", "refine", "dataset", "other")


def instrument():
    """Wrap the parts of ``elastic_solve.solve`` with CPU timers; returns the accumulator dict."""
    from snapping.simulate import elastic_advance as EA
    from snapping.simulate import elastic_model as EM
    from snapping.simulate import elastic_refine as ERF
    from snapping.simulate import elastic_rodas as ER
    from snapping.simulate import elastic_solve as ES

    acc = dict.fromkeys(PARTS, 0.0)
    depth = [0]

    def timed(part, fn):
        def wrapper(*args, **kw):
            if depth[0]:  # (a part inside another: counted there)
                return fn(*args, **kw)
            depth[0] += 1
            w = time.process_time()
            try:
                return fn(*args, **kw)
            finally:
                acc[part] += time.process_time() - w
                depth[0] -= 1
        return wrapper

    EM.ElasticLine.__init__ = timed("setup", EM.ElasticLine.__init__)
    ES._initial = timed("setup", ES._initial)
    ER.RodasStepper.__init__ = timed("setup", ER.RodasStepper.__init__)
    EA.RodasRun.__init__ = timed("setup", EA.RodasRun.__init__)
    EA.RodasRun.advance = timed("loop", EA.RodasRun.advance)
    ES._Peaks.refine = timed("refine", ES._Peaks.refine)
    ERF.refine = timed("refine", ERF.refine)
    ES._dataset = timed("dataset", ES._dataset)
    return acc


def measure(chi, N, c, tol, repeat, start="matched"):
    from snapping.simulate.elastic import solve

    p, el = E.problem(chi, N), E.elastic(c)
    ini = E.start_state(chi, N, c, start)
    bare = []
    for _ in range(repeat):  # as the table times a run (elastic_common.run_project)
        w = time.process_time()
        r = solve(p, el, tol=tol, method="rodas4", initial=ini)
        bare.append(time.process_time() - w)
    acc = instrument()
    rows = {k: [] for k in PARTS + ("total",)}
    for _ in range(repeat):
        for k in acc:
            acc[k] = 0.0
        w = time.process_time()
        r = solve(p, el, tol=tol, method="rodas4", initial=ini)
        total = time.process_time() - w
        acc["other"] = total - sum(acc[k] for k in PARTS if k != "other")
        for k in PARTS:
            rows[k].append(acc[k])
        rows["total"].append(total)
    _restore()
    a = r.dataset.attrs
    steps, nrhs = int(a["n_steps"]), int(a["n_rhs"])
    lo = min(rows["loop"])
    print(f"N = {N}, c = {c:g}, tol = {tol:g} (rodas4, start {start}): {nrhs:,} evaluations, {steps:,} steps, "
          f"{int(a['n_lu']):,} LU; v peak {r.peaks['v']['value']:.8f}")
    print(f"  run as the table times it: min {min(bare) * 1e3:.2f} ms, median {np.median(bare) * 1e3:.2f} ms "
          f"({repeat} runs)")
    for k in PARTS + ("total",):
        v = np.asarray(rows[k])
        print(f"  {k:<8} min {v.min() * 1e3:8.2f} ms  median {np.median(v) * 1e3:8.2f} ms  "
              f"({100 * np.median(v) / np.median(rows['total']):4.1f}% of the median run)")
    out = np.asarray(rows["total"]) - np.asarray(rows["loop"])  # per run: all but the compiled loop
    share = out / np.asarray(rows["total"])
    print(f"  loop: {lo / max(steps, 1) * 1e6:.1f} us a step, {lo / max(nrhs, 1) * 1e6:.2f} us an evaluation; "
          f"outside the loop: min {out.min() * 1e3:.2f} ms, median {np.median(out) * 1e3:.2f} ms a run "
          f"({100 * np.median(share):.0f}% of a run, median)\n", flush=True)


_ORIG = {}


def _save_originals():
    from snapping.simulate import elastic_advance as EA
    from snapping.simulate import elastic_model as EM
    from snapping.simulate import elastic_refine as ERF
    from snapping.simulate import elastic_rodas as ER
    from snapping.simulate import elastic_solve as ES

    for obj, name in ((EM.ElasticLine, "__init__"), (ES, "_initial"), (ER.RodasStepper, "__init__"),
                      (EA.RodasRun, "__init__"), (EA.RodasRun, "advance"), (ES._Peaks, "refine"), (ES, "_dataset"),
                      (ERF, "refine")):
        _ORIG[(obj, name)] = getattr(obj, name)


def _restore():
    for (obj, name), fn in _ORIG.items():
        setattr(obj, name, fn)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--N", default="100")
    ap.add_argument("--c", default="30")
    ap.add_argument("--tol", default="3e-5,3e-4", help="RODAS4 tolerances, comma-separated")
    ap.add_argument("--start", default="matched", choices=E.STARTS)
    ap.add_argument("--repeat", type=int, default=20)
    a = ap.parse_args(argv)
    sys.stdout.reconfigure(line_buffering=True)
    E.machine("numba")
    for st in E.STARTS:  # compile before timing
        E.run_project(a.chi, 10, 10.0, 1e-3, "rodas4", st)
    _save_originals()
    for N in (int(x) for x in a.N.split(",")):
        for c in (float(x) for x in a.c.split(",")):
            for tol in (float(x) for x in a.tol.split(",")):
                measure(a.chi, N, c, tol, a.repeat, a.start)
    print(f"uptime: {os.popen('uptime').read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
