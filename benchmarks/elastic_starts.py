"""Study: what the elastic line's start costs. The ``"stretched"`` start (the static
equilibrium with both ends held, one let go) launches an unloading wave; the ``"matched"``
start (the rigid chain's tensions after release) does not. For each start and grid damping:
the compiled RODAS4 to the snap, its steps, evaluations and rejected steps, and the links'
slack <-> taut crossings counted between accepted steps, each classed by the strain rate at
the crossing (``|de/dt|`` from the state after it): ``slow`` below ``c^-1.5`` (the geometric
mean of the quasi-static rate, strain T/EA ~ c^-2 changing over t ~ 1, and the ringing's,
amplitude c^-2 at frequency ~ c), ``fast`` above; ``rej@x`` the rejected steps met in the
steps that hold a crossing (a crossing's kink costs rejections), ``rej`` all of them.

With ``--sensitivity EPS,EPS,...``: how well each start's peaks are defined, the run (``--method``,
``--tol``) from the start and from the start moved by ``eps`` (interior nodes x_j += eps sin j,
as ``benchmarks/peers/elastic_sensitivity.py``), the peaks' change quoted.

Usage::

    PYTHONPATH=src python benchmarks/elastic_starts.py --N 300 --c 300 --grid-damping 0 1 --tol 1e-6
    PYTHONPATH=src python benchmarks/elastic_starts.py --N 100 --c 30 --grid-damping 0 --tol 1e-9 --method dop853 \
        --sensitivity 0,1e-12
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from snapping.simulate.elastic import Elastic, ElasticLine, solve
from snapping.simulate.elastic_rodas import RodasStepper
from snapping.simulate.problem import Links, Problem


def crossings(line, z0, t_end, tol, c):
    """Step RODAS4 from z0 to t_end; count the crossings and the rejections around them."""
    st = RodasStepper(line, 0.0, z0, t_end, tol)
    _, e_prev, _ = line.link_state(0.0, z0)
    slow = fast = rej_x = steps = 0
    rates = []
    thr = c ** -1.5
    while st.status == "running":
        r0 = st.nrej
        st.step()
        if st.status == "failed":
            break
        steps += 1
        _, e, ed = line.link_state(st.t, st.y)
        x = np.flatnonzero((e > 0.0) != (e_prev > 0.0))
        if x.size:
            r = np.abs(ed[x])
            rates.append(r)
            nf = int((r > thr).sum())
            fast += nf
            slow += x.size - nf
            rej_x += st.nrej - r0
        e_prev = e
    rates = np.concatenate(rates) if rates else np.zeros(1)
    return {"steps": steps, "rej": st.nrej, "rej_x": rej_x, "slow": slow, "fast": fast,
            "rate50": float(np.median(rates)) * c * c, "rate90": float(np.quantile(rates, 0.9)) * c * c}


def sensitivity(a):
    p = Problem.catenary(a.chi, links=Links.uniform(a.N, lumping="shared"))
    N = a.N
    for c in a.c:
        for zeta in a.grid_damping:
            el = Elastic.from_wave_speed(c, grid_damping=zeta)
            for start in a.starts:
                line = ElasticLine(p, el)
                x, y, vx, vy = line.unpack(line.start(start), 0.0)
                base = None
                for eps in [float(e) for e in a.sensitivity.split(",")]:
                    xx = x.copy()
                    xx[1:N] += eps * np.sin(np.arange(1, N))
                    t0 = time.process_time()
                    s = solve(p, el, tol=a.tol, method=a.method, initial=(xx, y, vx, vy)).summary()
                    pk = np.array([s["v_peak"], s["a_peak"], s["sigma_peak"]])
                    base = pk if base is None else base
                    d = pk / base - 1.0
                    print(f"N={N} c={c:g} zeta={zeta:g} {start} {a.method} tol={a.tol:g} eps={eps:g}: v {pk[0]:.9f} "
                          f"a {pk[1]:.6f} sigma {pk[2]:.6f}; change dv/v {d[0]:.1e} da/a {d[1]:.1e} ds/s {d[2]:.1e}; "
                          f"{s['n_rhs']} evaluations, {time.process_time() - t0:.1f} s CPU", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=300)
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--c", type=float, nargs="+", default=[300.0])
    ap.add_argument("--grid-damping", type=float, nargs="+", default=[0.0, 1.0])
    ap.add_argument("--starts", nargs="+", default=["stretched", "matched"])
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--method", default="rodas4", help="the method of --sensitivity")
    ap.add_argument("--sensitivity", default=None, metavar="EPS,EPS", help="the peaks' change when the start moves")
    a = ap.parse_args(argv)
    if a.sensitivity:
        return sensitivity(a)
    p = Problem.catenary(a.chi, links=Links.uniform(a.N, lumping="shared"))
    print(f"N = {a.N}, chi = {a.chi}, rodas4 tol = {a.tol}; rates in units of c^-2 (the quasi-static strain rate); "
          f"load {os.getloadavg()[0]:.1f}")
    print(f"{'c':>6} {'zeta':>5} {'start':>10} {'steps':>7} {'n_rhs':>8} {'rej':>6} {'rej@x':>6} {'slow':>8} "
          f"{'fast':>8} {'rate50':>9} {'rate90':>9} {'v_peak':>10} {'a_peak':>10} {'cpu_s':>7}")
    for c in a.c:
        for zeta in a.grid_damping:
            el = Elastic.from_wave_speed(c, grid_damping=zeta)
            for start in a.starts:
                t0 = time.process_time()
                s = solve(p, el, tol=a.tol, method="rodas4", start=start).summary()
                cpu = time.process_time() - t0
                line = ElasticLine(p, el)
                d = crossings(line, line.start(start), s["t_final"], a.tol, c)
                print(f"{c:>6g} {zeta:>5g} {start:>10} {s['n_steps']:>7} {s['n_rhs']:>8} {d['rej']:>6} "
                      f"{d['rej_x']:>6} {d['slow']:>8} {d['fast']:>8} {d['rate50']:>9.3g} {d['rate90']:>9.3g} "
                      f"{s['v_peak']:>10.7f} {s['a_peak']:>10.5f} {cpu:>7.1f}", flush=True)


if __name__ == "__main__":
    main()
