"""3D start curves (snapping.spatial.shape3d): nodes at exact chords on a curve in space, a
curve that crosses itself refused, and the CLI's 3D ``--shape`` CSV.

Independent references: a helix (nodes on it analytically: their distance from its axis and
their height against their angle), the planar placement of
:func:`snapping.simulate.shapes.place_on_curve` for a curve in the plane z = 0.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from snapping._validate import SnappingInputError
from snapping.cli import main
from snapping.simulate.dataset import load_run
from snapping.simulate.shapes import place_on_curve
from snapping.spatial.shape3d import check_no_crossing, place_on_curve3d
from snapping.simulate.links import Links
from snapping.spatial.starts3d import Problem3D


def _helix(n=2001, turns=1.2, radius=0.15, pitch=0.6):
    """Points of a helix about the vertical (y) from the origin: x = R (cos - 1), z = R sin."""
    phi = np.linspace(0.0, 2 * np.pi * turns, n)
    return np.column_stack([radius * (np.cos(phi) - 1.0), pitch * phi / (2 * np.pi), radius * np.sin(phi)])


def test_nodes_on_a_helix_at_exact_chords():
    h = np.random.default_rng(1).uniform(0.05, 0.12, 9)
    r = place_on_curve3d(_helix(), h)
    np.testing.assert_allclose(np.linalg.norm(np.diff(r, axis=0), axis=1), h, rtol=0, atol=2e-15)
    assert np.all(r[-1] == 0.0)
    # on the helix: at distance R from its axis, the height a linear function of the angle
    rho = np.hypot(r[:, 0] + 0.15, r[:, 2])
    phi = np.unwrap(np.arctan2(r[::-1, 2], r[::-1, 0] + 0.15))[::-1]  # (from the held end, angle 0)
    assert np.abs(rho - 0.15).max() < 1e-6  # (the splines through 2001 points)
    assert np.abs(r[:, 1] - 0.6 * phi / (2 * np.pi)).max() < 1e-6


def test_a_planar_curve_is_placed_as_the_planar_placement():
    s = np.linspace(0.0, 1.3, 400)
    xc, yc = 0.3 * np.sin(2 * s), s
    h = np.full(12, 1.0 / 12)
    x, y = place_on_curve((xc, yc), h)
    r = place_on_curve3d(np.column_stack([xc, yc, np.zeros_like(s)]), h)
    np.testing.assert_allclose(r[:, 0], x, rtol=0, atol=1e-13)
    np.testing.assert_allclose(r[:, 1], y, rtol=0, atol=1e-13)
    assert np.all(r[:, 2] == 0.0)


def _figure8(lift=0.0):
    t = np.linspace(0.5, 2 * np.pi + 0.5, 400)  # (a figure 8, crossing itself at the origin's image)
    p = np.column_stack([np.sin(t), np.sin(2 * t) / 2, lift * (t - 0.5)])
    return p - p[0]


def test_a_curve_crossing_itself_is_refused_and_a_near_miss_is_not():
    h = np.full(58, 0.1)
    with pytest.raises(SnappingInputError, match="crosses itself"):
        check_no_crossing(place_on_curve3d(_figure8(), h))
    check_no_crossing(place_on_curve3d(_figure8(0.05), h))  # (the same curve lifted out of its plane)
    with pytest.raises(SnappingInputError, match="folds back"):
        check_no_crossing(np.array([[0.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]))
    r = np.array([[0.5, -0.5, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])  # link 0 crosses link 2
    with pytest.raises(SnappingInputError, match="links 0 and 2"):
        Problem3D.nodes(r, links=Links.explicit(np.linalg.norm(np.diff(r, axis=0), axis=1), [1.0, 1.0, 1.0]))


def test_a_curve_shorter_than_the_chain_is_refused():
    with pytest.raises(SnappingInputError, match="too short"):
        place_on_curve3d(_helix(turns=0.2), np.full(10, 0.1))


# ---------------------------------------------------------------- the CLI
def _csv(path, pts, header="x,y,z"):
    np.savetxt(path, pts, delimiter=",", header=header, comments="")
    return str(path)


def test_cli_runs_a_3d_shape_csv(tmp_path, capsys):
    f = _csv(tmp_path / "helix.csv", _helix(401) + np.array([2.0, 1.0, -3.0]))  # (translated: the held end first)
    out = tmp_path / "r.nc"
    assert main(["simulate", "--shape", f, "--dims", "3", "--N", "8", "--t-end", "0.05", "--json",
                 "-o", str(out)]) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "completed"
    ds = load_run(out)
    r = np.column_stack([ds[f"start_{c}"].values for c in "xyz"])
    np.testing.assert_allclose(r, place_on_curve3d(_helix(401), np.full(8, 1 / 8)), rtol=0, atol=1e-12)
    assert np.abs(r[:, 2]).max() > 0.1


@pytest.mark.parametrize("pts, word", [
    (np.zeros((5, 4)), "3 comma-separated columns x, y, z"),
    (0.17 * _figure8(), "crosses itself"),
    (_helix(turns=0.2), "too short"),
])
def test_cli_bad_3d_shape_is_one_line_exit_2(tmp_path, capsys, pts, word):
    f = _csv(tmp_path / "bad.csv", pts, header="")
    assert main(["simulate", "--shape", f, "--dims", "3", "--N", "20", "--t-end", "0.01"]) == 2
    err = capsys.readouterr().err.strip()
    assert word in err and len(err.splitlines()) == 1


def test_segment_distance_against_dense_sampling():
    """The closest distance of two segments (clamped cases included) against the minimum
    over a dense grid of points on both, refined by the grid's spacing."""
    from snapping.spatial.shape3d import _segment_distance

    rng = np.random.default_rng(7)
    u = np.linspace(0.0, 1.0, 401)
    for _ in range(24):
        p0, p1, q0, q1 = rng.standard_normal((4, 3))
        if _ % 4 == 0:
            q1 = q0 + 0.3 * (p1 - p0)  # (parallel segments: the degenerate branch)
        P = p0 + u[:, None] * (p1 - p0)
        Q = q0 + u[:, None] * (q1 - q0)
        dense = np.sqrt(((P[:, None, :] - Q[None, :, :]) ** 2).sum(-1)).min()
        d = _segment_distance(p0, p1, q0, q1)
        assert d <= dense + 1e-12
        assert dense - d <= 0.5 * (np.linalg.norm(p1 - p0) + np.linalg.norm(q1 - q0)) / 400 + 1e-12
