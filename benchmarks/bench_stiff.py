"""The stiff method (``run(method="stiff")``, RODAS4: :mod:`snapping.simulate.methods.rodas4`)
against explicit dop853 on the snap of a chain with bending (issue 21, item 3 and its targets).

For each N, bending number beta (= B in the chain's units) and damping ratio zeta: a
reference run (dop853 at tol 1e-8, :data:`REF_TOL`), then for each method the loosest tolerance of a ladder
whose peaks v, a, sigma are all within ``acc`` (relative, default 1e-6) of the reference,
with its evaluations, steps and wall time; and the beta = 0 run of dop853 at the same
accuracy (the cost the issue's target compares with). A run longer than ``cap`` seconds
(default 600) is abandoned and reported as such. Counts are the primary measure (wall
times on a shared machine are noisy: the load is printed).

Counts. dop853: ``n_rhs`` (12 per attempted step, peak location included). rodas4:
``n_rhs`` (5 per attempted step, 1 per accepted step, the W/D rows' differences and f_t
where there are any, peak location: every real evaluation), ``jac`` Jacobians (each ten
real forward-mode derivatives of the compiled rows, not in ``n_rhs``), ``lu`` banded
factorisations; ``us/step`` its wall time per step and ``us/rhs`` dop853's per evaluation.

Bending damping (Kelvin-Voigt) ``eta = zeta sqrt(beta)/(2 N^2)``: damping ratio about zeta
for the chain's shortest bending wave (:mod:`snapping.simulate.stiffness`), negligible for
the long waves of the fall. Without it the release excites undamped grid-scale bending
waves (the catenary is not a bending equilibrium) that any error-controlled method must
follow.

Usage (N list, beta list, accuracy, zeta list, cap in seconds)::

    python benchmarks/bench_stiff.py 1000 1e-6,1e-4,1e-2 1e-6 0,1 600
"""

import os
import signal
import sys
import time

import numpy as np

from snapping.simulate import Body, Problem, run

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import print_machine  # noqa: E402

CHI = 0.25
Q = ("v", "a", "sigma")
CAP = [600.0]
#: tolerance of the reference runs (dop853 at 1e-8: peaks within ~5e-9 of tol 1e-11,
#: docs/benchmarks/bench_default_tol.txt)
REF_TOL = 1e-8


class _Cap(Exception):
    pass


def _alarm(signum, frame):
    raise _Cap()


def one(p, method, tol):
    """A run to the snap; None when it takes longer than the cap."""
    signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, CAP[0])
    t0 = time.perf_counter()
    try:
        ds = run(problem=p, method=method, tol=tol, checkpoint_every=None).dataset
    except _Cap:
        return None
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
    w = time.perf_counter() - t0
    a = ds.attrs
    return {"peaks": [a[f"{q}_peak"] for q in Q], "rhs": int(a["n_rhs"]), "steps": int(a["n_steps"]),
            "rej": int(a["n_rejected"]), "wall": w, "t_end": float(a["t_final"]), "method": a["method"],
            "jac": int(a.get("n_jacobians", 0)), "lu": int(a.get("n_factorizations", 0))}


def err(pk, ref):
    return max(abs(a - b) / abs(b) for a, b in zip(pk, ref))


def ladder(method, p, ref, acc, tols):
    last = None
    for tol in tols:
        r = one(p, method, tol)
        if r is None:
            print(f"      {method} tol {tol:g}: over {CAP[0]:.0f} s, abandoned", flush=True)
            return {"tol": f"{tol:g}(cap)", "rhs": None}
        r["tol"], r["err"] = tol, err(r["peaks"], ref)
        last = r
        print(f"      {method} tol {tol:g}: err {r['err']:.1e}, rhs {r['rhs']}, steps {r['steps']}, jac {r['jac']}, "
              f"wall {r['wall']:.1f} s (t_final {r['t_end']:.4f}, load {os.getloadavg()[0]:.1f})", flush=True)
        if r["err"] <= acc:
            return r
    last["tol"] = f"{last['tol']:g}(miss)"
    return last


def _cell(r, rodas=False):
    if r.get("rhs") is None:
        return f"{r['tol']}, -"
    s = f"{r['tol']}, {r['rhs']}, {r['steps']}, {r['wall']:.1f} s"
    if rodas:
        s += f", jac {r['jac']}, {1e6 * r['wall'] / max(1, r['steps'] + r['rej']):.0f} us/step"
    else:
        s += f", {1e6 * r['wall'] / max(1, r['rhs']):.1f} us/rhs"
    return s


def main():
    Ns = [int(a) for a in (sys.argv[1] if len(sys.argv) > 1 else "100").split(",")]
    betas = [float(a) for a in (sys.argv[2] if len(sys.argv) > 2 else "1e-6,1e-4,1e-2").split(",")]
    acc = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-6
    zetas = [float(a) for a in (sys.argv[4] if len(sys.argv) > 4 else "0,1").split(",")]
    CAP[0] = float(sys.argv[5]) if len(sys.argv) > 5 else 600.0
    print_machine()
    print(f"chi = {CHI}, peaks within {acc:g} (relative) of dop853 at tol {REF_TOL:g}, bending damping "
          f"eta = zeta sqrt(beta)/(2 N^2), runs capped at {CAP[0]:.0f} s\n", flush=True)
    rows = []
    for N in Ns:
        p0 = Problem.catenary(CHI, N)
        ref0 = one(p0, "dop853", REF_TOL)["peaks"]
        base = ladder("dop853", p0, ref0, acc, [1e-6, 1e-7, 1e-8])
        print(f"N={N} beta=0: dop853 tol {base['tol']} rhs {base['rhs']} steps {base['steps']}", flush=True)
        for zeta in zetas:
            for beta in betas:
                eta = zeta * beta ** 0.5 / (2 * N * N)
                p = Problem.catenary(CHI, N, body=Body(bending=beta, damping=eta))
                R = one(p, "dop853", REF_TOL)
                if R is None:
                    print(f"  N={N} beta={beta:g} zeta={zeta:g}: reference over the cap", flush=True)
                    continue
                ref = R["peaks"]
                fast = run(problem=p, t_end=1e-3).dataset.attrs
                print(f"  N={N} beta={beta:g} zeta={zeta:g} eta={eta:.3g}: reference dop853 {REF_TOL:g} rhs {R['rhs']} "
                      f"({R['wall']:.0f} s, t_final {R['t_end']:.4f}); fast runs {fast['method']}", flush=True)
                d = ladder("dop853", p, ref, acc, [1e-6, 1e-7, 1e-8])
                s = ladder("rodas4", p, ref, acc, [1e-5, 3e-6, 1e-6, 3e-7, 1e-7])
                rows.append((N, beta, zeta, base, d, s, fast["method"]))
    print("\n| N | beta | zeta | fast | dop853 beta=0: tol, rhs | dop853: tol, rhs, steps, wall | "
          "rodas4: tol, rhs, steps, wall, jac | dop853/rodas4 rhs | rodas4/(beta=0) rhs | dop853/rodas4 wall |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for N, beta, zeta, b, d, s, f in rows:
        ok = d.get("rhs") and s.get("rhs")
        r1 = f"{d['rhs'] / s['rhs']:.2f}" if ok else "-"
        r2 = f"{s['rhs'] / b['rhs']:.2f}" if s.get("rhs") else "-"
        r3 = f"{d['wall'] / s['wall']:.2f}" if ok else "-"
        print(f"| {N} | {beta:g} | {zeta:g} | {f} | {b['tol']}, {b['rhs']} | {_cell(d)} | {_cell(s, True)} | {r1} | "
              f"{r2} | {r3} |")
    print(f"\nload after: {os.getloadavg()}; np {np.__version__}")


if __name__ == "__main__":
    main()
