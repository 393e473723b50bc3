"""The bungee's snap against the inextensible chain with the same links (issue 22, item 4).

The catalogue's bungee cord (snapping.lines: 10 mm, 65 g/m, EA about 200 N, an estimate) 1 m
long, released from the catenary of chi = 0.25: the extensible, tension-only line
(snapping.simulate.elastic, stretched start, grid damping ZETA) against the rigid-link chain of
the same N uniform links and shared lumped masses (method fast). Prints the peaks (nondimensional
and SI), when and where they come, and where the two differ.

    PYTHONPATH=src python benchmarks/elastic_bungee.py --N 30 --grid-damping 1
"""

from __future__ import annotations

import argparse
import math

from snapping import lines
from snapping.simulate import run
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--N", type=int, default=30)
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--length", type=float, default=1.0, help="m")
    ap.add_argument("--grid-damping", type=float, default=1.0)
    ap.add_argument("--tol", type=float, default=1e-6)
    a = ap.parse_args()
    b = lines.get("bungee-cord")
    L, lam, g = a.length, b.mass_per_length, 9.81
    M = lam * L
    F, V, A = M * g, math.sqrt(g * L), g  # force, speed, acceleration units
    c = math.sqrt(b.ea / lam) / V
    p = Problem.catenary(a.chi, links=Links.uniform(a.N, lumping="shared"))
    rig = run(p, method="fast", tol=a.tol, progress=False).dataset.attrs
    el = solve(p, Elastic(ea=b.ea / F, grid_damping=a.grid_damping), tol=a.tol).dataset.attrs
    print(f"bungee cord {L:g} m, {lam * 1e3:g} g/m, EA {b.ea:g} N: c = {c * V:.1f} m/s = {c:.2f} sqrt(gL); "
          f"chi = {a.chi:g}, N = {a.N}, grid damping {a.grid_damping:g}, tol {a.tol:g}")
    print(f"{'':14} {'v_peak':>9} {'m/s':>7} {'a_peak':>9} {'m/s^2':>8} {'sigma_peak':>10} {'N':>7} "
          f"{'t_snap_v':>9} {'s(sigma)':>8} {'n_rhs':>7}")
    for name, r in (("inextensible", rig), ("bungee", el)):
        s_sig = r.get("s_sigma_peak", float("nan"))
        print(f"{name:14} {r['v_peak']:9.4f} {r['v_peak'] * V:7.2f} {r['a_peak']:9.1f} {r['a_peak'] * A:8.0f} "
              f"{r['sigma_peak']:10.3f} {r['sigma_peak'] * F:7.3f} {r['t_snap_v']:9.4f} {s_sig:8.3f} "
              f"{int(r['n_rhs']):7d}")
    for q in ("v_peak", "a_peak", "sigma_peak", "t_snap_v"):
        print(f"  {q}: bungee / inextensible - 1 = {el[q] / rig[q] - 1:+.3g}")
    print(f"  inextensible: compression (negative tension) from t = {rig.get('t_compression', float('nan')):.4g}, "
          f"least tension {rig.get('min_tension', float('nan')):.3g} at t = {rig.get('t_min_tension', float('nan')):.4g}"
          f", s = {rig.get('s_min_tension', float('nan')):.3g}")
    print(f"  bungee: first slack link at t = {el['t_first_slack']:.4g}; {el['n_slack_steps']} of {el['n_steps']} "
          f"steps with a slack link; peak strain {el['strain_peak']:.3g}; energy drift {el['energy_drift']:.2g}, "
          f"dissipated {el['dissipated_total']:.2g} (of E0 {el['energy_initial']:.3g})")


if __name__ == "__main__":
    main()
