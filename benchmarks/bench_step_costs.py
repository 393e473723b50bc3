"""Where the time of a DOP853 step goes: one chain against interleaved lanes (ensembles).

Prints, per node and per chain, the parts of a step of a single run (`rk.rk_step` and
`rk.after_attempt`): sines/cosines, the right-hand side, the stage sums, the end state
and error norm, the diagnostics and bookkeeping; then the same parts of the ensemble
kernel per lane for W = 2, 4 and 8 interleaved lanes. Only the right-hand side's
tension recurrence can gain from the lanes; the other parts are elementwise and
already vectorised along one chain. Last, the compiled loops themselves (no Python
between steps): M members advanced by `ensemble.advance_lanes` against the same M
members advanced one after another by `rk.advance_rk`, in ns per node and member step,
which adds what the arithmetic alone leaves out (the lanes' larger working set, the
copies and the lock step).

Usage::

    python benchmarks/bench_step_costs.py                  # N = 1000, 8 members chi = 0.2..0.5
    python benchmarks/bench_step_costs.py --N 300 --chis 0.2,0.3,0.4,0.5
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from snapping.simulate import angles as AG
from snapping.simulate import ensemble as E
from snapping.simulate.methods import dop853 as HO
from snapping.simulate import rk as R
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


def engines(chis, N, tol, steps_per_call):
    """Fresh engines of the members, returning to Python every ``steps_per_call`` steps."""
    out = []
    for chi in chis:
        e = HO.Engine(AG.state_to_angles(initial_state(chi, N, chords="exact")), 0.0, tol=tol, dt0=None,
                       t_end=10.0, stop_fraction=0.0, thin=0.0, max_link_error=1e-2, snapshot_times=())
        e.start()
        e.ctl[R.Q_STEPS_PER_CALL] = steps_per_call
        e.ctl[R.Q_VUP] = np.inf  # no speed-level snapshots
        out.append(e)
    return out


def loops(chis, N, tol, calls=6, steps_per_call=60):
    """ns per node and member step of the compiled loops: (ensemble, one after another)."""
    M = len(chis)
    ens = engines(chis, N, tol, steps_per_call)
    lanes = E._Lanes(ens)
    act = np.arange(M, dtype=np.int64)
    single = engines(chis, N, tol, steps_per_call)

    def go_single(e):
        w = e.w
        R.advance_rk(e.N, e.Y0, e.Y1, e.KK, e.TS, e.HS, e.DOK, e.ytmp, w.c, w.s, w.S, w.cp, w.dp, w.sig, e.Z,
                     e.rinv0, e.ctl, e.rec, e.pk, e.meas, e.mdl)

    def timed(step_all, engs):
        for e in engs:
            e.ctl[R.Q_REFINE] = 0.0  # (peaks are not located here: no Python between steps)
        step_all()  # warm-up
        attempts0 = sum(e.ctl[R.Q_NRHS] for e in engs) / R.NS
        t0 = time.perf_counter()
        for _ in range(calls):
            for e in engs:
                e.ctl[R.Q_REFINE] = 0.0
                e.drain()
            step_all()
        wall = time.perf_counter() - t0
        attempts = sum(e.ctl[R.Q_NRHS] for e in engs) / R.NS - attempts0
        return wall / attempts / N * 1e9

    t_ens = timed(lambda: lanes.advance(act), ens)
    t_one = timed(lambda: [go_single(e) for e in single], single)
    return t_ens, t_one


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--N", type=int, default=1000, help="links (default 1000)")
    p.add_argument("--chis", default="0.2,0.243,0.286,0.329,0.371,0.414,0.457,0.5",
                   help="ensemble members of the loop comparison (default 8 values 0.2..0.5)")
    p.add_argument("--tol", type=float, default=1e-8)
    a = p.parse_args(argv)
    N, n = a.N, 2 * a.N
    chis = [float(c) for c in a.chis.split(",")]
    print_machine()

    y = AG.state_to_angles(initial_state(0.25, N, chords="exact"))
    y = y + 1e-3 * np.random.default_rng(0).standard_normal(y.size)  # a generic moving state
    eng = engines([0.25], N, a.tol, 10)[0]
    c, s, S, cp, dp, sig = (np.zeros(N) for _ in range(6))
    f, yt, y1 = np.zeros(n), np.zeros(n), np.zeros(n)
    Kst = np.zeros((R.NS + 1, n))
    Kst[:] = y
    ns = 1e9 / N
    AG.angle_rhs(N, y, f, c, s, S, cp, dp, sig)

    def book(y1, c, s, sig, e=eng):  # an accepted attempt's diagnostics and bookkeeping
        e.ctl[R.Q_NREC] = 1.0
        R.after_attempt(N, 0.5, 1e-6, False, 1 - int(e.ctl[R.Q_SLOT]), y1, e.TS, e.HS, e.DOK, c, s, sig, e.Z,
                        e.rinv0, e.ctl, e.rec, e.pk, e.meas, e.mdl)

    t_sc = per_call(lambda: AG.sincos(N, y, c, s)) * ns
    t_rhs = per_call(lambda: AG.angle_rhs(N, y, f, c, s, S, cp, dp, sig)) * ns
    t_sum = per_call(lambda: [R._stage_state(n, st, 1e-3, y, Kst, yt) for st in range(1, R.NS)]) * ns
    t_step = per_call(lambda: R.rk_step(N, 0.0, 1e-4, y, y1, Kst, yt, c, s, S, cp, dp, sig, a.tol, eng.mdl)) * ns
    t_book = per_call(lambda: book(y, c, s, sig)) * ns
    t_err = per_call(lambda: (R.end_state(n, 1e-4, y, Kst, y1), R.step_error(n, 1e-4, a.tol, y, y1, Kst, yt))) * ns
    print(f"ns per node and chain, N = {N}   sincos     rhs  rhs-sincos  stage sums  end+error  diagnostics"
          f"  whole step")
    print(f"  single chain            {t_sc:10.2f} {t_rhs:7.2f} {t_rhs - t_sc:11.2f} {t_sum:11.2f} {t_err:10.2f} "
          f"{t_book:12.2f} {t_step + t_book:11.1f}")
    for W in (2, 4, 8):
        yW = np.repeat(y[:, None], W, axis=1).copy()
        fW, out = np.zeros((n, W)), np.zeros((n, W))
        ev = np.zeros((n, W))
        w = E.LaneWork(N, W)
        KE = np.zeros((R.NS + 1, n, W))
        KE[:] = yW
        hx = np.full(n * W, 1e-3)
        tolx = np.full(n * W, a.tol)
        errL = np.zeros(W)
        r = per_call(lambda: E.rhs_lanes(N, yW, fW, *w.args())) * ns / W
        m = per_call(lambda: [E._stage_flat(st, hx, yW, KE, out) for st in range(1, R.NS)]) * ns / W
        er = per_call(lambda: (E._y1_flat(hx, yW, KE, out), E._err_lanes(n, hx, tolx, yW, out, KE, ev, errL)))
        bk = per_call(lambda: [book(yW[:, k], w.c[:, k], w.s[:, k], w.sig[:, k]) for k in range(W)]) * ns / W
        er *= ns / W
        print(f"  per lane of W = {W}        {'-':>10s} {r:7.2f} {r - t_sc:11.2f} {m:11.2f} {er:10.2f} {bk:12.2f} "
              f"{12 * r + m + er + bk:11.1f}")
    print("  (rhs-sincos: the coefficients, the tension recurrence and the accelerations; lanes use the same sincos;\n"
          "   whole step: rk.rk_step and the diagnostics, for the single chain; the sum of the parts, per lane)")

    t_ens, t_one = loops(chis, N, a.tol)
    print(f"\ncompiled loops, {len(chis)} members chi = {chis[0]:g}..{chis[-1]:g}, N = {N}, tol {a.tol:g} "
          f"(ns per node and member step)")
    print(f"  ensemble (advance_lanes)      {t_ens:8.1f}")
    print(f"  one after another (advance_rk){t_one:8.1f}")
    print(f"  ensemble / one after another  {t_ens / t_one:8.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
