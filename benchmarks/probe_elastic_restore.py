"""What an elastic run's checkpoint must hold (branch elasticprogress; for the checkpoints of
``elastic.solve(method="rodas4"/"rodas4-links")``, not built yet): a RODAS4 run is stopped at a
return of its compiled loop (every 64 steps here, after 20 returns), every array of its stepper and
of its compiled-loop run is copied; fresh objects are built from the problem, the arrays restored
(``--minimal``: only the stepper's state y (zl, yn), ctl, St[0], B, gW, gD, dsp and the run's
PY0, PY1, PC, PT, PN0, ref, keep, nkeep, after, best, sctl, peak_z), and the run continued: are the
record, the final state, the controls, the peaks and the kept steps those of the run not stopped?

    PYTHONPATH=src python benchmarks/probe_elastic_restore.py rodas4 [--minimal]
    PYTHONPATH=src python benchmarks/probe_elastic_restore.py rodas4-links [--minimal]

chi 0.25, 30 links, c = 60, tol 1e-6, to the snap (~20,000 steps)."""
import sys
import numpy as np
from snapping.simulate.problem import Links, Problem
from snapping.simulate.elastic import Elastic
from snapping.simulate import elastic_solve as S, elastic_advance as EA
from snapping.simulate.elastic_model import ElasticLine
from snapping.simulate.elastic_rodas import RodasStepper
from snapping.simulate.elastic_links_rodas import LinksStepper

method = sys.argv[1]
def arrays(obj):
    out = {}
    for k, v in vars(obj).items():
        if isinstance(v, np.ndarray):
            out[k] = v.copy()
        elif isinstance(v, tuple) and v and all(isinstance(a, np.ndarray) for a in v):
            out[k] = tuple(a.copy() for a in v)
    return out
def restore(obj, saved):
    for k, v in saved.items():
        cur = getattr(obj, k)
        if isinstance(v, tuple):
            for a, b in zip(cur, v): a[...] = b
        else:
            cur[...] = v
def make():
    p = Problem.catenary(0.25, links=Links.uniform(30, lumping="shared"))
    line = ElasticLine(p, Elastic.from_wave_speed(60.0))
    z0 = line.start("stretched")
    St = RodasStepper if method == "rodas4" else LinksStepper
    st = St(line, 0.0, z0, 10.0, 1e-6)
    mm0 = line.measure(0.0, z0)
    E0 = float(S._record(line, 0.0, z0, 0.0, mm0)[S.STEP_NAMES.index("energy")])
    U0 = float(S._record(line, 0.0, z0, 0.0, mm0)[S.STEP_NAMES.index("elastic_energy")])
    floor = S.speed_floor(U0, float(np.min(line.m)), 0.5)
    R = EA.RodasRun if method == "rodas4" else EA.LinksRun
    return R(st, mm0, t_end_given=False, stop_fraction=0.5, floor=floor, E0=E0, U0=U0, max_rhs=50_000_000,
             energy_fail=S.ENERGY_ERROR_FAIL)
def go(run, chunks, rows=64):
    while True:
        code = run.advance(np.inf, rows)
        chunks.append(run.drain())
        if code not in (EA.R_BUFFER, EA.R_SNAPSHOT):
            return code
a = make(); ca = []
for _ in range(20):
    a.advance(np.inf, 64); ca.append(a.drain())
saved = (arrays(a.st), arrays(a))
St0 = saved[0]["St"][0].copy()
if "--minimal" in sys.argv:
    KEEP_ST = {"y", "yn", "zl", "ctl", "B", "gW", "gD", "dsp"}
    KEEP_RUN = {"PY0", "PY1", "PC", "PT", "PN0", "ref", "keep", "nkeep", "after", "best", "sctl", "peak_z"}
    saved = ({k: v for k, v in saved[0].items() if k in KEEP_ST}, {k: v for k, v in saved[1].items() if k in KEEP_RUN})
code_a = go(a, ca)
b = make(); restore(b.st, saved[0]); b.st.St[0] = St0; restore(b, saved[1]); cb = list(ca[:20])
code_b = go(b, cb)
ra, rb = np.concatenate(ca), np.concatenate(cb)
print(method, code_a, code_b, ra.shape, rb.shape, np.array_equal(ra, rb), np.array_equal(a.st.y, b.st.y),
      np.array_equal(a.sctl, b.sctl, equal_nan=True), np.array_equal(a.best, b.best), np.array_equal(a.PC, b.PC),
      "saved arrays:", {k: (v.shape if isinstance(v, np.ndarray) else len(v)) for k, v in {**saved[0], **saved[1]}.items()})
