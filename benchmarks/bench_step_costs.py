"""Where the time of a DOP853 step goes: one chain against interleaved lanes (ensembles).

Prints, per node and per chain: the right-hand side (sines/cosines, the tension
recurrence, the angular accelerations), the stage sums and a whole step of a single
run (`rk.rk_step`), then the same parts of the ensemble kernel for W = 4 and 8
interleaved lanes, and the lock-step utilisation of an ensemble (the members advance
one attempt per iteration, so a member that needs fewer attempts idles in its lane
until the others finish or its lane group of 4 empties). Together they bound what an
ensemble can save over single runs on this machine:

    ensemble / singles >= (12 rhs_lane + sums_lane) / (12 rhs_single + sums_single) / utilisation

Usage::

    python benchmarks/bench_step_costs.py                  # N = 1000, members chi = 0.2..0.5
    python benchmarks/bench_step_costs.py --N 2000 --chis 0.2,0.25,0.3,0.35
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from snapping.simulate import angles as AG
from snapping.simulate import ensemble as E
from snapping.simulate import rk as R
from snapping.simulate import run
from snapping.simulate.chain import initial_state

sys.path.insert(0, os.path.dirname(__file__))
from bench_simulate import print_machine  # noqa: E402


def per_call(fn, target_s: float = 0.3) -> float:
    """Best-of-5 seconds per call of fn (after a warm-up call)."""
    fn()
    t0 = time.perf_counter()
    fn()
    n = max(3, int(target_s / max(time.perf_counter() - t0, 1e-7)))
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        best = min(best, (time.perf_counter() - t0) / n)
    return best


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, default=1000, help="links (default 1000)")
    p.add_argument("--chis", default="0.2,0.243,0.286,0.329,0.371,0.414,0.457,0.5",
                   help="ensemble members for the utilisation (default 8 values 0.2..0.5)")
    p.add_argument("--tol", type=float, default=1e-8)
    a = p.parse_args(argv)
    N, n = a.N, 2 * a.N
    chis = [float(c) for c in a.chis.split(",")]
    print_machine()

    y = AG.state_to_angles(initial_state(0.25, N, chords="exact"))
    y = y + 1e-3 * np.random.default_rng(0).standard_normal(y.size)  # a generic moving state
    c, s, S, cp, dp, sig = (np.zeros(N) for _ in range(6))
    f, yt, y1 = np.zeros(n), np.zeros(n), np.zeros(n)
    Kst = np.zeros((R.NS + 1, n))
    Kst[:] = y
    ns = 1e9 / N
    t_sc = per_call(lambda: AG.sincos(N, y, c, s)) * ns
    t_rhs = per_call(lambda: AG.angle_rhs(N, y, f, c, s, S, cp, dp, sig)) * ns
    t_sum = per_call(lambda: [R._stage_state(n, st, 1e-3, y, Kst, yt) for st in range(1, R.NS)]) * ns
    t_step = per_call(lambda: R.rk_step(N, 1e-4, y, y1, Kst, yt, c, s, S, cp, dp, sig, a.tol)) * ns
    print(f"ns per node, N = {N}        sincos     rhs  stage sums/step  whole step  12 rhs + sums")
    print(f"  single chain          {t_sc:8.2f} {t_rhs:7.2f} {t_sum:16.2f} {t_step:11.1f} {12 * t_rhs + t_sum:14.1f}")
    lanes = {}
    for W in (4, 8):
        yW = np.repeat(y[:, None], W, axis=1).copy()
        fW, out = np.zeros((n, W)), np.zeros((n, W))
        cW, sW, SW, cpW, dpW, sigW = (np.zeros((N, W)) for _ in range(6))
        KE = np.zeros((R.NS + 1, n, W))
        KE[:] = yW
        hx = np.full(n * W, 1e-3)
        r = per_call(lambda: E._rhs_tiles(N, yW, fW, cW, sW, SW, cpW, dpW, sigW)) * ns / W
        m = per_call(lambda: [E._stage_flat(st, hx, yW, KE, out) for st in range(1, R.NS)]) * ns / W
        lanes[W] = 12 * r + m
        print(f"  per lane of W = {W}     {'-':>8s} {r:7.2f} {m:16.2f} {'-':>11s} {lanes[W]:14.1f}")

    attempts = []
    for chi in chis:
        at = run(chi, N, method="dop853", tol=a.tol, chords="exact").dataset.attrs
        attempts.append(int(at["n_steps"]) + int(at["n_rejected"]))
    M = len(chis)
    # lock step: every iteration costs W = 4 ceil(active / 4) lanes; a member leaves when done
    srt, iters, prev = sorted(attempts), 0, 0
    for i, at in enumerate(srt):
        iters += (at - prev) * 4 * ((M - i + 3) // 4)
        prev = at
    util = sum(attempts) / iters
    print(f"\nensemble of {M} (chi {chis[0]:g}..{chis[-1]:g}): attempts per member {min(attempts)}..{max(attempts)}, "
          f"lock-step utilisation of the lanes at best {util:.2f}")
    best = lanes[8 if M >= 8 else 4] / (12 * t_rhs + t_sum) / util
    print(f"bound: ensemble / singles >= {best:.2f} (arithmetic per lane {lanes[8 if M >= 8 else 4]:.0f} against "
          f"{12 * t_rhs + t_sum:.0f} ns/node per step, over the utilisation), before copies and bookkeeping")
    return 0


if __name__ == "__main__":
    sys.exit(main())
