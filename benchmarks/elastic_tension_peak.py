"""Where and when the elastic chain's tension peaks, against the rigid chain on the same links
(the stretching factor of snapping.caps: elastic over rigid, peak by peak).

For a catalogue line (its EA and mass per length; ``--line``) at each chi and N: the rigid chain
(the fast method) and the elastic line (``--start``, ``--grid-damping``, ``--method``) on the
same N uniform links (shared lumping), both at ``--tol``, each to its snap. Printed per run: the
three ratios (elastic / rigid: what caps.cap's factor is on those links), the rigid chain's snap
time (its tension peak), the elastic line's tension peak -- its value, where (arclength from the
held end), when (after the rigid chain's snap), how many links were slack at that step and the
tension one step before (a slack link jerked taut jumps in one step) -- the elastic line's
tension and acceleration peaks within the snap (steps up to its speed peak's time + 0.002) over
the rigid chain's, the rigid chain's smallest tension (negative: it carries compression, which
the elastic line cannot), each run's end time, evaluations and CPU seconds (time.process_time).

Usage::

    python benchmarks/elastic_tension_peak.py --line nylon-monofilament --chi 0.1 0.25 --N 30 60 120
    python benchmarks/elastic_tension_peak.py --chi 0.1 --N 30 --grid-damping 0 --tol 1e-8
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from snapping import caps, lines
from snapping.simulate import Links, Problem, run
from snapping.simulate.elastic import Elastic, solve


def one(sp, chi: float, N: int, zeta: float, start: str, method: str, tol: float) -> str:
    p = Problem.catenary(chi, links=Links.uniform(N, lumping="shared"))
    c0 = time.process_time()
    rr = run(p, method="fast", tol=tol, progress=False)
    c1 = time.process_time()
    er = solve(p, Elastic(ea=sp.ea / (sp.mass * sp.g), grid_damping=zeta), tol=tol, method=method, start=start)
    c2 = time.process_time()
    ra, ea, dr, ds = rr.dataset.attrs, er.dataset.attrs, rr.dataset, er.dataset
    t, sm, am = ds["t"].values, ds["sigma_max"].values, ds["a_max"].values
    i = int(np.argmax(sm))
    w = t <= float(ea["t_snap_v"]) + 0.002
    iw, jw = int(np.argmax(np.where(w, sm, -1.0))), int(np.argmax(np.where(w, am, -1.0)))
    smin = dr["sigma_min"].values
    k = int(np.argmin(smin))
    ts = float(ra["t_snap_sigma"])
    r = {q: float(ea[q]) / float(ra[q]) for q in caps.QUANTITIES}
    return (f"| {chi:g} | {N} | {zeta:g} | {start} | {tol:g} | {r['v_peak']:.4f} | {r['a_peak']:.4f} | "
            f"{r['sigma_peak']:.4f} | {ts:.5f} | {sm[i]:.4g} (before: {sm[i - 1]:.4g}) | "
            f"{float(ds['s_sigma_max'][i]):.3f} | "
            f"{t[i] - ts:+.4f} | {int(ds['n_slack'][i])} | {sm[iw] / float(ra['sigma_peak']):.4f} | "
            f"{am[jw] / float(ra['a_peak']):.4f} | {smin[k]:.3g} (t {float(dr['t'][k]):.4f}, "
            f"s {float(dr['s_sigma_min'][k]):.3f}) | "
            f"{float(ra['t_final']):.4f} / {float(ea['t_final']):.4f} | {int(ra['n_rhs'])} / {int(ea['n_rhs'])} | "
            f"{c1 - c0:.2f} / {c2 - c1:.2f} |")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--line", default="nylon-monofilament", choices=[n for n in lines.names() if lines.get(n).ea])
    ap.add_argument("--chi", type=float, nargs="+", default=[0.1, 0.25])
    ap.add_argument("--N", type=int, nargs="+", default=[30, 60, 120])
    ap.add_argument("--grid-damping", type=float, nargs="+", default=[1.0])
    ap.add_argument("--start", nargs="+", default=["matched"], choices=["matched", "stretched"])
    ap.add_argument("--method", default="dop853", choices=["dop853", "rodas4", "radau"])
    ap.add_argument("--tol", type=float, default=1e-6)
    a = ap.parse_args(argv)
    sp = caps.spec(a.line)
    c = (sp.ea / (sp.mass / sp.length)) ** 0.5
    print(f"{platform.node()} {platform.processor() or platform.machine()}, load {os.getloadavg()[0]:.1f}; "
          f"{a.line}: L = {sp.length} m, EA = {sp.ea:.4g} N, c = {c:.4g} m/s = {c / (sp.g * sp.length) ** 0.5:.4g} "
          f"sqrt(gL), L/c = {(sp.g / sp.length) ** 0.5 * sp.length / c:.4g} sqrt(L/g); elastic by {a.method}")
    print("| chi | N | zeta | start | tol | v ratio | a ratio | T ratio | rigid snap t | elastic T peak | at s | "
          "t - snap | slack links | T ratio in snap | a ratio in snap | rigid min T | t_final rigid / elastic | "
          "evaluations rigid / elastic | CPU s rigid / elastic |")
    print("|" + "---|" * 19)
    for chi in a.chi:
        for n in a.N:
            for z in a.grid_damping:
                for st in a.start:
                    print(one(sp, chi, n, z, st, a.method, a.tol), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
