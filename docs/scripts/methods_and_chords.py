"""Peak speed (and the other peaks) of the two methods and the two chord choices.

The numbers quoted on the conventions page (docs/conventions.md): chi = 0.1, N = 1000,
tol 1e-8, each of ``euler-richardson`` and ``dop853`` from the catenary sampled at
equal arclength (``chords="arclength"``, the paper's) and with exact chords 1/N
(``chords="exact"``). About 30 s on one core.

Usage::

    PYTHONPATH=src python docs/scripts/methods_and_chords.py [--chi 0.1] [--N 1000]
"""

from __future__ import annotations

import argparse

from snapping.simulate import run


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--chi", type=float, default=0.1)
    p.add_argument("--N", type=int, default=1000)
    p.add_argument("--tol", type=float, default=1e-8)
    args = p.parse_args()
    rows = {}
    print(f"chi = {args.chi:g}, N = {args.N}, tol = {args.tol:g}")
    print(f"  {'method':<17} {'chords':<10} {'v_peak':>12} {'a_peak':>12} {'sigma_peak':>12} {'t_snap_v':>10} "
          f"{'link_drift':>10} {'drift_init':>10} {'energy_drift':>12} {'n_rhs':>9} {'wall s':>7}")
    for method in ("euler-richardson", "dop853"):
        for chords in ("arclength", "exact"):
            a = run(args.chi, args.N, method=method, chords=chords, tol=args.tol).dataset.attrs
            rows[method, chords] = a
            print(f"  {method:<17} {chords:<10} {a['v_peak']:>12.8g} {a['a_peak']:>12.8g} {a['sigma_peak']:>12.8g} "
                  f"{a['t_snap_v']:>10.8g} {a['link_drift']:>10.2g} {a['link_drift_initial']:>10.2g} "
                  f"{a['energy_drift']:>12.2g} {a['n_rhs']:>9d} "
                  f"{a['wall_time']:>7.2f}")
    print("relative differences of v_peak:")
    ref = rows["dop853", "exact"]["v_peak"]
    for (method, chords), a in rows.items():
        print(f"  {method:<17} {chords:<10} {a['v_peak'] / ref - 1:+.2e}  (against dop853, exact chords)")
    for method in ("euler-richardson", "dop853"):
        d = rows[method, "arclength"]["v_peak"] / rows[method, "exact"]["v_peak"] - 1
        print(f"  {method:<17} arclength against exact chords: {d:+.2e}")


if __name__ == "__main__":
    main()
