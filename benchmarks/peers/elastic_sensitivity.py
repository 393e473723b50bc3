"""How well the elastic falling catenary's peaks are defined: this project's run from the
stretched start and from the start moved by ``eps`` (interior nodes x_j += eps sin j).

The undamped tension-only line rings at its grid scale and goes slack and taut again; its
fine motion is sensitive to round-off, so the peaks are defined only to the change a
round-off-sized perturbation makes (about 1e-3 in the peak speed at N = 100, c = 30).

Usage::

    python benchmarks/peers/elastic_sensitivity.py 100 30 1e-9 dop853 0,1e-12
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import elastic_common as E  # noqa: E402


def main(argv=None) -> int:
    a = sys.argv[1:] if argv is None else argv
    if len(a) != 5:
        print(__doc__)
        return 2
    from snapping.simulate.elastic import solve

    N, c, tol, method = int(a[0]), float(a[1]), float(a[2]), a[3]
    x, y = E.start_nodes(0.25, N, c)
    z = np.zeros(N + 1)
    for eps in [float(e) for e in a[4].split(",")]:
        xx = x.copy()
        xx[1:N] += eps * np.sin(np.arange(1, N))
        w = time.process_time()
        r = solve(E.problem(0.25, N), E.elastic(c), tol=tol, method=method, initial=(xx, y, z, z))
        print(f"N={N} c={c:g} {method} tol={tol:g} eps={eps:g}: v peak {r.peaks['v']['value']:.8f} at "
              f"{r.peaks['v']['t']:.6f}, T peak {r.peaks['sigma']['value']:.5f} at {r.peaks['sigma']['t']:.5f}, "
              f"t_end {r.dataset.attrs['t_final']:.5f}, {r.dataset.attrs['n_rhs']} evaluations, "
              f"{time.process_time() - w:.1f} s CPU", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
