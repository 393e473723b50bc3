"""The side-by-side table of issue 22: this project, MoorDyn and PyElastica on the elastic falling
catenary (``elastic_common.py``), at matched peak accuracy, for each (N, c, start).

For each point: the reference (this project at two tolerances; their difference says to what
accuracy it is established), then for each code a ladder of runs, cheapest first, until two
runs in a row are within the finest level eps (``--levels``, default 1e-3 and 1e-4) by the
criterion ``--peak``
(``v``: the peak speed; ``sigma``: the peak tension; ``both``) or the code's CPU budget for the
point would be exceeded (the next run's cost is projected from the last: it is not started if
it would go past the budget):

* this project: ``--methods`` (default ``dop853,rodas4``; ``rodas4-links`` the link-coordinate
  RODAS4) at tolerances 1e-3, 3e-4, ...; with ``--table-only``, ``--methods`` given keeps only
  this project's cached runs of those methods (the table then is per method);
* MoorDyn: ``--schemes`` (default ``rk2,rk4``) at steps 0.25 h/c (RK2; h/c for RK4, stable to
  1.41 h/c), halved;
* PyElastica (``--pyelastica``): PositionVerlet at 0.8 h/c, halved, each with the softest
  stable rod (``pyelastica_elastic.bending_for``); a run projected past ``--pe-run-cap`` CPU
  seconds is not started: its step count at the stability limit is reported instead.

Every run is cached in ``elastic_runs.json`` beside this file (``SNAPPING_PEERS_RUNS`` names
another file), keyed by code, setting, N, c and start, so the table can be printed again
(``--table-only``) or extended without rerunning. Times are CPU seconds (``time.process_time``,
setup included, single-threaded; the start, given data, is computed before the clock starts);
a run within the coarsest level and cheaper than ``--repeat-cap`` seconds is timed ``--repeats``
times (default 3) and its least time kept. MoorDyn's time is its stepping alone
(``moordyn_elastic.stepping_cpu``: the same build, ``Step`` for 1000 steps a call, nothing
sampled between), its peaks those of the run sampled after every step; PyElastica's time
includes that sampling (15-19% of its run at N = 100). Counts are this project's right-hand-side
evaluations, MoorDyn's steps (2 evaluations each for RK2, 4 for RK4) and PyElastica's steps.

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


def _method(setting):
    """This project's method in a run's setting (``"tol=0.0003 (rodas4-links)"``)."""
    return setting.rsplit("(", 1)[-1].rstrip(")")


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


#: a run within the coarsest level eps (by v or sigma) is timed again up to REPEATS times in all,
#: if it took less than REPEAT_CAP CPU seconds; its ``cpu`` is the least (``--repeats``)
REPEATS, REPEAT_CAP = 3, 10.0


def cached(code, setting, N, c, start, fn, ref, retime=None):
    """The run (from the cache, or ``fn()`` and cached), scored against ``ref``. A new run within
    the coarsest level (by v or sigma: the only runs a cost at eps can come from) is timed again
    by ``retime(r)`` (a list of CPU seconds), and its ``cpu`` is their least."""
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
        E.score(r, ref)
        if retime is not None and min(r.err, r.err_sigma) <= max(E.LEVELS):
            times = retime(r)
            r.cpu_runs = tuple(float(x) for x in times)
            r.cpu = min(times)
        save(key, r)
    E.score(r, ref)
    runs = f"  CPU runs {', '.join(f'{x:.4g}' for x in r.cpu_runs)}" if r.cpu_runs else ""
    print(f"  {r.code:<11}{r.setting:<26}{r.count:>10d}{r.cpu:>9.3f}  v {r.v_peak:.7f} ({r.err:.1e})  "
          f"sigma {r.sigma_peak:.5f} ({r.err_sigma:.1e}){runs}", flush=True)
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
        def project(t, meth=meth):
            def fn():
                return E.run_project(chi, N, c, t, meth, start)

            def retime(r):  # the same run again (the same numbers: only the CPU time varies)
                return [r.cpu] + [fn().cpu for _ in range(REPEATS - 1 if r.cpu < REPEAT_CAP else 0)]

            return cached("snapping", f"tol={t:g} ({meth})", N, c, start, fn, ref, retime)

        rows += ladder([(t, 1.5) for t in tols], project, a.budget_project, finest)
    if moordyn_ok:
        import moordyn_elastic as MD

        def moordyn_run(dt, scheme):
            def retime(r):  # MoorDyn's stepping alone, without the per-step sampling (moordyn_elastic.stepping_cpu)
                # (checked from the matched start, where they agree to 1e-11 or better: from the stretched
                # start, N = 100, c = 30, RK4 at h/c, they agree to 2e-15 after 1000 steps and differ by
                # 1.3e-2 after 2000, round-off amplified by the ringing's slack-taut switches)
                n = min(r.count, 2 * MD.CHUNK)
                d = MD.chunk_check(chi, N, c, dt, scheme, n, "matched")
                if d > 1e-9:
                    raise RuntimeError(f"MoorDyn: {MD.CHUNK} steps a call differ from one a call by {d:.1e}")
                times = MD.stepping_cpu(chi, N, c, dt, scheme, r.count, start, REPEATS if r.cpu < REPEAT_CAP else 1)
                r.extra = (f"sampled run {r.cpu:.4g} s (peaks); cpu: stepping alone, {MD.CHUNK} steps a call "
                           f"(same states to {d:.0e} after {n} steps)")
                return times

            return cached("MoorDyn", f"{scheme} dt={dt:.3g}", N, c, start,
                          lambda: MD.run_moordyn(chi, N, c, dt, scheme, ref.t_end, start=start), ref, retime)

        for scheme in a.schemes.split(","):
            dt0 = MD.axial_dt(N, c, scheme)
            rows += ladder([(dt0 / 2 ** k, 2.0) for k in range(12)],
                           lambda dt, scheme=scheme: moordyn_run(dt, scheme), a.budget_moordyn, finest)
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
                cell = {k: (f"{r.setting}: {r.count:,} {'ev' if k == 'snapping' else 'st'}, {r.cpu:.3g} s"
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
    global REPEATS, REPEAT_CAP
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--N", default="100", help="links, comma-separated")
    ap.add_argument("--c", default="30", help="wave speeds c/sqrt(gL), comma-separated")
    ap.add_argument("--start", default="stretched", help="starts, comma-separated (stretched, matched)")
    ap.add_argument("--methods", default=None,
                    help="this project's methods (default dop853,rodas4; rodas4-links); with --table-only, "
                         "only the cached runs of these (default: all)")
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
    ap.add_argument("--repeats", type=int, default=3,
                    help="timings of a run within the coarsest eps (its CPU time the least; default 3)")
    ap.add_argument("--repeat-cap", type=float, default=10.0,
                    help="runs of more CPU seconds than this are timed once (default 10)")
    ap.add_argument("--table-only", action="store_true", help="only the cached runs (nothing new is run)")
    a = ap.parse_args(argv)
    only = None if a.methods is None else {m.strip() for m in a.methods.split(",") if m.strip()}
    if a.methods is None:
        a.methods = "dop853,rodas4"
    REPEATS, REPEAT_CAP = max(1, a.repeats), a.repeat_cap
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
        for meth in a.methods.split(","):  # compile (numba) before timing, for each start
            for st in E.STARTS:
                E.run_project(a.chi, 10, 10.0, 1e-3, meth, st)
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
                            if k.endswith(f"|N={N}|c={c:g}|start={start}")
                            and (only is None or v["code"] != "snapping" or _method(v["setting"]) in only)]
                    points[(N, c, start)] = (ref, rows)
                else:
                    points[(N, c, start)] = point(a.chi, N, c, start, a, moordyn_ok, elastica_ok)
    summary(points, E.LEVELS)
    print(f"\nuptime: {os.popen('uptime').read().strip()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
