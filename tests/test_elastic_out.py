"""Snap loads of a slack tether jerked taut (elastic_loads.jerk_peak_force, jerk_taut) against an
independent quadrature of the mass on its spring, and the elastic run's figures and animation
(snapping.figures_elastic, snapping.animation): strain image, energy balance, strain colours."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from scipy.integrate import solve_ivp

from snapping._validate import SnappingInputError
from snapping.simulate.elastic import Elastic, jerk_peak_force, jerk_taut, solve
from snapping.simulate.problem import Links, Problem


def _quadrature(m, V, k, slack, g):
    """The mass (y down) under gravity, the end at -V t, the tension k (gap - L)^+ (gap: the end to the
    mass minus the slack line's rest length): integrated, the largest tension found on a fine grid."""
    def f(t, s):
        y, vy = s
        stretch = (y + V * t) - slack  # (the gap grows from 0 - ... the line is taut once it exceeds slack)
        return [vy, g - k / m * max(stretch, 0.0)]

    t_end = 2.0 * (slack / V + 4.0 * math.sqrt(m / k))
    sol = solve_ivp(f, (0.0, t_end), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True,
                    max_step=math.sqrt(m / k) / 50)
    t = np.linspace(0.0, t_end, 400_001)
    y = sol.sol(t)[0]
    T = k * np.maximum(y + V * t - slack, 0.0)
    i = int(np.argmax(T))
    return T[i], t[i]


@pytest.mark.parametrize("slack, g", [(0.0, 0.0), (0.5, 0.0), (0.5, 9.81), (0.0, 9.81)])
def test_jerk_closed_form_is_the_quadrature(slack, g):
    m, V, k = 5.0, 2.0, 2e4 / 3.0
    T, t = _quadrature(m, V, k, slack, g)
    r = jerk_peak_force(m, V, k, slack=slack, g=g)
    assert r["peak_force"] == pytest.approx(T, rel=1e-7)
    assert r["t_peak"] == pytest.approx(t, abs=2e-5)
    if g == 0.0:
        assert r["peak_force"] == pytest.approx(V * math.sqrt(k * m), rel=1e-14)


@pytest.mark.parametrize("g", [0.0, 9.81])
def test_jerk_taut_one_link_is_the_mass_on_its_spring(g):
    """N = 1: one node (the mass and half the tether's) on one spring EA/L: the closed form's model."""
    r = jerk_taut(mass=5.0, speed=2.0, slack=0.5, ea=2e4, length=3.0, mass_per_length=1e-4, N=1, g=g, tol=1e-8)
    assert r["peak_force"] == pytest.approx(r["formula_force"], rel=1e-6)
    assert r["t_peak_run"] == pytest.approx(r["t_peak"], rel=2e-3)
    assert r["formula_force"] == pytest.approx(jerk_peak_force(5.0 + 1.5e-4, 2.0, 2e4 / 3.0, slack=0.5, g=g)
                                               ["peak_force"], rel=1e-14)


@pytest.mark.parametrize("kw, needle", [({"slack": 1.0, "N": 4}, "slack=1.0"), ({"speed": 0.0}, "speed=0.0"),
                                        ({"g": -1.0}, "g=-1.0"), ({"ea": float("inf")}, "ea=inf")])
def test_jerk_taut_bad_input(kw, needle):
    args = dict(mass=5.0, speed=2.0, slack=0.5, ea=2e4, length=3.0, mass_per_length=1e-3, N=1)
    with pytest.raises(SnappingInputError, match=needle):
        jerk_taut(**{**args, **kw})


@pytest.fixture(scope="module")
def elastic_run():
    p = Problem.catenary(0.25, links=Links.uniform(8, lumping="shared"))
    return solve(p, Elastic.from_wave_speed(10.0, grid_damping=1.0), t_end=0.25, tol=1e-6,
                 snapshot_times=np.linspace(0.01, 0.24, 24)).dataset


def test_strain_history_is_the_snapshots_strain(elastic_run):
    from snapping.figures_elastic import energy_terms, strain_history

    ds = elastic_run
    t, s, e = strain_history(ds)
    assert np.all(np.diff(t) > 0) and np.all(np.diff(s) > 0) and e.shape == (8, t.size)
    k = int(np.argmin(np.abs(ds.t_snapshot.values - t[5])))
    j = int(np.argmin(np.abs(ds.s_link.values - s[2])))
    assert e[2, 5] == ds.strain.values[k, j]
    # the unloading wave: the free end's link is slack (strain <= 0) soon after the release, the held end's taut
    assert e[0, -1] > 0 and e[-1, 3] <= 0
    en = energy_terms(ds)
    bal = ds.energy.values - ds.pin_work.values + ds.dissipated.values
    assert en["residual"].max() == pytest.approx(np.abs(bal - bal[0]).max() / abs(ds.energy.values[0]), rel=1e-12)
    assert np.array_equal(en["elastic"], ds.elastic_energy.values)


def test_overview_and_animation_of_an_elastic_run(elastic_run, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from snapping import animation, figures

    fig = figures.overview(elastic_run)
    titles = [a.get_title(loc="left") for a in fig.axes]
    assert any(t.startswith("(e) strain along the line") for t in titles)
    assert any(t.startswith("(h) energy balance") for t in titles)
    plt.close(fig)
    fig, anim, art = animation.build(elastic_run, max_frames=6)
    assert art["colour"] == "strain"
    i = len(art["frames"]) - 1
    art["update"](i)
    E = elastic_run.strain.values[art["frames"][i]]
    shown = art["chain"].get_array()
    assert np.array_equal(np.ma.getmaskarray(shown), E <= 0)  # slack links: the 'bad' (grey) colour
    assert np.allclose(shown.compressed(), np.maximum(E[E > 0], art["norm"].vmin))
    anim._draw_was_started = True  # (not rendered here: no warning)
    plt.close(fig)
