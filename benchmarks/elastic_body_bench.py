"""Benchmark: the extensible line with a body (bending stiffness beta, air drag) on scipy's
Radau (:mod:`snapping.simulate.elastic_body`: the springs' analytic Jacobian blocks plus the
body's by coloured central differences, a 5-block band), to the snap from the ``"matched"``
start. For each N and wave speed c: the peaks, steps, right-hand-side evaluations,
Jacobians and LU factorisations, wall and CPU time; with ``--plain`` the same line without a
body beside it (what the body costs); with ``--combos`` the bending and the drag apart and
together, and the inextensible chain (:func:`snapping.simulate.run`, ``method="fast"``,
tol 1e-10) with the same body (what each caps).

Usage::

    PYTHONPATH=src python benchmarks/elastic_body_bench.py --N 100 400 --c 30 300 --beta 1e-4 --drag 1 --tol 1e-6
    PYTHONPATH=src python benchmarks/elastic_body_bench.py --N 100 --c 30 --combos
    PYTHONPATH=src python benchmarks/elastic_body_bench.py --N 100 400 --c 30 300 --method radau rodas4

``--method`` takes several methods (the compiled RODAS4 takes a body since branch rodasbody:
:mod:`snapping.simulate.elastic_rodas_body`); with more than one, each body's peaks are compared with
the first method's (relative differences).
"""

from __future__ import annotations

import os

# one BLAS thread: scipy Radau's small products (3 x n) otherwise wait on the busy machine's threads
# (measured: N = 400 to t = 0.5, 4.0 s CPU with the default threads under load ~3, 1.0 s with one)
for _k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_k, "1")

import argparse  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

from snapping.simulate import Body, run
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chi", type=float, default=0.3)
    ap.add_argument("--N", type=int, nargs="+", default=[100, 400])
    ap.add_argument("--c", type=float, nargs="+", default=[30.0, 300.0])
    ap.add_argument("--beta", type=float, default=1e-4)
    ap.add_argument("--drag", type=float, default=1.0, help="drag_normal")
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--method", nargs="+", default=["radau"], choices=("radau", "dop853", "rodas4"))
    ap.add_argument("--start", default="matched")
    ap.add_argument("--plain", action="store_true", help="also the line without a body")
    ap.add_argument("--combos", action="store_true", help="bending and drag apart and together, and the chain")
    a = ap.parse_args(argv)
    print(f"machine: {platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, "
          f"load {open('/proc/loadavg').read().split()[:3]}")
    print(f"chi={a.chi} beta={a.beta} drag_normal={a.drag} tol={a.tol} method={a.method} start={a.start}")
    print(f"{'N':>5} {'c':>6} {'body':>5} {'method':>6} {'status':>9} {'v_peak':>9} {'a_peak':>10} {'sig_peak':>9} "
          f"{'kap_peak':>9} {'steps':>6} {'n_rhs':>8} {'n_jac':>6} {'n_lu':>6} {'drift':>8} {'wall s':>7} {'cpu s':>7}")
    for N in a.N:
        for c in a.c:
            kinds = {"both": Body(a.beta, drag_normal=a.drag)}
            if a.plain or a.combos:
                kinds["none"] = None
            if a.combos:
                kinds.update({"bend": Body(a.beta), "drag": Body(drag_normal=a.drag), "chain": kinds["both"]})
            for kind, body in kinds.items():
                p = Problem.catenary(a.chi, links=Links.uniform(N, lumping="shared"), body=body)
                first = None
                for method in (a.method if kind != "chain" else ["fast"]):
                    w0, c0 = time.perf_counter(), time.process_time()
                    if kind == "chain":
                        d = run(problem=p, tol=1e-10, method="fast", progress=False).dataset.attrs
                        d = {**d, "n_jac": 0, "n_lu": 0}
                    else:
                        d = solve(p, Elastic.from_wave_speed(c), tol=a.tol, method=method, start=a.start).dataset.attrs
                    w, cp = time.perf_counter() - w0, time.process_time() - c0
                    print(f"{N:5d} {c:6g} {kind:>5} {method:>6} {d['status']:>9} {d['v_peak']:9.5f} {d['a_peak']:10.4g} "
                          f"{d['sigma_peak']:9.5f} {d['kappa_peak']:9.4f} {d['n_steps']:6d} {d['n_rhs']:8d} "
                          f"{d['n_jac']:6d} {d['n_lu']:6d} {d['energy_drift']:8.1e} {w:7.2f} {cp:7.2f}", flush=True)
                    if first is None:
                        first = d
                    else:
                        print("      peaks vs " + a.method[0] + ": " + ", ".join(
                            f"{k} {d[k] / first[k] - 1.0:+.2e}" for k in ("v_peak", "a_peak", "sigma_peak")), flush=True)
    print(f"load after: {open('/proc/loadavg').read().split()[:3]}")


if __name__ == "__main__":
    main()
