"""Figures of the extensible line's runs (:mod:`snapping.simulate.elastic`): the strain along the
line against time (:func:`strain_history`, :func:`strain_panel`: a space-time image in which the
release's unloading wave and the slack regions show) and the energy terms with their balance
(:func:`energy_terms`, :func:`energy_panels`). ``snapping plot`` of an elastic run adds them to its
overview (:func:`snapping.figures.overview`).

The image is made of the run's profile snapshots (``strain`` over the links at ``t_snapshot``):
a run with a few automatic snapshots gives a coarse one; ``solve(..., snapshot_times=...)`` or
``snapping simulate --snapshot-times`` with some hundred times gives the wave.

Example
-------
>>> import numpy as np, xarray as xr
>>> ds = xr.Dataset({"strain": (("snapshot", "link"), [[0.1, 0.2], [0.0, -0.1]])},
...                 coords={"t_snapshot": ("snapshot", [0.5, 0.0]), "s_link": ("link", [0.75, 0.25])})
>>> t, s, e = strain_history(ds)
>>> t.tolist(), s.tolist(), e.tolist()
([0.0, 0.5], [0.25, 0.75], [[-0.1, 0.2], [0.0, 0.1]])
"""

from __future__ import annotations

import numpy as np

from . import _validate as V

__all__ = ["is_elastic_run", "strain_history", "energy_terms", "strain_panel", "strain_profiles", "energy_panels",
           "figure"]


def is_elastic_run(ds) -> bool:
    """True for a run of the extensible line (it records the strain and the elastic energy)."""
    return "strain" in ds.variables and "elastic_energy" in ds.variables


def strain_history(ds):
    """(t, s, strain): the snapshot times (increasing, repeats dropped), the links' rest
    arclength from the held end (increasing), and the strain ``strain[link, time]``."""
    if "strain" not in ds.variables or "t_snapshot" not in ds.variables:
        raise V.SnappingInputError("the run has no strain profiles (not a run of the extensible line)")
    t = np.asarray(ds["t_snapshot"].values, dtype=float)
    order = np.argsort(t, kind="stable")
    order = order[np.r_[True, np.diff(t[order]) > 0]]
    s = np.asarray(ds["s_link"].values, dtype=float)
    so = np.argsort(s)
    e = np.asarray(ds["strain"].values, dtype=float)[order][:, so]
    return t[order], s[so], e.T


def energy_terms(ds) -> dict:
    """The energy terms of an elastic run (units of M g L) against ``t``: ``mechanical``
    (kinetic + gravity), ``elastic``, ``pin_work`` W, ``dissipated`` D (Kelvin-Voigt damping), the
    ``balance`` E - W + D (conserved; E = kinetic + gravity + elastic) and ``residual`` =
    |balance - balance(0)| / |E(0)| (absolute where E(0) = 0)."""
    g = {k: np.asarray(ds[k].values, dtype=float) for k in ("energy", "elastic_energy", "pin_work", "dissipated")}
    bal = g["energy"] - g["pin_work"] + g["dissipated"]
    e0 = abs(float(g["energy"][0]))
    return {"t": np.asarray(ds["t"].values, dtype=float), "mechanical": g["energy"] - g["elastic_energy"],
            "elastic": g["elastic_energy"], "pin_work": g["pin_work"], "dissipated": g["dissipated"],
            "balance": bal, "residual": np.abs(bal - bal[0]) / (e0 if e0 > 0 else 1.0)}


def strain_panel(ds, ax, t_snap=np.nan):
    """The strain along the line against time on ``ax`` (time across, rest arclength from the
    held end up; slack links, strain <= 0, in grey); returns the image (for a colour bar)."""
    import matplotlib.pyplot as plt

    t, s, e = strain_history(ds)
    taut = np.ma.masked_less_equal(e, 0.0)
    cmap = plt.get_cmap("magma").with_extremes(bad="0.8")  # (bad: slack)
    from matplotlib.colors import LogNorm

    top = float(np.nanmax(e)) if np.any(e > 0) else 1.0
    # (log scale: the release's small strains and the snap's large ones in one image)
    norm = LogNorm(vmin=max(top * 1e-3, float(taut.min()) if taut.count() else top * 1e-3), vmax=top)
    im = ax.pcolormesh(t, s, np.ma.clip(taut, norm.vmin, None), shading="nearest", cmap=cmap, norm=norm,
                       rasterized=True)
    if np.isfinite(t_snap):
        ax.axvline(t_snap, color="c", lw=0.8, ls="--")
    ax.set_xlabel(r"time $t$  [$\sqrt{L/g}$]")
    ax.set_ylabel(r"rest arclength $s$ from the held end  [$L$]")
    few = "" if t.size >= 20 else f"; {t.size} snapshots: more with snapshot_times"
    ax.set_title(f"(e) strain along the line (grey: slack{few})", loc="left", fontsize=10)
    return im


def strain_profiles(ds, ax, idx, colors) -> None:
    """(g) the strain along the line at the snapshots ``idx`` (colours ``colors``); slack below 0."""
    s = np.asarray(ds["s_link"].values, dtype=float)
    for c, i in zip(colors, idx):
        sn = ds.isel(snapshot=int(i))
        ax.plot(s, sn["strain"].values, color=c, label=f"t = {float(sn['t_snapshot']):.4f}")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel(r"rest arclength $s$ from the held end  [$L$]")
    ax.set_ylabel("strain $l/h - 1$ (below 0: slack)")
    ax.set_title("(g) strain along the line", loc="left", fontsize=10)
    ax.grid(alpha=0.3)


def energy_panels(ds, a_terms, a_res, t_snap=np.nan) -> None:
    """The energy terms of an elastic run against time on ``a_terms``; the residual of their
    balance on ``a_res``."""
    from .scaling.plots import thin_envelope

    e = energy_terms(ds)
    t = e["t"]
    for name, lab, c in (("mechanical", "kinetic + gravity", "C0"), ("elastic", "elastic", "C1"),
                         ("pin_work", "pin work W", "C2"), ("dissipated", "dissipated D (damping)", "C3"),
                         ("balance", "E - W + D (conserved)", "k")):
        k = thin_envelope(t, e[name])
        a_terms.plot(t[k], e[name][k], color=c, lw=1.0 if name != "balance" else 1.6, label=lab)
    a_terms.set_xlabel(r"time $t$  [$\sqrt{L/g}$]")
    a_terms.set_ylabel(r"energy  [$M g L$]")
    a_terms.set_title("(f) energy terms (E = kinetic + gravity + elastic)", loc="left", fontsize=10)
    a_terms.legend(fontsize=7, loc="best")
    r = e["residual"]
    k = thin_envelope(t, r)
    pos = k[r[k] > 0]
    a_res.semilogy(t[pos], r[pos], color="k", lw=1.0, label=f"max {float(r.max()):.2g}")
    a_res.set_xlabel(r"time $t$  [$\sqrt{L/g}$]")
    a_res.set_ylabel(r"$|E - W + D - E_0| / E_0$")
    a_res.set_title(f"(h) energy balance (tol {ds.attrs.get('tol', float('nan')):g})", loc="left", fontsize=10)
    a_res.legend(fontsize=7, loc="lower right")
    for a in (a_terms, a_res):
        if np.isfinite(t_snap):
            a.axvline(t_snap, color="k", lw=0.6, ls="--")
        a.grid(alpha=0.3)


def figure(ds, path=None):
    """The strain image and the energy terms of an elastic run, alone (the guide's figure of the
    unloading wave). Returns the Figure (saved to ``path`` when given)."""
    import matplotlib

    if path is not None:
        matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    if not is_elastic_run(ds):
        raise V.SnappingInputError("ds is not a run of the extensible line (no 'strain' and 'elastic_energy')")
    fig, (a0, a1, a2) = plt.subplots(1, 3, figsize=(15.5, 4.4))
    fig.subplots_adjust(left=0.06, right=0.98, bottom=0.13, top=0.88, wspace=0.32)
    t_snap = float(ds.attrs.get("t_snap_v", np.nan)) if int(ds.attrs.get("snap_reached", 1)) else np.nan
    im = strain_panel(ds, a0, t_snap)
    fig.colorbar(im, ax=a0, label="strain")
    energy_panels(ds, a1, a2, t_snap)
    for ax, k in zip((a0, a1, a2), "abc"):  # (the overview's panel letters, renamed)
        ax.set_title(f"({k})" + ax.get_title(loc="left")[3:], loc="left", fontsize=10)
    if path is not None:
        fig.savefig(path, dpi=110)
    return fig
