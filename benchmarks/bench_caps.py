"""The cost of a design answer for a real line (issue 24's target: at most 10 s of CPU for
100-1000 links, the peaks to 1%), before and after the stiff runs' rule of
:func:`snapping.caps.method_for`.

For every catalogue line and each N: :func:`snapping.caps.cap` (chi 0.25, the N/2 check, each
mechanism alone) twice:

* **before**: ``damping=0`` -- every run by the fast method (DOP853, tol 1e-6), undamped: the
  answers as they were made before the rule (the reference: DOP853 at 1e-6 is within 1e-6 of
  DOP853 at 1e-8 in these peaks);
* **after**: the default -- the runs whose bending waves would hold DOP853 to more than
  ``STIFF_RATIO`` times its accuracy-limited steps by RODAS4 at ``STIFF_TOL`` with those waves
  grid-damped, the others as before (bit for bit).

It prints, per line and N: CPU seconds and right-hand-side evaluations of each answer, the
real answer's peaks of each and their largest relative difference (the 1% check), the largest
difference over every run of the answer (ideal, full, each alone, the N/2 check), the capping
mechanism of each, and which runs RODAS4 took. ``--after-only`` skips the (slow) before answers.

Usage::

    python benchmarks/bench_caps.py                      # N = 100 200 400 1000, every line
    python benchmarks/bench_caps.py --N 1000 --lines bullwhip bungee-cord
"""

from __future__ import annotations

import argparse
import os

from snapping import caps, lines


def _peaks(r: dict) -> dict:
    """Every run's peaks of an answer, nondimensional keys: (what, quantity) -> SI value."""
    out = {("real", q): v for q, v in r["real"].items()}
    for m, pk in r["alone"].items():
        out.update({(m, q): v for q, v in pk.items()})
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--N", nargs="+", type=int, default=[100, 200, 400, 1000])
    p.add_argument("--lines", nargs="+", default=lines.names(), choices=lines.names())
    p.add_argument("--chi", type=float, default=0.25)
    p.add_argument("--after-only", action="store_true")
    a = p.parse_args(argv)
    caps.cap("bungee-cord", a.chi, N=12)  # compile the kernels (both methods)
    caps.cap("bungee-cord", a.chi, N=12, damping=0.0)
    print(f"chi = {a.chi:g}; load {os.getloadavg()[0]:.1f}\n")
    print("| line | N | CPU s before | CPU s after | evaluations before | evaluations after | T before (N) | "
          "T after (N) | v, a, T: largest change | every run: largest change | cap before / after | "
          "RODAS4 runs |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for N in a.N:
        for name in a.lines:
            after = caps.cap(name, a.chi, N=N)
            stiff = [f"{x['run']}@{x['N']}" for x in after["runs"] if x["method"] == "rodas4"]
            if a.after_only:
                print(f"| {name} | {N} | - | {after['cpu']:.2f} | - | {after['n_rhs']} | - | "
                      f"{after['real']['sigma_peak']:.5g} | - | - | {after['cap']} | {', '.join(stiff) or '-'} |",
                      flush=True)
                continue
            before = caps.cap(name, a.chi, N=N, damping=0.0)
            pb, pa = _peaks(before), _peaks(after)
            real = max(abs(pa[("real", q)] / pb[("real", q)] - 1.0) for q in caps.QUANTITIES)
            every = max(abs(pa[k] / pb[k] - 1.0) for k in pb)
            res = {k: abs(after["resolution"][k] - before["resolution"][k]) for k in caps.QUANTITIES}
            print(f"| {name} | {N} | {before['cpu']:.2f} | {after['cpu']:.2f} | {before['n_rhs']} | "
                  f"{after['n_rhs']} | {before['real']['sigma_peak']:.5g} | {after['real']['sigma_peak']:.5g} | "
                  f"{real:.2%} | {every:.2%} | {before['cap']} / {after['cap']} | {', '.join(stiff) or '-'} |",
                  flush=True)
            if max(res.values()) > 0.01:
                print(f"  (the N/2 check moved by {max(res.values()):.2%})")
    print(f"\nload {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
