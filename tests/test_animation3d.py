"""The animation of a 3D run file: the start's plane and, beside it, the chain seen along gravity."""

from __future__ import annotations

import numpy as np
import pytest

from snapping.animation import build
from snapping.cli import main
from snapping.spatial import Problem3D
from snapping.spatial.dataset3d import run3d_dataset


@pytest.fixture(scope="module")
def run3d_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("a3") / "r3.nc"
    ds = run3d_dataset(Problem3D.catenary(0.25, 12).perturbed(1e-3, k=2), tol=1e-9, snapshot_times=[0.5, 1.0],
                       output=str(path))
    return ds, path


def test_side_view_draws_x_against_z_of_every_frame(run3d_file):
    import matplotlib.pyplot as plt

    ds, _ = run3d_file
    fig, anim, art = build(ds)
    try:
        assert art["side"] is not None
        for i, k in enumerate(art["frames"]):
            art["update"](i)
            x, z, y = (ds[c].isel(snapshot=int(k)).values for c in ("x", "z", "y"))
            seg = art["side"].get_segments()
            np.testing.assert_array_equal(np.array([s[0] for s in seg]), np.column_stack([x[:-1], z[:-1]]))
            np.testing.assert_array_equal(seg[-1][1], [x[-1], z[-1]])
            main_seg = art["chain"].get_segments()  # the first panel: x against height -y
            np.testing.assert_array_equal(np.array([s[0] for s in main_seg]), np.column_stack([x[:-1], -y[:-1]]))
        assert float(np.abs(ds["z"].values).max()) > 0.0  # (a view of z that is not all zero)
        ylim = fig.axes[1].get_ylim()
        assert ylim[1] == pytest.approx(1.1 * float(np.abs(ds["z"].values[art["frames"]]).max()))
    finally:
        anim._draw_was_started = True  # (not rendered: no warning)
        plt.close(fig)


def test_planar_file_has_no_side_view():
    import matplotlib.pyplot as plt

    from snapping.simulate import Problem, run

    ds = run(Problem.catenary(0.25, 12), tol=1e-8).dataset
    fig, anim, art = build(ds)
    anim._draw_was_started = True
    assert art["side"] is None and len(fig.axes) == 2  # the chain's axes and its colour bar
    plt.close(fig)


def test_cli_animates_a_3d_file_and_reruns_it_for_frames(run3d_file, tmp_path, capsys):
    _, path = run3d_file
    out = tmp_path / "a.gif"
    assert main(["animate", str(path), "-o", str(out), "--max-frames", "3"]) == 0
    assert out.stat().st_size > 1000
    assert main(["animate", str(path), "-o", str(tmp_path / "b.gif"), "--max-frames", "2", "--frames", "4"]) == 0
    assert "rerunning" in capsys.readouterr().err
