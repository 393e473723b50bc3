"""The paper's run figures (Fig. 1, Fig. 2) are drawn from run Datasets with the right content."""

import numpy as np
import pytest

from snapping import figures, simulate
from snapping.estimates import PAPER_CHAIN


@pytest.fixture(scope="module")
def run025():
    # the paper's figures are drawn from the paper's runs (snapping reproduce): its method and chain
    return simulate.run(0.25, 40, tol=1e-7, method="euler-richardson", chords="arclength").dataset


def test_shapes_draw_the_snapshots_in_metres(run025, tmp_path):
    fig = figures.shapes([run025], units="si")
    ax = fig.axes[0]
    first = ax.lines[0]
    # the first curve is the initial catenary: from the pin to the free end at chi * length
    x, y = first.get_xdata(), first.get_ydata()
    assert x[0] == pytest.approx(0.25 * PAPER_CHAIN.length)  # node 1, the free end
    assert y[0] == pytest.approx(0.0, abs=1e-12) and x[-1] == 0.0
    assert ax.get_xlabel() == "$x$  [m]" and "[s]" in ax.child_axes[0].get_ylabel()  # the colour bar: time in s
    paths = figures.save(fig, tmp_path / "shapes")
    assert [p.suffix for p in paths] == [".png", ".pdf"] and all(p.stat().st_size > 1000 for p in paths)


def test_shapes_are_nondimensional_by_default(run025):
    fig = figures.shapes([run025])
    ax = fig.axes[0]
    x = ax.lines[0].get_xdata()
    assert x[0] == pytest.approx(0.25)  # the free end at chi lengths from the pin
    assert "ell" in ax.get_xlabel() and "ell" in ax.get_ylabel() and "[m]" not in ax.get_xlabel()
    with pytest.raises(ValueError, match="units='cgs'"):
        figures.shapes([run025], units="cgs")


def test_pin_force_is_the_tension_of_the_last_link_in_newtons(run025):
    init = run025.isel(snapshot=0)
    N = int(run025.attrs["N"])
    assert float(init["t_snapshot"]) == 0.0
    # momentum balance of the whole chain at release: weight - pin force = sum of m a (m = 1/N)
    expected_y = 1.0 - float(init["ay"].sum()) / N
    expected_x = -float(init["ax"].sum()) / N
    fig = figures.pin_force(run025, units="si")
    fy = fig.axes[1].lines[0].get_ydata()
    assert fy[0] == pytest.approx(PAPER_CHAIN.force(expected_y), rel=1e-9)
    assert run025["pin_force_x"].values[0] == pytest.approx(expected_x, rel=1e-9, abs=1e-12)
    assert np.nanmax(fy) == pytest.approx(PAPER_CHAIN.force(np.nanmax(run025["pin_force_y"].values)))
    assert fig.axes[1].get_xlabel() == "time $t$  [s]" and "[N]" in fig.axes[1].get_ylabel()
    # nondimensional by default: the weight of the chain is 1 (rho g l)
    fig = figures.pin_force(run025)
    assert fig.axes[1].lines[0].get_ydata()[0] == pytest.approx(expected_y, rel=1e-9)
    assert r"\rho g \ell" in fig.axes[1].get_ylabel() and r"\sqrt{\ell/g}" in fig.axes[1].get_xlabel()


def _legends(fig):
    return [a.get_legend() for a in fig.axes if a.get_legend() is not None]


def test_no_figure_asks_for_the_slow_best_legend_placement(run025):
    """matplotlib's loc='best' (also the default) is slow on large data: every legend has a fixed place."""
    import matplotlib as mpl

    with mpl.rc_context({"legend.loc": "best"}):
        figs = [figures.shapes([run025]), figures.pin_force(run025), figures.profiles(run025),
                figures.peak_speed_vs_N({0.25: [(100, 5.0), (400, 7.0)]})]
    for fig in figs:
        for leg in _legends(fig):
            assert leg._loc != 0, fig  # 0 is 'best'


def test_profiles_end_at_the_snap(run025):
    fig = figures.profiles(run025)
    speed_lines = fig.axes[0].lines
    # the last profile drawn is the one at the snap: its largest speed is the run's peak
    kinds = [str(k) for k in run025["snapshot_kind"].values]
    peak = run025.isel(snapshot=kinds.index("peak"))
    np.testing.assert_array_equal(speed_lines[-1].get_ydata(), peak["speed"].values)
    # the sampled peak state is within a step of the interpolated peak speed
    assert np.max(speed_lines[-1].get_ydata()) == pytest.approx(run025.attrs["v_peak"], rel=1e-3)


def test_peak_speed_vs_N_draws_the_half_power_line():
    fig = figures.peak_speed_vs_N({0.25: [(100, 5.0), (400, 7.0)]})
    ax = fig.axes[0]
    ref = ax.lines[1]
    assert ref.get_ydata()[-1] == pytest.approx(5.0 * 2.0)  # N^(1/2): 4x the links -> 2x the speed
