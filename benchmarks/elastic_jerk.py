"""Snap loads of a slack tether jerked taut by its moving end (snapping.simulate.elastic.jerk_taut)
against the closed form of a mass on a massless spring (jerk_peak_force), and a mooring-like line.

1. A 5 kg mass on 3 m of line (EA 20 kN), 0.5 m of slack, the end pulled up at 2 m/s, with and
   without gravity: N = 1 (the closed form's own model) and N = 4 with the line's mass 1e-3 and
   0.05 kg/m (what the line's own mass adds: about V sqrt(EA lambda)).
2. A mooring-like line: the OC4-DeepCwind semisubmersible's chain (Robertson et al. 2014, NREL/TP-
   5000-60601; the same numbers as MoorDyn's OC4 example: 0.0766 m, 113.35 kg/m, EA 753.6 MN),
   835 m, a 10 t clump weight at its far end, on the level (g = 0), jerked at 1 m/s after 0.5 m of
   slack, N = 10 ... 80: the peak against the line's impedance estimate V sqrt(EA lambda) and the
   massless formula.
3. ``--damping BA`` (N s; e.g. 1e5) and ``--N 10,20,...``: the mooring-like line alone with a
   Kelvin-Voigt damping BA the same for every N (a property of the line, not of the grid), the
   peak over all t and over t >= ``--after`` s (default 0.6: past the instant the line goes
   taut, whose damping force BA V/h grows without bound as h -> 0). The docs' elastic guide,
   "The mooring-like tether in N", quotes these beside ``elastic_jerk_lattice.py``.

    PYTHONPATH=src python benchmarks/elastic_jerk.py
    PYTHONPATH=src python benchmarks/elastic_jerk.py --damping 1e5 --N 10,20,40,80,160,320
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from snapping.simulate.elastic import jerk_taut


def row(label, **kw):
    t = time.process_time()
    r = jerk_taut(**kw)
    a = r["run"].dataset.attrs
    z = kw["speed"] * math.sqrt(kw["ea"] * kw["mass_per_length"])
    print(f"{label:34} N={kw['N']:3d} peak {r['peak_force']:11.1f} N  formula {r['formula_force']:11.1f} N  "
          f"ratio-1 {r['peak_force'] / r['formula_force'] - 1:+.3e}  V sqrt(EA lam) {z:9.1f} N  "
          f"t_peak {r['t_peak_run']:.4f} s (formula {r['t_peak']:.4f})  n_rhs {a['n_rhs']}  "
          f"CPU {time.process_time() - t:.1f} s", flush=True)


MOOR = dict(mass=1e4, speed=1.0, slack=0.5, ea=7.536e8, length=835.0, mass_per_length=113.35, g=0.0, tol=1e-6)


def damped_row(N: int, damping: float, after: float) -> None:
    """The mooring-like line with Kelvin-Voigt ``damping`` (N s): the peak over all t and over t >= ``after`` s."""
    t = time.process_time()
    r = jerk_taut(**MOOR, N=N, damping=damping)
    ds = r["run"].dataset
    a = ds.attrs
    force = r["peak_force"] / a["sigma_peak"]  # N per unit of the run's force
    ts = ds["t"].values * MOOR["length"] / MOOR["speed"]  # s
    sig = np.where(ts >= after, ds["sigma_max"].values, -np.inf)
    k = int(np.argmax(sig))
    print(f"OC4 chain, 10 t clump, BA {damping:g} N s  N={N:4d}  peak {r['peak_force'] / 1e3:9.2f} kN at "
          f"{r['t_peak_run']:.4f} s;  after {after:g} s: {sig[k] * force / 1e3:9.2f} kN at {ts[k]:.4f} s (steps)  "
          f"n_rhs {a['n_rhs']}  CPU {time.process_time() - t:.1f} s", flush=True)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--damping", type=float, default=None, help="the mooring-like line alone, with this BA (N s)")
    ap.add_argument("--N", default="10,20,40,80,160,320")
    ap.add_argument("--after", type=float, default=0.6)
    args = ap.parse_args()
    if args.damping is not None:
        for n in (int(x) for x in args.N.split(",")):
            damped_row(n, args.damping, args.after)
        raise SystemExit(0)
    base = dict(mass=5.0, speed=2.0, slack=0.5, ea=2e4, length=3.0, tol=1e-8)
    for g in (0.0, 9.81):
        row(f"5 kg, lam 1e-4, g {g}", **base, mass_per_length=1e-4, N=1, g=g)
    for lam, g in ((1e-3, 9.81), (0.05, 9.81), (0.05, 0.0)):
        row(f"5 kg, lam {lam:g}, g {g}", **{**base, "tol": 1e-6}, mass_per_length=lam, N=4, g=g)
    for N in (10, 20, 40, 80):
        row("OC4 chain 835 m, 10 t clump", **MOOR, N=N)
