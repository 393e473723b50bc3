"""The peak guard (:mod:`snapping.simulate.elastic_checks`, issue 22) against the peaks' own
convergence: chi 0.25, uniform links (shared lumping), undamped, RODAS4, to the snap, over N, c,
tol and start. Each row: the peaks, the guard's ringing measure and verdict, and a_peak's and
sigma_peak's relative difference from the tightest tol's run of the same (N, c, start).
``verdict``: ``ok`` (resolved and within ``--agree`` of the tightest), ``caught`` (flagged and
off), ``FALSE`` (flagged but within ``--agree``: a converged run flagged), ``MISS`` (passed but
off), ``ref`` (the tightest run: flagged or not, nothing to compare; ``no ref`` when it did not reach
the snap). Runs stopped by ``--max-rhs`` are reported with their stop reason (``no snap``).

Usage::

    PYTHONPATH=src python benchmarks/elastic_guard.py
    PYTHONPATH=src python benchmarks/elastic_guard.py --N 30 --c 3000 --tol 1e-5 1e-7 --start matched
"""

from __future__ import annotations

import argparse
import time

from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.problem import Links, Problem


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--N", type=int, nargs="+", default=[30, 100])
    ap.add_argument("--c", type=float, nargs="+", default=[30.0, 300.0, 3000.0])
    ap.add_argument("--tol", type=float, nargs="+", default=[1e-4, 1e-5, 1e-6, 1e-7])
    ap.add_argument("--start", nargs="+", default=["matched", "stretched"])
    ap.add_argument("--chi", type=float, default=0.25)
    ap.add_argument("--agree", type=float, default=1e-2, help="relative difference that counts as converged")
    ap.add_argument("--max-rhs", type=int, default=4_000_000)
    a = ap.parse_args(argv)
    print("| N | c | start | tol | status | v_peak | a_peak | sigma_peak | evaluations | CPU s | peak_ringing | "
          "resolved | da/a | dsigma/sigma | verdict | peak_note |")
    print("|" + "---|" * 16)
    counts = {}
    for N in a.N:
        for c in a.c:
            for start in a.start:
                rows = []
                for tol in sorted(a.tol):  # tightest first: the reference
                    c0 = time.process_time()
                    r = solve(Problem.catenary(a.chi, links=Links.uniform(N, lumping="shared")), Elastic(ea=c * c),
                              tol=tol, method="rodas4", start=start, max_rhs=a.max_rhs)
                    rows.append((tol, r.dataset.attrs, time.process_time() - c0))
                ref = rows[0][1] if rows[0][1]["stop_reason"] == "snap" else None
                for tol, at, cpu in rows:
                    da = ds = float("nan")
                    if ref is not None and at["stop_reason"] == "snap":
                        da = at["a_peak"] / ref["a_peak"] - 1.0
                        ds = at["sigma_peak"] / ref["sigma_peak"] - 1.0
                    ok = bool(at["peaks_resolved"])
                    if at is rows[0][1]:
                        verdict = "ref" if ref is not None else "no snap"
                    elif ref is None:
                        verdict = "no ref"
                    elif at["stop_reason"] != "snap":
                        verdict = "no snap"
                    else:
                        off = max(abs(da), abs(ds)) > a.agree
                        verdict = {(True, False): "ok", (False, True): "caught", (False, False): "FALSE",
                                   (True, True): "MISS"}[(ok, off)]
                    counts[verdict] = counts.get(verdict, 0) + 1
                    print(f"| {N} | {c:g} | {start} | {tol:g} | {at['status']} ({at['stop_reason']}) | "
                          f"{at['v_peak']:.6g} | {at['a_peak']:.5g} | {at['sigma_peak']:.5g} | {at['n_rhs']} | "
                          f"{cpu:.1f} | {at['peak_ringing']:.3g} | {int(ok)} | {da:+.1e} | {ds:+.1e} | {verdict} | "
                          f"{at['peak_note'][:60]} |", flush=True)
    print("verdicts:", counts)


if __name__ == "__main__":
    main()
