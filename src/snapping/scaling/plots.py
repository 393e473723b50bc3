"""Figures of the scaling analysis (matplotlib, Agg backend): the paper's Fig. 3
(maxima against t* - t, curvature amplification), local slopes, and Fig. 4
(delta scales and the predicted peaks).

Each function takes run Datasets and their :class:`~snapping.scaling.run.RunFit`
results and saves a PNG (or PDF, by the suffix of ``path``). Everything is
nondimensional (length l, velocity sqrt(g l), force rho g l), as the axis labels
say; runs are coloured by chi on one colour bar and quantities told apart by line
style, so a legend holds a few entries whatever the number of runs. The per-step
record (10^5-10^6 steps) is thinned on the log tau axis before plotting
(:func:`thin_log`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import _validate as V
from .. import estimates

__all__ = ["plot_maxima", "plot_local_slopes", "plot_delta", "front_arclength", "thin_log", "thin_envelope", "chi_colours"]

#: Units of the nondimensional quantities (length l, g, rho: paper section 3), for axis labels.
U_TIME = r"$\sqrt{\ell/g}$"
U_SPEED = r"$\sqrt{g\ell}$"
U_ACCEL = r"$g$"
U_FORCE = r"$\rho g \ell$"
U_LENGTH = r"$\ell$"
TAU_LABEL = r"$\tau = t^*_\chi - t$  [" + U_TIME + "]"

#: Log-spaced bins of t* - t used to thin a per-step record before plotting (two points kept per bin).
PLOT_BINS = 400


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _paths(path) -> list[Path]:
    """``path`` (or a list of paths: one figure drawn once, saved in several formats), checked."""
    paths = [Path(p) for p in path] if isinstance(path, (list, tuple)) else [Path(path)]
    if not paths:
        raise V.SnappingInputError("path=[]: give at least one figure path")
    for p in paths:
        if p.suffix.lower() not in (".png", ".pdf", ".svg"):
            raise V.SnappingInputError(f"path={str(p)!r}: the figure suffix must be .png, .pdf or .svg")
    return paths


def _save(fig, path):
    """Save ``fig`` to ``path`` (or to each of a list of paths) and close it; returns the
    Path (or the list of Paths)."""
    paths = _paths(path)
    from .._files import save_figure

    try:
        for p in paths:
            p.parent.mkdir(parents=True, exist_ok=True)
            save_figure(fig, p, dpi=150)
    finally:
        _plt().close(fig)
    return paths if isinstance(path, (list, tuple)) else paths[0]


def _data_ylim(ax, ys, margin=2.0):
    """Fit the y axis of a log plot to the data ``ys`` (so that reference lines drawn over
    the whole tau range do not squeeze it)."""
    ys = [np.asarray(y, float) for y in ys if np.size(y)]
    if ys:
        y = np.concatenate(ys)
        y = y[np.isfinite(y) & (y > 0)]
        if y.size:
            ax.set_ylim(float(y.min()) / margin, float(y.max()) * margin)


def chi_colours(chis):
    """Colours of runs by chi on one viridis scale, and the ScalarMappable for their colour
    bar; a single chi gives ``"C0"`` and None (the run is named in the title instead).

    >>> cols, sm = chi_colours([0.1, 0.4])
    >>> len(cols), sm.norm.vmin, sm.norm.vmax
    (2, 0.1, 0.4)
    """
    plt = _plt()
    from matplotlib.colors import LinearSegmentedColormap, Normalize

    chis = [float(c) for c in chis]
    if len(set(chis)) <= 1:
        return ["C0"] * len(chis), None
    base = plt.get_cmap("viridis")
    cmap = LinearSegmentedColormap.from_list("viridis_0_0.9", base(np.linspace(0.0, 0.9, 256)))
    norm = Normalize(min(chis), max(chis))
    sm = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    return [cmap(norm(c)) for c in chis], sm


def _chi_bar(fig, sm, cax, chis):
    """The chi colour bar in axes ``cax`` (fixed positions: no layout engine, which would
    cost seconds per save on log axes of many decades)."""
    if sm is None:
        cax.remove()
        return None
    cb = fig.colorbar(sm, cax=cax)
    ticks = sorted(set(float(c) for c in chis))
    if len(ticks) <= 8:
        cb.set_ticks(ticks)
    cb.set_label(r"initial end separation $\chi$ (fraction of the length)")
    return cb


def thin_log(tau, y, bins: int = PLOT_BINS):
    """Indices of the samples of ``y(tau)`` (tau > 0) worth plotting on a log tau axis: in
    each of ``bins`` log-spaced bins of tau the smallest and the largest y are kept (and
    the first and last sample), so a record of 10^5-10^6 steps becomes at most
    ``2 bins + 2`` points and keeps its envelope (a spike inside a bin still shows).

    >>> import numpy as np
    >>> tau = np.geomspace(1.0, 1e-6, 100_000)
    >>> i = thin_log(tau, tau ** (-1 / 3), bins=50)
    >>> bool(i.size <= 102), int(i[0]), int(i[-1])
    (True, 0, 99999)
    """
    return thin_envelope(np.log(np.asarray(tau, dtype=float)), y, bins)


def thin_envelope(x, y, bins: int = 2000):
    """Indices of the samples of ``y(x)`` to plot on a linear ``x`` axis: the smallest and
    the largest ``y`` in each of ``bins`` equal bins of ``x`` (and the first and last
    sample), in the record's order (:func:`thin_log` on log x)."""
    lt = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if lt.size <= 2 * bins + 2:
        return np.arange(lt.size)
    lo, hi = float(lt.min()), float(lt.max())
    b = np.minimum(((lt - lo) / max(hi - lo, 1e-300) * bins).astype(np.int64), bins - 1)
    order = np.lexsort((y, b))
    bs = b[order]
    first = np.flatnonzero(np.r_[True, bs[1:] != bs[:-1]])
    last = np.r_[first[1:] - 1, bs.size - 1]
    return np.unique(np.concatenate([order[first], order[last], [0, lt.size - 1]]))


def front_arclength(t, s, s_node=None):
    r"""The arclength of the curvature maximum between the nodes, from its per-step record
    ``s`` (the node of the largest discrete curvature: a staircase of steps 1/N).

    Derivation: near its maximum the curvature is a parabola in s; through the three
    nodes s_k - h, s_k, s_k + h around the discrete maximum its vertex is at

        s* = s_k + (h/2) (kappa_{k+1} - kappa_{k-1}) / (2 kappa_k - kappa_{k-1} - kappa_{k+1}).

    The record switches from node k to its neighbour k+1 when kappa_{k+1} = kappa_k, and
    there the formula gives s* = s_k + h/2: the midpoint of the two nodes. So the record
    pins the vertex at every switch (at the midpoint of the two recorded steps around it
    in time, at the midpoint of the two nodes in s), and the vertex is interpolated
    linearly in time between switches. Errors: a profile with kappa''' != 0 has its true
    maximum (h^2/8) |kappa'''/kappa''| away from the midpoint at a switch (expand kappa to
    third order about the maximum), and the linear interpolation adds at most
    (1/8) |s*''| (h/|s*'|)^2 between switches, against h/2 for the staircase. A jump over
    more than one node (the maximum moving to another part of the chain) stays a jump.

    Parameters
    ----------
    t : array_like
        Recorded times (increasing).
    s : array_like
        Recorded arclength of the curvature maximum (``s_kappa_max``), node values.
    s_node : array_like, optional
        Arclengths of the nodes (a run's ``s_node``): neighbours are consecutive nodes.
        Without it, changes of at most 1.5 times the smallest recorded change count as
        neighbours (right for uniform chains).

    Returns
    -------
    ndarray
        The interpolated arclength at the times ``t`` (NaN where ``s`` is).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 1.0, 11)
    >>> s = np.array([0.5, 0.5, 0.5, 0.6, 0.6, 0.6, 0.6, 0.7, 0.7, 0.7, 0.7])
    >>> front_arclength(t, s)[[0, 2, 3, 5, 7, 10]].round(4).tolist()
    [0.5, 0.54, 0.5625, 0.6125, 0.6571, 0.7]
    """
    t = np.asarray(t, dtype=float)
    s = np.asarray(s, dtype=float)
    if t.shape != s.shape or t.ndim != 1:
        raise V.SnappingInputError(f"t and s must be 1-d arrays of the same length (got shapes {t.shape}, {s.shape})")
    ok = np.isfinite(t) & np.isfinite(s)
    out = np.full(s.shape, np.nan)
    tt, ss = t[ok], s[ok]
    i = np.flatnonzero(ss[1:] != ss[:-1]) + 1 if ss.size > 1 else np.array([], dtype=int)
    if i.size == 0:
        out[ok] = ss
        return out
    if s_node is not None:
        nodes = np.sort(np.asarray(s_node, dtype=float))
        k0 = np.searchsorted(nodes, ss[i - 1])
        k1 = np.searchsorted(nodes, ss[i])
        adjacent = np.abs(k1 - k0) == 1
    else:
        d = np.abs(ss[i] - ss[i - 1])
        adjacent = d <= 1.5 * d.min()
    mid_t = 0.5 * (tt[i - 1] + tt[i])
    mid_s = 0.5 * (ss[i - 1] + ss[i])
    # a jump contributes both plateau ends; a switch to a neighbour its midpoint
    at = np.concatenate([tt[:1], np.where(adjacent, mid_t, tt[i - 1]), tt[i][~adjacent], tt[-1:]])
    av = np.concatenate([ss[:1], np.where(adjacent, mid_s, ss[i - 1]), ss[i][~adjacent], ss[-1:]])
    order = np.argsort(at, kind="stable")
    out[ok] = np.interp(tt, at[order], av[order])
    return out


def _before(ds, t_star, var, thin: bool = True):
    """tau = t* - t > 0 and the positive finite values of ``var`` there, thinned for a log axis."""
    t = np.asarray(ds["t"].values, dtype=float)
    y = np.asarray(ds[var].values, dtype=float)
    tau = t_star - t
    ok = (tau > 0) & np.isfinite(y) & (y > 0)
    tau, y = tau[ok], y[ok]
    if thin:
        k = thin_log(tau, y)
        tau, y = tau[k], y[k]
    return tau, y


#: Distinct colours of the fitted power laws (single-run figures, where the data is C0).
FIT_COLOURS = ("tab:red", "tab:orange", "tab:purple", "tab:green", "tab:brown", "tab:pink")

_ROW_TEX = {
    "v_max": r"$v_{\max}$",
    "a_end": r"$a_{\mathrm{end}}$",
    "a_max": r"$a_{\max}$",
    "sigma_max": r"$\sigma_{\max}$",
    "kappa_max": r"$\kappa_{\max}$",
}


def _title_run(runs, results):
    if len({float(r.chi) for r in results}) == 1 and results:
        r = results[0]
        return rf", $\chi$ = {r.chi:.3g}" + (f", N = {r.N}" if r.N else "")
    Ns = sorted({r.N for r in results if r.N})
    return f", N = {Ns[0]}" if len(Ns) == 1 else ""


def plot_maxima(runs, results, path, *, show_fits: bool = True) -> Path:
    """The paper's Fig. 3: maxima of speed, acceleration (max and free end), tension
    and the curvature amplification against tau = t*_chi - t, on log-log axes, with
    the folded-string scalings and prefactors (eq. asymptoticscalings) drawn in.

    Runs are coloured by chi (one colour bar), quantities by line style (panel (b):
    a_max solid, a_end dashed), references in black; each legend names only styles.

    Parameters
    ----------
    runs : list of xarray.Dataset
        Runs (several chi give the collapse of the paper's figure).
    results : list of RunFit
        Their fit reports (:func:`~snapping.scaling.run.fit_run`), for t*_chi and
        the fitted windows.
    path : str or Path, or a list of them
        Output file (.png, .pdf or .svg); a list saves the one drawing in each.
    show_fits : bool
        Draw each fitted power law over its window, each in its own colour (single
        run only).

    Returns
    -------
    Path (a list of Paths for a list of paths)
    """
    from matplotlib.lines import Line2D

    from .run import report_specs

    plt = _plt()
    specs = {s.name: s for s in report_specs()}
    fig, axs = plt.subplots(2, 2, figsize=(10.5, 8))
    fig.subplots_adjust(left=0.075, right=0.87, bottom=0.07, top=0.93, wspace=0.27, hspace=0.28)
    (ax_v, ax_a), (ax_s, ax_k) = axs
    cols, sm = chi_colours([r.chi for r in results])
    single = len(runs) == 1
    taus = []
    data = {ax: [] for ax in (ax_v, ax_a, ax_s, ax_k)}
    for ds, res, c in zip(runs, results, cols):
        ts = res.snap.t_star
        for ax, var, ls in ((ax_v, "v_max", "-"), (ax_a, "a_max", "-"), (ax_a, "a_end", "--"), (ax_s, "sigma_max", "-")):
            if var not in ds.variables:
                continue
            tau, y = _before(ds, ts, var)
            taus.append(tau)
            data[ax].append(y)
            ax.loglog(tau, y, color=c, lw=1.2, ls=ls)
        if "kappa_max" in ds.variables and math.isfinite(res.kappa_max_0):
            tau, y = _before(ds, ts, "kappa_max")
            data[ax_k].append(y / res.kappa_max_0)
            ax_k.loglog(tau, y / res.kappa_max_0, color=c, lw=1.2)
    handles = {ax: [] for ax in (ax_v, ax_a, ax_s, ax_k)}
    handles[ax_a] += [Line2D([], [], color="0.35", lw=1.2, ls="-", label=r"$a_{\max}$"),
                      Line2D([], [], color="0.35", lw=1.2, ls="--", label=r"$a_{\mathrm{end}}$")]
    if show_fits and single:
        res = results[0]
        k = 0
        for r in res.rows:
            if r.fit is None:
                continue
            ax = {"v_max": ax_v, "a_max": ax_a, "a_end": ax_a, "sigma_max": ax_s, "kappa_max": ax_k}[r.spec.var]
            tt = np.geomspace(r.fit.tau_lo, r.fit.tau_hi, 50)
            scale = 1.0 / res.kappa_max_0 if r.spec.var == "kappa_max" else 1.0
            line, = ax.loglog(tt, r.fit.predict(tt) * scale, color=FIT_COLOURS[k % len(FIT_COLOURS)], lw=3,
                              alpha=0.7, solid_capstyle="butt",
                              label=f"fit {_ROW_TEX.get(r.spec.name, r.spec.name)}: "
                                    rf"$\beta = {r.fit.beta:+.3f} \pm {r.fit.beta_err:.3f}$")
            handles[ax].append(line)
            k += 1
    if taus:
        allt = np.concatenate(taus)
        lo, hi = max(float(allt.min()), 1e-12), float(allt.max())
    else:
        lo, hi = 1e-6, 1.0
    tt = np.geomspace(lo, hi, 200)
    for ax, key, txt in (
        (ax_v, "v_max", r"folded string $2s_0' = {A:.4f}\,\tau^{{-1/3}}$"),
        (ax_a, "a_end", r"folded string $2s_0'' = {A:.4f}\,\tau^{{-4/3}}$"),
        (ax_s, "sigma_max", r"folded string $s_0'^2 = {A:.4f}\,\tau^{{-2/3}}$"),
    ):
        s = specs[key]
        line, = ax.loglog(tt, s.prefactor * tt**s.ref, "k-", lw=0.9, alpha=0.8, label=txt.format(A=s.prefactor))
        handles[ax].append(line)
    # guides for the observed laws, anchored on the first run's fit where there is one
    r0 = results[0] if results else None
    for ax, name, expo, txt in (
        (ax_a, "a_max", -5.0 / 6.0, r"$\tau^{-5/6}$ (paper, intermediate)"),
        (ax_k, "kappa_max", -1.0 / 6.0, r"$\tau^{-1/6}$ (paper, anomalous)"),
    ):
        A = None
        if r0 is not None:
            try:
                f = r0.row(name).fit
                A = None if f is None else f.A
            except KeyError:
                A = None
        if A is not None:
            scale = 1.0 / r0.kappa_max_0 if name == "kappa_max" else 1.0
            line, = ax.loglog(tt, A * scale * tt**expo, "k:", lw=1.2, label=txt)
            handles[ax].append(line)
    if r0 is not None and math.isfinite(r0.kappa_max_0):
        try:
            f = r0.row("kappa_max").fit
        except KeyError:
            f = None
        if f is not None:
            line, = ax_k.loglog(tt, f.A / r0.kappa_max_0 * (tt / f.tau_hi) ** (-2.0 / 3.0) * f.tau_hi**f.beta, "k--",
                                lw=0.9, label=r"$\tau^{-2/3}$ (inferred from $\dot\kappa \sim v\kappa^2$)")
            handles[ax_k].append(line)
    for ax, ylab, tag in (
        (ax_v, r"maximum speed $v_{\max}$  [" + U_SPEED + "]", "(a)"),
        (ax_a, r"acceleration $a_{\max}$, $a_{\mathrm{end}}$  [" + U_ACCEL + "]", "(b)"),
        (ax_s, r"maximum tension $\sigma_{\max}$  [" + U_FORCE + "]", "(c)"),
        (ax_k, r"curvature amplification $\kappa_{\max}/\kappa_{\max}(0)$", "(d)"),
    ):
        ax.set_xlabel(TAU_LABEL)
        ax.set_ylabel(ylab)
        ax.set_title(tag, loc="left")
        ax.invert_xaxis()
        ax.grid(True, which="major", alpha=0.3)
        _data_ylim(ax, data[ax], 1.3 if ax is ax_k else 2.0)
        if handles[ax]:  # below the plateaus at small tau (right) is free; (d) is free below 1 at large tau
            ax.legend(handles=handles[ax], fontsize=7, loc="lower left" if ax is ax_k else "lower right",
                      framealpha=0.85)
    _chi_bar(fig, sm, fig.add_axes((0.895, 0.12, 0.014, 0.76)), [r.chi for r in results])
    if sm is None:  # one chi: no colour bar, the run is named in the title
        fig.subplots_adjust(right=0.98)
    fig.suptitle("Maxima against the time to snap (paper Fig. 3), nondimensional" + _title_run(runs, results))
    return _save(fig, path)


def plot_local_slopes(runs, results, path) -> Path:
    """Local slopes d ln y / d ln tau of the maxima (tau = t*_chi - t), with the
    reference exponents and the fitted windows shaded (single run) - for judging the fits.

    Parameters
    ----------
    runs : list of xarray.Dataset
    results : list of RunFit
    path : str or Path, or a list of them

    Returns
    -------
    Path (a list of Paths for a list of paths)
    """
    from .run import local_slopes

    plt = _plt()
    vars_ = ("v_max", "a_end", "a_max", "sigma_max", "kappa_max")
    tex = {"v_max": r"$v_{\max}$", "a_end": r"$a_{\mathrm{end}}$", "a_max": r"$a_{\max}$",
           "sigma_max": r"$\sigma_{\max}$", "kappa_max": r"$\kappa_{\max}$"}
    fig, axs = plt.subplots(len(vars_), 1, figsize=(8.5, 2.2 * len(vars_)), sharex=True)
    fig.subplots_adjust(left=0.11, right=0.84, bottom=0.06, top=0.95, hspace=0.12)
    cols, sm = chi_colours([r.chi for r in results])
    for ds, res, c in zip(runs, results, cols):
        ls = local_slopes(ds, res.snap.t_star, vars_)
        for ax, v in zip(axs, vars_):
            if v in ls:
                x, y = np.asarray(ls[v].tau, float), np.asarray(ls[v].slope, float)
                ok = np.isfinite(x) & np.isfinite(y) & (x > 0)
                x, y = x[ok], y[ok]
                k = thin_log(x, y)
                ax.semilogx(x[k], y[k], color=c, lw=1.2)
    r0 = results[0]
    for ax, v in zip(axs, vars_):
        refs = set()
        for r in r0.rows:
            if r.spec.var != v:
                continue
            refs.add(r.spec.ref)
            if r.spec.alt is not None:
                refs.add(r.spec.alt)
            if len(runs) == 1 and r.fit is not None:
                ax.axvspan(r.fit.tau_lo, r.fit.tau_hi, color="tab:red", alpha=0.12)
        for ref in sorted(refs):
            ax.axhline(ref, color="k", lw=0.8, ls="--")
            ax.text(1.0, ref, f" {ref:+.3f}", transform=ax.get_yaxis_transform(), fontsize=7, va="center")
        ax.set_ylabel(r"$d\ln$" + tex[v] + r"$/d\ln\tau$", fontsize=9)
        ax.grid(True, alpha=0.3)
    axs[0].invert_xaxis()
    axs[-1].set_xlabel(TAU_LABEL)
    _chi_bar(fig, sm, fig.add_axes((0.905, 0.15, 0.018, 0.7)), [r.chi for r in results])
    if sm is None:
        fig.subplots_adjust(right=0.93)
    fig.suptitle("Local log-log slopes (dashed: reference exponents; shaded: fit windows)" + _title_run(runs, results))
    return _save(fig, path)


def plot_delta(runs, results, path) -> Path:
    """The paper's Fig. 4: (a) the front's distance 1 - s(kappa_m) from the free end
    (interpolated between nodes, :func:`front_arclength`; drawn until it reaches the
    end, as in the paper) and the quarter circle
    (pi/2)/kappa_m against tau = t*_chi - t, their crossing delta_kappa_m, and the
    folded string's kink 1 - s0; (b)-(d) computed peak tension, speed and
    acceleration (black dots) against the whirling-rod predictions (eq. estimates)
    of delta_kappa0, delta_kappa_m and delta_c (delta_c, eq. deltacrude, as a curve).

    Parameters
    ----------
    runs : list of xarray.Dataset
    results : list of RunFit
    path : str or Path, or a list of them

    Returns
    -------
    Path (a list of Paths for a list of paths)
    """
    from matplotlib.lines import Line2D

    from .. import ideal

    plt = _plt()
    fig, axs = plt.subplots(2, 2, figsize=(10.5, 8))
    fig.subplots_adjust(left=0.075, right=0.975, bottom=0.07, top=0.93, wspace=0.42, hspace=0.28)
    ax0, axs_b, axs_c, axs_d = axs[0, 0], axs[0, 1], axs[1, 0], axs[1, 1]
    cols, sm = chi_colours([r.chi for r in results])
    taus, data = [], []
    for ds, res, c in zip(runs, results, cols):
        if res.delta is None:
            continue
        t = np.asarray(ds["t"].values, dtype=float)
        s_node = ds["s_node"].values if "s_node" in ds.variables else None
        s_raw = np.asarray(ds["s_kappa_max"].values, dtype=float)
        s = front_arclength(t, s_raw, s_node)
        k = np.asarray(ds["kappa_max"].values, dtype=float)
        tau = res.snap.t_star - t
        # the front only until it first reaches the last node that has a curvature (paper Fig. 4(a))
        reached = np.flatnonzero(s_raw >= np.nanmax(s_raw))
        before_end = np.arange(t.size) < (reached[0] if reached.size else t.size)
        ok = (tau > 0) & np.isfinite(k) & (k > 0)
        okf = ok & before_end & np.isfinite(s) & (s < 1.0)
        tf, front = tau[okf], 1.0 - s[okf]
        tq, quarter = tau[ok], 0.5 * math.pi / k[ok]
        i = thin_log(tf, front)
        j = thin_log(tq, quarter)
        taus.append(tq)
        data += [front[i], quarter[j]]
        ax0.loglog(tf[i], front[i], color=c, lw=1.2)
        ax0.loglog(tq[j], quarter[j], color=c, lw=1.2, ls="--")
        d = res.delta.deltas["delta_kappa_m"]
        if math.isfinite(d):
            ax0.plot([res.snap.t_star - res.delta.t_cross], [d], "o", mfc="k", mec="w", ms=6, zorder=5)
    handles = [Line2D([], [], color="0.35", lw=1.2, label=r"$1 - s(\kappa_m)$"),
               Line2D([], [], color="0.35", lw=1.2, ls="--", label=r"$\frac{\pi}{2}\kappa_m^{-1}$"),
               Line2D([], [], ls="", marker="o", mfc="k", mec="w", ms=6, label=r"$\delta_{\kappa_m}$ (crossing)")]
    if taus:
        allt = np.concatenate(taus)
        tt = np.geomspace(max(float(allt.min()), 1e-9), float(allt.max()), 200)
        tstar = ideal.t_star()
        tt = tt[tt < tstar]
        line, = ax0.loglog(tt, 1.0 - ideal.s0(tstar - tt), "k-", lw=0.9, label=r"folded string $1 - s_0$")
        handles.append(line)
    ax0.set_xlabel(TAU_LABEL)
    ax0.set_ylabel(r"length  [" + U_LENGTH + "]")
    ax0.invert_xaxis()
    ax0.set_title("(a) front distance meets quarter circle", loc="left", fontsize=10)
    ax0.grid(True, which="major", alpha=0.3)
    _data_ylim(ax0, data, 1.5)
    ax0.legend(handles=handles, fontsize=7, loc="lower right", framealpha=0.85)
    _chi_bar(fig, sm, ax0.inset_axes((1.03, 0.0, 0.035, 1.0)), [r.chi for r in results])
    fitted = [r for r in results if r.delta is not None]
    chis = np.array([r.chi for r in fitted])
    if chis.size:
        lo, hi = max(0.02, 0.7 * chis.min()), min(0.98, 1.3 * chis.max())
        cc = np.linspace(lo, hi, 100)
        for ax, q, tag, unit in ((axs_b, "sigma", r"(b) peak tension $\sigma$", U_FORCE),
                                 (axs_c, "v", r"(c) peak speed $v$", U_SPEED),
                                 (axs_d, "a", r"(d) peak acceleration $a$", U_ACCEL)):
            pred_c = [estimates.whirling_rod(estimates.available_energy(x), estimates.delta_crude(x))[q] for x in cc]
            ax.semilogy(cc, pred_c, "r-", lw=1.2, label=r"$\delta_c$ (analytic)")
            for key, mk, lab in (("delta_kappa0", "bs", r"$\delta_{\kappa_0}$"),
                                 ("delta_kappa_m", "g^", r"$\delta_{\kappa_m}$ (from the run)")):
                ax.semilogy(chis, [r.delta.predicted[key][q] for r in fitted], mk, mfc="none", label=lab)
            ax.semilogy(chis, [r.delta.computed[q] for r in fitted], "ko", label="computed")
            ax.set_xlabel(r"initial end separation $\chi$ (fraction of the length)")
            ax.set_ylabel(tag[4:] + "  [" + unit + "]")
            ax.set_title(tag, loc="left", fontsize=10)
            ax.grid(True, which="both", alpha=0.3)
        axs_b.legend(fontsize=7, loc="upper right", framealpha=0.85, title="predictions (eq. estimates)",
                     title_fontsize=7)
    fig.suptitle("Regularising scales and predicted peaks (paper Fig. 4), nondimensional" + _title_run(runs, results))
    return _save(fig, path)
