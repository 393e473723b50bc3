"""How stiff a 3D chain with bending is for the explicit 3D stepper, against the planar run.

The 3D stepper (:mod:`snapping.spatial.solve3d`) is DOP853 only: with bending stiffness its
step is limited by the shortest bending wave (``omega_max ~ 4 N^2 sqrt(beta)``,
:func:`snapping.simulate.stiffness.shortest_wave`), as the planar DOP853's is. This script
runs the same planar problem (the catenary, chi = 0.25, a body with bending ``beta`` and an
optional Kelvin-Voigt damping ratio ``zeta`` of the shortest wave) with the planar DOP853
(``method="dop853"``) and in space (:func:`snapping.spatial.run3d` of
:meth:`Problem3D.from_planar`), to ``t_end``, and prints the evaluations, steps, the median
accepted step times omega_max, and the wall times (with the machine's load).

Usage::

    python benchmarks/bench_body3d.py                               # N 100, 300; beta 1e-4; t_end 0.3
    python benchmarks/bench_body3d.py --N 100,300 --beta 1e-4 --zeta 0,1 --t-end 0.3 --tol 1e-8
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", default="100,300")
    ap.add_argument("--beta", default="1e-4")
    ap.add_argument("--zeta", default="0,1")
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--t-end", type=float, default=0.3)
    ap.add_argument("--tol", type=float, default=1e-8)
    a = ap.parse_args(argv)
    import warnings

    from snapping.simulate import Body, Problem, run
    from snapping.simulate import stiffness as S
    from snapping.spatial import Problem3D, run3d

    warnings.simplefilter("ignore", S.CostWarning)
    print(f"chi={a.chi} t_end={a.t_end} tol={a.tol}; load {os.getloadavg()[0]:.2f}")
    print(f"{'N':>5} {'beta':>7} {'zeta':>5} {'omega_max':>10} | {'2D rhs':>8} {'2D steps':>8} {'2D dt*om':>8} "
          f"{'2D s':>6} | {'3D rhs':>8} {'3D steps':>8} {'3D dt*om':>8} {'3D s':>6} | {'rhs 3D/2D':>9}")
    for N in (int(x) for x in a.N.split(",")):
        for beta in (float(x) for x in a.beta.split(",")):
            for zeta in (float(x) for x in a.zeta.split(",")):
                om, _ = S.shortest_wave(Problem.catenary(a.chi, N, body=Body(beta)).model())
                eta = 0.0
                if zeta > 0.0:  # zeta = 8 (eta/l)/(m h^2 omega) at a uniform chain: eta = zeta m h^3 omega / 8
                    h = 1.0 / N
                    eta = zeta * h * h ** 3 * om / 8.0
                prob = Problem.catenary(a.chi, N, body=Body(beta, damping=eta))
                t0 = time.perf_counter()
                ds = run(problem=prob, method="dop853", tol=a.tol, t_end=a.t_end, progress=False).dataset
                w2 = time.perf_counter() - t0
                dt2 = np.median(ds["dt"].values[1:])
                t0 = time.perf_counter()
                res = run3d(Problem3D.from_planar(prob), tol=a.tol, t_end=a.t_end)
                w3 = time.perf_counter() - t0
                dt3 = np.median(res["record"][1:, 1])
                n2, n3 = int(ds.attrs["n_rhs"]), res["n_rhs"]
                print(f"{N:>5} {beta:>7.0e} {zeta:>5.2g} {om:>10.4g} | {n2:>8} {int(ds.attrs['n_steps']):>8} "
                      f"{dt2 * om:>8.3g} {w2:>6.2f} | {n3:>8} {res['n_steps']:>8} {dt3 * om:>8.3g} {w3:>6.2f} | "
                      f"{n3 / n2:>9.3f}")
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
