"""The curvature peak of a general chain (issue 24, branch kappa): ``kappa_max_interior`` (the turning
angle over the mean link at the joints at least ``KAPPA_TIP_JOINTS`` links from the free end) and the
run's ``kappa_peak_approach`` (its peak while v_max rises to the snap).

* the estimator against closed forms, through the compiled measurement itself
  (:func:`snapping.simulate.general.general_measure` at a given shape): nodes on a circle of radius R
  with equal chords h give exactly 2 asin(h/2R)/h, a relative error h^2/(24 R^2) (order 2); on a
  clothoid (kappa = s) with links graded by a fixed ratio r the error at a joint is kappa' (h+ - h-)/3
  + O(h^2) (order 1: derived in docs/guide/regimes.md), checked at two resolutions;
* the joints fewer than KAPPA_TIP_JOINTS links from the free end are left out (a planted kink at the
  7th joint is ignored by kappa_max_interior and seen by kappa_max; at the 8th it is seen);
* a real run (the ideal chain, chi 0.3, fold level 1): kappa_peak_approach lies before the speed
  peak, below the run's kappa_peak (whose joint is the free end's first), and equals the largest
  interior curvature recomputed by :func:`snapping.simulate.chain.curvature_profile` (independent
  Python) on snapshots at dense times around it (the snapshots change no peak); the record's
  kappa_max_interior never above kappa_max;
* the study's worker keeps it for the chain mechanisms, not for stretching; the shipped drag study holds it
  for every run, never above the run's kappa_peak.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping import regimes as R
from snapping.continuum import level_parameters
from snapping.simulate import Links, run
from snapping.simulate import general as G
from snapping.simulate import kernels as K
from snapping.simulate.chain import curvature_profile


def _measure(h, theta):
    """The compiled measurement of a general chain at rest with link angles ``theta`` (free end first)."""
    h = np.asarray(h, float)
    N = h.size
    links = Links.graded(h)
    par, hh, invm, invh, snode, tab = G.make_model(h, 1.0 / links.m)
    y = np.zeros(2 * N + 1)
    y[:N] = theta
    c, s, sig = np.cos(theta), np.sin(theta), np.zeros(N)
    Z = np.zeros((K.NROWS, N + 1))
    meas = np.zeros(G.NMEAS_G)
    G.general_measure(N, 0.0, y, c, s, sig, Z, np.zeros(N), meas, par, hh, invm, invh, snode, tab)
    return meas


def test_circle_equal_chords_closed_form_order_two():
    R0 = 0.3
    errs = []
    for n in (40, 80, 160):
        h = np.full(n, 0.5 * math.pi * R0 / n / 1.0)  # a quarter circle's arc cut in n chords of equal length
        alpha = 2.0 * math.asin(h[0] / (2.0 * R0))  # each chord turns by the central angle it subtends
        theta = 0.2 + alpha * np.arange(n)
        meas = _measure(h, theta)
        want = 2.0 * math.asin(h[0] / (2.0 * R0)) / h[0]  # closed form
        assert meas[G.M_KIN] == pytest.approx(want, rel=1e-12)
        assert meas[K.M_KMAX] == pytest.approx(want, rel=1e-12)
        err = meas[G.M_KIN] * R0 - 1.0
        assert err == pytest.approx(h[0] ** 2 / (24.0 * R0**2), rel=1e-2)  # leading term of the expansion
        errs.append(err)
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.01)


def _clothoid_angles(h):
    """Chord angles of nodes on the clothoid theta(s) = s^2/2 (kappa = s) at arclengths cumsum(h)
    (exact chord directions by quadrature)."""
    from scipy.integrate import quad

    s = np.concatenate([[0.0], np.cumsum(h)])
    out = []
    for a, b in zip(s[:-1], s[1:]):
        cx = quad(lambda u: math.cos(0.5 * u * u), a, b, epsabs=1e-15, epsrel=1e-14)[0]
        cy = quad(lambda u: math.sin(0.5 * u * u), a, b, epsabs=1e-15, epsrel=1e-14)[0]
        out.append(math.atan2(cy, cx))
    return s, np.unwrap(np.array(out))


@pytest.mark.parametrize("ratio", [1.05, 0.95])
def test_clothoid_graded_links_error_is_first_order_with_the_derived_coefficient(ratio):
    # on links graded by a fixed ratio the error at a joint is kappa' (h+ - h-)/3 + O(h^2): order 1.
    # Derivation: a chord of length h turns by theta(mid) + theta'' h^2/24; the midpoints' angles differ by
    # kappa (h+ + h-)/2 + kappa' (h+^2 - h-^2)/8, the chords' corrections by kappa' (h+^2 - h-^2)/24; over
    # the mean link (h+ + h-)/2: kappa + kappa' (h+ - h-)/3
    res = []
    for h0 in (2e-3, 1e-3):
        n = 40
        h = h0 * ratio ** np.arange(n)
        s, theta = _clothoid_angles(h)
        j = 20  # the joint between chords j - 1 and j, at arclength s[j]
        est = (theta[j] - theta[j - 1]) / (0.5 * (h[j - 1] + h[j]))
        hh = np.asarray(h)
        # the measurement agrees at the joints it sees (all here: the free end is far)
        full = np.abs(curvature_profile(np.cumsum(np.r_[0, np.cos(theta)] * np.r_[0, hh]),
                                        np.cumsum(np.r_[0, np.sin(theta)] * np.r_[0, hh]), hh))
        assert full[j] == pytest.approx(est, rel=1e-10)
        kappa = s[j]  # the clothoid's curvature at the joint
        lead = (h[j] - h[j - 1]) / 3.0  # kappa' = 1: the derived first-order term
        res.append((est - kappa, lead, h0))
    for err, lead, h0 in res:
        assert err == pytest.approx(lead, rel=0.05, abs=0.05 * h0**2 * 40)
    assert res[0][0] / res[1][0] == pytest.approx(2.0, rel=0.05)  # halving the links halves the error


def test_joints_next_to_the_free_end_are_left_out():
    n, h = 60, np.full(60, 1.0 / 60)
    base = 0.3 + 0.5 * h[0] * np.arange(n)  # a circle of curvature 0.5
    for joint, seen in ((G.KAPPA_TIP_JOINTS - 1, False), (G.KAPPA_TIP_JOINTS, True), (1, False)):
        theta = base.copy()
        theta[joint:] += 0.4  # a kink of 0.4 rad at node ``joint`` (between links joint - 1 and joint)
        meas = _measure(h, theta)
        kink = (0.4 + 0.5 * h[0]) / h[0]
        assert meas[K.M_KMAX] == pytest.approx(kink, rel=1e-12)
        assert meas[K.M_SK] == pytest.approx(1.0 - joint * h[0], rel=1e-12)
        assert meas[G.M_KIN] == pytest.approx(kink if seen else 0.5, rel=1e-12)


@pytest.fixture(scope="module")
def ideal_run():
    # fold level 1 (1,004 links): the whirl's peak after the speed peak is the larger (at the tip joint 133.6
    # against 123.9; inside, ~103 against 96): the approach's window decides
    level = level_parameters(1, 0.5, first=1)[0]
    p = R.cell_problem(0.3, None, 0.0, level)
    return p, run(problem=p, method="fast", tol=1e-7, progress=False).dataset


def test_real_run_approach_peak_before_the_speed_peak_and_below_the_tip_joint(ideal_run):
    p, ds = ideal_run
    a = ds.attrs
    k, t = a["kappa_peak_approach"], a["t_kappa_peak_approach"]
    assert np.isfinite(k) and t <= a["t_snap_v"]
    assert t > 0.9 * a["t_snap_v"]  # the approach's peak, at the tip just before the snap
    assert k < 0.9 * a["kappa_peak"]  # the run's peak: the free end's first joint (a node-index layer)
    assert np.nanmax(ds.kappa_max_interior.values) > 1.03 * k  # the whole run's interior maximum: after the snap
    i = int(np.argmax(ds.kappa_max.values))
    assert ds.s_kappa_max.values[i] == pytest.approx(1.0 - p.links.h[0], rel=1e-12)
    # the record: the interior maximum never above the full one; the sampled approach peak <= the refined
    kin, kmax, v = ds.kappa_max_interior.values, ds.kappa_max.values, ds.v_max.values
    assert np.all(kin <= kmax + 1e-12)
    gate = v >= np.maximum.accumulate(v)
    assert np.max(kin[gate]) <= k * (1 + 1e-12)
    assert np.max(kin[gate]) > 0.98 * k


def test_real_run_approach_peak_against_snapshots_by_curvature_profile(ideal_run):
    p, ds = ideal_run
    a = ds.attrs
    tk = a["t_kappa_peak_approach"]
    ts = tk + np.linspace(-2e-4, 2e-4, 41)
    ds2 = run(problem=p, method="fast", tol=1e-7, progress=False, snapshot_times=list(ts)).dataset
    for q in ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "kappa_peak_approach"):  # snapshots change no peak
        assert ds2.attrs[q] == a[q]
    h = ds2.link_length.values
    best = []
    for i in np.flatnonzero(ds2.snapshot_kind.values == "requested"):
        kap = np.abs(curvature_profile(ds2.x.values[i], ds2.y.values[i], h))
        best.append(np.nanmax(kap[G.KAPPA_TIP_JOINTS:]))  # node index = links from the free end
    best = np.array(best)
    assert best.max() <= a["kappa_peak_approach"] * (1 + 1e-7)
    assert best.max() == pytest.approx(a["kappa_peak_approach"], rel=2e-4)  # 1e-5 time grid around a smooth max


def test_worker_keeps_the_approach_peak_for_chain_mechanisms():
    level = level_parameters(1, 0.5, first=-2)[0]
    row = R._run_task(0.5, "end-mass", 1e-3, level, 1e-7)
    assert np.isfinite(row["kappa_peak_approach"]) and row["kappa_peak_approach"] <= row["kappa_peak"]  # (an end mass: its peak inside, the same)
    assert R._extra("end-mass") == ("kappa_peak_approach",) and R._extra("drag") == ("kappa_peak_approach",)
    assert R._extra("stretching") == ("sigma_peak_taut", "kappa_peak_approach")  # (branch stretchapp)


def test_shipped_drag_study_holds_the_approach_peak_of_every_run():
    ds = R.bundled_study("drag")
    for a, k in ((ds.kappa_peak_approach_level.values, ds.kappa_peak_level.values),
                 (ds.kappa_peak_approach_ideal_level.values, ds.kappa_peak_ideal_level.values)):
        ok = np.isfinite(k)
        assert np.array_equal(ok, np.isfinite(a))  # every run has one
        assert np.all(a[ok] <= k[ok] * (1 + 1e-12))  # the interior joints on the approach: never above the run's
    # the ideal converges on the approach (its run's peak did not: 8.4% and 6.9% at chi 0.3 and 0.5)
    assert np.all(np.abs(ds.kappa_peak_approach_ideal_error / ds.kappa_peak_approach_ideal) < 0.01)
