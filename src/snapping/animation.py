"""An animation of the snap from a run file's snapshots (``snapping animate``).

Each frame is one profile snapshot of the run (``x``, ``y``, ``speed`` over the
nodes, at ``t_snapshot``; names in :mod:`snapping.schema`): the chain drawn as a
LineCollection coloured by the speed of each link (the mean of its two nodes' speeds)
on a logarithmic colour scale, since the speeds span decades, with a colour bar,
the time and the time to the snap shown, equal aspect, nondimensional units
(lengths in chain lengths l, speeds in sqrt(g l), time in sqrt(l/g)).

The automatic snapshots of a run (:func:`snapping.simulate.run`) are taken when the
maximum speed first reaches 1, 1.5, 1.5^2, ... and pile up towards the snap, but
give only some ten frames; :func:`dense_snapshot_times` suggests times for
``snapping simulate --snapshot-times`` that make a smooth animation (geometric in
the time to the snap), and ``snapping animate`` prints the command when a run has
fewer than :data:`DENSE_FRAMES` snapshots up to the snap.

A run with bending stiffness (a :class:`snapping.simulate.Body`) is coloured instead by the
magnitude of the bending moment at each link (the mean of its nodes': :func:`bending_moments`,
``B (turning angle - natural) / l`` at a node, zero at a free end), and its ends are marked:
the tip body (a tip mass or a tip drag) as a circle, a clamped held end as a short thick
handle along the clamp's direction (it turns with a prescribed clamp motion). A run of the
extensible line (:mod:`snapping.simulate.elastic`: its file has ``strain``) is coloured by each
link's strain, slack links (strain <= 0) in grey.

A 3D run (:mod:`snapping.spatial.dataset3d`: its file has ``z``) gets a second panel: the
chain seen along gravity, ``z`` (out of the start's plane) against ``x``, its scale fitted to
the largest out-of-plane distance of all frames (a perturbation of 1e-6 stays visible),
coloured as the first panel, which shows the chain projected on the start's plane.

GIF is written with matplotlib's PillowWriter (pillow comes with matplotlib), MP4
with FFMpegWriter when ``ffmpeg`` is on PATH.

Example
-------
>>> from snapping.animation import dense_snapshot_times
>>> ts = dense_snapshot_times(1.2, n=5)
>>> [round(t, 6) for t in ts]
[0.0, 1.08, 1.188, 1.1988, 1.19988]
"""

from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

import numpy as np

from . import _validate as V

__all__ = ["dense_snapshot_times", "frames_of", "animate", "bending_moments", "clamp_angle", "DENSE_FRAMES", "SUFFIXES"]

#: Fewer snapshots than this up to the snap make a jerky animation: ``snapping animate`` says how to get more.
DENSE_FRAMES = 24

#: Most snapshot times of :func:`dense_snapshot_times` (each is a whole profile in the run file)
MAX_TIMES = 100_000

#: Frames per second accepted (a GIF frame lasts a whole number of milliseconds)
FPS_RANGE = (0.01, 100.0)

#: Output formats by suffix.
SUFFIXES = (".gif", ".mp4")

#: Needed snapshot variables.
_NEEDED = ("t_snapshot", "x", "y", "speed")


def dense_snapshot_times(t_snap: float, n: int = 60, tau_min: float = 1e-4) -> list[float]:
    """``n`` snapshot times from 0 to the snap ``t_snap``, geometric in the time to the
    snap tau = t_snap - t from tau = t_snap (t = 0) down to ``tau_min * t_snap``: a
    frame per equal factor of tau, so the slow fall and the fast snap both get frames.

    Parameters
    ----------
    t_snap : float
        Snapping time of the run (its ``t_snap_v`` attribute), > 0.
    n : int
        Number of times, >= 2.
    tau_min : float
        Smallest time to the snap, as a fraction of ``t_snap``, in (0, 1).

    Returns
    -------
    list of float
        Increasing times, the first 0; the last is ``t_snap (1 - tau_min)``.
    """
    t_snap = V.positive("t_snap", t_snap)
    n = V.integer("n", n, 2, MAX_TIMES)
    if not (isinstance(tau_min, (int, float)) and 0.0 < tau_min < 1.0):
        raise V.SnappingInputError(f"tau_min={tau_min!r} must be in (0, 1)")
    tau = np.geomspace(1.0, tau_min, n) * t_snap
    return [float(t) for t in t_snap - tau]


def _check_run(ds, name: str = "run"):
    V.run_dataset(name, ds)
    missing = [v for v in _NEEDED if v not in ds.variables]
    if missing:
        raise V.SnappingInputError(f"{name} has no profile snapshots (missing {missing}): nothing to animate")
    if ds.sizes.get("snapshot", 0) < 1:
        raise V.SnappingInputError(f"{name} has no profile snapshots: nothing to animate")


def frames_of(ds, max_frames: int | None = None) -> np.ndarray:
    """Indices of the snapshots that become frames: all of them in time order (dropping
    repeated times), thinned evenly in index to at most ``max_frames`` (first and last kept)."""
    _check_run(ds)
    t = np.asarray(ds["t_snapshot"].values, dtype=float)
    order = np.argsort(t, kind="stable")
    keep = order[np.r_[True, np.diff(t[order]) > 0]]
    if max_frames is not None:
        max_frames = V.integer("max_frames", max_frames, 2)
        if keep.size > max_frames:
            keep = keep[np.unique(np.round(np.linspace(0, keep.size - 1, max_frames)).astype(int))]
    return keep


def snapshots_before_snap(ds) -> int:
    """Number of snapshots at or before the run's snapping time ``t_snap_v``."""
    t = np.asarray(ds["t_snapshot"].values, dtype=float)
    t_snap = float(ds.attrs.get("t_snap_v", np.nan))
    return int(np.sum(t <= t_snap)) if math.isfinite(t_snap) else int(t.size)


def denser_run_hint(ds, path: str, n: int = 60) -> str | None:
    """The command that makes a denser-snapshot run of ``ds``, or None where it has at least
    :data:`DENSE_FRAMES` snapshots up to the snap (or no snapping time)."""
    t_snap = float(ds.attrs.get("t_snap_v", np.nan))
    if not math.isfinite(t_snap) or t_snap <= 0 or snapshots_before_snap(ds) >= DENSE_FRAMES:
        return None
    times = ",".join(f"{t:.9g}" for t in dense_snapshot_times(t_snap, n)[1:])  # t = 0 is always taken
    stem = Path(path).with_suffix("").name
    head = (f"only {snapshots_before_snap(ds)} snapshots up to the snap (t = {t_snap:.6g}); for a smoother "
            f"animation make a run with {n} snapshots dense towards the snap")
    if str(ds.attrs.get("initial", "catenary")) == "catenary" and "chi" in ds.attrs:
        opts = f"--chi {float(ds.attrs['chi']):g} --N {int(ds.attrs['N'])}"
        for k, o in (("tol", "--tol"), ("method", "--method")):
            if k in ds.attrs:
                opts += f" {o} {ds.attrs[k]:g}" if k == "tol" else f" {o} {ds.attrs[k]}"
        return f"{head}:\n  snapping simulate {opts} --snapshot-times {times} -o {stem}_dense.nc"
    return f"{head}: add to the command that made it\n  --snapshot-times {times}"


def _body_of(ds):
    """The run's :class:`snapping.simulate.Body` and link lengths, or (None, None) without one."""
    import json

    text = ds.attrs.get("body")
    if not text or "link_length" not in ds:
        return None, None
    from .simulate.body import Body

    h = np.asarray(ds["link_length"].values, dtype=float)
    return Body.from_describe(json.loads(text), h), h


def clamp_angle(body, t: float) -> float:
    """The direction (radians, from +x towards +y downward) in which a clamped held end holds
    the line at time ``t``: the clamp's angle, or its prescribed motion (the cubic spline with
    zero rate at both ends that the run follows, constant after the last sample)."""
    if isinstance(body.clamp, tuple):
        from scipy.interpolate import CubicSpline

        ts, a = body.clamp
        return float(CubicSpline(ts, a, bc_type="clamped")(min(max(float(t), 0.0), float(ts[-1]))))
    return float(body.clamp)


def bending_moments(x, y, body, h, t: float = 0.0) -> np.ndarray:
    """|bending moment| at the N + 1 nodes of one snapshot (positions ``x, y``, index 0 the
    free end) of a line with ``body`` and links ``h``: ``B_j |phi_j - kappa0_j l_j| / l_j`` with
    ``phi_j`` the turning angle between the node's two links and ``l_j`` its share of length
    (the moment whose energy the run records as ``bending_energy``); 0 at the free end, and at
    the held end unless it is clamped (then ``phi`` is measured from the clamp's direction at
    ``t``). Units of M g L (nondimensional)."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    N = h.size
    th = np.arctan2(np.diff(y), np.diff(x))  # link j: from node j to node j + 1
    l = np.zeros(N + 1)
    l[0], l[N] = 0.5 * h[0], 0.5 * h[N - 1]
    l[1:N] = 0.5 * (h[:-1] + h[1:])
    phi = np.zeros(N + 1)
    phi[1:N] = np.angle(np.exp(1j * (th[1:] - th[:-1])))
    inner = np.zeros(N + 1)
    inner[1:N] = 1.0
    if body.clamp is not None and not isinstance(body.clamp, str):
        leave = math.atan2(y[N - 1] - y[N], x[N - 1] - x[N])  # the direction the line leaves the held end
        phi[N] = np.angle(np.exp(1j * (clamp_angle(body, t) - leave)))
        inner[N] = 1.0
    B, k0 = body.node_values("bending", h), body.node_values("curvature", h)
    return inner * B * np.abs(phi - k0 * l) / l


def _writer(suffix: str, fps: float):
    from matplotlib import animation as A

    if suffix == ".gif":
        class _Gif(A.PillowWriter):  # the format named, not guessed from the temporary file's name
            def finish(self):
                self._frames[0].save(self.outfile, format="GIF", save_all=True, append_images=self._frames[1:],
                                     duration=int(1000 / self.fps), loop=0)

        return _Gif(fps=fps)
    return A.FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p", "-f", "mp4"])


#: free space an animation file needs (checked before any work; a 70-frame GIF is ~2 MB)
ANIMATION_BYTES = 5e6


def check_output(output, *, overwrite: bool = False) -> str:
    """The animation path to write, checked before any work: suffix .gif or .mp4 (ffmpeg on
    PATH for .mp4), an existing directory, no existing file unless ``overwrite``."""
    from . import _files

    p = V.file_path("output", output)
    suffix = Path(p).suffix.lower()
    if suffix not in SUFFIXES:
        raise V.SnappingInputError(f"output={p!r}: the animation suffix must be .gif or .mp4 (got {suffix or 'none'!r})")
    if suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise V.SnappingInputError(f"output={p!r}: writing MP4 needs ffmpeg on PATH, which is not found; "
                                   f"write a GIF instead (-o {Path(p).with_suffix('.gif').name})")
    return _files.check_output(p, name="output", overwrite=overwrite, need_bytes=ANIMATION_BYTES)


def build(ds, *, max_frames: int | None = None, vmin_fraction: float = 1e-4):
    """The figure and FuncAnimation of run ``ds`` (not saved), with ``artists``: a dict of
    the LineCollection ``chain``, the colour ``norm``, the ``frames`` (snapshot indices) and
    the time ``text``, for inspection.

    Colours: the speed of each link (mean of its nodes' speeds), or with bending stiffness
    the bending moment's magnitude (mean of its nodes' :func:`bending_moments`), on a LogNorm
    from the largest value of all frames down to ``vmin_fraction`` of it (or the smallest
    positive value, if larger); smaller values take the lowest colour. ``artists`` then has
    the tip body's marker ``tip`` and the clamped handle ``handle`` (None where there is none)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt
    from matplotlib import animation as A
    from matplotlib.collections import LineCollection
    from matplotlib.colors import LogNorm

    frames = frames_of(ds, max_frames)
    X = np.asarray(ds["x"].values, dtype=float)[frames]
    H = -np.asarray(ds["y"].values, dtype=float)[frames]  # y points down: height = -y
    S = np.asarray(ds["speed"].values, dtype=float)[frames]
    T = np.asarray(ds["t_snapshot"].values, dtype=float)[frames]
    body, h = _body_of(ds)
    bending = body is not None and body.has_bending
    strain = "strain" in ds.variables and "elastic_energy" in ds.variables  # the extensible line
    if strain:  # the colour: each link's strain; slack links (strain <= 0) grey
        E = np.asarray(ds["strain"].values, dtype=float)[frames]
        seg_speed = np.where(E > 0.0, E, np.nan)
        n_slack = np.sum(E <= 0.0, axis=1)
    elif bending:  # the colour: the bending moment (its mean over each link's two nodes)
        mom = np.array([bending_moments(X[i], -H[i], body, h, T[i]) for i in range(len(frames))])
        seg_speed = 0.5 * (mom[:, 1:] + mom[:, :-1])
    else:
        seg_speed = 0.5 * (S[:, 1:] + S[:, :-1])
    finite = seg_speed[np.isfinite(seg_speed)]
    vmax = float(finite.max()) if finite.size and finite.max() > 0 else 1.0
    pos = finite[finite > 0]
    vmin = max(float(pos.min()) if pos.size else vmax * vmin_fraction, vmax * vmin_fraction)
    if vmin >= vmax:
        vmin = vmax / 10.0
    norm = LogNorm(vmin=vmin, vmax=vmax, clip=True)

    ok = np.isfinite(X) & np.isfinite(H)
    xlo, xhi, hlo, hhi = X[ok].min(), X[ok].max(), H[ok].min(), H[ok].max()
    pad = 0.05 * max(xhi - xlo, hhi - hlo, 1e-9)
    xr, hr = xhi - xlo + 2 * pad, hhi - hlo + 2 * pad
    height = 5.0  # inches of the axes; the width follows the chain's extent (equal aspect) plus the colour bar
    spatial = "z" in ds.variables and int(ds.attrs.get("dims", 2)) == 3
    width = min(max(4.8, height * xr / hr + 2.2), 12.0)
    if spatial:  # the start's plane, and the chain seen along gravity
        fig, (ax, az) = plt.subplots(1, 2, figsize=(width + 4.5, height + 1.0), dpi=100, layout="constrained",
                                     gridspec_kw={"width_ratios": [max(width - 2.2, 2.6), 4.0]})
    else:
        fig, ax = plt.subplots(figsize=(width, height + 1.0), dpi=100, layout="constrained")
    ax.set_xlim(xlo - pad, xhi + pad)
    ax.set_ylim(hlo - pad, hhi + pad)
    ax.set_aspect("equal")
    ax.set_xlabel(r"$x$  [$\ell$]")
    ax.set_ylabel(r"height  [$\ell$]")
    ax.grid(alpha=0.25)

    def segments(i):
        pts = np.column_stack([X[i], H[i]])
        return np.stack([pts[:-1], pts[1:]], axis=1)

    cmap = plt.get_cmap("viridis").with_extremes(bad="0.72")  # (bad: a slack link of the extensible line)

    def values(i):
        return np.ma.masked_invalid(np.maximum(seg_speed[i], vmin)) if strain else np.maximum(seg_speed[i], vmin)

    chain = LineCollection(segments(0), cmap=cmap, norm=norm, linewidths=2.0, capstyle="round")
    chain.set_array(values(0))
    ax.add_collection(chain)
    pin, = ax.plot([X[0, -1]], [H[0, -1]], "ks", ms=6, zorder=3)
    side = None
    if spatial:
        Z = np.asarray(ds["z"].values, dtype=float)[frames]

        def side_segments(i):
            pts = np.column_stack([X[i], Z[i]])
            return np.stack([pts[:-1], pts[1:]], axis=1)

        zmax = float(np.nanmax(np.abs(Z))) if np.any(np.isfinite(Z)) else 0.0
        zlim = 1.1 * zmax if zmax > 0.0 else 1.0
        side = LineCollection(side_segments(0), cmap="viridis", norm=norm, linewidths=2.0, capstyle="round")
        side.set_array(np.maximum(seg_speed[0], vmin))
        az.add_collection(side)
        az.set_xlim(xlo - pad, xhi + pad)
        az.set_ylim(-zlim, zlim)
        az.axhline(0.0, color="0.6", lw=0.8)
        az.set_xlabel(r"$x$  [$\ell$]")
        az.set_ylabel(r"$z$ (out of the start's plane)  [$\ell$]")
        az.set_title(f"seen along gravity (z scale: max |z| = {zmax:.3g})", fontsize=9)
        az.grid(alpha=0.25)
        ax.set_ylabel(r"height, in the start's plane  [$\ell$]")
    clamped = body is not None and body.clamp is not None and not isinstance(body.clamp, str)
    hl = 0.08 * max(xr, hr)  # the handle's drawn length

    def handle_xy(i):  # behind the held end, opposite to the direction the clamp holds the line
        a = clamp_angle(body, T[i])
        return [X[i, -1], X[i, -1] - hl * math.cos(a)], [H[i, -1], H[i, -1] + hl * math.sin(a)]

    handle = ax.plot(*handle_xy(0), color="saddlebrown", lw=6, solid_capstyle="round", zorder=2,
                     label="clamped handle")[0] if clamped else None
    tip_body = float(ds.attrs.get("tip_mass", 0.0) or 0.0) > 0 or (body is not None and body.tip_drag > 0)
    tip = ax.plot([X[0, 0]], [H[0, 0]], "o", color="tab:red", mec="k", ms=7, zorder=4,
                  label="tip body")[0] if tip_body else None
    if clamped or tip_body:
        ax.legend(loc="lower left", fontsize=8)
    cb = fig.colorbar(chain, ax=[ax, az] if spatial else ax, shrink=0.85, pad=0.02)
    cb.set_label("strain $l/h - 1$  (log scale; grey: slack)" if strain
                 else r"bending moment $|M|$  [$M g \ell$]  (log scale)" if bending
                 else r"speed $|v|$  [$\sqrt{g\ell}$]  (log scale)")
    t_snap = float(ds.attrs.get("t_snap_v", np.nan))
    text = ax.set_title("", fontsize=9, family="monospace", loc="left")
    from .figures import run_label

    import textwrap

    fig.suptitle("\n".join(textwrap.wrap(f"falling chain{' in 3D' if spatial else ''}, {run_label(ds)} "
                                         f"(nondimensional)", 70)), fontsize=10)

    def label(i):
        s = f"t = {T[i]:.6f}"
        if math.isfinite(t_snap):
            tau = t_snap - T[i]
            s += f"\nt_snap - t = {tau:+.2e}" if abs(tau) < 1e-2 else f"\nt_snap - t = {tau:+.4f}"
        return s + f"\nmax |v| = {np.nanmax(S[i]):.3g}" + (f", slack links {int(n_slack[i])}" if strain else "")

    text.set_text(label(0))
    fig.canvas.draw()  # lay out once (the longest label is the first frame's), then freeze the positions:
    fig.set_layout_engine("none")  # a layout engine would redo the layout for every frame

    def update(i):
        chain.set_segments(segments(i))
        chain.set_array(values(i))
        pin.set_data([X[i, -1]], [H[i, -1]])
        if handle is not None:
            handle.set_data(*handle_xy(i))
        if tip is not None:
            tip.set_data([X[i, 0]], [H[i, 0]])
        text.set_text(label(i))
        if side is not None:
            side.set_segments(side_segments(i))
            side.set_array(np.maximum(seg_speed[i], vmin))
        return chain, pin, text

    anim = A.FuncAnimation(fig, update, frames=len(frames), blit=False, repeat=False)
    return fig, anim, {"chain": chain, "norm": norm, "frames": frames, "text": text, "update": update,
                       "segment_speed": seg_speed, "colour": "strain" if strain else "bending moment" if bending else "speed",
                       "tip": tip, "handle": handle, "side": side}


def animate(ds, output, *, fps: float = 8.0, max_frames: int | None = None, overwrite: bool = False) -> str:
    """Write the animation of run ``ds`` to ``output`` (.gif, or .mp4 with ffmpeg), atomically;
    returns the path written.

    Parameters
    ----------
    ds : xarray.Dataset
        A run with profile snapshots (:func:`snapping.simulate.load_run`).
    output : path
        ``.gif`` (PillowWriter) or ``.mp4`` (FFMpegWriter, needs ffmpeg on PATH).
    fps : float
        Frames per second, > 0.
    max_frames : int, optional
        At most this many frames (snapshots thinned evenly).
    overwrite : bool
        Replace an existing file (default: refuse it).
    """
    from . import _files

    fps = V.positive("fps", fps)
    if not FPS_RANGE[0] <= fps <= FPS_RANGE[1]:
        raise V.SnappingInputError(f"fps={fps!r} is out of range: must lie in [{FPS_RANGE[0]:g}, {FPS_RANGE[1]:g}] "
                                   f"frames per second")
    _check_run(ds)
    frames_of(ds, max_frames)  # (max_frames checked before any work)
    p = check_output(output, overwrite=overwrite)
    _check_run(ds)
    import matplotlib.pyplot as plt

    fig, anim, _ = build(ds, max_frames=max_frames)
    writer = _writer(Path(p).suffix.lower(), fps)
    try:
        return _files.write_atomic(p, lambda tmp: anim.save(os.fspath(tmp), writer=writer), name="output",
                                   overwrite=overwrite)
    finally:
        plt.close(fig)
