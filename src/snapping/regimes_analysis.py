"""What a regime study finds (issue 24, item 3): power laws, crossovers, the regime map.

Pure functions on arrays, then on a study (:func:`snapping.regimes.regimes`):

* :func:`power_law` fits ``y = A x^p`` on the longest run of points whose local log-log
  slopes agree within ``slope_tol`` (three points or more), with the exponent's
  uncertainty; where no such run exists it says so plainly (``constant`` False) and fits
  nothing.
* :func:`crossover` finds the first number where a ratio to the ideal falls below
  ``level`` (0.9: 10% below), interpolated linearly in (log number, log ratio), with an
  interval from the ratios' error bars.
* :func:`analyze` applies both to the resolved cells (converging, error bar <= 5%, and the study's
  ``converged`` flag where it has one) of each chi of a study
  (the power law to the capped cells alone, ratio < 0.9), fits the crossover against chi,
  and :func:`report` prints it; :func:`regime_map` draws chi against the number, colour
  the peak over the ideal's, with the 0.9 contour.

>>> import numpy as np
>>> x = np.array([1e-4, 1e-3, 1e-2, 1e-1])
>>> f = power_law(x, 2.0 * x**-0.5)
>>> round(f["exponent"], 12), round(f["prefactor"], 12), f["constant"]
(-0.5, 2.0, True)
>>> round(crossover([1e-4, 1e-2], [1.0, 0.81])["number"], 12)
0.001
"""

from __future__ import annotations

import math

import numpy as np

from . import _validate as V

__all__ = ["power_law", "crossover", "crossover_law", "resolved", "analyze", "report", "regime_map", "LEVEL", "MAX_REL_ERROR", "RATIO_MAX_ERROR",
           "level_ratios", "with_level_ratios"]

#: the crossover: the peak 10% below the ideal's
LEVEL = 0.9


def _xy(x, y, yerr=None):
    x = np.asarray(V.float_array("x", x), dtype=float).ravel()
    y = np.asarray(V.float_array("y", y), dtype=float).ravel()
    if x.size != y.size:
        raise V.SnappingInputError(f"x and y must have one length; got {x.size} and {y.size}")
    e = None if yerr is None else np.asarray(V.float_array("yerr", yerr), dtype=float).ravel()
    if e is not None and e.size != x.size:
        raise V.SnappingInputError(f"yerr must have the length of x ({x.size}); got {e.size}")
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if e is not None:
        ok &= np.isfinite(e)
    order = np.argsort(x[ok])
    return x[ok][order], y[ok][order], (None if e is None else e[ok][order])


def power_law(x, y, yerr=None, *, slope_tol: float = 0.1, min_points: int = 3) -> dict:
    """Fit ``y = A x^p`` where the local log-log slope is constant.

    Parameters
    ----------
    x, y : array_like
        Positive samples (others are dropped); ``x`` need not be sorted.
    yerr : array_like, optional
        Error bars of ``y`` (weights 1/(yerr/y)^2 in log; None: equal weights).
    slope_tol : float
        Largest spread (max - min) of the local slopes ``d log y / d log x`` between
        neighbours over the fitted points.
    min_points : int
        Fewest points of a power law (>= 2).

    Returns
    -------
    dict
        ``constant`` (bool: a run of ``min_points`` points or more with constant slope was
        found), ``exponent``, ``exponent_err`` (least-squares standard error -- from the
        error bars, or the scatter when larger -- and half the slopes' spread, in
        quadrature), ``prefactor`` (A), ``x_lo``, ``x_hi``, ``n_points``, ``slopes``
        (all local slopes), ``statement`` (one sentence).
    """
    tol = V.real("slope_tol", slope_tol)
    if not (math.isfinite(tol) and tol > 0):
        raise V.SnappingInputError(f"slope_tol={slope_tol!r} is out of range: must be finite and > 0")
    min_points = V.integer("min_points", min_points, 2)
    x, y, e = _xy(x, y, yerr)
    nan = float("nan")
    out = {"constant": False, "exponent": nan, "exponent_err": nan, "prefactor": nan, "x_lo": nan, "x_hi": nan,
           "n_points": 0, "slopes": []}
    if x.size < 2:
        out["statement"] = f"no power law: {x.size} usable point(s)"
        return out
    X, Y = np.log(x), np.log(y)
    s = np.diff(Y) / np.diff(X)
    out["slopes"] = s.tolist()
    best = None  # (points, last index, first index): the longest run, at the largest x on ties
    for i in range(s.size):
        for j in range(i, s.size):
            run = s[i:j + 1]
            if run.max() - run.min() > tol:
                break
            n = j - i + 2
            if n >= min_points and (best is None or (n, j) >= (best[0], best[1])):
                best = (n, j, i)
    if best is None:
        out["statement"] = (f"no power law: the local slopes vary from {s.min():.3g} to {s.max():.3g} over "
                            f"{x[0]:.3g}..{x[-1]:.3g} (no {min_points} neighbours within {tol:g})")
        return out
    n, j, i = best
    sl = slice(i, j + 2)
    Xf, Yf = X[sl], Y[sl]
    w = np.ones_like(Xf) if e is None else 1.0 / np.maximum((e[sl] / y[sl]) ** 2, 1e-300)
    W = w.sum()
    xm, ym = (w @ Xf) / W, (w @ Yf) / W
    sxx = w @ (Xf - xm) ** 2
    p = float((w @ ((Xf - xm) * (Yf - ym))) / sxx)
    a = float(ym - p * xm)
    res = Yf - (a + p * Xf)
    stat = math.sqrt(float(w @ res**2) / max(n - 2, 1) / sxx) if n > 2 else 0.0
    if e is not None:
        stat = max(stat, math.sqrt(1.0 / sxx))
    spread = float(s[i:j + 1].max() - s[i:j + 1].min())
    err = math.hypot(stat, 0.5 * spread)
    out.update({"constant": True, "exponent": p, "exponent_err": err, "prefactor": math.exp(a),
                "x_lo": float(x[i]), "x_hi": float(x[j + 1]), "n_points": n,
                "statement": f"power law exponent {p:.3f} +- {err:.2g} over {x[i]:.3g}..{x[j + 1]:.3g} "
                             f"({n} points)"})
    return out


def _cross(x, r, level):
    """First crossing of ``level`` from above by ``r`` (x ascending): the number, or a side."""
    above = r >= level
    if not above[0]:
        return "below"
    k = np.flatnonzero(~above)
    if k.size == 0:
        return "above"
    k = int(k[0])
    x1, x2, r1, r2 = x[k - 1], x[k], r[k - 1], r[k]
    f = (math.log(level) - math.log(r1)) / (math.log(r2) - math.log(r1))
    return math.exp(math.log(x1) + f * (math.log(x2) - math.log(x1)))


def crossover(numbers, ratio, ratio_err=None, *, level: float = LEVEL) -> dict:
    """The number where ``ratio`` (peak / the ideal's) first falls below ``level``, scanning
    the numbers upward, interpolated linearly in (log number, log ratio).

    Returns
    -------
    dict
        ``number`` (nan when not bracketed), ``lo`` and ``hi`` (the crossover of
        ``ratio + err`` and ``ratio - err``: its interval; nan when not bracketed),
        ``bracketed`` (bool), ``statement``.
    """
    lev = V.real("level", level)
    if not (0.0 < lev < 1.0 or lev > 1.0):
        raise V.SnappingInputError(f"level={level!r} is out of range: must be > 0 and not 1")
    x, r, e = _xy(numbers, ratio, ratio_err)
    nan = float("nan")
    if x.size == 0:
        return {"number": nan, "lo": nan, "hi": nan, "bracketed": False, "statement": "no finite ratios"}
    c = _cross(x, r, lev)
    if isinstance(c, str):
        side = (f"above {x[-1]:.3g}: the ratio stays >= {lev:g} up to the largest number" if c == "above" else
                f"below {x[0]:.3g}: the ratio is already < {lev:g} at the smallest number")
        return {"number": nan, "lo": nan, "hi": nan, "bracketed": False, "statement": f"crossover {side}"}
    lo = hi = nan
    if e is not None:
        a, b = _cross(x, r - e, lev), _cross(x, r + e, lev)
        lo = a if not isinstance(a, str) else (x[0] if a == "below" else nan)
        hi = b if not isinstance(b, str) else (x[-1] if b == "above" else nan)
    return {"number": c, "lo": lo, "hi": hi, "bracketed": True,
            "statement": f"crossover at {c:.3g}" + (f" (interval {lo:.3g}..{hi:.3g})" if e is not None else "")}


def crossover_law(chis, crossovers, lo=None, hi=None) -> dict:
    """Fit ``crossover = A chi^q`` through the crossovers of several chi (least squares in log).

    Parameters
    ----------
    chis, crossovers : array_like
        Positive values (others dropped).
    lo, hi : array_like, optional
        Each crossover's interval (:func:`crossover`); the log half-width ``log(hi/lo)/2`` is
        its standard error (weights its inverse square). Without them, or where an interval
        is not finite, the points weigh equally and the error comes from the scatter.

    Returns
    -------
    dict
        ``exponent`` q, ``exponent_err`` (the weighted fit's standard error, scaled up by
        sqrt(chi^2/dof) when the points scatter more than their intervals), ``prefactor`` A,
        ``n_points``, ``statement``. Two points: the exponent through them, error from their
        intervals (nan without). Fewer: nan and a statement saying so.
    """
    c = np.asarray(V.float_array("chis", chis), dtype=float).ravel()
    n = np.asarray(V.float_array("crossovers", crossovers), dtype=float).ravel()
    if c.size != n.size:
        raise V.SnappingInputError(f"chis and crossovers must have one length; got {c.size} and {n.size}")
    if lo is not None and hi is not None:
        lo = np.asarray(V.float_array("lo", lo), dtype=float).ravel()
        hi = np.asarray(V.float_array("hi", hi), dtype=float).ravel()
        if lo.size != c.size or hi.size != c.size:
            raise V.SnappingInputError(f"lo and hi must have the length of chis ({c.size})")
        with np.errstate(invalid="ignore", divide="ignore"):
            sig = 0.5 * np.abs(np.log(hi / lo))
    else:
        sig = np.full(c.size, np.nan)
    ok = np.isfinite(c) & np.isfinite(n) & (c > 0) & (n > 0)
    c, n, sig = c[ok], n[ok], sig[ok]
    nan = float("nan")
    if c.size < 2 or np.unique(c).size < 2:
        return {"exponent": nan, "exponent_err": nan, "prefactor": nan, "n_points": int(c.size),
                "statement": f"crossover against chi: {c.size} chi with a bracketed crossover (a law needs 2 or more)"}
    X, Y = np.log(c), np.log(n)
    weighted = bool(np.all(np.isfinite(sig) & (sig > 0)))
    w = 1.0 / sig**2 if weighted else np.ones_like(X)
    W = w.sum()
    xm, ym = (w @ X) / W, (w @ Y) / W
    sxx = float(w @ (X - xm) ** 2)
    q = float((w @ ((X - xm) * (Y - ym))) / sxx)
    a = float(ym - q * xm)
    dof = c.size - 2
    chi2 = float(w @ (Y - a - q * X) ** 2)
    if weighted:
        err = math.sqrt(1.0 / sxx) * (max(1.0, math.sqrt(chi2 / dof)) if dof > 0 else 1.0)
    else:
        err = math.sqrt(chi2 / dof / sxx) if dof > 0 else nan
    how = "weighted by the crossovers' intervals" if weighted else "equal weights"
    return {"exponent": q, "exponent_err": err, "prefactor": math.exp(a), "n_points": int(c.size),
            "statement": f"crossover ~ {math.exp(a):.3g} chi^{q:.3f} +- {err:.2g} ({c.size} chi, {how})"}


#: a cell is resolved when its extrapolation converged with an error bar at most this fraction of its value
MAX_REL_ERROR = 0.05


def resolved(value, error, order, max_rel_error: float = MAX_REL_ERROR) -> np.ndarray:
    """Which cells are resolved: an observed order (the levels converge) and a relative error
    bar <= ``max_rel_error``. The others are left out of fits and crossovers, and named."""
    v, e, o = (np.asarray(a, dtype=float) for a in (value, error, order))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.isfinite(o) & np.isfinite(v) & (np.abs(e) <= max_rel_error * np.abs(v))


def analyze(ds, quantity: str = "v_peak", *, slope_tol: float = 0.1, max_rel_error: float = MAX_REL_ERROR) -> dict:
    """Per chi of a study: the power law of the peak against the number in the capped regime
    (resolved cells whose ratio to the ideal is below :data:`LEVEL`) and the crossover (on
    the resolved cells, :func:`resolved`); and the crossover against chi."""
    if quantity not in ds or f"{quantity}_ratio" not in ds:
        raise V.SnappingInputError(f"quantity={quantity!r} is not in the study")
    nums = ds.number.values
    rows = {}
    for chi in ds.chi.values:
        c = ds.sel(chi=chi)
        ok = resolved(c[quantity].values, c[f"{quantity}_error"].values, c[f"{quantity}_order"].values, max_rel_error)
        if "converged" in c:  # the study's own verdict (snapping.regimes_resolution): levels before the asymptotics
            ok &= c["converged"].values.astype(bool)
        ideal_ok = abs(float(c[f"{quantity}_ideal_error"])) <= max_rel_error * abs(float(c[f"{quantity}_ideal"]))
        capped = ok & (c[f"{quantity}_ratio"].values < LEVEL)  # the law of the cap: past the crossover only
        fit = power_law(nums[capped], c[quantity].values[capped], c[f"{quantity}_error"].values[capped],
                        slope_tol=slope_tol)
        fit["statement"] = f"capped regime (ratio < {LEVEL:g}, {int(capped.sum())} resolved cells): " + fit["statement"]
        cross = crossover(nums[ok], c[f"{quantity}_ratio"].values[ok], c[f"{quantity}_ratio_error"].values[ok])
        if not ideal_ok:
            cross = {**cross, "number": float("nan"), "bracketed": False,
                     "statement": "no crossover: the ideal's limit is not resolved (error bar > "
                                  f"{max_rel_error:.0%})"}
        bad = [format(n, "g") for n in nums[~ok]]
        if bad:
            note = f" [unresolved, left out: {', '.join(bad)}]"
            fit["statement"] += note
        rows[float(chi)] = {"fit": fit, "crossover": cross, "ideal": float(c[f"{quantity}_ideal"]),
                            "ideal_error": float(c[f"{quantity}_ideal_error"]), "unresolved": bad}
    pts = [(chi, r["crossover"]["number"], r["crossover"]["lo"], r["crossover"]["hi"]) for chi, r in rows.items()
           if r["crossover"]["bracketed"]]
    if pts:
        cx, nx, lo, hi = np.array(pts).T
        law = crossover_law(cx, nx, lo, hi)
    else:
        law = crossover_law([], [])
    return {"quantity": quantity, "mechanism": ds.attrs["mechanism"], "number_name": ds.attrs["number_name"],
            "chi": rows, "crossover_law": law}


def report(ds, quantities=("v_peak", "a_peak", "sigma_peak")) -> list[str]:
    """Text lines: each cell's limit and ratio, then each chi's power law and crossover."""
    name = ds.attrs["number_name"]
    lines = [f"regime study: {ds.attrs['mechanism']} ({ds.attrs['mechanism_description']}), number {name}; "
             f"{ds.attrs['grading']} levels x{ds.sizes['level']}, status {ds.attrs['status']}"]
    if ds.attrs.get("peaks") == "snap" and ds.attrs["mechanism"] == "bending":
        lines.append("a_peak, sigma_peak of the cells: the snap's without the release (while v_max is above half its "
                     "peak around it: snapping.simulate.snap_window.run_snap_peaks), not the run's")
    elif ds.attrs.get("peaks") == "snap":
        lines.append("a_peak, sigma_peak of the cells: the snap's (each run's a_peak_snap, sigma_peak_snap: up to v_max "
                     "below 0.9 of its peak after it, snapping.simulate.snap_window), not the run's")
    elif ds.attrs.get("peaks") == "snap-taut":
        lines.append("a_peak of the cells: the snap's (each run's a_peak_snap: up to v_max below 0.9 of its peak after "
                     "it); sigma_peak: the taut snap's (sigma_peak_taut: until the line first goes slack after the "
                     "speed peak; snapping.simulate.snap_window), not the run's")
    if ds.sizes["level"] > int(ds.attrs.get("levels", ds.sizes["level"])):
        lines.append(f"escalated: a cell whose v, a or sigma bar exceeds {ds.attrs['escalate']:g} of its limit runs up "
                     f"to {ds.attrs['extra_levels']} more level(s) (levels_run; snapping.regimes_escalate)")
    for q in quantities:
        lines.append(f"{q}: limit +- error (ratio to the ideal)")
        lines.append(f"{'chi':>6} {'ideal':>18} " + " ".join(f"{name + '=' + format(n, 'g'):>28}"
                                                           for n in ds.number.values))
        for chi in ds.chi.values:
            c = ds.sel(chi=chi)
            cells = [f"{float(c[q][j]):.5g} +- {float(c[q + '_error'][j]):.2g} ({float(c[q + '_ratio'][j]):.3f})"
                     + ("*" if _unconverged(c, j) else "") for j in range(ds.sizes["number"])]
            lines.append(f"{chi:6.3g} {float(c[q + '_ideal']):9.5g} +- {float(c[q + '_ideal_error']):5.2g} "
                         + " ".join(f"{x:>28}" for x in cells))
        if "converged" in ds and not ds["converged"].values.all():
            lines.append("  * not converged (snapping.regimes_resolution): the levels are not yet in their asymptotic "
                         "regime; the value is the finest level's extrapolation, not the continuum's")
        a = analyze(ds, q)
        for chi, r in a["chi"].items():
            lines.append(f"  chi={chi:g}: {r['fit']['statement']}; {r['crossover']['statement']}")
        lines.append(f"  {a['crossover_law']['statement']}")
    return lines


def _unconverged(c, j) -> bool:
    """Whether cell ``j`` of one chi's row is flagged not converged (a study without the flag: no)."""
    return "converged" in c and not bool(c["converged"].values[j])


def regime_map(ds, path=None, quantity: str = "v_peak"):
    """The regime map: chi against the number (log), colour = peak / the ideal's, the 0.9
    contour where the grid has 2 x 2 cells or more. Saved to ``path`` when given."""
    import matplotlib

    if path is not None:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    r = ds[f"{quantity}_ratio"].values
    nums, chis = ds.number.values, ds.chi.values
    fig, ax = plt.subplots(figsize=(6, 4))
    def edges(v, log):  # cell edges halfway between the values (in log for the numbers)
        u = np.log(v) if log else np.asarray(v, float)
        if u.size == 1:
            e = np.array([u[0] - 0.5, u[0] + 0.5]) if log else np.array([u[0] * 0.9, u[0] * 1.1])
        else:
            mid = 0.5 * (u[1:] + u[:-1])
            e = np.concatenate([[2 * u[0] - mid[0]], mid, [2 * u[-1] - mid[-1]]])
        return np.exp(e) if log else e

    mesh = ax.pcolormesh(edges(nums, True), edges(chis, False), r, shading="flat", cmap="viridis", vmin=0.0,
                         vmax=max(1.0, np.nanmax(r)))
    fig.colorbar(mesh, ax=ax, label=f"{quantity} / ideal")
    if r.shape[0] >= 2 and r.shape[1] >= 2 and np.nanmin(r) < LEVEL < np.nanmax(r):
        cs = ax.contour(nums, chis, r, levels=[LEVEL], colors="w")
        ax.clabel(cs, fmt={LEVEL: f"{LEVEL:g}"})
    for i, chi in enumerate(chis):
        for j, n in enumerate(nums):
            if np.isfinite(r[i, j]):
                ax.annotate(f"{r[i, j]:.2f}" + ("?" if _unconverged(ds.isel(chi=i), j) else ""), (n, chi), ha="center", va="center", fontsize=7, color="k",
                            bbox={"boxstyle": "round", "fc": "w", "alpha": 0.6, "lw": 0})
    ax.set_xscale("log")
    ax.set_xlabel(f"{ds.attrs['number_name']} ({ds.attrs['mechanism']})")
    ax.set_ylabel("chi")
    head, tail = f"what caps the snap: {ds.attrs['mechanism']}", f"({quantity} / ideal; contour {LEVEL:g})"
    title = f"{head} {tail}" if len(head) + len(tail) < 60 else f"{head}\n{tail}"  # (a long one in two lines)
    if "converged" in ds and not ds["converged"].values.all():
        ax.set_title(title + "\n?: not converged (left out of the fits)", fontsize=10)
    else:
        ax.set_title(title, fontsize=10 if "\n" in title else None)
    fig.tight_layout()
    if path is not None:
        from ._files import save_figure

        save_figure(fig, path)
    return fig


#: level_ratios: an extrapolated same-links ratio whose error bar (its last Richardson correction) exceeds
#: this fraction of it is no limit and is left out (the node-method stretching study shipped before branch
#: shipstretch, at chi = 0.1: orders 0.2-0.3, bars 56-114% of the ratio, the ideal's own peak still growing
#: 17.2, 22.0, 26.7 over its levels -4 ... -2)
RATIO_MAX_ERROR = 0.5


def level_ratios(ds, quantity: str = "v_peak") -> dict:
    """The peak over the ideal's *on the same links*, level by level, extrapolated across the levels
    (:func:`snapping.continuum.extrapolate`) -- for a study whose levels are too coarse for each
    limit apart (the node-method stretching study shipped before branch shipstretch: its ideal limits
    carried 3-40% error bars, observed orders 0.2-0.3) while the ratio, its discretisation errors shared,
    moves by 1-2% from level to level; for the shipped links study, whose limits are resolved (bars
    <= 0.36%), a second estimate of its crossovers (the same within 1% at chi = 0.1-0.3). Per chi: ``ratio``, ``error`` and ``order`` per number (nan where the extrapolated ratio
    leaves (0, 2) or its error bar exceeds :data:`RATIO_MAX_ERROR` of it: an order near 0, a failed
    extrapolation), and :func:`crossover` on them.

    Returns
    -------
    dict
        chi -> {"ratio", "error", "order" (arrays over the numbers), "levels" (numbers x levels),
        "crossover"}, and "crossover_law" (:func:`crossover_law` over the bracketed chi).
    """
    from .continuum import extrapolate

    from .regimes_escalate import prefix

    nums = ds.number.values
    res = ds.resolution.values
    base = int(ds.attrs.get("levels", res.size))
    out = {"chi": {}}
    pts = []
    for chi in ds.chi.values:
        c = ds.sel(chi=chi)
        lv = c[f"{quantity}_level"].values / c[f"{quantity}_ideal_level"].values[None, :]
        r, e, o = (np.full(nums.size, np.nan) for _ in range(3))
        for j in range(nums.size):
            n = prefix(lv[j])  # the levels both ran (an escalated study's cells: more than the base, regimes_escalate)
            if n >= base:
                x = extrapolate(res[:n], lv[j][:n])
                # else a failed extrapolation (an order near 0, a correction of the ratio's own size): left out
                if 0.0 < x["limit"] < 2.0 and abs(x["error"]) <= RATIO_MAX_ERROR * x["limit"]:
                    r[j], e[j], o[j] = x["limit"], x["error"], x["order"]
        ok = np.isfinite(r) & np.isfinite(e)
        cross = crossover(nums[ok], r[ok], e[ok])
        out["chi"][float(chi)] = {"ratio": r, "error": e, "order": o, "levels": lv, "crossover": cross}
        if cross["bracketed"]:
            pts.append((float(chi), cross["number"], cross["lo"], cross["hi"]))
    if pts:
        cx, nx, lo, hi = np.array(pts).T
        out["crossover_law"] = crossover_law(cx, nx, lo, hi)
    else:
        out["crossover_law"] = crossover_law([], [])
    return out


def with_level_ratios(ds, quantity: str = "v_peak"):
    """A copy of the study whose ``{quantity}_ratio`` (and ``_error``) are the same-links ratios
    extrapolated across the levels (:func:`level_ratios`): the regime map of a study whose limits
    are not resolved apart (stretching). Its ``converged`` flag is the ratio's: an error bar within
    :data:`MAX_REL_ERROR` of the ratio (the map's "?" marks the others)."""
    lr = level_ratios(ds, quantity)
    out = ds.copy()
    r = np.array([lr["chi"][float(c)]["ratio"] for c in ds.chi.values])
    e = np.array([lr["chi"][float(c)]["error"] for c in ds.chi.values])
    out[f"{quantity}_ratio"] = (("chi", "number"), r)
    out[f"{quantity}_ratio_error"] = (("chi", "number"), e)
    with np.errstate(invalid="ignore"):
        ok = np.isfinite(r) & np.isfinite(e) & (np.abs(e) <= MAX_REL_ERROR * np.abs(r))
    out["converged"] = (("chi", "number"), ok.astype(np.int8),
                        {"long_name": f"1: the same-links ratio's error bar is within {MAX_REL_ERROR:.0%} of it"})
    out.attrs["mechanism"] = f"{ds.attrs['mechanism']}, same-links ratios"
    return out
