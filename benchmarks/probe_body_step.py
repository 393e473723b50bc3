"""Where a step of the compiled RODAS4 with a body goes (branch fastbody): the climbing rope's combined model at
chi 0.1 on the stretching study's fold grading (:mod:`benchmarks.rope_study_grid`'s runs), stepped ``STEPS``
accepted steps from the matched start by :class:`snapping.simulate.elastic_rodas_body.RodasBodyStepper` (the
Python-called stepper: one compiled step a call), then its kernels timed apart at the state reached: the rhs,
the Jacobian (and its parts: the springs', the body's exact terms, the bending's, the drag's; the coloured
differences it replaced), the stage matrix's assembly and LU, one stage solve. CPU by ``time.process_time``.

Usage::

    PYTHONPATH=src python benchmarks/probe_body_step.py [LEVEL [STEPS]]    # default 0 (947 links), 3000
"""

import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from snapping import caps  # noqa: E402
from snapping.caps_runs import method_for, problem  # noqa: E402
from snapping.continuum import level_parameters  # noqa: E402
from snapping.simulate import elastic_body_jacobian as BJ  # noqa: E402
from snapping.simulate import elastic_rodas_body as RB  # noqa: E402
from snapping.simulate import grading  # noqa: E402
from snapping.simulate.elastic import Elastic  # noqa: E402
from snapping.simulate.elastic_checks import initial_state  # noqa: E402
from snapping.simulate.elastic_model import ElasticLine  # noqa: E402


def main():
    k = int(sys.argv[1]) if len(sys.argv) > 1 else 0
    nst = int(sys.argv[2]) if len(sys.argv) > 2 else 3000
    sp, chi = caps.spec("climbing-rope"), 0.1
    lv = level_parameters(k + 1, 0.5, first=-1)[-1]
    h = grading.fold_following(chi, frac=lv["frac"], h_min=lv["h_min"], h_max=lv["h_max"])
    p = problem(sp, chi, h.size, ("bending", "drag"), h=h)
    _, _, om = method_for(p, 1e-6)
    p = problem(sp, chi, h.size, ("bending", "drag"), h=h, damping=1.0, omega_min=om)
    line = ElasticLine(p, Elastic(ea=sp.ea / (sp.mass * sp.g), grid_damping=4.0))
    st = RB.RodasBodyStepper(line, 0.0, initial_state(line, "matched", None), 10.0, 1e-6)
    st.step()  # (compiled before the clock starts)
    t0 = time.process_time()
    for _ in range(nst):
        st.step()
    dt = time.process_time() - t0
    print(f"N {line.N}: {nst} steps to t {st.t:.5g}: {dt / nst * 1e3:.3f} ms a step (one Python call each), "
          f"{st.nrej} rejected, load {open('/proc/loadavg').read().split()[0]}")
    N, a, t, pin = line.N, st.bargs(), st.t, st.pins[6]
    Bl, K0L, El, CN, CT, KN, KT, sc, cx, cc = st.bd
    bs, dq, f = st.bs, np.zeros((4, 4)), np.zeros(4 * N + 2)
    ex, ey, phid = RB.clamp_at(t, sc, cx, cc)
    gh = RB.ER.GAMMA * st.h
    b, U = np.random.default_rng(1).standard_normal(4 * N + 2), np.zeros(4 * N + 2)
    jac = (N, t, st.y, st.pinpar, st.pintab, pin, *a, f, st.B5, st.gW12, st.gDb, *st.work, st.J3, st.gW4, bs, st.zz,
           st.GX, st.GY, st.QP, st.Q, st.hmin)
    jfd = (N, t, st.y, pin, *a[:6], *st.work[:3], st.J3, st.gW4, st.bd, st.B5, st.gW12, st.gDb, bs, st.zz, st.GX,
           st.GY, st.QP, st.Q, st.hmin)

    def lu():
        RB.assemble_band5(N, st.B5, gh, st.ab5)
        RB.band_lu55(st.ab5, 2 * N, st.piv5)

    parts = [
        ("rhs (body_rhs)", lambda: RB.body_rhs(N, t, st.y, pin, *a, f, *st.work, bs)),
        ("f and Jacobian (body_f_and_jacobian)", lambda: RB.body_f_and_jacobian(*jac)),
        ("  the springs' part (+ push)", lambda: RB._springs_part(N, st.y, pin, *a[:6], *st.work[:3], st.J3, st.gW4,
                                                                   st.bd, st.B5, st.gW12, st.gDb)),
        ("  the body's exact terms", lambda: BJ.body_terms_jacobian(N, st.y, pin, line._invm, Bl, K0L, El, CN, CT, KN,
                                                                      KT, sc, ex, ey, phid, bs, st.B5, st.gW12,
                                                                      st.gDb, dq)),
        ("    bending", lambda: BJ.bending_jacobian(N, st.y, pin, line._invm, Bl, K0L, El, sc[RB.P_CLAMPED] != 0.0,
                                                     ex, ey, phid, *bs, st.B5, st.gW12, st.gDb, dq)),
        ("    drag", lambda: BJ.drag_jacobian(N, st.y, line._invm, CN, CT, KN, KT, sc[0], sc[1], sc[2], bs[0], bs[1],
                                              bs[2], st.B5, st.gDb)),
        ("  (before: the coloured differences, body_jacobian_fd)", lambda: RB.body_jacobian_fd(*jfd)),
        ("stage matrix: assembly and LU (band_lu55)", lu),
        ("one stage solve (solve5)", lambda: RB.solve5(N, st.B5, st.gW12, st.gDb, gh, st.ab5, st.piv5, b, U, st.w)),
    ]
    for name, fn in parts:
        fn()
        n = 200
        t1 = time.process_time()
        for _ in range(n):
            fn()
        print(f"{name:58s} {(time.process_time() - t1) / n * 1e3:.4f} ms")
    print(f"load {open('/proc/loadavg').read().split()[0]}")


if __name__ == "__main__":
    main()
