"""Benchmark: RODAS4 in link coordinates (``method="rodas4-links"``) against the inextensible run.

chi = 0.25, N links (shared lumping), the matched start, undamped, to the snap (v_max falls
to half its peak). For each wave speed c: a reference run (``rodas4-links`` at ``--ref-tol``),
then ``rodas4-links`` at each ``--tol``: steps, right-hand-side evaluations, CPU time (process
time) and its multiple of the inextensible fast run's (``run(method="fast", tol=1e-10)``), the
peaks of v, a and sigma relative to the reference's and the worst of the three. Optionally the
Cartesian (node) ``rodas4`` at ``--cart-tol`` (the same columns) and a Cartesian reference at
``--cart-ref`` (every run's worst peak error is then also quoted against it: ``worst_cart``).

Usage::

    PYTHONPATH=src python benchmarks/bench_elastic_links.py                       # N = 1000, c = 30, 300, 3000
    PYTHONPATH=src python benchmarks/bench_elastic_links.py --N 200 --c 300 --tol 1e-5 --cart-tol 1e-6

CPU times are noisy on a shared machine: the load average is printed with them.
"""

from __future__ import annotations

import argparse
import os
import time

from snapping.simulate import run
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem

KEYS = ("v_peak", "a_peak", "sigma_peak")


def _solve(p, c, method, tol, max_rhs):
    t0 = time.process_time()
    s = solve(p, Elastic.from_wave_speed(c), tol=tol, method=method, start="matched", max_rhs=max_rhs).summary()
    return s, time.process_time() - t0


def _errs(s, ref):
    return [s[k] / ref[k] - 1.0 for k in KEYS]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=1000)
    ap.add_argument("--c", type=float, nargs="+", default=[30.0, 300.0, 3000.0])
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--tol", type=float, nargs="+", default=[1e-5, 1e-6, 1e-7])
    ap.add_argument("--ref-tol", type=float, default=1e-8, help="tol of the rodas4-links reference run")
    ap.add_argument("--cart-tol", type=float, nargs="*", default=[], help="tols of Cartesian rodas4 runs")
    ap.add_argument("--cart-ref", type=float, default=None, help="tol of a Cartesian rodas4 reference run")
    ap.add_argument("--max-rhs", type=int, default=5_000_000)
    a = ap.parse_args(argv)
    p = Problem.catenary(a.chi, links=Links.uniform(a.N, lumping="shared"))
    # (compile)
    run(problem=p, method="fast", tol=1e-10)
    small = Problem.catenary(a.chi, links=Links.uniform(10, lumping="shared"))
    for m in ("rodas4-links", "rodas4"):
        solve(small, Elastic.from_wave_speed(30.0), tol=1e-5, method=m, start="matched", t_end=0.05)
    t0 = time.process_time()
    fast = run(problem=p, method="fast", tol=1e-10).summary()
    cpu_fast = time.process_time() - t0
    print(f"chi = {a.chi}, N = {a.N}, matched start, undamped; load average {os.getloadavg()[0]:.1f}")
    print(f"fast (inextensible, tol 1e-10): {fast['n_steps']} steps, {fast['n_rhs']} evaluations, CPU "
          f"{cpu_fast:.3f} s; v {fast['v_peak']:.8g} a {fast['a_peak']:.8g} sigma {fast['sigma_peak']:.8g}")
    hdr = ("| c | method | tol | steps | evaluations | CPU s | x fast | dv/v | da/a | dsigma/sigma | worst |"
           + (" worst_cart |" if a.cart_ref else "") + " status |")
    print(hdr)
    print("|" + "---|" * (hdr.count("|") - 1))
    for c in a.c:
        ref, cpu = _solve(p, c, "rodas4-links", a.ref_tol, a.max_rhs)
        rows = [("rodas4-links (ref)", a.ref_tol, ref, cpu)]
        cref = None
        if a.cart_ref:
            cref, cpu = _solve(p, c, "rodas4", a.cart_ref, a.max_rhs)
            rows.append(("rodas4 (cart ref)", a.cart_ref, cref, cpu))
        for tol in a.tol:
            rows.append(("rodas4-links", tol) + _solve(p, c, "rodas4-links", tol, a.max_rhs))
        for tol in a.cart_tol:
            rows.append(("rodas4", tol) + _solve(p, c, "rodas4", tol, a.max_rhs))
        for name, tol, s, cpu in rows:
            e = _errs(s, ref)
            line = (f"| {c:g} | {name} | {tol:.0e} | {s['n_steps']} | {s['n_rhs']} | {cpu:.2f} | "
                    f"{cpu / cpu_fast:.2f} | "
                    f"{e[0]:+.1e} | {e[1]:+.1e} | {e[2]:+.1e} | {max(abs(x) for x in e):.1e} |")
            if cref is not None:
                line += f" {max(abs(x) for x in _errs(s, cref)):.1e} |"
            print(line + f" {s['stop_reason']} |", flush=True)
        print(f"(c = {c:g}: reference peaks against the fast run's: "
              + ", ".join(f"{k} {ref[k] / fast[k] - 1.0:+.2e}" for k in KEYS) + f"; load {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
