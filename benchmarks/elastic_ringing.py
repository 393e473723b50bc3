"""Diagnosis: which links of the falling elastic line flip slack/taut, how often, at what frequency
and with what amplitude (chi = 0.25, released from the stretched equilibrium, to the snap).

For each listed link: its mean strain, the rms of its strain about a running mean over 0.05
(the ringing), the dominant frequency of that ringing (cycles per time unit sqrt(L/g)), the
fraction of the samples it is slack and its number of slack/taut flips; the grid-scale
frequency 2c/h/(2 pi) and the slowest longitudinal one c/(4L) for comparison.

Usage::

    PYTHONPATH=src python benchmarks/elastic_ringing.py --N 30 --c 30 [--grid-damping 1] [--plot ringing.png]
"""

from __future__ import annotations

import argparse

import numpy as np

from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=30)
    ap.add_argument("--c", type=float, default=30.0)
    ap.add_argument("--grid-damping", type=float, default=0.0)
    ap.add_argument("--samples", type=int, default=2000)
    ap.add_argument("--plot", default=None, help="write a figure: strain against time and arclength")
    a = ap.parse_args(argv)
    p = Problem.catenary(0.25, links=Links.uniform(a.N, lumping="shared"))
    el = Elastic.from_wave_speed(a.c, grid_damping=a.grid_damping)
    s = solve(p, el, tol=1e-6).summary()
    ts = s["t_final"]
    r = solve(p, el, tol=1e-6, t_end=ts, snapshot_times=np.linspace(0.0, ts, a.samples + 1)[1:-1])
    ds = r.dataset
    t, E = ds.t_snapshot.values, ds.strain.values
    keep = np.r_[True, np.diff(t) > 1e-12]
    t, E = t[keep], E[keep]
    print(f"N={a.N} c={a.c:g} zeta={a.grid_damping:g}: steps {s['n_steps']}, evaluations {s['n_rhs']}, "
          f"steps with a slack link {s['n_slack_steps']}, t_snap {s['t_snap_v']:.4f}")
    print(f"grid-scale frequency 2c/h/(2 pi) = {a.c * a.N / np.pi:.1f}, slowest c/(4L) = {a.c / 4:.2f} (per sqrt(L/g))")
    tu = np.linspace(0.0, t[-1], 4096)
    w = max(3, int(0.05 / (tu[1] - tu[0])))
    slack = E <= 0.0
    flips = np.abs(np.diff(slack.astype(int), axis=0)).sum(0)
    print(f"{'link':>5} {'s_free':>7} {'mean':>10} {'ring rms':>9} {'f_ring':>7} {'slack':>6} {'flips':>6}")
    for j in sorted({0, 1, 2, a.N // 6, a.N // 3, a.N // 2, 2 * a.N // 3, 5 * a.N // 6, a.N - 1}):
        e = np.interp(tu, t, E[:, j])
        hp = e - np.convolve(e, np.ones(w) / w, mode="same")
        F = np.abs(np.fft.rfft(hp * np.hanning(hp.size)))
        fr = np.fft.rfftfreq(hp.size, tu[1] - tu[0])
        k = int(np.argmax(F[5:])) + 5
        print(f"{j:>5} {(j + 0.5) / a.N:>7.3f} {e.mean():>+10.2e} {hp.std():>9.2e} {fr[k]:>7.1f} "
              f"{slack[:, j].mean():>6.2f} {flips[j]:>6}")
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 4))
        lim = np.abs(E).max() * 0.3
        im = ax.pcolormesh(ds.s_link.values, t, E, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="auto")
        ax.set_xlabel("arclength from the held end s/L")
        ax.set_ylabel("t / sqrt(L/g)")
        ax.set_title(f"strain, N={a.N}, c={a.c:g}, grid damping {a.grid_damping:g} (blue: slack)")
        fig.colorbar(im, ax=ax)
        fig.savefig(a.plot, dpi=120, bbox_inches="tight")
        print(f"wrote {a.plot}")


if __name__ == "__main__":
    main()
