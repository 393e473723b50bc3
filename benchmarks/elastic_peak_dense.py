"""Study: why a_peak of the elastic line seemed to level off as EA -> infinity
(``benchmarks/elastic_ea_limit.py``). For each wave speed c, the elastic run's acceleration
around its peak three ways, relative to the inextensible chain's a_peak: the largest at the
accepted steps' ends; the largest over the ``PEAK_SAMPLES - 1`` interior samples of the steps
around the peak read off the method's dense output (what ``elastic.solve`` reported before the
fix); and the largest over the same samples with the state integrated from the step's start by
the same method (at the run's tol and at tol/100: the states the method reaches).

RODAS4's dense output is of order 3: at an interior time it misplaces the nodes by about the
tolerance, and the part along a link, even at 1e-13, becomes a tension error EA dl/h and an
acceleration error at the free end EA dl/(h m_0) = 2 c^2 N^2 dl (uniform chain, shared lumping):
at N = 100, c = 10000, tol 1e-7 the dense samples sat up to +8.5e-5 (relative) above the states
the method reaches. The refinement now integrates (``elastic_solve._Peaks``).

Usage::

    PYTHONPATH=src python benchmarks/elastic_peak_dense.py --N 100 --tol 1e-7 --c 1000 3000 10000
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from snapping.simulate import elastic_solve as ES
from snapping.simulate import run
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.elastic_rodas import RodasStepper
from snapping.simulate.problem import Links, Problem


def _integrate(line, t0, y0, t1, tol):
    st = RodasStepper(line, t0, y0, t1, tol, h0=t1 - t0)
    while st.status == "running":
        st.step()
    return st.y


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=100)
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--c", type=float, nargs="+", default=[1000.0, 3000.0, 10000.0])
    ap.add_argument("--tol", type=float, default=1e-7)
    ap.add_argument("--start", default="matched", choices=["stretched", "matched", "unstretched"])
    ap.add_argument("--grid-damping", type=float, default=0.0)
    a = ap.parse_args(argv)
    p = Problem.catenary(a.chi, links=Links.uniform(a.N, lumping="shared"))
    A = run(problem=p, method="fast", tol=1e-11).summary()["a_peak"]
    kept = {}
    refine = ES._Peaks.refine

    def spy(self, line, restep):
        kept["a"] = list(self.keep["a"])
        return refine(self, line, restep)

    ES._Peaks.refine = spy
    print(f"N = {a.N}, chi = {a.chi}, start = {a.start}, zeta = {a.grid_damping}, tol = {a.tol}, rodas4, "
          f"load {os.getloadavg()[0]:.1f}; inextensible a_peak = {A:.8g}")
    print(f"{'c':>7} {'steps':>10} {'dense':>10} {'integr.':>10} {'tol/100':>10} {'reported':>10} {'dt':>9} "
          f"{'n_rhs':>9} {'cpu_s':>6}")
    try:
        for c in a.c:
            t0 = time.process_time()
            e = solve(p, Elastic.from_wave_speed(c, grid_damping=a.grid_damping), tol=a.tol, method="rodas4",
                      start=a.start)
            s, line = e.summary(), e.line
            step_max = float(e.dataset["a_max"].values.max())
            dense = integ = fine = -np.inf
            for t_old, y_old, t_new, d in kept["a"]:
                for tt in np.linspace(t_old, t_new, ES.PEAK_SAMPLES + 1)[1:-1]:
                    dense = max(dense, line.measure(tt, d(tt))[2])
                    integ = max(integ, line.measure(tt, _integrate(line, t_old, y_old, tt, a.tol))[2])
                    fine = max(fine, line.measure(tt, _integrate(line, t_old, y_old, tt, a.tol / 100))[2])
            dt = kept["a"][0][2] - kept["a"][0][0]
            print(f"{c:>7g} {step_max / A - 1:>10.3e} {dense / A - 1:>10.3e} {integ / A - 1:>10.3e} "
                  f"{fine / A - 1:>10.3e} {s['a_peak'] / A - 1:>10.3e} {dt:>9.2e} {s['n_rhs']:>9d} "
                  f"{time.process_time() - t0:>6.1f}", flush=True)
    finally:
        ES._Peaks.refine = refine


if __name__ == "__main__":
    main()
