"""Diagnostic: what sets a bending cell's snap acceleration peak, the links or the grid damping? (issue 24)

Usage: ``PYTHONPATH=src python benchmarks/bend_a_echo.py CHI BETA RUN [RUN ...]``, each RUN ``Lk[:ZETA]``
(the bending study's level k = 0-3 of its 4 fold levels, :func:`snapping.regimes._levels`, frac 0.08-0.01)
or ``UN[:ZETA]`` (N uniform links), ZETA the grid damping ratio (default 1, the study's). Each run is the
study's own (:func:`snapping.regimes.cell_problem`, RODAS4, tol 1e-7, the snap window's peaks
:func:`snapping.simulate.snap_window.run_snap_peaks`). Printed per run: the links, ``eta_max`` (the
largest per-node grid damping, ``zeta sqrt(beta) h^2 / 2`` at the longest links), the windowed a_peak,
its time and node (s_a_max; s = 1 the free end), v_peak and its time, sigma_peak, the free end's
acceleration ripple (RMS of ``a_end`` minus its 0.03-wide running mean over 0.9 <= t < 1.0 and 1.0 <= t
< 1.1), steps and CPU seconds (``time.process_time``). Then a least-squares line of a_peak against
``eta_max^(-1/2)`` over the runs given.

``--quench K T:ZQ [T:ZQ ...]`` instead of RUNs: level K run to t = T at the grid damping ratio ZQ, then on
from that state (:meth:`snapping.simulate.Problem.nodes`, positions and velocities) at the study's ratio 1;
printed: the largest acceleration after t = 0.8, its time and node, v_peak and the ripple as above. ``T:1``
is the control (the same run, restarted); a heavy ZQ (8) before T damps the bending waves already present
at T: if the crest goes, they made it.

Two runs with the same eta_max on different links (``L2:0.5`` and ``L3:2``: eta is proportional to
zeta h^2) separate the links' effect from the damping's. docs/guide/regimes.md ("Why chi = 0.5, beta =
0.01 misses in a_peak") gives the commands and numbers.
"""
from __future__ import annotations

import sys
import time

import numpy as np


def parse(spec: str):
    kind, _, z = spec.partition(":")
    zeta = float(z) if z else 1.0
    if kind[0] == "U":
        return {"n_links": int(kind[1:])}, zeta
    from snapping.regimes import _levels

    return _levels("fold", {"levels": 4, "first": -1, "n0": 50}, 0.5)[int(kind[1:])], zeta


def ripple(ds, lo: float, hi: float, width: float = 0.03, dt: float = 2e-4) -> float:
    t = ds.t.values
    tg = np.arange(max(lo - width, 0.0), min(hi + width, t[-1]), dt)
    a = np.interp(tg, t, ds.a_end.values)
    w = max(int(round(width / dt)), 1)
    hp = a - np.convolve(a, np.ones(w) / w, "same")
    m = (tg >= lo) & (tg < hi)
    return float(np.sqrt(np.mean(hp[m] ** 2))) if m.any() else float("nan")


def one(chi: float, beta: float, spec: str) -> dict:
    from snapping.regimes import cell_problem, eta_grid
    from snapping.simulate import run
    from snapping.simulate.snap_window import run_snap_peaks

    level, zeta = parse(spec)
    p = cell_problem(chi, "bending", beta, level, damping=zeta)
    cpu = time.process_time()
    ds = run(p, method="rodas4", tol=1e-7, progress=False).dataset
    cpu = time.process_time() - cpu
    w = run_snap_peaks(ds)
    t, a = ds.t.values, ds.a_max.values
    m = (t >= w["t_snap_start"]) & (t <= w["t_snap_end"])
    k = np.flatnonzero(m)[np.argmax(a[m])]
    return {"spec": spec, "N": p.links.N, "eta_max": float(np.max(eta_grid(p.links.h, beta, zeta))), "a": w["a_peak"],
            "t_a": float(t[k]), "s_a": float(ds.s_a_max.values[k]), "v": float(ds.attrs["v_peak"]),
            "t_v": float(ds.attrs["t_snap_v"]), "sigma": w["sigma_peak"], "rip1": ripple(ds, 0.9, 1.0),
            "rip2": ripple(ds, 1.0, 1.1), "steps": int(t.size), "cpu": cpu}


def quench(chi: float, beta: float, k: int, T: float, zq: float) -> dict:
    from snapping.regimes import cell_problem, eta_grid
    from snapping.simulate import Body, Problem, run

    level, _ = parse(f"L{k}")
    p1 = cell_problem(chi, "bending", beta, level, damping=zq)
    cpu = time.process_time()
    d1 = run(p1, method="rodas4", tol=1e-7, t_end=T, progress=False).dataset
    s = d1.isel(snapshot=[str(x) for x in d1.snapshot_kind.values].index("final"))
    t0 = float(s.t_snapshot)
    body = Body(bending=beta, damping=eta_grid(p1.links.h, beta, 1.0))
    p2 = Problem.nodes(s.x.values, s.y.values, links=p1.links, vx=s.vx.values, vy=s.vy.values, name="quenched",
                       body=body)
    d2 = run(p2, method="rodas4", tol=1e-7, progress=False).dataset
    cpu = time.process_time() - cpu
    d2 = d2.assign_coords(t=d2.t + t0)
    t, a = d2.t.values, d2.a_max.values
    i = np.flatnonzero(t > 0.8)[np.argmax(a[t > 0.8])]
    return {"spec": f"L{k} {T:g}:{zq:g}", "a": float(a[i]), "t_a": float(t[i]), "s_a": float(d2.s_a_max.values[i]),
            "v": float(d2.attrs["v_peak"]), "t_v": float(d2.attrs["t_snap_v"]) + t0, "rip1": ripple(d2, 0.9, 1.0),
            "t0": t0, "cpu": cpu}


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    chi, beta, specs = float(argv[0]), float(argv[1]), argv[2:]
    import os

    print(f"chi {chi:g} beta {beta:g}; load {os.getloadavg()[0]:.1f}")
    if specs and specs[0] == "--quench":
        k = int(specs[1])
        print(f"{'run':>12} {'t0':>7} {'a after 0.8':>11} {'t_a':>8} {'s_a':>6} {'v_peak':>9} {'t_v':>8} {'rip.9-1':>7} "
              f"{'cpu s':>6}")
        for tz in specs[2:]:
            T, zq = (float(x) for x in tz.split(":"))
            r = quench(chi, beta, k, T, zq)
            print(f"{r['spec']:>12} {r['t0']:7.4f} {r['a']:11.6g} {r['t_a']:8.5f} {r['s_a']:6.4f} {r['v']:9.6f} "
                  f"{r['t_v']:8.5f} {r['rip1']:7.3f} {r['cpu']:6.1f}", flush=True)
        return
    print(f"{'run':>9} {'links':>5} {'eta_max':>9} {'a_peak':>11} {'t_a':>8} {'s_a':>6} {'v_peak':>9} {'t_v':>8} "
          f"{'sigma':>9} {'rip.9-1':>7} {'rip1-1.1':>8} {'steps':>6} {'cpu s':>6}")
    rows = []
    for s in specs:
        r = one(chi, beta, s)
        rows.append(r)
        print(f"{r['spec']:>9} {r['N']:5d} {r['eta_max']:9.3e} {r['a']:11.6g} {r['t_a']:8.5f} {r['s_a']:6.4f} "
              f"{r['v']:9.6f} {r['t_v']:8.5f} {r['sigma']:9.6f} {r['rip1']:7.3f} {r['rip2']:8.3f} {r['steps']:6d} "
              f"{r['cpu']:6.1f}", flush=True)
    if len(rows) >= 3:
        x = np.array([r["eta_max"] for r in rows]) ** -0.5
        y = np.array([r["a"] for r in rows])
        c1, c0 = np.polyfit(x, y, 1)
        res = y - (c0 + c1 * x)
        print(f"a_peak = {c0:.6g} + {c1:.4g} eta_max^(-1/2); residuals over a_peak max {np.max(np.abs(res / y)):.1e}")


if __name__ == "__main__":
    main()
