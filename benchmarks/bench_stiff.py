"""Stiff (RODAS4, banded O(N) stage solves: :mod:`snapping.simulate.stiff`) against explicit
dop853 (``method="fast"``) on the snap of a chain with bending (issue 21, item 3).

For each N and bending number beta (= B in the chain's units): a reference run (dop853 at
tol 1e-11, cross-checked by the stiff method at tol 1e-9), then for each method the loosest
tolerance of a ladder whose peaks v, a, sigma are all within ``acc`` (relative, default
1e-6) of the reference, with its evaluations, steps and wall time; and the beta = 0 run of
dop853 at the same accuracy (the cost the issue's target compares with). Counts are the
primary measure (wall times on a shared machine are noisy).

Stiff's counts: ``rhs`` = right-hand-side evaluations of the steps (5 per attempted step,
1 per accepted step, the compiled kernel of every method, plus the W/D rows' differences
where there are any), ``+ref`` those of the peak location, ``jac`` Jacobians (each 20
complex-step evaluations of the compiled rows, not counted in ``rhs``), ``lu`` banded
factorisations, ``sol`` banded solves. dop853's ``rhs`` is its ``n_rhs``.

Optional bending damping (Kelvin-Voigt) ``eta = zeta sqrt(beta)/(2 N^2)``: damping ratio
about ``zeta`` for the chain's shortest bending wave (frequency ``sqrt(beta) (2N)^2``,
damping rate ``eta (2N)^4/2``), negligible for the long waves of the fall. Without it
the release excites undamped grid-scale bending waves (the catenary is not a bending
equilibrium: the free end and the hinge have zero moment) that any error-controlled
method must follow.

Usage (N list, beta list, accuracy, zeta)::

    python benchmarks/bench_stiff.py 100 1e-6,1e-4,1e-2
    python benchmarks/bench_stiff.py 100,300 1e-4,1e-2 1e-6 1
"""

import os
import sys
import time

import numpy as np

from snapping.simulate import Body, Problem, run
from snapping.simulate import stiff as ST

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_simulate import print_machine  # noqa: E402

CHI = 0.25
Q = ("v", "a", "sigma")


def dop(p, tol):
    t0 = time.perf_counter()
    ds = run(problem=p, method="fast", tol=tol).dataset
    w = time.perf_counter() - t0
    a = ds.attrs
    return {"peaks": [a[f"{q}_peak"] for q in Q], "rhs": int(a["n_rhs"]), "steps": int(a["n_steps"]),
            "rej": int(a["n_rejected"]), "wall": w, "t_end": float(ds["t"].values[-1])}


def stf(p, tol):
    o = ST.solve(p, None, tol, records=False)
    return {"peaks": [o[f"{q}_peak"] for q in Q], "rhs": o["n_rhs"] + o["n_rhs_extra"], "ref": o["n_rhs_refine"],
            "steps": o["n_steps"],
            "rej": o["n_rejected"], "jac": o["n_jac"], "lu": o["n_lu"], "sol": o["n_solves"], "wall": o["wall"]}


def err(pk, ref):
    return max(abs(a - b) / abs(b) for a, b in zip(pk, ref))


def ladder(fn, p, ref, acc, tols):
    last = None
    for tol in tols:
        r = fn(p, tol)
        r["tol"], r["err"] = tol, err(r["peaks"], ref)
        last = r
        print(f"      {fn.__name__} tol {tol:g}: err {r['err']:.1e}, rhs {r['rhs']}, steps {r['steps']}, "
              f"wall {r['wall']:.1f} s", flush=True)
        if r["err"] <= acc:
            return r
    last["tol"] = f"{last['tol']:g}(miss)"
    return last


def main():
    Ns = [int(a) for a in (sys.argv[1] if len(sys.argv) > 1 else "100").split(",")]
    betas = [float(a) for a in (sys.argv[2] if len(sys.argv) > 2 else "1e-6,1e-4,1e-2").split(",")]
    acc = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-6
    zeta = float(sys.argv[4]) if len(sys.argv) > 4 else 0.0
    print_machine()
    print(f"chi = {CHI}, peaks within {acc:g} (relative) of dop853 at tol 1e-11, bending damping "
          f"zeta = {zeta:g} (eta = zeta sqrt(beta)/(2 N^2))\n", flush=True)
    rows = []
    for N in Ns:
        p0 = Problem.catenary(CHI, N)
        ref0 = dop(p0, 1e-11)["peaks"]
        base = ladder(dop, p0, ref0, acc, [1e-5, 1e-6, 1e-7, 1e-8])
        print(f"N={N} beta=0: dop853 tol {base['tol']} rhs {base['rhs']} steps {base['steps']}", flush=True)
        for beta in betas:
            eta = zeta * beta ** 0.5 / (2 * N * N)
            p = Problem.catenary(CHI, N, body=Body(bending=beta, damping=eta))
            R = dop(p, 1e-11)
            ref = R["peaks"]
            chk = stf(p, 1e-9)
            print(f"  N={N} beta={beta:g} eta={eta:.3g}: reference dop853 1e-11 rhs {R['rhs']} ({R['wall']:.0f} s); "
                  f"stiff 1e-9 "
                  f"differs by {err(chk['peaks'], ref):.1e}", flush=True)
            d = ladder(dop, p, ref, acc, [1e-5, 1e-6, 1e-7, 1e-8])
            s = ladder(stf, p, ref, acc, [1e-5, 3e-6, 1e-6, 3e-7, 1e-7])
            rows.append((N, beta, eta, base, d, s, err(chk["peaks"], ref)))
    print("\n|   N | beta | eta | dop853 beta=0: tol, rhs | dop853: tol, rhs, steps, wall | "
          "stiff: tol, rhs (+ref), steps, "
          "jac/lu/sol, wall | dop853/stiff rhs | stiff / (beta=0 dop853) rhs | ref check |")
    print("|---|---|---|---|---|---|---|---|---|")
    for N, beta, eta, b, d, s, c in rows:
        tot = s["rhs"] + s["ref"]
        print(f"| {N} | {beta:g} | {eta:.2g} | {b['tol']}, {b['rhs']} | {d['tol']}, {d['rhs']}, {d['steps']}, "
              f"{d['wall']:.1f} s | "
              f"{s['tol']}, {s['rhs']} (+{s['ref']}), {s['steps']}, {s['jac']}/{s['lu']}/{s['sol']}, "
              f"{s['wall']:.1f} s | {d['rhs'] / tot:.2f} | {tot / b['rhs']:.2f} | {c:.1e} |")


if __name__ == "__main__":
    main()
