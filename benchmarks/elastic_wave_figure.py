"""The guide's figure of the release's unloading wave (docs/guide/elastic_wave.png).

The line of chi = 0.25, N = 40, c = 10 sqrt(gL) (a soft bungee-like line, so that the wave is slow
enough to see), grid damping 1, released from its stretched equilibrium; 150 strain profiles to
t = 0.3; the strain image, the energy terms and their balance (snapping.figures_elastic.figure).

    PYTHONPATH=src python benchmarks/elastic_wave_figure.py docs/guide/elastic_wave.png
"""

from __future__ import annotations

import sys

import numpy as np

from snapping.figures_elastic import figure
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem

if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "elastic_wave.png"
    p = Problem.catenary(0.25, links=Links.uniform(40, lumping="shared"))
    r = solve(p, Elastic.from_wave_speed(10.0, grid_damping=1.0), t_end=0.3, tol=1e-6,
              snapshot_times=np.linspace(0.002, 0.3, 150))
    s = r.summary()
    print(f"n_steps {s['n_steps']}, n_rhs {s['n_rhs']}, energy drift {s['energy_drift']:.2g}, first slack "
          f"t = {s['t_first_slack']:.4g}, wall {s['wall_time']:.1f} s")
    figure(r.dataset, out)
    print(f"wrote {out}")
