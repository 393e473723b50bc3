"""Figures of 3D runs: the out-of-plane amplitude at the snap against eps, and the chain in space.

* :func:`growth` runs a planar start with the out-of-plane kick of amplitude eps
  (:meth:`snapping.spatial.starts3d.Problem3D.perturbed`) to the snap for several eps;
* :func:`amplitude_vs_eps` draws what it measured, log-log, with the line of linear growth
  through the smallest eps;
* :func:`chain_views` draws a 3D run Dataset's snapshots (:mod:`snapping.spatial.dataset3d`)
  in space and in projection (the plane of the start, and seen from below along gravity).

Each returns a matplotlib Figure; :func:`snapping.figures.save` writes it.

Example
-------
>>> from snapping.spatial.figures3d import growth, amplitude_vs_eps
>>> g = growth(0.5, 10, [1e-6, 1e-4], tol=1e-8)
>>> fig = amplitude_vs_eps(g); len(fig.axes)
2
"""

from __future__ import annotations

import numpy as np

from ..figures import _plt

__all__ = ["growth", "amplitude_vs_eps", "chain_views"]


def growth(chi: float, N: int, eps_values, *, tol: float = 1e-10, mode: str = "sin", seed: int | None = None) -> dict:
    """Run the catenary start of ``chi``, ``N`` with the out-of-plane kick ``eps`` (each of
    ``eps_values``) and the planar start to the snap; returns arrays ``eps``, ``z_amp_snap``,
    ``vz_amp_snap``, ``v_peak``, ``n_rhs`` and the planar ``v_peak0`` (with ``chi``, ``N``, ``mode``)."""
    from .solve3d import run3d
    from .starts3d import Problem3D

    p0 = Problem3D.catenary(chi, N)
    base = run3d(p0, tol=tol)
    out = {"chi": chi, "N": N, "mode": mode, "v_peak0": base["v_peak"]}
    rows = [run3d(p0.perturbed(e, mode, seed=seed), tol=tol) for e in eps_values]
    out["eps"] = np.asarray(eps_values, dtype=float)
    for k in ("z_amp_snap", "vz_amp_snap", "v_peak", "n_rhs"):
        out[k] = np.array([r[k] for r in rows])
    return out


def amplitude_vs_eps(g: dict):
    """Left: the out-of-plane amplitude (distance from the plane, and speed) at the snap
    against eps, log-log, with the lines of linear growth through the smallest eps. Right:
    the amplitude over eps (flat: linear growth) and the relative change of the peak speed
    over eps^2 (flat: second order)."""
    plt = _plt()
    eps = g["eps"]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(9.5, 3.8), constrained_layout=True)
    i0 = int(np.argmin(eps))
    line = np.array([eps.min(), eps.max()])
    for key, mk, lab in (("z_amp_snap", "o", "distance from the plane"), ("vz_amp_snap", "s", "out-of-plane speed")):
        ax.loglog(eps, g[key], mk, label=lab)
        ax.loglog(line, g[key][i0] / eps[i0] * line, "k:", lw=0.8)
        bx.semilogx(eps, g[key] / eps, mk + "-", label=f"{lab} / eps")
    ax.set_xlabel("eps (amplitude of the out-of-plane start velocity)")
    ax.set_ylabel("at the snap (largest over the nodes)")
    ax.set_title(f"chi = {g['chi']:g}, N = {g['N']}, mode {g['mode']}; dotted: linear growth", fontsize=9)
    ax.legend(fontsize=8)
    dv = (g["v_peak"] - g["v_peak0"]) / g["v_peak0"]
    bx.semilogx(eps, dv / eps**2, "^-", label="(v_peak - planar) / planar / eps^2")
    bx.set_xlabel("eps")
    bx.set_title("amplification (flat: linear in eps)", fontsize=9)
    bx.legend(fontsize=8)
    return fig


def chain_views(ds, n: int = 4):
    """The chain of a 3D run Dataset at ``n`` snapshots up to the speed peak (the initial,
    requested and peak snapshots, evenly picked): in space (left; y drawn downward), in the
    start's plane x-y (middle) and seen along gravity, x-z (right; z magnified to fill)."""
    plt = _plt()
    kinds = ds["snapshot_kind"].values
    ts = ds["t_snapshot"].values
    tpk = ts[kinds == "peak"][0] if np.any(kinds == "peak") else ts[-1]
    idx = [i for i in range(ts.size) if ts[i] <= tpk and kinds[i] != "final"] or [0]
    idx = [idx[int(round(k))] for k in np.linspace(0, len(idx) - 1, min(n, len(idx)))]
    fig = plt.figure(figsize=(12, 4.3), constrained_layout=True)
    a3 = fig.add_subplot(1, 3, 1, projection="3d")
    axy = fig.add_subplot(1, 3, 2)
    axz = fig.add_subplot(1, 3, 3)
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(idx)))
    for c, i in zip(colors, idx):
        x, y, z = (ds[k].isel(snapshot=i).values for k in ("x", "y", "z"))
        lab = f"t = {ts[i]:.4g} ({kinds[i]})"
        a3.plot(x, z, -y, color=c, label=lab)
        axy.plot(x, y, color=c, label=lab)
        axz.plot(x, z, color=c)
    a3.set_xlabel("x")
    a3.set_ylabel("z")
    a3.set_zlabel("-y (up)")
    axy.invert_yaxis()
    axy.set_aspect("equal")
    axy.set_xlabel("x")
    axy.set_ylabel("y (down)")
    axy.set_title("in the start's plane", fontsize=9)
    fig.legend(*axy.get_legend_handles_labels(), loc="outside lower center", ncol=len(idx), fontsize=8)
    axz.set_xlabel("x")
    axz.set_ylabel("z (out of the plane)")
    axz.set_title("seen along gravity", fontsize=9)
    fig.suptitle(f"3D run: N = {int(ds.attrs['N'])}, v_peak = {float(ds.attrs['v_peak']):.6g}, "
                 f"z_amp at the snap = {float(ds.attrs['z_amp_snap']):.3g}", fontsize=10)
    return fig
