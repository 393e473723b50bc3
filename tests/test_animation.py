"""`snapping animate`: an animation of the snap from a run file's snapshots."""

import numpy as np
import pytest
import xarray as xr

from snapping import animation, simulate
from snapping.cli import main


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    d = tmp_path_factory.mktemp("anim")
    ds = simulate.run(0.25, 20, tol=1e-6, progress=False).dataset
    p = d / "run.nc"
    simulate.save(ds, p)
    return d, p, simulate.load_run(p)


def test_dense_snapshot_times_are_geometric_in_the_time_to_the_snap():
    ts = np.array(animation.dense_snapshot_times(1.5, n=9, tau_min=1e-4))
    tau = 1.5 - ts
    assert ts[0] == 0.0 and tau[-1] == pytest.approx(1.5e-4, rel=1e-12)
    np.testing.assert_allclose(tau[1:] / tau[:-1], (1e-4) ** (1 / 8), rtol=1e-12)  # one factor per frame
    with pytest.raises(ValueError, match="tau_min"):
        animation.dense_snapshot_times(1.5, tau_min=1.0)


def test_gif_has_one_frame_per_snapshot_and_the_chain_coloured_by_speed(tiny, capsys):
    from PIL import Image

    d, p, ds = tiny
    out = d / "snap.gif"
    assert main(["animate", str(p), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    n_snap = np.unique(ds["t_snapshot"].values).size
    with Image.open(out) as im:
        assert im.format == "GIF" and im.n_frames == n_snap
    # few automatic snapshots: the note says how to get more (--frames) in one short line
    assert "add --frames 60" in err and len(err.strip().splitlines()) == 1 and len(err) < 300
    hint = animation.denser_run_hint(ds, str(p))  # (from Python: the runnable command with denser snapshots)
    assert "--snapshot-times" in hint and "--chi 0.25 --N 20" in hint
    times = [float(v) for v in hint.split("--snapshot-times ")[1].split()[0].split(",")]
    assert len(times) >= animation.DENSE_FRAMES and np.all(np.diff(times) > 0) and times[-1] < ds.attrs["t_snap_v"]

    # the colours are the links' speeds (mean of the two nodes' |v|) on a log scale
    fig, anim, art = animation.build(ds)
    from matplotlib.colors import LogNorm

    assert isinstance(art["norm"], LogNorm)
    kinds = [str(k) for k in ds["snapshot_kind"].values]
    k = list(art["frames"]).index(kinds.index("peak"))
    art["update"](k)
    sn = ds.isel(snapshot=kinds.index("peak"))
    speed = np.hypot(sn["vx"].values, sn["vy"].values)
    expected = np.maximum(0.5 * (speed[1:] + speed[:-1]), art["norm"].vmin)
    np.testing.assert_allclose(art["chain"].get_array(), expected, rtol=1e-12)
    rgba = art["chain"].to_rgba(art["chain"].get_array())
    assert np.ptp(rgba[:, :3], axis=0).max() > 0.5  # the colours vary along the chain
    # ... and in the GIF: inside the chain's axes the drawn colours span the colour map
    import matplotlib.pyplot as plt

    fig.canvas.draw()
    ax = fig.axes[0]
    x0, y0, x1, y1 = ax.get_window_extent().extents
    H = fig.canvas.get_width_height()[1]
    plt.close(fig)
    with Image.open(out) as im:
        im.seek(k)
        px = np.asarray(im.convert("RGB"), dtype=float)[int(H - y1) + 2:int(H - y0) - 2, int(x0) + 2:int(x1) - 2]
    px = px.reshape(-1, 3) / 255.0
    colourful = px[np.ptp(px, axis=1) > 0.25]  # not white, black or grey
    lut = plt.get_cmap("viridis")(np.linspace(0, 1, 256))[:, :3]
    pos = np.argmin(((colourful[:, None, :] - lut[None, :, :]) ** 2).sum(-1), axis=1) / 255.0
    assert colourful.shape[0] > 20 and np.ptp(pos) > 0.5


def test_max_frames_and_overwrite(tiny, capsys):
    from PIL import Image

    d, p, _ = tiny
    out = d / "few.gif"
    assert main(["animate", str(p), "-o", str(out), "--max-frames", "3"]) == 0
    with Image.open(out) as im:
        assert im.n_frames == 3
    capsys.readouterr()
    assert main(["animate", str(p), "-o", str(out), "--max-frames", "4"]) == 2  # exists: refused
    assert "already exists" in capsys.readouterr().err
    assert main(["animate", str(p), "-o", str(out), "--max-frames", "4", "--overwrite"]) == 0
    with Image.open(out) as im:
        assert im.n_frames == 4


def test_a_denser_run_as_suggested_gives_a_dense_animation(tiny):
    _, _, ds = tiny
    times = animation.dense_snapshot_times(float(ds.attrs["t_snap_v"]), 30)[1:]
    dense = simulate.run(0.25, 20, tol=1e-6, progress=False, snapshot_times=times).dataset
    assert animation.snapshots_before_snap(dense) >= 29
    assert animation.denser_run_hint(dense, "dense.nc") is None


def _one_error_line(capsys, *needles):
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    for n in needles:
        assert n in err, err


def test_bad_inputs_say_so_in_one_line_and_exit_2(tiny, tmp_path, capsys, monkeypatch):
    _, p, ds = tiny
    notes = tmp_path / "notes.nc"
    notes.write_text("not a netCDF file\n")
    assert main(["animate", str(notes), "-o", str(tmp_path / "a.gif")]) == 2
    _one_error_line(capsys, "not a readable netCDF run file")
    assert main(["animate", str(tmp_path / "missing.nc"), "-o", str(tmp_path / "a.gif")]) == 2
    _one_error_line(capsys, "does not exist")
    bare = tmp_path / "bare.nc"
    ds.drop_dims(["snapshot"]).to_netcdf(bare)
    assert main(["animate", str(bare), "-o", str(tmp_path / "a.gif")]) == 2
    _one_error_line(capsys, "no profile snapshots")
    assert main(["animate", str(p), "-o", str(tmp_path / "a.avi")]) == 2
    _one_error_line(capsys, ".gif or .mp4")
    assert main(["animate", str(p), "-o", str(tmp_path / "nowhere" / "a.gif")]) == 2
    _one_error_line(capsys, "does not exist")
    monkeypatch.setattr(animation.shutil, "which", lambda name: None)
    assert main(["animate", str(p), "-o", str(tmp_path / "a.mp4")]) == 2
    _one_error_line(capsys, "ffmpeg", "a.gif")
    assert not any(tmp_path.glob("a.*"))
