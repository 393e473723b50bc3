"""Figures of the scaling analysis (matplotlib, Agg backend): the paper's Fig. 3
(maxima against t* - t, curvature amplification), local slopes, and Fig. 4
(delta scales and the predicted peaks).

Each function takes run Datasets and their :class:`~snapping.scaling.run.RunFit`
results and saves a PNG (or PDF, by the suffix of ``path``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import _validate as V
from .. import estimates

__all__ = ["plot_maxima", "plot_local_slopes", "plot_delta"]

_UNIT = " (nondimensional)"


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path) -> Path:
    path = Path(path)
    if path.suffix.lower() not in (".png", ".pdf", ".svg"):
        raise V.SnappingInputError(f"path={str(path)!r}: the figure suffix must be .png, .pdf or .svg")
    from .._files import save_figure

    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        save_figure(fig, path, dpi=150, bbox_inches="tight")
    finally:
        _plt().close(fig)
    return path


def _colors(n):
    plt = _plt()
    cmap = plt.get_cmap("viridis")
    return [cmap(x) for x in np.linspace(0.0, 0.85, max(n, 1))]


def _before(ds, t_star, var):
    t = np.asarray(ds["t"].values, dtype=float)
    y = np.asarray(ds[var].values, dtype=float)
    tau = t_star - t
    ok = (tau > 0) & np.isfinite(y) & (y > 0)
    return tau[ok], y[ok]


def plot_maxima(runs, results, path, *, show_fits: bool = True) -> Path:
    """The paper's Fig. 3: maxima of speed, acceleration (max and free end), tension
    and the curvature amplification against t*_chi - t, on log-log axes, with the
    folded-string scalings and prefactors (eq. asymptoticscalings) drawn in.

    Parameters
    ----------
    runs : list of xarray.Dataset
        Runs (several chi give the collapse of the paper's figure).
    results : list of RunFit
        Their fit reports (:func:`~snapping.scaling.run.fit_run`), for t*_chi and
        the fitted windows.
    path : str or Path
        Output file (.png, .pdf or .svg).
    show_fits : bool
        Draw each fitted power law over its window (single run only).

    Returns
    -------
    Path
    """
    from .run import report_specs

    plt = _plt()
    specs = {s.name: s for s in report_specs()}
    fig, axs = plt.subplots(2, 2, figsize=(10, 8))
    (ax_v, ax_a), (ax_s, ax_k) = axs
    cols = _colors(len(runs))
    taus = []
    for ds, res, c in zip(runs, results, cols):
        ts = res.snap.t_star
        lab = f"chi = {res.chi:.3g}" + (f", N = {res.N}" if res.N else "")
        for ax, var, kw in (
            (ax_v, "v_max", {}),
            (ax_a, "a_max", {}),
            (ax_a, "a_end", {"ls": "--"}),
            (ax_s, "sigma_max", {}),
        ):
            if var not in ds.variables:
                continue
            tau, y = _before(ds, ts, var)
            taus.append(tau)
            l = lab if ax is not ax_a else f"{var}, {lab}"
            ax.loglog(tau, y, color=c, lw=1.2, label=l, **kw)
        if "kappa_max" in ds.variables and math.isfinite(res.kappa_max_0):
            tau, y = _before(ds, ts, "kappa_max")
            ax_k.loglog(tau, y / res.kappa_max_0, color=c, lw=1.2, label=lab)
        if show_fits and len(runs) == 1:
            for r in res.rows:
                if r.fit is None:
                    continue
                ax = {"v_max": ax_v, "a_max": ax_a, "a_end": ax_a, "sigma_max": ax_s, "kappa_max": ax_k}[r.spec.var]
                tt = np.geomspace(r.fit.tau_lo, r.fit.tau_hi, 50)
                scale = 1.0 / res.kappa_max_0 if r.spec.var == "kappa_max" else 1.0
                ax.loglog(tt, r.fit.predict(tt) * scale, color="tab:red", lw=2.5, alpha=0.6,
                          label=f"fit {r.spec.name}: beta = {r.fit.beta:+.3f} ± {r.fit.beta_err:.3f}")
    if taus:
        allt = np.concatenate(taus)
        lo, hi = max(float(allt.min()), 1e-12), float(allt.max())
    else:
        lo, hi = 1e-6, 1.0
    tt = np.geomspace(lo, hi, 200)
    for ax, key, txt in (
        (ax_v, "v_max", "ideal 2 s0' = {A:.4f} tau^(-1/3)"),
        (ax_a, "a_end", "ideal 2 s0'' = {A:.4f} tau^(-4/3)"),
        (ax_s, "sigma_max", "ideal s0'^2 = {A:.4f} tau^(-2/3)"),
    ):
        s = specs[key]
        ax.loglog(tt, s.prefactor * tt**s.ref, "k-", lw=0.9, alpha=0.8, label=txt.format(A=s.prefactor))
    # guides for the observed laws, anchored on the first run's fit where there is one
    r0 = results[0] if results else None
    for ax, name, expo, txt in (
        (ax_a, "a_max", -5.0 / 6.0, "tau^(-5/6) (paper, intermediate)"),
        (ax_k, "kappa_max", -1.0 / 6.0, "tau^(-1/6) (paper, anomalous)"),
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
            ax.loglog(tt, A * scale * tt**expo, "k:", lw=1.2, label=txt)
    if r0 is not None and math.isfinite(r0.kappa_max_0):
        try:
            f = r0.row("kappa_max").fit
        except KeyError:
            f = None
        if f is not None:
            ax_k.loglog(tt, f.A / r0.kappa_max_0 * (tt / f.tau_hi) ** (-2.0 / 3.0) * f.tau_hi**f.beta, "k--",
                        lw=0.9, label="tau^(-2/3) (inferred)")
    for ax, ylab, tag in (
        (ax_v, "maximum speed v_max", "(a)"),
        (ax_a, "acceleration a_max, a_end", "(b)"),
        (ax_s, "maximum tension sigma_max", "(c)"),
        (ax_k, "kappa_max / kappa_max(0)", "(d)"),
    ):
        ax.set_xlabel("time to snap t*_chi - t" + _UNIT)
        ax.set_ylabel(ylab + _UNIT)
        ax.set_title(tag, loc="left")
        ax.invert_xaxis()
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=6, loc="best")
    fig.suptitle("Maxima against the time to snap (paper Fig. 3)")
    fig.tight_layout()
    return _save(fig, path)


def plot_local_slopes(runs, results, path) -> Path:
    """Local slopes d ln y / d ln (t* - t) of the maxima, with the reference exponents
    and the fitted windows shaded (single run) - for judging the fits.

    Parameters
    ----------
    runs : list of xarray.Dataset
    results : list of RunFit
    path : str or Path

    Returns
    -------
    Path
    """
    from .run import local_slopes

    plt = _plt()
    vars_ = ("v_max", "a_end", "a_max", "sigma_max", "kappa_max")
    fig, axs = plt.subplots(len(vars_), 1, figsize=(8, 2.2 * len(vars_)), sharex=True)
    cols = _colors(len(runs))
    for ds, res, c in zip(runs, results, cols):
        ls = local_slopes(ds, res.snap.t_star, vars_)
        for ax, v in zip(axs, vars_):
            if v in ls:
                ax.semilogx(ls[v].tau, ls[v].slope, color=c, lw=1.2, label=f"chi = {res.chi:.3g}")
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
        ax.set_ylabel(f"slope of {v}" + "\n(nondimensional)", fontsize=8)
        ax.invert_xaxis() if ax is axs[0] else None
        ax.grid(True, alpha=0.3)
    axs[0].legend(fontsize=7)
    axs[-1].set_xlabel("time to snap t*_chi - t (nondimensional)")
    fig.suptitle("Local log-log slopes (shaded: fit windows)")
    fig.tight_layout()
    return _save(fig, path)


def plot_delta(runs, results, path) -> Path:
    """The paper's Fig. 4: (a) 1 - s(kappa_m) and (pi/2)/kappa_m against t* - t with
    the crossing delta_kappa_m; (b)-(d) computed peak tension, speed and
    acceleration (black dots) against the whirling-rod predictions of
    delta_kappa0, delta_kappa_m and delta_c (eq. estimates; delta_c as a curve).

    Parameters
    ----------
    runs : list of xarray.Dataset
    results : list of RunFit
    path : str or Path

    Returns
    -------
    Path
    """
    plt = _plt()
    fig, axs = plt.subplots(2, 2, figsize=(10, 8))
    ax0, axs_b, axs_c, axs_d = axs[0, 0], axs[0, 1], axs[1, 0], axs[1, 1]
    cols = _colors(len(runs))
    for ds, res, c in zip(runs, results, cols):
        if res.delta is None:
            continue
        t = np.asarray(ds["t"].values, dtype=float)
        tau = res.snap.t_star - t
        ok = tau > 0
        s = np.asarray(ds["s_kappa_max"].values, dtype=float)[ok]
        k = np.asarray(ds["kappa_max"].values, dtype=float)[ok]
        ax0.loglog(tau[ok], 1.0 - s, color=c, lw=1.2, label=f"1 - s(kappa_m), chi = {res.chi:.3g}")
        ax0.loglog(tau[ok], 0.5 * math.pi / k, color=c, lw=1.2, ls="--", label="(pi/2)/kappa_m")
        d = res.delta.deltas["delta_kappa_m"]
        if math.isfinite(d):
            ax0.plot([res.snap.t_star - res.delta.t_cross], [d], "ko", ms=6)
    ax0.set_xlabel("time to snap t*_chi - t" + _UNIT)
    ax0.set_ylabel("length" + _UNIT)
    ax0.invert_xaxis()
    ax0.set_title("(a) delta_kappa_m: front distance meets quarter circle", loc="left", fontsize=9)
    ax0.legend(fontsize=6)
    chis = np.array([r.chi for r in results if r.delta is not None])
    if chis.size:
        lo, hi = max(0.02, 0.7 * chis.min()), min(0.98, 1.3 * chis.max())
        cc = np.linspace(lo, hi, 100)
        for ax, q, tag in ((axs_b, "sigma", "(b) peak tension"), (axs_c, "v", "(c) peak speed"), (axs_d, "a", "(d) peak acceleration")):
            pred_c = [estimates.whirling_rod(estimates.available_energy(x), estimates.delta_crude(x))[q] for x in cc]
            ax.semilogy(cc, pred_c, "r-", lw=1.2, label="delta_c (eq. deltacrude)")
            for key, mk, lab in (("delta_kappa0", "bs", "delta_kappa_m(0)"), ("delta_kappa_m", "g^", "delta_kappa_m (run)")):
                xs = [r.chi for r in results if r.delta is not None]
                ys = [r.delta.predicted[key][q] for r in results if r.delta is not None]
                ax.semilogy(xs, ys, mk, mfc="none", label=lab)
            ax.semilogy(chis, [r.delta.computed[q] for r in results if r.delta is not None], "ko", label="computed")
            ax.set_xlabel("initial end separation chi" + _UNIT)
            ax.set_ylabel(tag[4:] + _UNIT)
            ax.set_title(tag, loc="left")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=6)
    fig.suptitle("Regularising scales and predicted peaks (paper Fig. 4)")
    fig.tight_layout()
    return _save(fig, path)
