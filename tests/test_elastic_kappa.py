"""The extensible line's curvature record (branch stretchk, issue 24): ``kappa_max`` per step,
``kappa_peak`` and ``kappa_max_0``, the chain's discrete curvature (turning angle over the mean
of the two links' rest lengths). Expectations: closed forms of hand-built polylines, the
chain's own numpy profile (:func:`snapping.simulate.chain.curvature_profile`) on the run's
snapshots, and the inextensible chain (a different model and method) as EA -> infinity."""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping.simulate import Links, Problem, run
from snapping.simulate.chain import curvature_profile
from snapping.simulate.elastic import Elastic, solve
from snapping.simulate.elastic_kernels import curvature_max


def _z(x, y):
    """The elastic state vector of nodes 0..N-1 (node N, the held end, apart), at rest."""
    N = len(x) - 1
    z = np.zeros(4 * N + 2)
    z[0:4 * N:4], z[1:4 * N:4] = x[:N], y[:N]
    return z, np.array([x[N], y[N], 0.0, 0.0])


def test_arc_of_a_circle_rest_lengths_not_the_chords():
    # nodes on a circle of radius R, each chord turning by the central angle D: at node i
    # (1..N-1) kappa = 2 D/(h_{i-1} + h_i) with the rest lengths h, not the chords (stretched)
    R, N, D = 0.7, 9, 0.05
    ang = D * np.arange(N + 1)
    x, y = R * np.cos(ang), R * np.sin(ang)
    chord = 2 * R * math.sin(D / 2)
    h = chord / (1.0 + np.array([0.01, 0.02, 0.0, 0.03, 0.005, 0.04, 0.01, 0.002, 0.02]))
    h[4], h[5] = 0.45 * chord, 0.55 * chord  # links 4 and 5 much shorter at rest: node 5 has the largest
    z, pin = _z(x, y)
    k, i = curvature_max(N, z, pin, h)
    assert i == 5
    assert k == pytest.approx(2 * D / (h[4] + h[5]), rel=1e-12)
    # uniform rest lengths 1/N on an arc: N times the turning angle, at the first joint on a tie
    k, i = curvature_max(N, z, pin, np.full(N, 1.0 / N))
    assert k == pytest.approx(N * D, rel=1e-12) and 1 <= i <= N - 1


@pytest.mark.parametrize("turn", [2.9, 1.2, 0.4])
def test_a_fold_at_the_last_joint_through_the_held_end(turn):
    # a straight line with one kink of `turn` radians at node N-1 (its far link is the held end's)
    N, h = 6, np.full(6, 1.0 / 6)
    x = np.concatenate([np.arange(N) / N, [(N - 1) / N + math.cos(turn) / N]])
    y = np.concatenate([np.zeros(N), [math.sin(turn) / N]])
    z, pin = _z(x, y)
    k, i = curvature_max(N, z, pin, h)
    assert i == N - 1 and k == pytest.approx(turn * N, rel=1e-12)
    # a kink of `turn` at node 1 and a smaller one elsewhere: the fold (turn > pi/2: dot < 0) wins
    x2, y2 = x[::-1].copy(), y[::-1].copy()
    z2, pin2 = _z(x2, y2)
    k2, i2 = curvature_max(N, z2, pin2, h)
    assert i2 == 1 and k2 == pytest.approx(turn * N, rel=1e-12)


def test_one_link_has_no_joint():
    k, i = curvature_max(1, np.array([0.0, -1.0, 0.0, 0.0, 0.0, 0.0]), np.zeros(4), np.array([1.0]))
    assert (k, i) == (0.0, 0)


@pytest.mark.parametrize("method", ["rodas4-links", "rodas4", "radau"])
def test_run_records_the_chains_curvature(method):
    p = Problem.catenary(0.3, links=Links.graded(np.linspace(0.05, 0.2, 8) / np.linspace(0.05, 0.2, 8).sum(),
                                                 lumping="shared"), chords="exact")
    ds = solve(p, Elastic.from_wave_speed(30.0), tol=1e-7, method=method, start="matched", t_end=0.4).dataset
    h = ds.link_length.values
    k = ds.kappa_max.values
    assert ds.kappa_max.dims == ("step",) and np.all(np.isfinite(k)) and k.size == ds.sizes["step"]
    for kind, row in (("initial", 0), ("final", -1)):
        snap = ds.sel(snapshot=int(np.flatnonzero(ds.snapshot_kind.values == kind)[0]))
        prof = np.abs(curvature_profile(snap.x.values, snap.y.values, h))
        assert k[row] == pytest.approx(np.nanmax(prof), rel=1e-12)
        assert ds.s_kappa_max.values[row] == pytest.approx(ds.s_node.values[np.nanargmax(prof)], abs=1e-15)
    assert ds.attrs["kappa_max_0"] == k[0]
    assert ds.attrs["kappa_peak"] == np.max(k) and np.max(k) > k[0]


def test_stiff_line_reaches_the_chains_kappa_peak():
    # the same links, the same interval [0, t_end] (both land on t_end): the elastic line's largest
    # curvature tends to the inextensible chain's as 1/c^2 (measured chi 0.3, N 40, t_end 1.2:
    # +2.2e-3, +2.8e-4, +4.7e-5, +4.8e-6 at c 100, 300, 1000, 3000; N 12, t_end 1.15: -5.2e-5,
    # -5.2e-7, -3.3e-9 at c 300, 3000, 30000)
    p = Problem.catenary(0.3, links=Links.uniform(12, lumping="shared"), chords="exact")
    ref = run(p, method="fast", tol=1e-10, t_end=1.15, progress=False).dataset.attrs["kappa_peak"]
    err = []
    for c in (300.0, 3000.0):
        a = solve(p, Elastic.from_wave_speed(c), tol=1e-9, method="rodas4-links", start="matched",
                  t_end=1.15).dataset.attrs
        err.append(abs(a["kappa_peak"] / ref - 1.0))
    assert err[1] < 2e-6 and err[1] < err[0] / 30.0


def test_level_row_takes_the_runs_kappa_peak(tmp_path):
    from snapping.simulate.dataset import load_run
    from snapping.sweep_elastic import level_row

    h = np.full(4, 0.25)
    path = str(tmp_path / "level.nc")
    row = level_row(0.3, h, "shared", None, 1e-4, path, Elastic.from_wave_speed(10.0).describe(), start="matched")
    ds = load_run(path)
    assert np.isfinite(row["kappa_peak"]) and row["kappa_peak"] == float(np.max(ds.kappa_max.values))
    assert row["kappa_peak"] > ds.attrs["kappa_max_0"] > 0
