"""Figures and animation of a run with a body (bending, drag, a clamped moving handle, a tip
body): the energy panels of ``snapping plot`` show the recorded terms and their balance, and the
animation colours the line by its bending moment and marks the handle and the tip body; each
checked against values computed here from the run's records and the catalogue's line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping import animation, figures, lines
from snapping.cli import main
from snapping.simulate import PinMotion, Problem, load_run, run, save

N = 20
PERIOD, TURN = 0.3, 1.0


@pytest.fixture(scope="module")
def whip(tmp_path_factory):
    """A bullwhip of 20 links: the handle jerked back and turned (a clamp following samples)."""
    wh = lines.get("bullwhip")
    links = wh.links(N)
    start = Problem.catenary(0.25, links=links)
    a0 = math.atan2(start.y[-2] - start.y[-1], start.x[-2] - start.x[-1])
    t = np.linspace(0.0, PERIOD, 5)
    clamp = (t, a0 + TURN * 0.5 * (1 - np.cos(math.pi * t / PERIOD)))
    p = Problem.catenary(0.25, links=links, pin=PinMotion.flick((-4.0, 0.0), PERIOD), body=wh.body(clamp=clamp))
    path = tmp_path_factory.mktemp("whip") / "whip.nc"
    run(p, output=str(path), snapshot_times=list(np.linspace(0.05, 0.6, 12)), progress=False)
    return path, load_run(path), clamp


def _residual(ds):
    e, w, d = (np.asarray(ds[k].values, dtype=float) for k in ("energy", "pin_work", "dissipated"))
    b = e - w + d
    return np.abs(b - b[0]) / abs(e[0])


def test_plot_of_a_body_run_has_the_energy_panels_and_its_residual_is_the_balance(whip, tmp_path, capsys):
    path, ds, _ = whip
    fig = figures.overview(ds)
    assert len(fig.axes) == 6
    ax_e, ax_f = fig.axes[2], fig.axes[5]
    assert ax_e.get_title(loc="left").startswith("(e) energy terms")
    t = np.asarray(ds["t"].values, dtype=float)
    (line,) = [ln for ln in ax_f.get_lines() if ln.get_label().startswith("max")]
    x, y = line.get_xdata(), line.get_ydata()
    idx = np.searchsorted(t, x)
    np.testing.assert_array_equal(t[idx], x)
    np.testing.assert_allclose(y, _residual(ds)[idx], rtol=1e-14, atol=0)
    assert 0 < y.max() < 1e-6  # the balance closes to the method's accuracy (tol 1e-6)
    # the terms: kinetic + gravity is energy - bending, and the conserved sum is flat
    terms = {ln.get_label(): ln for ln in ax_e.get_lines()}
    bal = terms["E - W + D (conserved)"].get_ydata()
    assert np.ptp(bal) < 1e-6 * abs(bal[0])
    bend = terms["bending"]
    k = np.searchsorted(t, bend.get_xdata())
    np.testing.assert_array_equal(bend.get_ydata(), np.asarray(ds["bending_energy"].values)[k])
    assert np.all(bend.get_ydata() > 0) and terms["pin work W"].get_ydata().std() > 0
    import matplotlib.pyplot as plt

    plt.close(fig)
    # wrong data shows: without the dissipated energy the plotted residual is the dissipation's size
    bad = ds.copy()
    bad["dissipated"] = bad["dissipated"] * 0.0
    fig = figures.overview(bad)
    (line,) = [ln for ln in fig.axes[5].get_lines() if ln.get_label().startswith("max")]
    r = line.get_ydata()
    d_end = float(ds["dissipated"][-1]) / float(ds["energy"][0])
    assert r.max() == pytest.approx(_residual(bad).max(), rel=1e-14) and r.max() > 0.5 * d_end > 1e-4
    plt.close(fig)
    # snapping plot: the figure and the balance in one line
    assert main(["plot", str(path), "-o", str(tmp_path / "w.png")]) == 0
    out = capsys.readouterr().out
    assert f"= {_residual(ds).max():.3g} (panel f)" in out
    assert "bullwhip" in out and "bending + drag + tip drag + clamped" in out


def _moments_by_hand(x, y, t, clamp):
    """|M| at the nodes from the catalogue's EI(s) = EI0 r^4 (r = 0.2 + 0.8 (distance from the tip)/L)."""
    wh = lines.get("bullwhip")
    L, M = wh.length, wh.mass()
    dist = np.arange(N + 1) / N  # from the tip, in L
    B = wh.ei * (0.2 + 0.8 * dist) ** 4 / (M / L * 9.81 * L ** 3)
    ex, ey = np.diff(x), np.diff(y)
    ang = np.zeros(N + 1)
    ang[1:N] = np.arctan2(ex[:-1] * ey[1:] - ey[:-1] * ex[1:], ex[:-1] * ex[1:] + ey[:-1] * ey[1:])
    # the held end: its link leaves along (x[N-1] - x[N], y[N-1] - y[N]); the clamp after the stroke: its last angle
    assert t > clamp[0][-1]
    c = np.array([math.cos(clamp[1][-1]), math.sin(clamp[1][-1])])
    lx, ly = x[N - 1] - x[N], y[N - 1] - y[N]
    ang[N] = math.atan2(c[0] * ly - c[1] * lx, c[0] * lx + c[1] * ly)
    l = np.full(N + 1, 1.0 / N)
    l[0] = l[N] = 0.5 / N
    mom = B * np.abs(ang) / l
    mom[0] = 0.0
    return mom


def test_animation_colours_the_whip_by_its_bending_moment_and_marks_handle_and_tip(whip, tmp_path):
    path, ds, clamp = whip
    fig, anim, art = animation.build(ds)
    assert art["colour"] == "bending moment" and "bending moment" in fig.axes[1].get_ylabel()
    ts = np.asarray(ds["t_snapshot"].values, dtype=float)
    frames = list(art["frames"])
    i = int(np.flatnonzero(ts > PERIOD + 0.05)[0])  # a frame after the stroke
    k = frames.index(i)
    art["update"](k)
    sn = ds.isel(snapshot=i)
    x, y = sn["x"].values, sn["y"].values
    mom = _moments_by_hand(x, y, ts[i], clamp)
    expected = np.maximum(0.5 * (mom[1:] + mom[:-1]), art["norm"].vmin)
    np.testing.assert_allclose(art["chain"].get_array(), expected, rtol=1e-9)
    # the handle: from the held end, backwards along the clamp's last angle; the tip body at the free end
    hx, hy = art["handle"].get_data()
    assert (hx[0], hy[0]) == (x[-1], -y[-1])
    a = math.atan2(-(hy[1] - hy[0]), hx[1] - hx[0]) + math.pi  # (height = -y)
    assert math.remainder(a - clamp[1][-1], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    assert tuple(np.ravel(art["tip"].get_data())) == (x[0], -y[0])
    # at t = 0 the handle holds the start's direction (the first sample)
    art["update"](0)
    hx, hy = art["handle"].get_data()
    a = math.atan2(-(hy[1] - hy[0]), hx[1] - hx[0]) + math.pi
    assert math.remainder(a - clamp[1][0], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    import matplotlib.pyplot as plt

    plt.close(fig)
    out = tmp_path / "whip.gif"
    assert main(["animate", str(path), "-o", str(out)]) == 0 and out.stat().st_size > 0


def test_a_run_without_bending_keeps_the_speed_colours(tmp_path):
    p = lines.get("nylon-monofilament").problem(0.3, 10, length=2.0, ei=0.0)  # drag only
    ds = run(p, progress=False).dataset
    fig, anim, art = animation.build(ds)
    assert art["colour"] == "speed" and art["handle"] is None and art["tip"] is None
    art["update"](0)
    import matplotlib.pyplot as plt

    plt.close(fig)
