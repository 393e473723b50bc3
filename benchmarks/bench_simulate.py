"""Benchmark of the chain simulator.

Prints (1) nanoseconds per node per right-hand-side evaluation (tension solve +
accelerations), per evaluation of the per-step diagnostics, and of both, for
several N; (2) wall time, evaluation count and cost per node-evaluation of full
runs to the snap.

Usage::

    python benchmarks/bench_simulate.py                 # everything (minutes)
    python benchmarks/bench_simulate.py --quick         # N = 1000, 5000 kernels; chi = 0.25, N = 500 run
    python benchmarks/bench_simulate.py --sizes 2000 --runs 0.25:2000
    python benchmarks/bench_simulate.py --no-runs
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numba
import numpy as np

from snapping import __version__
from snapping.simulate import initial_state, run
from snapping.simulate import kernels as K


def cpu_name() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_rows():
    return [
        ("cpu", cpu_name()),
        ("cores", str(os.cpu_count())),
        ("platform", platform.platform()),
        ("python", platform.python_version()),
        ("numpy / numba", f"{np.__version__} / {numba.__version__}"),
        ("snapping", __version__),
    ]


def print_machine(load: bool = True) -> None:
    """The machine table every benchmark starts with (and the load average, which makes
    shared-machine timings readable)."""
    print("machine")
    for k, v in machine_rows():
        print(f"  {k:<14} {v}")
    if load:
        print(f"  load average   {os.getloadavg()[0]:.2f} (at start; timings are single-threaded)")
    print()


def _state(chi: float, N: int):
    """A moving state (catenary positions, smooth velocities) in the kernel layout."""
    st = initial_state(chi, N)
    rng = np.random.default_rng(0)
    st.vx[:-1] = 0.1 * rng.standard_normal(N)
    st.vy[:-1] = 0.1 * rng.standard_normal(N)
    return st, st.as_array()


def _time(fn, n_iter: int, repeats: int = 5) -> float:
    """Best of ``repeats`` wall times of fn(n_iter), in seconds per iteration."""
    fn(1)  # compile / warm caches
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(n_iter)
        best = min(best, time.perf_counter() - t0)
    return best / n_iter


def bench_kernels(sizes, chi: float, target_s: float):
    rows = []
    for N in sizes:
        st, Z = _state(chi, N)
        w = np.zeros((4, N))
        l0 = st.link_lengths()
        rinv0 = 1.0 / (l0 * l0)
        meas = np.zeros(K.NMEAS)
        n_iter = max(10, int(target_s / (15e-9 * N)))
        t_rhs = _time(lambda n: K.bench_rhs(N, Z, w[0], w[1], w[2], w[3], n), n_iter)
        t_thomas = _time(lambda n: K.bench_rhs_thomas(N, Z, w[0], w[1], w[2], w[3], n), n_iter)
        t_meas = _time(lambda n: K.bench_measure(N, Z, rinv0, meas, n), n_iter)
        t_both = _time(lambda n: K.bench_rhs_measure(N, Z, w[0], w[1], w[2], w[3], rinv0, meas, n), n_iter)
        rows.append((N, chi, n_iter, t_rhs * 1e9 / N, t_thomas * 1e9 / N, t_meas * 1e9 / N, t_both * 1e9 / N,
                     t_rhs * 1e6))
    return rows


def bench_runs(cases):
    rows = []
    for chi, N in cases:
        r = run(chi, N, progress=None)
        a = r.dataset.attrs
        rows.append((chi, N, int(a["n_steps"]), int(a["n_rhs"]), float(a["wall_time"]),
                     float(a["wall_time"]) * 1e9 / (int(a["n_rhs"]) * N), float(a["v_peak"]),
                     float(a["a_peak"]), float(a["sigma_peak"]), float(a["t_snap_v"])))
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="a quick subset")
    p.add_argument("--sizes", default=None, help="comma-separated N for the kernel timings (default 1000,5000,20000)")
    p.add_argument("--chi", type=float, default=0.25, help="chi of the kernel-timing state (default 0.25)")
    p.add_argument("--runs", default=None, help="comma-separated chi:N full runs (default 0.25:2000,0.1:5000)")
    p.add_argument("--no-runs", action="store_true", help="kernel timings only")
    p.add_argument("--target", type=float, default=0.3, help="seconds per kernel timing repeat (default 0.3)")
    args = p.parse_args(argv)
    sizes = [1000, 5000] if args.quick else [1000, 5000, 20000]
    if args.sizes:
        sizes = [int(v) for v in args.sizes.split(",")]
    runs = [(0.25, 500)] if args.quick else [(0.25, 2000), (0.1, 5000)]
    if args.runs:
        runs = [(float(c), int(n)) for c, n in (v.split(":") for v in args.runs.split(","))]
    if args.no_runs:
        runs = []

    print_machine(load=False)
    print("kernels: nanoseconds per node per evaluation (best of 5), one core")
    hdr = f"  {'N':>6} {'chi':>5} {'evals':>9} {'rhs':>8} {'thomas':>8} {'record':>8} {'rhs+rec':>8} {'rhs us':>9}"
    print(hdr)
    for N, chi, n, a, th, b, c, us in bench_kernels(sizes, args.chi, args.target):
        print(f"  {N:>6} {chi:>5g} {n:>9} {a:>8.2f} {th:>8.2f} {b:>8.2f} {c:>8.2f} {us:>9.2f}")
    print("  (rhs: tension solve + accelerations, the simulator's kernel; thomas: the same with the textbook\n"
          "   Thomas sweep; record: the per-step diagnostics of an accepted step; rhs us: microseconds per rhs)")
    if runs:
        print()
        print("full runs to the snap (tol 1e-8, the paper's Euler-Richardson), one core")
        print(f"  {'chi':>5} {'N':>6} {'steps':>9} {'rhs evals':>10} {'wall s':>8} {'ns/node/eval':>13} "
              f"{'v_peak':>9} {'a_peak':>10} {'sigma_peak':>10} {'t_snap_v':>10}")
        for chi, N, ns, ne, wall, per, v, a, s, t in bench_runs(runs):
            print(f"  {chi:>5g} {N:>6} {ns:>9} {ne:>10} {wall:>8.2f} {per:>13.2f} {v:>9.5g} {a:>10.5g} "
                  f"{s:>10.5g} {t:>10.7g}")
        print("  (ns/node/eval: the whole run's wall time per node per RHS evaluation, stepping and recording included)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
