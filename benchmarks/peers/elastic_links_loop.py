"""CPU of a ``method="rodas4-links"`` run with and without its compiled parts.

Interleaved rounds of the same run (``elastic_common.run_project``: ``time.process_time``
around ``solve``) under three settings of ``elastic_solve``: the Python step loop with the
Python peak refinement (``COMPILED_LOOP = COMPILED_REFINE = False``, the path before branch
``linkloop``), the Python loop with the compiled refinement, and both compiled (the default).
The peaks are checked to be the same in all three. ::

    python benchmarks/peers/elastic_links_loop.py --N 100 --c 30 --tol 3e-4 --rounds 10
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import elastic_common as E  # noqa: E402

SETTINGS = {"python loop + python refine": (False, False), "python loop + compiled refine": (False, True),
            "compiled loop + compiled refine": (True, True)}


def main(argv=None) -> int:
    from snapping.simulate import elastic_solve as S

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--N", type=int, default=100)
    ap.add_argument("--c", type=float, default=30.0)
    ap.add_argument("--tol", type=float, default=3e-4)
    ap.add_argument("--start", default="matched", choices=E.STARTS)
    ap.add_argument("--rounds", type=int, default=10)
    a = ap.parse_args(argv)
    cpu = {k: [] for k in SETTINGS}
    peaks = {}
    for r in range(a.rounds + 1):  # (round 0 compiles and warms up; not counted)
        for k, (loop, ref) in SETTINGS.items():
            S.COMPILED_LOOP, S.COMPILED_REFINE = loop, ref
            res = E.run_project(a.chi, a.N, a.c, a.tol, "rodas4-links", a.start)
            peaks[k] = (res.v_peak, res.t_v, res.sigma_peak, res.t_sigma)
            if r:
                cpu[k].append(res.cpu)
    print(f"chi = {a.chi:g}, N = {a.N}, c = {a.c:g}, tol = {a.tol:g}, start {a.start}, {res.extra.split()[0]}; "
          f"CPU ms, median [min - max] of {a.rounds} interleaved rounds")
    for k, ts in cpu.items():
        print(f"  {k:32s} {np.median(ts) * 1e3:7.2f} [{min(ts) * 1e3:.2f} - {max(ts) * 1e3:.2f}]")
    print(f"  the same peaks in all three: {len(set(peaks.values())) == 1}")
    print(f"uptime: {os.popen('uptime').read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
