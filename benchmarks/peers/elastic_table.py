"""The side-by-side table of issue 22: this project, MoorDyn and PyElastica on the elastic falling
catenary (``elastic_common.py``), at matched peak accuracy, for each (N, c, start).

For each point: the reference (this project at two tolerances; their difference says to what
accuracy it is established), then for each code a ladder of runs, cheapest first, until two
runs in a row are within the finest level eps (``--levels``, default 1e-3 and 1e-4) by the
criterion ``--peak``
(``v``: the peak speed; ``sigma``: the peak tension; ``both``) or the code's CPU budget for the
point would be exceeded (the next run's cost is projected from the last: it is not started if
it would go past the budget):

* this project: ``--methods`` (default ``dop853,rodas4``) at tolerances 1e-3, 3e-4, ...;
* MoorDyn: ``--schemes`` (default ``rk2,rk4``) at steps 0.25 h/c (RK2; 0.5 h/c for RK4), halved;
* PyElastica (``--pyelastica``): PositionVerlet at 0.8 h/c, halved, each with the softest
  stable rod (``pyelastica_elastic.bending_for``); a run projected past ``--pe-run-cap`` CPU
  seconds is not started: its step count at the stability limit is reported instead.

Every run is cached in ``elastic_runs.json`` beside this file (``SNAPPING_PEERS_RUNS`` names
another file), keyed by code, setting, N, c and start, so the table can be printed again
(``--table-only``) or extended without rerunning. Times are CPU seconds (``time.process_time``,
setup included, single-threaded); counts are this project's right-hand-side evaluations,
MoorDyn's steps (2 evaluations each for RK2, 4 for RK4) and PyElastica's steps.

Usage::

    python benchmarks/peers/elastic_table.py --N 100 --c 30 --start stretched,matched
    python benchmarks/peers/elastic_table.py --N 100,400 --c 30,300 --start stretched,matched --table-only
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from dataclasses import asdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import elastic_common as E  # noqa: E402

RUNS = os.environ.get("SNAPPING_PEERS_RUNS", os.path.join(E.HERE, "elastic_runs.json"))
#: this project's tolerance ladder (loosest first)
TOLS = (1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7)


def _key(code, setting, N, c, start):
    return f"{code}|{setting}|N={N}|c={c:g}|start={start}"


def load():
    if os.path.exists(RUNS):
        with open(RUNS) as fh:
            return json.load(fh)
    return {}


def save(key, r):
    cache = load()
    cache[key] = asdict(r)
    with open(RUNS, "w") as fh:
        json.dump(cache, fh, indent=1, sort_keys=True)


def cached(code, setting, N, c, start, fn, ref):
    """The run (from the cache, or ``fn()`` and cached), scored against ``ref``."""
    key = _key(code, setting, N, c, start)
    cache = load()
    if key in cache:
        r = E.Result(**cache[key])
    else:
        try:
            r = fn()
        except FloatingPointError as e:
            print(f"  ({e})", flush=True)
            return None
        save(key, r)
    E.score(r, ref)
    print(f"  {r.code:<11}{r.setting:<26}{r.count:>10d}{r.cpu:>9.2f}  v {r.v_peak:.7f} ({r.err:.1e})  "
          f"sigma {r.sigma_peak:.5f} ({r.err_sigma:.1e})", flush=True)
    return r


def ladder(settings, run, budget, finest):
    """Runs ``run(setting)`` along ``settings`` until two in a row are within ``finest`` (by
    ``E.CRITERION``: one within it by chance is not taken for converged) or the next run's
    projected cost (``factor`` times the last) would exceed the budget; settings are
    (setting, projected-cost factor) pairs."""
    rows, spent, last = [], 0.0, None
    for setting, factor in settings:
        if last is not None and spent + factor * last.cpu > budget:
            print(f"  (next run {setting} skipped: projected {factor * last.cpu:.0f} s CPU, budget {budget:g} s, "
                  f"spent {spent:.0f} s)", flush=True)
            break
        r = run(setting)
        if r is None:
            continue
        rows.append(r)
        spent += r.cpu
        last = r
        if len(rows) >= 2 and E.error(rows[-1]) <= finest and E.error(rows[-2]) <= finest:
            break
    return rows


def point(chi, N, c, start, a, moordyn_ok, elastica_ok):
    ref = E.reference(chi, N, c, start=start)
    E.header(ref, chi)
    finest = min(E.LEVELS)
    rows = []
    for meth in a.methods.split(","):
        tols = [float(x) for x in a.tols.split(",")] if a.tols else TOLS
        rows += ladder([(t, 1.5) for t in tols],
                       lambda t, meth=meth: cached("snapping", f"tol={t:g} ({meth})", N, c, start,
                                                   lambda: E.run_project(chi, N, c, t, meth, start), ref),
                       a.budget_project, finest)
    if moordyn_ok:
        import moordyn_elastic as MD

        for scheme in a.schemes.split(","):
            dt0 = MD.axial_dt(N, c, scheme)
            rows += ladder([(dt0 / 2 ** k, 2.0) for k in range(12)],
                           lambda dt, scheme=scheme: cached(
                               "MoorDyn", f"{scheme} dt={dt:.3g}", N, c, start,
                               lambda: MD.run_moordyn(chi, N, c, dt, scheme, ref.t_end, start=start), ref),
                           a.budget_moordyn, finest)
    if elastica_ok and a.pyelastica:
        import pyelastica_elastic as PE

        dt0 = PE.axial_dt(N, c)
        pe_rows = []
        for k in range(14):
            dt = dt0 / 2 ** k
            steps = int(ref.t_end / dt)
            if pe_rows:
                per = pe_rows[-1].cpu / max(pe_rows[-1].count, 1)
                if steps * per > a.pe_run_cap:
                    print(f"  (PyElastica dt={dt:.3g} not run: {steps} steps, projected {steps * per:.0f} s CPU "
                          f"> {a.pe_run_cap:g} s at {per * 1e6:.0f} us a step)", flush=True)
                    break
            r = cached("PyElastica", f"dt={dt:.3g} B={PE.bending_for(dt, c * c):.2g}", N, c, start,
                       lambda dt=dt: PE.run_pyelastica(chi, N, c, dt, t_end=ref.t_end, start=start), ref)
            if r is not None:
                pe_rows.append(r)
                if E.error(r) <= finest:
                    break
        rows += pe_rows
    return ref, rows


def summary(points, levels, criteria=("v", "both")) -> None:
    """The markdown table: per point and level, the cheapest run of each code within eps from
    which on every finer run of its ladder (smaller tol or dt) is within eps too (``elastic_common.cheapest``),
    and the ratios of CPU times."""
    print("\n| N | c | start | ref (agreement v / sigma) | peak | eps | this project | MoorDyn | PyElastica "
          "| MoorDyn/this | PyElastica/this | >= 10x |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for (N, c, start), (ref, rows) in points.items():
        for crit in criteria:
            for eps in levels:
                best = {k: E.cheapest(rows, k, eps, crit) for k in ("snapping", "MoorDyn", "PyElastica")}
                ran = {k: any(r.code == k for r in rows) for k in best}
                cell = {k: (f"{r.setting}: {r.count:,} {'ev' if k == 'snapping' else 'st'}, {r.cpu:.2f} s"
                            if r else "not reached" if ran[k] else "not run") for k, r in best.items()}
                s = best["snapping"]
                q = {k: (f"{best[k].cpu / s.cpu:.3g}x" if s and best[k] else "-") for k in ("MoorDyn", "PyElastica")}
                ok = []
                for k in ("MoorDyn", "PyElastica"):
                    if s and best[k]:
                        ok.append("yes" if best[k].cpu >= 10 * s.cpu else "no")
                    elif s:
                        ok.append("(peer not reached)" if ran[k] else "(peer not run)")
                    else:
                        ok.append("(this project not reached)")
                agree = ref.agree_v if crit == "v" else max(ref.agree_v, ref.agree_sigma)
                flag = " (ref not established)" if eps < agree else ""
                print(f"| {N} | {c:g} | {start} | {ref.v_peak:.6f} ({ref.agree_v:.1e} / {ref.agree_sigma:.1e}) | "
                      f"{crit} | {eps:g}{flag} | {cell['snapping']} | {cell['MoorDyn']} | {cell['PyElastica']} | "
                      f"{q['MoorDyn']} | {q['PyElastica']} | {' / '.join(ok)} |")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--N", default="100", help="links, comma-separated")
    ap.add_argument("--c", default="30", help="wave speeds c/sqrt(gL), comma-separated")
    ap.add_argument("--start", default="stretched", help="starts, comma-separated (stretched, matched)")
    ap.add_argument("--methods", default="dop853,rodas4", help="this project's methods")
    ap.add_argument("--tols", default="", help="this project's tolerances, in the order tried (default 1e-3 ... 1e-7)")
    ap.add_argument("--schemes", default="rk2,rk4", help="MoorDyn's schemes (its tScheme names)")
    ap.add_argument("--pyelastica", action="store_true", help="run PyElastica too")
    ap.add_argument("--peak", default="v", choices=("v", "sigma", "both"), help="the ladders' stop criterion")
    ap.add_argument("--levels", default="1e-3,1e-4")
    ap.add_argument("--ref-tol", default="", help="the reference's tolerance per N, e.g. 100:1e-9,400:1e-6")
    ap.add_argument("--ref-method", default=E.REF_METHOD)
    ap.add_argument("--budget-project", type=float, default=300.0, help="CPU s per method and point")
    ap.add_argument("--budget-moordyn", type=float, default=400.0, help="CPU s per scheme and point")
    ap.add_argument("--pe-run-cap", type=float, default=180.0, help="CPU s for one PyElastica run")
    ap.add_argument("--table-only", action="store_true", help="only the cached runs (nothing new is run)")
    a = ap.parse_args(argv)
    sys.stdout.reconfigure(line_buffering=True)
    E.CRITERION, E.REF_METHOD = a.peak, a.ref_method.lower()
    E.LEVELS = tuple(sorted((float(x) for x in a.levels.split(",") if x), reverse=True))
    ref_tols = {int(k): float(v) for k, v in (x.split(":") for x in a.ref_tol.split(",") if x)}
    try:
        import moordyn  # noqa: F401
        moordyn_ok = True
    except ImportError:
        moordyn_ok = False
    try:
        import elastica  # noqa: F401
        elastica_ok = True
    except ImportError:
        elastica_ok = False
    if not a.table_only:
        E.machine("moordyn")
        for meth in a.methods.split(","):  # compile (numba) before timing
            E.run_project(a.chi, 10, 10.0, 1e-3, meth, "stretched")
        if elastica_ok and a.pyelastica:
            import pyelastica_elastic as PE

            PE.run_pyelastica(a.chi, 10, 30.0, 1e-4, t_end=1e-3)  # compile before timing
    points = {}
    for N in (int(x) for x in a.N.split(",")):
        for c in (float(x) for x in a.c.split(",")):
            for start in a.start.split(","):
                E.REF_TOL = ref_tols.get(N, E.REF_TOL)
                if a.table_only:
                    ref = E.reference(a.chi, N, c, start=start)
                    cache = load()
                    rows = [E.score(E.Result(**v), ref) for k, v in cache.items()
                            if k.endswith(f"|N={N}|c={c:g}|start={start}")]
                    points[(N, c, start)] = (ref, rows)
                else:
                    points[(N, c, start)] = point(a.chi, N, c, start, a, moordyn_ok, elastica_ok)
    summary(points, E.LEVELS)
    print(f"\nuptime: {os.popen('uptime').read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
