"""The paper's run figures (Fig. 1 and Fig. 2) drawn from run Datasets.

Every function takes run Datasets (names from :mod:`snapping.schema`) and
returns a matplotlib Figure; :func:`save` writes it as PNG and PDF. Scaling
figures (Fig. 3 and 4) live in :mod:`snapping.scaling`.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from .estimates import Chain, PAPER_CHAIN

__all__ = ["shapes", "pin_force", "profiles", "overview", "peak_speed_vs_N", "convergence_figure", "save",
           "run_label", "energy_terms"]


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def save(fig, path_stem) -> list[Path]:
    """Save ``fig`` as ``<stem>.png`` (150 dpi) and ``<stem>.pdf``; returns both paths."""
    stem = Path(path_stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    out = []
    from ._files import save_figure

    try:
        for ext in (".png", ".pdf"):
            p = stem.with_suffix(ext)
            save_figure(fig, p, dpi=150)
            out.append(p)
    finally:
        _plt().close(fig)
    return out


UNITS = ("nondimensional", "si")

#: Axis-label units: nondimensional (length l, velocity sqrt(g l), force rho g l, time sqrt(l/g)) or SI.
_U = {
    "nondimensional": {"length": r"$\ell$", "time": r"$\sqrt{\ell/g}$", "force": r"$\rho g \ell$",
                       "speed": r"$\sqrt{g\ell}$", "accel": r"$g$"},
    "si": {"length": "m", "time": "s", "force": "N", "speed": "m/s", "accel": r"m/s$^2$"},
}


def _units(units: str) -> dict:
    if units not in UNITS:
        from ._validate import SnappingInputError

        raise SnappingInputError(f"units={units!r} must be one of {list(UNITS)}")
    return _U[units]


def _conv(units: str, chain: Chain):
    """Converters (length, time, force) from the library's nondimensional values to ``units``."""
    if units == "si":
        return chain.distance, chain.time, chain.force
    ident = lambda x: x  # noqa: E731
    return ident, ident, ident


def _snapshots_before(ds, n: int):
    """Indices of up to ``n`` snapshots from t = 0 up to and including the snap.

    The snap is the snapshot of kind 'peak' (the state at the largest sampled
    maximum speed) when the run has one, else the last snapshot at or before
    ``t_snap_v``. The automatic snapshots are taken at geometric levels of the
    maximum speed, so they crowd towards the snap; thinning keeps the first and
    the last and spreads the rest evenly in index.
    """
    ts = ds["t_snapshot"].values
    kinds = [str(k) for k in ds["snapshot_kind"].values] if "snapshot_kind" in ds else []
    if "peak" in kinds:
        last = kinds.index("peak")
    else:
        t_snap = float(ds.attrs.get("t_snap_v", np.nan))
        before = np.flatnonzero(ts <= t_snap) if np.isfinite(t_snap) else np.arange(ts.size)
        last = int(before[-1]) if before.size else ts.size - 1
    idx = np.arange(last + 1)
    if idx.size <= n:
        return idx
    return np.unique(np.round(np.linspace(0, last, n)).astype(int))


def run_label(ds) -> str:
    """A short title of a run that tells it from others: chi (or the start: supports, a shape
    file), N, and what is not the paper's chain: tip mass, taper, held-end motion, gravity.

    >>> import xarray as xr
    >>> run_label(xr.Dataset(attrs={"chi": 0.25, "N": 1000}))
    '$\\chi$ = 0.25, N = 1000'
    """
    import json
    import math

    a = ds.attrs
    try:
        prob = json.loads(a["problem"]) if a.get("problem") else {}
    except (TypeError, ValueError):
        prob = {}
    start, chain, pin = prob.get("start", {}), prob.get("chain", {}), prob.get("pin", {})
    chi = float(a.get("chi", start.get("chi", math.nan)))
    parts = []
    if start.get("kind") == "supports":
        parts.append(f"supports ({start['dx']:g}, {start['dy']:g})")
    elif start.get("kind") in ("curve", "nodes"):
        name = str(start.get("name", ""))
        parts.append(f"start {name.rsplit('/', 1)[-1] or start['kind']}")
    elif math.isfinite(chi):
        parts.append(rf"$\chi$ = {chi:g}")
    parts.append(f"N = {int(a['N'])}" if "N" in a else "")
    if chain.get("tip_mass"):
        parts.append(f"tip mass {float(chain['tip_mass']):g}")
    if chain.get("kind") == "taper":
        power = float(chain.get("power", 1.0))
        parts.append(f"taper {float(chain['ratio']):g}" + ("" if power == 1.0 else f":{power:g}"))
    elif chain.get("kind") == "line":
        parts.append(str(chain.get("line", "line")))
    elif chain.get("kind") not in (None, "uniform", "paper"):
        parts.append(f"{chain['kind']} links")
    if pin.get("kind") in ("pull", "flick"):
        ax, ay = pin.get("accel", (math.nan, math.nan))
        T = pin.get("period" if pin["kind"] == "flick" else "duration")
        parts.append(f"{pin['kind']} ({float(ax):g}, {float(ay):g})" + ("" if T is None else f" T {float(T):g}")
                     + (f" from t {float(pin['t0']):g}" if pin.get("t0") else ""))
    elif pin.get("kind") not in (None, "fixed"):
        parts.append(f"held end: {pin['kind']}")
    if "gravity" in prob and float(prob["gravity"]) != 1.0:
        parts.append(f"gravity {float(prob['gravity']):g}")
    if a.get("body"):
        from .simulate.body import summarize

        try:
            b = summarize(a["body"])
        except (TypeError, ValueError):
            b = {}
        parts.append(" + ".join(name for k, name in (("beta", "bending"), ("drag_normal", "drag"),
                                                     ("tip_drag", "tip drag"), ("clamp", "clamped")) if k in b))
    return ", ".join(p for p in parts if p)


def _held_end(sn, dist):
    """The held end (the last node) of a snapshot, drawn as (x, height)."""
    return dist(float(sn["x"].values[-1])), -dist(float(sn["y"].values[-1]))


def shapes(runs, chain: Chain = PAPER_CHAIN, n: int = 8, units: str = "nondimensional"):
    """Fig. 1(b)-(d): chain shapes at several times up to the snap, one panel per run,
    coloured by time (a colour bar per panel).

    ``units="nondimensional"`` (default) draws lengths in units of the chain's length
    and times in sqrt(l/g); ``units="si"`` in metres and seconds for ``chain``."""
    plt = _plt()
    u = _units(units)
    dist, time, _ = _conv(units, chain)
    runs = list(runs)
    fig, axes = plt.subplots(1, len(runs), figsize=(4.6 * len(runs), 4.4), squeeze=False)
    # fixed positions (a layout engine costs seconds per save): room for each panel's colour bar
    titles = ["\n".join(textwrap.wrap(run_label(ds), 34)) for ds in runs]
    lines = max(t.count("\n") for t in titles)  # (a general problem's title takes more lines)
    fig.subplots_adjust(left=0.07 + 0.1 / len(runs), right=0.93, bottom=0.12, top=0.86 - 0.045 * lines,
                        wspace=0.55)
    from matplotlib.colors import Normalize

    for ax, ds, title in zip(axes[0], runs, titles):
        idx = _snapshots_before(ds, n)
        ts = np.array([time(float(ds["t_snapshot"].values[int(i)])) for i in idx])
        norm = Normalize(0.0, max(float(ts.max()), 1e-300))
        cmap = plt.get_cmap("viridis")
        for tt, i in zip(ts, idx):
            sn = ds.isel(snapshot=int(i))
            ax.plot(dist(sn["x"].values), -dist(sn["y"].values), color=cmap(norm(tt)), lw=1.2)
            ax.plot(*_held_end(sn, dist), "s", color=cmap(norm(tt)), mec="k", ms=5, zorder=3)  # (it may move)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=9 if "\n" in title else None)
        ax.set_xlabel(f"$x$  [{u['length']}]")
        ax.set_ylabel(f"height  [{u['length']}]")
        x0, x1 = ax.get_xlim()
        y0, y1 = ax.get_ylim()
        w = 0.05 * min(max(abs(y1 - y0) / max(abs(x1 - x0), 1e-12), 1.0), 5.0)  # equal aspect: as wide as tall
        cb = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), cax=ax.inset_axes((1.04, 0.0, w, 1.0)))
        cb.set_label(f"$t$  [{u['time']}]")
    what = f"chain of {chain.length:g} m" if units == "si" else "nondimensional"
    fig.suptitle(f"Falling chain shapes up to the snap ({what})")
    return fig


def pin_force(ds, chain: Chain = PAPER_CHAIN, units: str = "nondimensional"):
    """Fig. 1(e): horizontal and vertical components of the force on the pin against time;
    nondimensional (rho g l, sqrt(l/g)) by default, or ``units="si"`` (N and s for ``chain``)."""
    plt = _plt()
    u = _units(units)
    _, time, force = _conv(units, chain)
    from .scaling.plots import thin_envelope

    t = time(np.asarray(ds["t"].values, dtype=float))
    fx, fy = force(np.asarray(ds["pin_force_x"].values)), force(np.asarray(ds["pin_force_y"].values))
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6, 5), sharex=True)
    fig.subplots_adjust(left=0.15, right=0.96, bottom=0.11, top=0.92, hspace=0.1)
    k = thin_envelope(t, fx)  # 10^5-10^6 steps: the envelope of 2000 bins of t
    a1.plot(t[k], fx[k], color="tab:red")
    a1.set_ylabel(f"horizontal force  [{u['force']}]")
    k = thin_envelope(t, fy)
    a2.plot(t[k], fy[k], color="tab:red")
    a2.set_ylabel(f"vertical force  [{u['force']}]")
    a2.set_xlabel(f"time $t$  [{u['time']}]")
    for a in (a1, a2):
        a.grid(alpha=0.3)
    what = f", chain {chain.length:g} m, {chain.mass:g} kg" if units == "si" else " (nondimensional)"
    a1.set_title(f"Force on the pin, {run_label(ds)}{what}", fontsize=10)
    return fig


def profiles(ds, n: int = 7):
    """Fig. 2(a)-(c): speed, acceleration and tension along the chain at several times up to the snap
    (the last, in purple, is the snap), nondimensional."""
    plt = _plt()
    u = _U["nondimensional"]
    idx = _snapshots_before(ds, n)
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    fig.subplots_adjust(left=0.05, right=0.99, bottom=0.13, top=0.88, wspace=0.25)
    colors = plt.cm.plasma(np.linspace(0.85, 0.0, max(len(idx), 2)))[::-1]
    colors[-1] = (0.5, 0.0, 0.5, 1.0)  # the snap in purple, as in the paper
    s_node, s_link = ds["s_node"].values, ds["s_link"].values
    for c, i in zip(colors, idx):
        sn = ds.isel(snapshot=int(i))
        lab = f"$t$ = {float(sn['t_snapshot']):.4f}"
        axes[0].plot(s_node, sn["speed"].values, color=c, label=lab)
        axes[1].semilogy(s_node[:-1], np.maximum(sn["accel"].values[:-1], 1e-3), color=c, label=lab)
        axes[2].plot(s_link, sn["tension"].values, color=c, label=lab)
    for a, name in zip(axes, (rf"speed $|v|$  [{u['speed']}]", rf"acceleration $|a|$  [{u['accel']}]",
                              rf"tension $\sigma$  [{u['force']}]")):
        a.set_xlabel(f"arclength $s$ from the pin  [{u['length']}]")
        a.set_ylabel(name)
        a.grid(alpha=0.3)
    # the speed grows towards the free end (s = 1): the upper left of panel (a) is free
    axes[0].legend(fontsize=7, loc="upper left", title=f"time [{u['time']}]", title_fontsize=7)
    fig.suptitle(f"Along the chain up to the snap: {run_label(ds)} (nondimensional)")
    return fig


def overview(ds, n: int = 7):
    """One run at a glance (``snapping plot``): (a) the chain's shapes at up to ``n``
    snapshots up to the snap, the held end marked (it may move); (b) speed and (c) tension
    along the chain at the same snapshots; (d) the maxima over the chain (speed,
    acceleration, tension) against time, with the snapping time; a run with a body
    (bending, drag: :class:`snapping.simulate.Body`) adds (e) its energy terms and (f) the
    residual of their balance (:func:`energy_terms`); a run of the extensible line adds (e) the
    strain along the line against time and (f) its energy terms with their balance (inset)
    (:mod:`snapping.figures_elastic`). Nondimensional. Returns the Figure."""
    plt = _plt()
    u = _U["nondimensional"]
    idx = _snapshots_before(ds, n)
    from . import figures_elastic

    elastic = figures_elastic.is_elastic_run(ds)
    body = "dissipated" in ds and "bending_energy" in ds or elastic
    ncol = 4 if elastic else 3 if body else 2
    fig, axes = plt.subplots(2, ncol, figsize=(5.5 * ncol, 8.4), squeeze=False)
    fig.subplots_adjust(left=0.06 if body else 0.08, right=0.97, bottom=0.07, top=0.9, wspace=0.3, hspace=0.3)
    (a_shape, a_speed, *a_e), (a_tension, a_max, *a_b) = axes
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, max(len(idx), 2)))
    s_node, s_link = ds["s_node"].values, ds["s_link"].values
    ident = lambda x: x  # noqa: E731
    for c, i in zip(colors, idx):
        sn = ds.isel(snapshot=int(i))
        lab = f"t = {float(sn['t_snapshot']):.4f}"
        a_shape.plot(sn["x"].values, -sn["y"].values, color=c, lw=1.2, label=lab)
        a_shape.plot(*_held_end(sn, ident), "s", color=c, mec="k", ms=5, zorder=3)
        a_speed.plot(s_node, sn["speed"].values, color=c, label=lab)
        a_tension.plot(s_link, sn["tension"].values, color=c, label=lab)
    a_shape.set_aspect("equal", adjustable="datalim")
    a_shape.set_xlabel(f"$x$  [{u['length']}]")
    a_shape.set_ylabel(f"height  [{u['length']}]")
    a_shape.set_title("(a) shapes (square: the held end)", loc="left", fontsize=10)
    a_speed.set_xlabel(f"arclength $s$ from the held end  [{u['length']}]")
    a_speed.set_ylabel(f"speed $|v|$  [{u['speed']}]")
    a_speed.set_title("(b) speed along the chain", loc="left", fontsize=10)
    a_tension.set_xlabel(f"arclength $s$ from the held end  [{u['length']}]")
    a_tension.set_ylabel(rf"tension $\sigma$  [{u['force']}]")
    a_tension.set_title("(c) tension along the chain", loc="left", fontsize=10)
    a_speed.legend(fontsize=7, loc="upper left", title=f"time [{u['time']}]", title_fontsize=7)
    from .scaling.plots import thin_envelope

    t = np.asarray(ds["t"].values, dtype=float)
    for name, lab, c in (("v_max", rf"speed [{u['speed']}]", "C0"), ("a_max", rf"acceleration [{u['accel']}]", "C1"),
                         ("sigma_max", rf"tension [{u['force']}]", "C2")):
        y = np.asarray(ds[name].values, dtype=float)
        k = thin_envelope(t, y)
        a_max.semilogy(t[k], y[k], color=c, label=lab)
    t_snap = float(ds.attrs.get("t_snap_v", np.nan))
    if np.isfinite(t_snap):
        a_max.axvline(t_snap, color="k", lw=0.6, ls="--", label=f"snap, t = {t_snap:.5g}")
    a_max.set_xlabel(f"time $t$  [{u['time']}]")
    a_max.set_ylabel("maximum over the chain (units in the legend)")
    a_max.set_title("(d) maxima against time", loc="left", fontsize=10)
    a_max.legend(fontsize=7, loc="upper left")
    for a in (a_speed, a_tension, a_max):
        a.grid(alpha=0.3)
    if elastic:  # (e) strain against time and arclength, (f) energy terms, (g) strain profiles, (h) the balance
        im = figures_elastic.strain_panel(ds, a_e[0], t_snap)
        fig.colorbar(im, ax=a_e[0], label="strain")
        figures_elastic.energy_panels(ds, a_e[1], a_b[1], t_snap)
        figures_elastic.strain_profiles(ds, a_b[0], idx, colors)
    elif body:
        _energy_panels(ds, a_e[0], a_b[0], t_snap)
    fig.suptitle(f"{run_label(ds)}: {ds.attrs.get('status', '')}, {ds.attrs.get('method', '')} "
                 f"(nondimensional)")
    return fig


def energy_terms(ds) -> dict:
    """The energy terms of a body run (units of M g L) against ``t``: ``mechanical``
    (kinetic + gravity: ``energy - bending_energy``), ``bending`` (``bending_energy``),
    ``pin_work``, ``dissipated``, the ``balance`` E - W + D (conserved), and ``residual``
    = |balance - balance(0)| / |E(0)| (relative to the energy at t = 0; absolute if that is 0).

    >>> import numpy as np, xarray as xr
    >>> ds = xr.Dataset({"energy": ("step", [2.0, 1.5]), "bending_energy": ("step", [0.5, 0.25]),
    ...                  "pin_work": ("step", [0.0, 0.0]), "dissipated": ("step", [0.0, 0.5 + 1e-9])},
    ...                 coords={"t": ("step", [0.0, 1.0])})
    >>> [float(x) for x in energy_terms(ds)["residual"]]
    [0.0, 5e-10]
    """
    g = {k: np.asarray(ds[k].values, dtype=float) for k in ("energy", "bending_energy", "dissipated")}
    w = np.asarray(ds["pin_work"].values, dtype=float) if "pin_work" in ds else np.zeros_like(g["energy"])
    bal = g["energy"] - w + g["dissipated"]
    e0 = abs(float(g["energy"][0]))
    return {"t": np.asarray(ds["t"].values, dtype=float), "mechanical": g["energy"] - g["bending_energy"],
            "bending": g["bending_energy"], "pin_work": w, "dissipated": g["dissipated"], "balance": bal,
            "residual": np.abs(bal - bal[0]) / (e0 if e0 > 0 else 1.0)}


def _energy_panels(ds, a_terms, a_res, t_snap) -> None:
    """(e) the energy terms of a body run against time; (f) the residual of their balance."""
    from .scaling.plots import thin_envelope

    e = energy_terms(ds)
    t = e["t"]
    for name, lab, c in (("mechanical", "kinetic + gravity", "C0"), ("bending", "bending", "C1"),
                         ("pin_work", "pin work W", "C2"), ("dissipated", "dissipated D (drag, damping)", "C3"),
                         ("balance", "E - W + D (conserved)", "k")):
        k = thin_envelope(t, e[name])
        a_terms.plot(t[k], e[name][k], color=c, lw=1.0 if name != "balance" else 1.6, label=lab)
    a_terms.set_xlabel(r"time $t$  [$\sqrt{\ell/g}$]")
    a_terms.set_ylabel(r"energy  [$M g \ell$]")
    a_terms.set_title("(e) energy terms (E = kinetic + gravity + bending)", loc="left", fontsize=10)
    a_terms.legend(fontsize=7, loc="best")
    r = e["residual"]
    k = thin_envelope(t, r)
    pos = k[r[k] > 0]  # (log axis: the exact zeros, t = 0 among them, are left out)
    a_res.semilogy(t[pos], r[pos], color="k", lw=1.0, label=f"max {float(r.max()):.2g}")
    a_res.set_xlabel(r"time $t$  [$\sqrt{\ell/g}$]")
    a_res.set_ylabel(r"$|E - W + D - E_0| / E_0$")
    a_res.set_title(f"(f) energy balance (tol {ds.attrs.get('tol', float('nan')):g})", loc="left", fontsize=10)
    a_res.legend(fontsize=7, loc="lower right")
    for a in (a_terms, a_res):
        if np.isfinite(t_snap):
            a.axvline(t_snap, color="k", lw=0.6, ls="--")
        a.grid(alpha=0.3)


def peak_speed_vs_N(table):
    """Fig. 2(d): peak speed against N for several chi, with the N^(1/2) line a singularity
    regularised by discreteness would follow (nondimensional).

    ``table`` maps chi to a list of (N, v_peak)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    fig.subplots_adjust(left=0.15, right=0.97, bottom=0.13, top=0.91)
    for chi, rows in sorted(table.items()):
        rows = sorted(rows)
        N = np.array([r[0] for r in rows], float)
        v = np.array([r[1] for r in rows], float)
        line, = ax.loglog(N, v, "o-", label=rf"$\chi$ = {chi:g}")
        ax.loglog(N, v[0] * np.sqrt(N / N[0]), ":", color=line.get_color(), lw=1)
    ax.plot([], [], "k:", label=r"$N^{1/2}$ (discreteness regularised)")
    ax.set_xlabel("number of links $N$")
    ax.set_ylabel(r"peak speed $v$  [$\sqrt{g\ell}$]")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3, which="both")
    ax.set_title("Snapping velocity against N")
    return fig


def _order_text(order) -> str:
    """The observed order of convergence for a legend (not a number where it was not measured)."""
    order = float(order)
    return f"order {order:.2f}" if np.isfinite(order) else "order not measured (not converging)"


def _level_ticks(ax, frac) -> None:
    """Major ticks of a log axis at ``frac`` (thinned to at most 6), labelled as plain numbers,
    and no minor tick labels."""
    from matplotlib.ticker import FixedLocator, NullFormatter

    ticks = np.unique(np.asarray(frac, dtype=float))
    if ticks.size > 6:
        ticks = ticks[np.unique(np.round(np.linspace(0, ticks.size - 1, 6)).astype(int))]
    ax.xaxis.set_major_locator(FixedLocator(ticks))
    ax.xaxis.set_major_formatter(lambda x, pos: f"{x:.3g}")
    ax.xaxis.set_minor_formatter(NullFormatter())


def convergence_figure(ds, path=None, uniform=None, other=None):
    """The continuum limit (:func:`snapping.continuum.converge`): (a) each peak over its
    extrapolated limit against the resolution of the fold (``frac``), with the limit's
    error band, and the paper's uniform chains beside them (``uniform``: run Datasets,
    plotted at their equivalent ``frac = 1/(N a)``), and ``other`` (a second study, e.g.
    the paper's lumping) dotted against the same limit; (b) the distance to the limit on
    log axes, whose slope is the order of convergence. Returns the Figure (and saves it
    to ``path`` if given)."""
    plt = _plt()
    from . import estimates

    quantities = (("v_peak", r"$v$"), ("a_peak", r"$a$"), ("sigma_peak", r"$\sigma$"))
    colors = ("C0", "C1", "C2")
    frac = np.asarray(ds.frac.values, dtype=float)
    a_cat = estimates.catenary_parameter(float(ds.attrs["chi"]))
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 5.2), constrained_layout=True)
    for (q, label), c in zip(quantities, colors):
        lim, err = float(ds.attrs[q + "_limit"]), float(ds.attrs[q + "_error"])
        vals = np.asarray(ds[q].values, dtype=float)
        ax1.plot(frac, vals / lim, "o-", color=c, label=f"{label} graded (limit {lim:.6g} $\\pm$ {err:.1g})")
        ax1.fill_between([frac.min() / 2, frac.max() * 2], 1 - err / lim, 1 + err / lim, color=c, alpha=0.15, lw=0)
        if uniform:
            fu = [1.0 / (int(u.attrs["N"]) * a_cat) for u in uniform]
            ax1.plot(fu, [float(u.attrs[q]) / lim for u in uniform], "s--", color=c, mfc="none",
                     label=f"{label} uniform N = " + ", ".join(str(int(u.attrs["N"])) for u in uniform))
        dist = np.abs(vals - lim) / abs(lim)
        ok = dist > 0
        ax2.loglog(frac[ok], dist[ok], "o-", color=c, label=f"{label}: {_order_text(ds.attrs[q + '_order'])}")
        if other is not None:
            fo, vo = np.asarray(other.frac.values, dtype=float), np.asarray(other[q].values, dtype=float)
            lump = other.attrs.get("lumping", "other")
            ax1.plot(fo, vo / lim, "^:", color=c, label=f"{label} graded, {lump} lumping")
            do = np.abs(vo - lim) / abs(lim)
            ax2.loglog(fo[do > 0], do[do > 0], "^:", color=c,
                       label=f"{label}, {lump} lumping: {_order_text(other.attrs[q + '_order'])}")
    ax1.set_xscale("log")
    ax1.set_xlim(frac.min() / 1.5, max([frac.max(), *(1.0 / (int(u.attrs["N"]) * a_cat) for u in (uniform or []))])
                 * 1.5)
    ax1.axhline(1.0, color="k", lw=0.6)
    ax1.set_xlabel("link length on the fold / its radius of curvature")
    ax1.set_ylabel("peak / extrapolated limit")
    ax1.set_title(f"(a) $\\chi$ = {float(ds.attrs['chi']):g}: peaks against resolution "
                  f"({ds.attrs.get('lumping', '')} lumping)")
    ax2.set_xlabel("link length on the fold / its radius of curvature")
    ax2.set_ylabel(r"$|$peak $-$ limit$|$ / limit")
    ax2.set_title("(b) distance to the limit")
    for ax in (ax1, ax2):  # ticks at the levels' resolutions, plain numbers (log minor labels overlap)
        _level_ticks(ax, frac)
    # the legends below the panels: inside they hide points (the coarsest level's acceleration)
    ax1.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=1, frameon=False)
    ax2.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2 if other is not None else 1,
               frameon=False)
    if path is not None:
        from ._files import save_figure

        save_figure(fig, path, dpi=130)
    return fig
