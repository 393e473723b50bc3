"""The fit report as text tables: one run's rows (:func:`report_rows`), its delta comparison
(:func:`delta_rows`), and one line a run (:func:`summary_rows`).
"""

from __future__ import annotations

import math

from .delta import DeltaComparison
from .references import exponent_text
from .run_fit import RunFit


def _pad(rows: list[tuple], left: tuple = (0, -1)) -> list[tuple]:
    """Pad every column to its width (the columns ``left``, by default the first and the
    last, left-aligned; the rest right-aligned)."""
    rows = [tuple(str(c) for c in r) for r in rows]
    n = max(len(r) for r in rows)
    rows = [r + ("",) * (n - len(r)) for r in rows]
    w = [max(len(r[i]) for r in rows) for i in range(n)]
    lefts = {i % n for i in left}
    return [tuple(c.ljust(w[i]) if i in lefts else c.rjust(w[i]) for i, c in enumerate(r)) for r in rows]


def _pm(x: float, e: float) -> str:
    if not math.isfinite(x):
        return "-"
    return f"{x:+.4f} ± {e:.4f}" if math.isfinite(e) else f"{x:+.4f} ± inf"


def report_rows(res: RunFit) -> list[tuple]:
    """Rows (name, value, ...) of the exponent table of one run, for ``print_table``.

    Columns: quantity, beta with uncertainty (t* = t*_chi), reference exponent,
    window of t* - t, beta with t* fitted jointly, prefactor A against the ideal
    one, verdict.
    """
    out = [("quantity", "beta (t*=t*_chi)", "ref", "ideal in window", "window t*-t", "beta (t* fitted)",
            "A / A_ideal", "verdict", "notes")]
    for r in res.rows:
        s = r.spec
        refs = exponent_text(s.ref) + ("" if s.alt is None else f", {exponent_text(s.alt)}")
        if r.fit is None:
            out.append((s.name, "-", refs, "-", "-", "-", "-", f"{r.verdict}: {r.error}", ""))
            continue
        f = r.fit
        win = f"[{f.tau_lo:.2e}, {f.tau_hi:.2e}]"
        bj = "-" if r.fit_joint is None else _pm(r.fit_joint.beta, r.fit_joint.beta_err)
        ratio = "-" if s.prefactor is None else f"{f.A / s.prefactor:.3f}"
        bw = "-" if not math.isfinite(r.ideal_window_beta) else f"{r.ideal_window_beta:+.4f}"
        out.append((s.name, _pm(f.beta, f.beta_err), refs, bw, win, bj, ratio, r.verdict, r.notes))
    return _pad(out, left=(0, -2, -1))


def delta_rows(dc: DeltaComparison) -> list[tuple]:
    """Rows of the Fig. 4 table: each scale delta, its predicted v, a, sigma and the
    ratios predicted / computed; first the run's computed peaks."""
    rows = [("scale", "delta", "v", "a", "sigma", "predicted/computed v, a, sigma")]
    c = dc.computed
    rows.append(("computed peaks", "", f"{c['v']:.4g}", f"{c['a']:.4g}", f"{c['sigma']:.4g}", ""))
    ratios = dc.ratios()
    for k, dv in dc.deltas.items():
        p, rr = dc.predicted[k], ratios[k]
        rows.append((k, f"{dv:.4g}", f"{p['v']:.4g}", f"{p['a']:.4g}", f"{p['sigma']:.4g}",
                     f"{rr['v']:.3g}, {rr['a']:.3g}, {rr['sigma']:.3g}"))
    return _pad(rows)


def summary_rows(results: list[RunFit]) -> list[tuple]:
    """One row per run (several files or a sweep): chi, N, t*_chi and every exponent."""
    if not results:
        return []
    names = [r.spec.name for r in results[0].rows]
    head = ("chi", "N", "t*_chi", *names, "delta_kappa_m")
    out = [head]
    for res in results:
        cells = []
        for n in names:
            try:
                r = res.row(n)
            except KeyError:
                cells.append("-")
                continue
            cells.append("-" if r.fit is None else _pm(r.fit.beta, r.fit.beta_err))
        dkm = "-" if res.delta is None else f"{res.delta.deltas['delta_kappa_m']:.4g}"
        out.append((f"{res.chi:.4g}", str(res.N), f"{res.snap.t_star:.8f}", *cells, dkm))
    return _pad(out)
