"""What caps the snap of each line of the catalogue, in newtons (issue 24): the table of
:func:`snapping.caps_report.catalogue` (each line from runs of the real model, the ideal chain
beside it, the factor, the capping mechanism, the resolution check N/2 -> N, the cost).

Usage::

    python examples/caps_catalogue.py                 # chi = 0.25, N = 200 (the ball chain on its 229 links)
    python examples/caps_catalogue.py --N 100 400 1000 --chi 0.25   # the same at several N (the cost and the resolution)
    python examples/caps_catalogue.py --lines fly-line bungee-cord --N 1000
    python examples/caps_catalogue.py --N auto        # each line on the links that resolve its tension to 1%
"""

from __future__ import annotations

import argparse
import os

from snapping import caps, caps_report, lines


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--N", nargs="+", default=["200"],
                   help="links of the runs (default 200); auto: doubled from 100 until the tension moves by <= 1%%")
    p.add_argument("--chi", type=float, default=0.25, help="end separation (default 0.25)")
    p.add_argument("--lines", nargs="+", default=None, choices=lines.names(), help="default: every line")
    p.add_argument("--details", action="store_true", help="print each answer in full too")
    a = p.parse_args(argv)
    for N in a.N:
        N = N if N == "auto" else int(N)
        answers = caps_report.catalogue(a.chi, N, names=a.lines)
        print(f"\nchi = {a.chi:g}, N = {N} (load {os.getloadavg()[0]:.1f}; wall "
              f"{sum(r['wall'] for r in answers):.1f} s, CPU {sum(r['cpu'] for r in answers):.1f} s in all)\n")
        print("\n".join(caps_report.catalogue_table(answers)))
        if a.details:
            for r in answers:
                print("\n" + "\n".join(caps.format_answer(r)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
