"""Text of the design answers of :mod:`snapping.caps`: :func:`format_answer` (one :func:`snapping.caps.cap`
answer) and :func:`format_design` (a :func:`snapping.caps.design`), both importable from :mod:`snapping.caps`."""

from __future__ import annotations

from .caps_runs import QUANTITIES

__all__ = ["format_answer", "format_design"]


def format_answer(r: dict) -> list[str]:
    """Text lines of a :func:`snapping.caps.cap` answer."""
    from .caps import RESOLVED

    out = [f"What caps the snap: {r['line']} at chi = {r['chi']:g}, {r['N']} links (runs of the real model, tol "
           f"{r['tol']:g})", f"  {'peak':<12}{'ideal chain':>14}{'real line':>14}{'factor':>9}   units"]
    for q, u in QUANTITIES.items():
        out.append(f"  {q:<12}{r['ideal'][q]:14.5g}{r['real'][q]:14.5g}{r['factor'][q]:9.4f}   {u}")
    io = r.get("ideal_on")
    if io:
        src = {"limit": "its continuum limit (shipped, snapping.table.limits)",
               "graded": "on the answer's graded links " + "/".join(map(str, io.get("links") or ())) + ", extrapolated",
               "uniform": f"on {io['N']} uniform links"}

        def err(q):
            e = io["relative_error"][q]
            return f"+- {e:.2%}" if e == e else "(error unknown)"

        groups = {}  # (one phrase per source: the peaks it gives, with their bars)
        for q in QUANTITIES:
            groups.setdefault(io["source"][q], []).append(f"{q} {err(q)}")
        out.append("  ideal chain: " + "; ".join(f"{src[k]}: {', '.join(v)}" for k, v in groups.items())
                   + "".join(f" [{q}: {w}]" for q, w in io.get("why", {}).items())
                   + f" (the ideal's peaks grow with its links; on {io['N']} uniform links: "
                   + ", ".join(f"{q} {io['uniform'][q]:.5g}" for q in QUANTITIES) + ")")
    if r["alone"]:
        left = not r["stretching"].get("resolved", {}).get(r["quantity"], True)
        out.append(f"  each mechanism alone ({r['quantity']}): " + ", ".join(
            f"{m} {v[r['quantity']]:.5g}"
            + (" (factor not resolved: the ideal's)" if m == "stretching" and left else "")
            for m, v in r["alone"].items()))
    out.append(f"  stretching: {r['stretching']['why']}")
    if r.get("auto_N") and r.get("graded", {}).get("used"):
        out.append(f"  links: graded (below) from the first, {r['N']} links for the ideal chain and each "
                   f"mechanism alone")
    elif r.get("own_links"):
        out.append(f"  links: {r['own_links']['why']}")
    elif r.get("auto_why"):
        out.append(f"  links: {r['auto_why']}")
    elif r.get("auto_N"):
        out.append(f"  links: doubled over {', '.join(map(str, r['auto_N']))} until {r['quantity']} moved by <= "
                   f"{RESOLVED:.0%}: {'resolved' if r['resolved'] else 'NOT resolved'} at {r['N']}")
    g = r.get("graded", {})
    if g.get("too_fine"):
        out.append(f"  graded links: {g['why']}")
    if g.get("used"):
        a, b = (g["levels"][k] for k in g["pair"])
        obs = g.get("observed_order")
        out.append(f"  graded links: {g['why']}; full run on levels of {', '.join(map(str, g['levels']))} links, "
                   f"{a} and {b} extrapolated (order {g['order']:g}"
                   + (", observed " + ", ".join(f"{q} {v:.2f}" for q, v in obs.items()) if obs else "")
                   + f"; {g['stop_why']}): " + ", ".join(
                       f"{q} +- {g['relative_error'][q]:.2%}" for q in QUANTITIES)
                   + f" ({'within' if g['within'] else 'NOT within'} 1%)")
    if r["resolution"]:
        what = "graded levels, coarse -> fine" if g.get("used") else "full run, N/2 -> N"
        out.append(f"  resolution ({what}): " + ", ".join(f"{q} {v:+.2%}" for q, v in r["resolution"].items()))
    verdict = ("nothing but the ideal chain's own cap (real within 10% of ideal)" if r["cap"] == "none" else r["cap"])
    out.append(f"  capped by: {verdict} -- {r['quantity']} {r['real'][r['quantity']]:.5g} "
               f"{QUANTITIES[r['quantity']]} (ideal {r['ideal'][r['quantity']]:.5g})"
               + (f"; {r['cap_why']}" if r.get("cap_why") else ""))
    out.append(f"  rule: {r['rule']}")
    stiff = [f"{x['run']} ({x['N']})" for x in r.get("runs", ()) if x["method"] == "rodas4"]
    out.append(f"  cost: {r['n_rhs']} right-hand-side evaluations, {r['wall']:.2f} s ({r['cpu']:.2f} s CPU); "
               f"{len(r.get('runs', ()))} runs" + (f", RODAS4 (stiff): {', '.join(stiff)}" if stiff else ""))
    return out


def format_design(d: dict) -> list[str]:
    """Text lines of a :func:`snapping.caps.design` answer."""
    from .caps import AUTO_N, RESOLVED

    lim = ", ".join(f"{q} <= {v:g} {QUANTITIES[q]}" for q, v in d["limits"].items())
    q = d.get("quantity", "sigma_peak")
    auto = d["N"] == "auto"
    links = (f"links resolved per chi (N='auto': doubled from {AUTO_N[0]} until {q} moves by <= {RESOLVED:.0%}, or "
             f"graded)" if auto else f"{d['N']} links")
    out = [f"Design from runs of the real model: {d['line']}, {links}; limits {lim}",
           f"  {'chi':>6}{'ideal v':>11}{'real v':>11}{'ideal a':>11}{'real a':>11}{'ideal T':>11}{'real T':>11}"
           f"{'T factor':>10}  {'capped by':<12}  real ok  ideal ok" + ("  links" if auto else "")]
    for r in d["rows"]:
        i, x = r["ideal"], r["real"]
        where = ""
        if auto:
            where = ("combined" if r.get("stretching", {}).get("combined") else
                     "graded" if r.get("graded", {}).get("used") else str(r.get("N")))
            where = f"  {where}{'' if r.get('resolved') else ' (NOT resolved)'}"
        out.append(f"  {r['chi']:6.3g}{i['v_peak']:11.4g}{x['v_peak']:11.4g}{i['a_peak']:11.4g}{x['a_peak']:11.4g}"
                   f"{i['sigma_peak']:11.4g}{x['sigma_peak']:11.4g}{r['factor']['sigma_peak']:10.4f}  "
                   f"{_cap_word(r['cap']):<12}  {('yes?' if r.get('unsure') else 'yes') if r['admissible'] else 'no':>7}  "
                   f"{'yes' if r['ideal_admissible'] else 'no':>8}" + where)
    gr = [f"{r['chi']:g} (T +- {r['graded']['relative_error']['sigma_peak']:.2%}"
          + ("" if r["graded"].get("stopped", "within") == "within" else ", NOT all peaks within 1%") + ")"
          for r in d["rows"] if r.get("graded", {}).get("used")]
    if gr:
        out.append(f"  real peaks from graded links, the last two levels extrapolated, at chi: {', '.join(gr)}")
    cb = [f"{r['chi']:g} (T +- {r['stretching']['combined']['relative_error']['sigma_peak']:.2%}; capped by "
          f"{r['cap']}: {r.get('cap_why') or '-'})" for r in d["rows"] if r.get("stretching", {}).get("combined")]
    if cb:
        out.append("  real peaks from the combined model (elastic + body) on graded links, extrapolated, against the "
                   f"ideal chain's continuum limit, at chi: {'; '.join(cb)}")
    st = [f"{r['chi']:g} ({', '.join(q for q, ok in r['stretching']['resolved'].items() if not ok)})"
          for r in d["rows"] if r.get("stretching", {}).get("run") and not all(r["stretching"]["resolved"].values())]
    if st:
        lv = sorted({tuple(x["N"] for x in r["stretching"]["levels"]) for r in d["rows"] if r.get("stretching", {}).get("run")})
        out.append(f"  stretching factor NOT applied (not resolved from {' or '.join(f'{a} to {b}' for a, b in lv)} "
                   f"links) at chi: {'; '.join(st)}")
    if d.get("admissible_unsure"):
        out.append("  under the limits but NOT counted admissible: " + "; ".join(
            f"{x['chi']:g} ({', '.join(x['why'])})" for x in d["admissible_unsure"]))
    ok = d["admissible_chi"]
    out.append(f"  admissible chi (real line): {', '.join(f'{c:g}' for c in ok) if ok else 'none of those tried'}")
    out.append(f"  capped by: the mechanism whose run alone comes nearest the real {q} (none: real/ideal >= 0.9, "
               f"the ideal chain's own cap)")
    out.append(f"  cost: {d.get('n_rhs', 0)} right-hand-side evaluations, {d['wall']:.1f} s "
               f"({d.get('cpu', d['wall']):.1f} s CPU)")
    return out


def _cap_word(c: str) -> str:
    return "-" if c.startswith("not decided") else c
