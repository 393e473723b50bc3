"""The mooring-like tether of ``elastic_jerk.py`` (OC4-DeepCwind chain, 835 m, a 10 t clump,
jerked taut at 1 m/s after 0.5 m of slack, g = 0) as the 1D lumped line it is, stepped by a
leapfrog written here (independent of the package): the peak link tension against N, far
beyond what the package's runs reach, beside the continuum's closed form.

The line is straight and moves along itself, so the lumped model of
``snapping.simulate.elastic.jerk_taut`` is a 1D chain: node masses lambda h (half at the ends;
the clump added to the far node), links of rest length h = L/N that pull with
``max(0, EA e + BA de/dt)`` while stretched (e > 0) and carry nothing when slack; the held end
moves at V; the link at the held end starts shortened by the slack. Kick-drift leapfrog with
the damping taken from the half-step velocities, dt = 0.1 h/c (and below the explicit limit
of the damping, 0.2 h^2 lambda / BA); the peak is the largest link tension at the steps.

The continuum (d'Alembert): going taut launches a tension step Z V (Z = sqrt(EA lambda)) toward
the clump; the clump (mass M) reflects it as Z V (2 exp(-t Z/M) - 1), a spike that doubles the
tension and decays in M/Z = 34 ms (88 m of line); the held end (a prescribed velocity)
reflects it again with the same sign: 3 Z V = 877 kN at the held end at t_taut + 2 L/c, the
undamped line's peak.

Usage::

    python benchmarks/elastic_jerk_lattice.py                       # undamped, N = 10 ... 2560
    python benchmarks/elastic_jerk_lattice.py --zeta 1               # MoorDyn's BA/-zeta = -1 (per segment)
    python benchmarks/elastic_jerk_lattice.py --ba 1e5 --after 0.6   # a material BA (N s); peak after t = 0.6 s
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

L, LAM, EA, M, V, SLACK = 835.0, 113.35, 7.536e8, 1e4, 1.0, 0.5
C, Z = math.sqrt(EA / LAM), math.sqrt(EA * LAM)


def peak(N: int, ba: float = 0.0, zeta: float = 0.0, after: float = 0.0, frac: float = 0.1):
    """(largest link tension in N, its time in s, its link: 0 at the clump) for t >= ``after``;
    the damping ``ba`` (N s) plus ``zeta h Z`` (MoorDyn's per-segment ratio)."""
    h = L / N
    b = ba + zeta * h * Z
    m = np.full(N, LAM * h)
    m[0] = 0.5 * LAM * h + M
    x = np.arange(N + 1) * h
    x[:N] += SLACK  # the link at the held end shortened by the slack
    v = np.zeros(N + 1)
    v[N] = V
    dt = frac * h / C if b == 0.0 else min(frac * h / C, 0.2 * h * h * LAM / b)
    t_end = SLACK / V + 2.6 * L / C
    k = EA / h
    best = (0.0, 0.0, 0)
    for i in range(int(t_end / dt) + 1):
        t = i * dt
        ext = np.diff(x) - h
        T = np.where(ext > 0.0, np.maximum(0.0, k * ext + b * np.diff(v) / h), 0.0)
        j = int(np.argmax(T))
        if T[j] > best[0] and t >= after:
            best = (float(T[j]), t, j)
        f = np.zeros(N + 1)
        f[:N] += T
        f[1:] -= T
        v[:N] += dt * f[:N] / m
        x += dt * v
    return best


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--N", default="10,20,40,80,160,320,640,1280,2560")
    ap.add_argument("--ba", type=float, default=0.0, help="Kelvin-Voigt damping BA (N s), the same for every N")
    ap.add_argument("--zeta", type=float, default=0.0, help="MoorDyn's per-segment damping ratio (BA = zeta h Z)")
    ap.add_argument("--after", type=float, default=0.0, help="the peak over t >= this (s)")
    ap.add_argument("--frac", type=float, default=0.1, help="the step dt as a fraction of h/c (default 0.1)")
    a = ap.parse_args(argv)
    print(f"Z V = {Z * V / 1e3:.1f} kN, 3 Z V = {3 * Z * V / 1e3:.1f} kN (the undamped continuum's peak), "
          f"t_taut + 2 L/c = {SLACK / V + 2 * L / C:.4f} s, M/Z = {M / Z * 1e3:.1f} ms")
    for N in (int(n) for n in a.N.split(",")):
        w = time.process_time()
        T, t, j = peak(N, a.ba, a.zeta, a.after, a.frac)
        print(f"BA={a.ba:g} N s zeta={a.zeta:g} after {a.after:g} s dt={a.frac:g} h/c  N={N:5d}  peak {T / 1e3:8.2f} kN at t = {t:.4f} s, "
              f"link {j}/{N}  ({time.process_time() - w:.1f} s CPU)", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
