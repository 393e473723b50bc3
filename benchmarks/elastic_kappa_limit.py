"""The elastic line's kappa_peak against the inextensible chain's on the same links (branch stretchk).

    PYTHONPATH=src python benchmarks/elastic_kappa_limit.py 0.3 40 1.2 30 100 300 1000 3000 10000 30000
    PYTHONPATH=src python benchmarks/elastic_kappa_limit.py 0.3 40 snap 30 100 300 1000 3000 10000

Arguments: chi, N (uniform links, shared lumping), t_end (a number: both runs land on it; ``snap``: the
stop rule), then the wave speeds c. The chain: ``run(method="fast", tol=1e-10)``; the elastic line:
``solve(method="rodas4-links", start="matched", tol=1e-9)`` (to the snap: ``stop_floor=1``).
"""

from __future__ import annotations

import sys

import numpy as np

from snapping.simulate import Links, Problem, run
from snapping.simulate.elastic import Elastic, solve


def main(argv):
    chi, N = float(argv[0]), int(argv[1])
    T = None if argv[2] == "snap" else float(argv[2])
    p = Problem.catenary(chi, links=Links.uniform(N, lumping="shared"), chords="exact")
    ch = run(p, method="fast", tol=1e-10, t_end=T, progress=False).dataset
    tc, kc = ch.t.values, ch.kappa_max.values
    i = int(np.argmax(kc))
    print(f"chi {chi} N {N} t_end {argv[2]}: chain kappa_peak {ch.attrs['kappa_peak']:.6f} (largest step end "
          f"{kc[i]:.6f} at t {tc[i]:.5f}, s {float(ch.s_kappa_max.values[i]):.3f}; last step t {tc[-1]:.5f})")
    for c in (float(x) for x in argv[3:]):
        kw = {"t_end": T} if T is not None else {"stop_floor": 1.0}
        r = solve(p, Elastic.from_wave_speed(c), tol=1e-9, method="rodas4-links", start="matched", **kw).dataset
        te, ke = r.t.values, r.kappa_max.values
        j = int(np.argmax(ke))
        print(f"  c {c:7g}: kappa_peak {r.attrs['kappa_peak']:.6f} ({r.attrs['kappa_peak'] / ch.attrs['kappa_peak'] - 1:+.2e})"
              f" at t {te[j]:.5f} s {float(r.s_kappa_max.values[j]):.3f} (last step t {te[-1]:.5f}); "
              f"strain_peak {r.attrs['strain_peak']:.1e}")


if __name__ == "__main__":
    main(sys.argv[1:])
