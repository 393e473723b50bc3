"""Why does a little bending stiffness raise the snap at small chi? (issue 24)

The bending study (``docs/guide/regimes.md``, ``bench_bendconv.py``) found the converged peak tip
speed at chi = 0.1 raised by a small stiffness: x1.729 at beta = 7.2e-8, x1.288 at 1e-8, x1.685 at
5.2e-7; x1.193 at chi = 0.2, x1.030 at 0.3, none at 0.5. This script runs the bent cell of the study
(:func:`snapping.regimes.cell_problem`: rest start, grid damping 1, RODAS4) and, on the SAME links,
the ideal chain and variants that switch one ingredient at a time:

* ``ideal``: no body, the catenary start (DOP853);
* ``bent``: the study's cell (bending, its grid damping, the heavy-elastica rest start);
* ``bent-cat``: the same body released from the catenary instead of its rest shape;
* ``ideal-rest``: the ideal chain released from the bent line's rest shape;
* ``damp-only``: the grid damping alone (bending 0);
* ``bent-z0.5`` / ``bent-z2``: the grid damping ratio halved / doubled;
* ``ideal-late`` / ``bent-late``: as ``ideal`` / ``bent``, run on after the snap until v_max falls to
  ``LATE_STOP`` of its peak or to t = ``LATE_END`` (is the peak the stop rule's?).

Each run's diagnostics (``row``): its peaks, cost (evaluations, CPU by ``time.process_time``), the
energy balance (max over the run of |E + dissipated - E0|, E = kinetic + gravity + bending, and the
recorded energy at the peak against kinetic + gravity recomputed here from the peak profile), where
the kinetic energy sits at the peak (fractions within arclength r of the free end, the length
holding half of it), the bending energy (its maximum, when, its value at the peak), the fold (the
curvature maximum's growth exponent ``kappa_max ~ (t* - t)^-p`` over t* - t in [1e-4, 1e-2], and the
paper's regularisation length: the first time the fold's distance from the free end falls to its
quarter circle pi / (2 kappa_max), delta_kappa, with the estimate v_delta = sqrt(6 P / delta), P the
energy released), and the bending length l_B = sqrt(beta / sigma_max) there against the fold radius.

Results are kept in a JSON file (``--out``) and reused (rerunning resumes); ``--figure`` draws the
fold's curvature and the peak speed against t* - t, bent against ideal.

Usage::

    python benchmarks/bending_rise.py                                  # the default set (below)
    python benchmarks/bending_rise.py --table                          # what is done so far
    python benchmarks/bending_rise.py --chi 0.1 --beta 7.2e-8 --k 0 --variants ideal bent bent-cat
    python benchmarks/bending_rise.py --table --figure docs/guide/bending_rise.png
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "results", "bending_rise.json")
VARIANTS = ("ideal", "bent", "bent-cat", "ideal-rest", "damp-only", "bent-z0.5", "bent-z2", "ideal-late", "bent-late")
#: the '-late' variants: run on until v_max falls to LATE_STOP of its peak (the study's 0.5) or to t = LATE_END
LATE_STOP, LATE_END = 0.1, 1.3
#: the bent runs' RODAS4 tolerance (the study's 1e-7 moves the peaks by < 1e-5 relative at these levels,
#: bench_bendconv's measurement) and the ideal's DOP853 tolerance (the study's)
TOL_BENT, TOL_IDEAL = 1e-6, 1e-7
RADII = (1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 1e-2)
#: the window of the curvature exponent fit, t* - t
FIT = (1e-4, 1e-2)


def level(k: int) -> dict:
    from snapping.continuum import level_parameters

    return level_parameters(1, 0.5, first=k)[0]


def problems(chi: float, beta: float, k: int, variant: str):
    """The problem of ``variant`` on the bent cell's links, and the method and tolerance it runs at."""
    from snapping.regimes import GRID_DAMPING, cell_problem, eta_grid
    from snapping.simulate import Body, Links, Problem

    bent = cell_problem(chi, "bending", beta, level(k))
    h = bent.links.h
    variant = variant.replace("-late", "")
    links = Links.graded(h, lumping="shared")
    if variant == "ideal":
        return Problem.catenary(chi, links=links, chords="exact"), "fast", TOL_IDEAL
    if variant == "bent":
        return bent, "rodas4", TOL_BENT
    if variant == "ideal-rest":
        return Problem.nodes(bent.x, bent.y, links=links, name="bent rest shape"), "fast", TOL_IDEAL
    zeta = {"bent-z0.5": 0.5, "bent-z2": 2.0}.get(variant, GRID_DAMPING)
    eta = eta_grid(h, beta, zeta)
    if variant == "bent-cat":
        body = Body(bending=beta, damping=eta)
        return Problem.catenary(chi, links=links, chords="exact", body=body, start="catenary"), "rodas4", TOL_BENT
    if variant == "damp-only":
        return Problem.catenary(chi, links=links, chords="exact", body=Body(damping=eta)), "rodas4", TOL_BENT
    if variant in ("bent-z0.5", "bent-z2"):
        return cell_problem(chi, "bending", beta, level(k), damping=zeta), "rodas4", TOL_BENT
    raise SystemExit(f"unknown variant {variant!r}: one of {VARIANTS}")


def peak_profile(ds) -> dict:
    """Where the kinetic energy sits at the peak (the snapshot of kind 'peak'), and the energy there
    recomputed from the profile: kinetic + gravity (zero for the line hanging straight down at rest)."""
    m, h = ds.node_mass.values, ds.link_length.values
    r = np.concatenate([[0.0], np.cumsum(h)])  # distance of each node from the free end (index 0)
    kinds = [str(x) for x in ds.snapshot_kind.values]
    s = ds.isel(snapshot=kinds.index("peak"))
    ke = 0.5 * m * (s.vx.values ** 2 + s.vy.values ** 2)
    K = float(ke.sum())
    ck = np.cumsum(ke)
    # gravity: y downward; hanging straight down from the pin, node j sits at depth L - r_j
    U = -float(np.sum(m * s.y.values)) + float(np.sum(m * (r[-1] - r)))
    t = float(s.t_snapshot)
    i = int(np.argmin(np.abs(ds.t.values - t)))
    rec = float(ds.energy.values[i]) - (float(ds.bending_energy.values[i]) if "bending_energy" in ds else 0.0)
    return {"K": K, "K_within": {f"{x:g}": float(ke[r <= x].sum()) for x in RADII},
            "l50": float(r[np.searchsorted(ck, 0.5 * K)]), "l90": float(r[np.searchsorted(ck, 0.9 * K)]),
            "energy_check": abs(K + U - rec), "t_peak_snapshot": t}


def fold(ds, beta: float) -> dict:
    """The fold from the step record: the curvature maximum's growth exponent, the paper's
    regularisation length delta_kappa (the fold's distance from the free end first at or below its
    quarter circle pi / (2 kappa_max)), the estimate v_delta = sqrt(6 P / delta), and the bending
    length sqrt(beta / sigma_max) against the fold radius 1 / kappa_max there."""
    t, km = ds.t.values, ds.kappa_max.values
    dist = 1.0 - ds.s_kappa_max.values
    ts = float(ds.attrs["t_snap_v"])
    P = float(ds.attrs["energy_initial"])
    w = (ts - t >= FIT[0]) & (ts - t <= FIT[1])
    p = -float(np.polyfit(np.log(ts - t[w]), np.log(km[w]), 1)[0])
    hit = np.flatnonzero(dist <= 0.5 * math.pi / km)
    before = t <= ts
    h0 = float(ds.link_length.values[0])
    out = {"kappa_exponent": p, "dist_min": float(dist[before].min()), "dist_min_links": float(dist[before].min()) / h0,
           "kappa_at": {f"{x:g}": float(np.interp(ts - x, t, km)) for x in (1e-2, 1e-3, 1e-4)}}
    if hit.size:
        i = int(hit[0])
        d = float(dist[i])
        out.update({"delta": d, "t_delta": float(t[i]), "tstar_minus_t_delta": ts - float(t[i]),
                    "v_delta": math.sqrt(6.0 * P / d), "fold_radius": 1.0 / float(km[i]),
                    "sigma_at_delta": float(ds.sigma_max.values[i])})
        if beta > 0:
            out["l_B_at_delta"] = math.sqrt(beta / float(ds.sigma_max.values[i]))
    return out


def history(ds, n: int = 160) -> dict:
    """The step record thinned to ~n steps log-spaced in t* - t (for the figure)."""
    t = ds.t.values
    ts = float(ds.attrs["t_snap_v"])
    want = ts - np.logspace(-0.5, -7.0, n)
    i = np.unique(np.clip(np.searchsorted(t, want), 0, t.size - 1))
    return {"tstar_minus_t": (ts - t[i]).tolist(), "kappa_max": ds.kappa_max.values[i].tolist(),
            "v_max": ds.v_max.values[i].tolist(), "dist": (1.0 - ds.s_kappa_max.values[i]).tolist()}


def diagnose(ds, beta: float) -> dict:
    a = ds.attrs
    E, E0 = ds.energy.values, float(a["energy_initial"])
    D = ds.dissipated.values if "dissipated" in ds else np.zeros_like(E)
    i = int(np.argmax(ds.v_max.values))
    row = {q: float(a[q]) for q in ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "t_snap_v", "energy_initial")}
    row.update({"N": int(a["N"]), "n_rhs": int(a["n_rhs"]), "method": a["method"], "tol": float(a["tol"]),
                "start_rest": a.get("start_rest", "catenary"), "closure": float(np.abs(E + D - E0).max()),
                "dissipated_at_peak": float(D[i]), "dissipated_final": float(D[-1]),
                "s_v_max_at_peak": float(ds.s_v_max.values[i]), "t_final": float(a["t_final"]),
                "stop_reason": a.get("stop_reason", "")})
    if "bending_energy" in ds:
        Eb = ds.bending_energy.values
        j = int(np.argmax(Eb))
        row.update({"Eb_start": float(Eb[0]), "Eb_max": float(Eb[j]), "t_Eb_max": float(ds.t.values[j]),
                    "Eb_at_peak": float(Eb[i])})
    row["peak"] = peak_profile(ds)
    row["fold"] = fold(ds, beta)
    row["history"] = history(ds)
    return row


def key(chi, beta, k, variant):
    return f"{chi:g} {beta:g} {k} {variant}"


def load(path):
    return json.load(open(path)) if os.path.isfile(path) else {}


def run_one(chi, beta, k, variant, path):
    from snapping.simulate import run

    db = load(path)
    kk = key(chi, beta, k, variant)
    if kk in db:
        return db[kk]
    prob, method, tol = problems(chi, beta, k, variant)
    cpu = time.process_time()
    late = variant.endswith("-late")
    ds = run(prob, method=method, tol=tol, stop_fraction=LATE_STOP if late else 0.5,
             t_end_max=LATE_END if late else 10.0, progress=False).dataset
    cpu = time.process_time() - cpu
    if ds.attrs.get("status") != "completed" or not (late or int(ds.attrs.get("snap_reached", 0))):
        raise RuntimeError(f"{kk}: {ds.attrs.get('status')} {ds.attrs.get('stop_reason')}")
    row = diagnose(ds, beta if variant.startswith("bent") else 0.0)
    row["cpu"] = cpu
    row["load"] = os.getloadavg()[0]
    db = load(path)
    db[kk] = row
    tmp = path + ".tmp"
    json.dump(db, open(tmp, "w"), indent=1)
    os.replace(tmp, path)
    print(f"{kk}: v_peak={row['v_peak']:.5g} N={row['N']} rhs={row['n_rhs']} cpu={cpu:.1f}s "
          f"load={row['load']:.1f}", flush=True)
    return row


def table(path):
    db = load(path)
    print(f"machine: {platform.node()} {platform.machine()} {os.cpu_count()} cpus; CPU seconds by time.process_time "
          f"(includes the first run's compilation)")
    cells = sorted({tuple(x.split()[:3]) for x in db}, key=lambda c: (float(c[0]), float(c[1]), int(c[2])))
    for c in cells:
        chi, beta, k = float(c[0]), float(c[1]), int(c[2])
        rows = {v: db[key(chi, beta, k, v)] for v in VARIANTS if key(chi, beta, k, v) in db}
        ide = rows.get("ideal")
        n = next(iter(rows.values()))["N"]
        print(f"\nchi={chi:g} beta={beta:g} level k={k} (frac {level(k)['frac']:g}), N={n} links, all variants "
              f"on these links")
        print(f"  {'variant':10} {'v_peak':>8} {'ratio':>6} {'t*':>10} {'closure':>8} {'E chk':>7} {'diss@pk':>8} "
              f"{'Eb max':>8} {'K<1e-4':>6} {'K<1e-3':>6} {'l50':>8} {'p_kappa':>7} {'k(1e-3)':>7} {'k(1e-4)':>7} "
              f"{'delta':>8} {'v_delta':>7} {'R/l_B':>6} {'d_min/h':>7} {'t_final':>9} {'rhs':>7} {'cpu s':>6}")
        for v, r in rows.items():
            pk, fo = r["peak"], r["fold"]
            ratio = r["v_peak"] / ide["v_peak"] if ide else float("nan")
            rlb = fo["fold_radius"] / fo["l_B_at_delta"] if "l_B_at_delta" in fo else float("nan")
            print(f"  {v:10} {r['v_peak']:8.4g} {ratio:6.3f} {r['t_snap_v']:10.7f} {r['closure']:8.1e} "
                  f"{pk['energy_check']:7.0e} {r['dissipated_at_peak']:8.1e} {r.get('Eb_max', 0.0):8.1e} "
                  f"{pk['K_within']['0.0001'] / pk['K']:6.3f} {pk['K_within']['0.001'] / pk['K']:6.3f} "
                  f"{pk['l50']:8.2e} {fo['kappa_exponent']:7.3f} {fo['kappa_at']['0.001']:7.0f} "
                  f"{fo['kappa_at']['0.0001']:7.0f} {fo.get('delta', float('nan')):8.2e} "
                  f"{fo.get('v_delta', float('nan')):7.4g} {rlb:6.1f} {fo['dist_min_links']:7.1f} {r['t_final']:9.6f} "
                  f"{r['n_rhs']:7d} {r['cpu']:6.1f}")
        b = rows.get("bent")
        if ide and b:
            pb, pi = b["peak"], ide["peak"]
            vr = b["v_peak"] / ide["v_peak"]
            dr = b["fold"].get("v_delta", float("nan")) / ide["fold"].get("v_delta", float("nan"))
            print(f"  bent / ideal: v_peak x{vr:.3f}; the fold's estimate sqrt(delta_ideal/delta_bent) x{dr:.3f}; "
                  f"delta {b['fold'].get('delta', float('nan')):.2e} against {ide['fold'].get('delta', float('nan')):.2e}"
                  f" (t* - t there {b['fold'].get('tstar_minus_t_delta', float('nan')):.1e} against "
                  f"{ide['fold'].get('tstar_minus_t_delta', float('nan')):.1e}); t* earlier by "
                  f"{ide['t_snap_v'] - b['t_snap_v']:.2e}")
            for x in ("0.0001", "0.0003", "0.001"):
                ex = pb["K_within"][x] - pi["K_within"][x]
                print(f"  kinetic energy within {float(x):g} of the free end at the peak: bent {pb['K_within'][x]:.4f}, "
                      f"ideal {pi['K_within'][x]:.4f} (excess {ex:+.4f} = {ex / b['Eb_max']:+.1f} x the bent "
                      f"line's largest bending energy {b['Eb_max']:.2e})")
            print(f"  kinetic energy at the peak: bent {pb['K']:.4f}, ideal {pi['K']:.4f}; released P: bent "
                  f"{b['energy_initial']:.5f}, ideal {ide['energy_initial']:.5f}; dissipated by the grid damping to "
                  f"the peak {b['dissipated_at_peak']:.2e}")


def figure(path, out, cells):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    db = load(path)
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    styles = {"ideal": "-", "bent": "--"}
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ci, (chi, beta, k) in enumerate(cells):
        for v, ls in styles.items():
            r = db.get(key(chi, beta, k, v))
            if r is None:
                continue
            h = r["history"]
            lab = f"chi={chi:g} k={k} " + ("ideal" if v == "ideal" else f"beta={beta:g}")
            ax[0].loglog(h["tstar_minus_t"], h["kappa_max"], ls, color=colors[ci % len(colors)], label=lab)
            ax[1].loglog(h["tstar_minus_t"], h["v_max"], ls, color=colors[ci % len(colors)], label=lab)
            fo = r["fold"]
            if "delta" in fo:
                ax[0].plot(fo["tstar_minus_t_delta"], 0.5 * math.pi / fo["delta"], "o", color=colors[ci % len(colors)],
                           mfc="none" if v == "ideal" else colors[ci % len(colors)])
    ax[0].set_xlabel("t* - t")
    ax[0].set_ylabel("kappa_max (o: fold meets its quarter circle, delta)")
    ax[1].set_xlabel("t* - t")
    ax[1].set_ylabel("v_max")
    for a in ax:
        a.invert_xaxis()
        a.grid(True, which="both", alpha=0.3)
    ax[0].legend(fontsize=7)
    ax[0].set_title("the fold's curvature: bent (dashed) vs ideal (solid)", fontsize=9)
    ax[1].set_title("maximum speed, same links", fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"figure: {out}")


#: the default set: the rise's cell at two levels (the second resolves the bending length at the fold),
#: every variant on the coarser; the other betas and the controls chi = 0.3 and 0.5
DEFAULT = ([(0.1, 7.2e-8, 0, VARIANTS), (0.1, 7.2e-8, 2, ("ideal", "bent", "bent-cat")),
            (0.1, 1e-8, 0, ("ideal", "bent")), (0.1, 5.18e-7, 0, ("ideal", "bent")),
            (0.1, 3.73e-6, 0, ("ideal", "bent")),
            (0.3, 5.18e-7, 0, ("ideal", "bent")), (0.5, 5.18e-7, 0, ("ideal", "bent"))])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--chi", type=float, nargs="*", default=[])
    ap.add_argument("--beta", type=float, nargs="*", default=[])
    ap.add_argument("--k", type=int, nargs="*", default=[], help="fold levels: frac = 0.04 * 2**-k (the study's)")
    ap.add_argument("--variants", nargs="*", default=["ideal", "bent"], choices=VARIANTS)
    ap.add_argument("--out", default=OUT)
    ap.add_argument("--table", action="store_true", help="only print what is done")
    ap.add_argument("--figure", default=None, help="draw the fold's curvature and v_max against t* - t")
    a = ap.parse_args(argv)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    todo = [(c, b, k, tuple(a.variants)) for k in a.k for c in a.chi for b in a.beta] if a.chi else \
        ([] if a.table else DEFAULT)
    for chi, beta, k, vs in todo:
        for v in vs:
            run_one(chi, beta, k, v, a.out)
    table(a.out)
    if a.figure:
        figure(a.out, a.figure, [(0.1, 7.2e-8, 0), (0.1, 7.2e-8, 2), (0.3, 5.18e-7, 0)])


if __name__ == "__main__":
    main()
