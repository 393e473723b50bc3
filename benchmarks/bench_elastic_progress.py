"""CPU time of one elastic run (chi 0.25, to the snap) with and without the progress bar (stderr to /dev/null) and the calls into the compiled loop. usage: PYTHONPATH=src python benchmarks/bench_elastic_progress.py METHOD N C"""
import contextlib, os, sys, time
from snapping.simulate.problem import Links, Problem
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate import elastic_advance as EA

method, N, c = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
p = Problem.catenary(0.25, links=Links.uniform(N, lumping="shared"))
solve(p, Elastic.from_wave_speed(c), t_end=0.01, tol=1e-6, method=method)  # warm
calls = [0]
orig = EA.RodasRun.drain
def drain(self):
    calls[0] += 1
    return orig(self)
EA.RodasRun.drain = drain
for rep in range(1):
    for prog in (False, True):
        calls[0] = 0
        t0, w0 = time.process_time(), time.perf_counter()
        with open(os.devnull, "w") as dn, contextlib.redirect_stderr(dn):
            r = solve(p, Elastic.from_wave_speed(c), tol=1e-6, method=method, progress=prog)
        a = r.dataset.attrs
        print(f"{method} N={N} c={c:g} progress={prog}: cpu {time.process_time() - t0:.2f} s wall {time.perf_counter() - w0:.2f} s "
              f"steps {a['n_steps']} calls {calls[0]} v_peak {a['v_peak']!r}", flush=True)
