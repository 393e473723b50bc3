"""Study: EA -> infinity. The peaks (v, a, sigma) of the elastic line against the inextensible
chain of the same links (``run(problem=..., method="fast")``) as the wave speed c grows; the
rate p of |peak/peak_inextensible - 1| ~ c^-p fitted over the listed c; and where the peak
tension sits (arclength from the held end, time, slack links in the step before it).

``--start matched`` releases the line stretched to the rigid chain's tensions after release (no
release wave; :func:`snapping.simulate.elastic_statics.matched`), ``stretched`` (default) from
the static equilibrium with both ends held.

From the matched start every peak converges as c^-2 once the snap is slow against the links'
longitudinal period (chi 0.25, N = 200, 3000 -> 10000: rates 2.08 (v), 2.01 (a), 2.13 (sigma);
da/a +1.40e-4, +1.23e-5): along a taut link the strain follows T/EA with corrections of relative
size (omega tau)^-2, omega ~ c/h, and the matched start's ringing has a tension amplitude
T''(0)/omega^2, both O(c^-2) in tension and in acceleration. A floor in a_peak (+1.4e-4 at
c = 3000 and 10000, measured before) was the peak search reading RODAS4's order-3 dense output,
whose error dl along a link becomes 2 c^2 N^2 dl at the free end's acceleration; the peaks are
now refined on integrated states (``benchmarks/elastic_peak_dense.py`` compares the two). At
c = 10000 undamped, a_peak still moves by 2e-5 between tol 1e-7 and 1e-8: the free-end link's
longitudinal ringing (sqrt(3) c/h) that the integration's errors excite and nothing damps; with
``--grid-damping 0.1`` the two agree to 1e-7 (+1.04e-5, +1.03e-5). From
the stretched start the release's front, a strain step T_end/EA moving at c with the particle
velocity T_end/(lambda c) across a few links, carries an acceleration that does not depend on c:
a floor that is physics (docs/guide/elastic.md, "EA -> infinity").

Usage::

    PYTHONPATH=src python benchmarks/elastic_ea_limit.py --N 100 --c 30 100 300 1000 3000 --grid-damping 1
    PYTHONPATH=src python benchmarks/elastic_ea_limit.py --N 200 --grid-damping 0 --start matched
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from snapping.simulate import run
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=100)
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--c", type=float, nargs="+", default=[30.0, 100.0, 300.0, 1000.0, 3000.0])
    ap.add_argument("--grid-damping", type=float, default=1.0)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--method", default="rodas4")
    ap.add_argument("--start", default="stretched", choices=["stretched", "matched", "unstretched"])
    a = ap.parse_args(argv)
    p = Problem.catenary(a.chi, links=Links.uniform(a.N, lumping="shared"))
    r = run(problem=p, method="fast", tol=1e-11)
    ref = r.summary()
    keys = ("v_peak", "a_peak", "sigma_peak")
    print(f"N = {a.N}, chi = {a.chi}, start = {a.start}, zeta = {a.grid_damping}, tol = {a.tol}, {a.method}, "
          f"load {os.getloadavg()[0]:.1f}")
    print(f"inextensible: v={ref['v_peak']:.8g} a={ref['a_peak']:.8g} sigma={ref['sigma_peak']:.8g} "
          f"t_sigma={ref['t_snap_sigma']:.6f}")
    print(f"{'c':>7} {'dv/v':>10} {'da/a':>10} {'ds/s':>10} {'t_sigma':>9} {'s_sigma':>8} {'slack@':>7} "
          f"{'strain_pk':>9} {'n_rhs':>9} {'cpu_s':>7}")
    errs = []
    for c in a.c:
        t0 = time.process_time()
        e = solve(p, Elastic.from_wave_speed(c, grid_damping=a.grid_damping), tol=a.tol, method=a.method,
                  start=a.start)
        s = e.summary()
        w = time.process_time() - t0
        rel = [s[k] / ref[k] - 1.0 for k in keys]
        errs.append(rel)
        es = e.dataset
        k = int(np.searchsorted(es["t"].values, s["t_snap_sigma"]))
        slack = int(es["n_slack"].values[max(k - 1, 0)])
        print(f"{c:>7g} {rel[0]:>10.3e} {rel[1]:>10.3e} {rel[2]:>10.3e} {s['t_snap_sigma']:>9.6f} "
              f"{s['s_sigma_peak']:>8.4f} {slack:>7d} {s['strain_peak']:>9.2e} {s['n_rhs']:>9d} {w:>7.1f}", flush=True)
    if len(a.c) < 2:
        return
    errs = np.abs(np.asarray(errs))
    lc = np.log(np.asarray(a.c))
    for j, k in enumerate(keys):
        pfit = -np.polyfit(lc, np.log(errs[:, j]), 1)[0]
        last = -np.diff(np.log(errs[-2:, j]))[0] / np.diff(lc[-2:])[0]
        print(f"{k}: |error| ~ c^-p, p = {pfit:.2f} (fit over all c), {last:.2f} (last two)")


if __name__ == "__main__":
    main()
