"""The graded ladder's floor on the fold's links (``heldarm``, issue 24): along the fold's path the links
are FOLD_LINK (1.5) bending lengths but never finer than 1% of the fold's radius ``a (2x)^(1/4)``
(``caps_runs.FOLD_FRAC``). Checked: the climbing rope's links at chi 0.5 section by section against
their counts by hand (closed-form integrals of the spacing, the catenary parameter solved here), the
ladder unchanged bit for bit where the floor does not act (every other catalogue line at chi 0.1-0.5,
the climbing rope at chi <= 0.2, its unresolved answers included), and an answer on the new ladder
against direct runs of the same problem (``Body.from_si``) and against the old, finer ladder's
extrapolation, both computed here. ~5 s."""

from __future__ import annotations

import math

import numpy as np
import pytest

from snapping import caps, caps_runs, estimates, lines
from snapping.simulate import Body, Links, Problem, grading, run
from snapping.simulate.stiffness import grid_damping

G = 9.81
GAMMA, XF = 0.1, 0.6  # grading.fold_following's slope and the fold path's end (1/2 + margin)


def _catenary_a(chi: float) -> float:
    """The catenary parameter by bisection: a chain of length 1 hung between ends chi apart,
    ``2 a sinh(chi / (2 a)) = 1`` (the arclength falls as a grows)."""
    lo, hi = 1e-4, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if 2.0 * mid * math.sinh(chi / (2.0 * mid)) > 1.0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _rope_lb() -> float:
    rope = lines.get("climbing-rope")
    lam = rope.mass() / rope.length
    return math.sqrt(rope.ei / (lam * G * rope.length)) / rope.length


def test_climbing_rope_ladder_at_chi_half_by_hand():
    lb, chi = _rope_lb(), 0.5
    a = _catenary_a(chi)
    assert lb == pytest.approx(1.9115e-4, rel=1e-3) and a == pytest.approx(0.1150, rel=2e-3)
    assert 1.5 * lb / a < 0.01  # the fold is wider than 150 bending lengths: the floor acts
    for level in (0, 1):
        s = 0.5 ** level
        c, h_min, h_max = 0.01 * a * s, 0.4 * lb * s, 20.0 * lb * s  # fold (at x >= 1/2), free end, held arm
        h = caps_runs.graded_h(chi, lb, level)
        x = np.cumsum(h)  # each link's far end, from the free end
        # the free end: h_min + gamma x until it meets the fold's c (2x)^(1/4), at xt
        lo, hi = 0.0, 0.5
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if h_min + GAMMA * mid < c * (2.0 * mid) ** 0.25 else (lo, mid)
        xt = lo
        n_tip = math.log((h_min + GAMMA * xt) / h_min) / GAMMA
        # the fold's path: int dx / (c (2x)^(1/4)) = (2/(3c)) (2x)^(3/4) up to 1/2, then c to 1/2 + margin
        n_fold = 2.0 / (3.0 * c) * (1.0 - (2.0 * xt) ** 0.75) + (XF - 0.5) / c
        # the held arm: c + gamma (x - XF) up to h_max, reached at x1, then h_max
        x1 = XF + (h_max - c) / GAMMA
        n_held = math.log(h_max / c) / GAMMA + (1.0 - x1) / h_max
        got = [int((x <= xt).sum()), int(((x > xt) & (x <= XF)).sum()), int((x > XF).sum())]
        for n, want in zip(got, (n_tip, n_fold, n_held)):
            assert abs(n - want) <= 2, (level, got, (n_tip, n_fold, n_held))
        assert abs(h.size - (n_tip + n_fold + n_held)) <= 2
        assert h.max() == pytest.approx(h_max, rel=2e-3)  # the held arm's links: 20 l_b (level 0), 10 l_b
        assert h[0] == pytest.approx(h_min, rel=0.05)  # the free end's: 0.4 l_b, halved
        assert np.interp(0.3, x - 0.5 * h, h) == pytest.approx(c * 0.6 ** 0.25, rel=0.01)  # the fold's at x 0.3
    # the old ladder's fold links, 1.5 l_b: 2785 links on level 0; now 782 (the fold's path 3.6x coarser)
    assert caps_runs.graded_h(chi, lb, 0).size == 782


@pytest.mark.parametrize("name,chis", [("nylon-monofilament", (0.1, 0.2, 0.3, 0.4, 0.5)),
                                       ("fly-line", (0.1, 0.2, 0.3, 0.4, 0.5)),
                                       ("bungee-cord", (0.1, 0.2, 0.3, 0.4, 0.5)),
                                       ("bullwhip", (0.1, 0.2, 0.3, 0.4, 0.5)),
                                       ("climbing-rope", (0.05, 0.1, 0.15, 0.2))])
def test_ladder_unchanged_where_the_fold_is_near_the_bending_length(name, chis):
    # the ladder before the floor, literally: fold 1.5 l_b, free end 0.4 l_b, held arm 20 l_b (<= 0.5), halved
    lb = caps_runs.bending_length(caps.spec(name))
    for chi in chis:
        a = estimates.catenary_parameter(chi)  # (the ladder's own a, bit for bit; the same as solved here)
        assert a == pytest.approx(_catenary_a(chi), rel=1e-9)
        for level in (0, 1):
            s = 0.5 ** level
            h_max = min(0.5, 20.0 * lb)
            old = grading.fold_following(chi, frac=min(0.5, 1.5 * lb / a) * s, h_min=min(h_max, 0.4 * lb) * s,
                                         h_max=h_max * s)
            assert np.array_equal(caps_runs.graded_h(chi, lb, level), old), (name, chi, level)
    if name == "climbing-rope":  # its unresolved answers keep their ladder: the finer level over MAX_GRADED_LINKS
        assert caps_runs.graded_h(0.1, lb, 1).size == 5552 > caps_runs.MAX_GRADED_LINKS


def _levels(chi, lb, frac, kw, Lc, Mc):
    """Levels 0 and 1 of the graded ladder with the fold's links ``frac`` of the catenary parameter, run
    directly: RODAS4 at tol 1e-3, every node's shortest bending wave damped at ratio 0.01, drag corrected
    in the stage solves (caps' graded runs), peaks in SI."""
    out = []
    for k in (0, 1):
        s = 0.5 ** k
        h = grading.fold_following(chi, frac=frac * s, h_min=0.4 * lb * s, h_max=min(0.5, 20.0 * lb) * s)
        links = Links.graded(h)
        eta = grid_damping(h, links.m, np.full(h.size + 1, lb ** 2), 0.01)
        body = Body.from_si(Lc, Mc, G, **kw)
        body = Body(body.bending, damping=eta, drag_normal=body.drag_normal, drag_tangential=body.drag_tangential)
        ds = run(Problem.catenary(chi, links=links, body=body), method="rodas4", tol=1e-3, progress=False,
                 drag_jacobian="correct").dataset
        out.append({"links": h.size, "v_peak": float(ds.attrs["v_peak"]) * math.sqrt(G * Lc),
                    "a_peak": float(ds.attrs["a_peak"]) * G, "sigma_peak": float(ds.attrs["sigma_peak"]) * Mc * G})
    return out


def test_answer_on_the_new_ladder_matches_direct_runs_and_the_finer_ladder():
    # a line whose fold is drag-capped and wide: bending length 1e-3 L, the catenary at chi 0.7 (a = 0.231,
    # 231 bending lengths), heavy drag (drag number 3.8)
    Lc, Mc, chi, lb = 2.0, 0.1, 0.7, 1e-3
    kw = {"ei": lb ** 2 * (Mc / Lc) * G * Lc ** 3, "diameter": 0.05}
    a = _catenary_a(chi)
    assert 1.5 * lb / a < 0.01
    r = caps.cap(None, chi, N=12, check=False, alone=False, graded=True, length=Lc, mass=Mc, **kw)
    g = r["graded"]
    new = _levels(chi, lb, 0.01, kw, Lc, Mc)  # the floor: 1% of the fold's radius
    assert g["levels"] == [x["links"] for x in new] == [365, 716]
    for q in caps.QUANTITIES:
        for k in (0, 1):
            assert g["levels_peaks"][k][q] == pytest.approx(new[k][q], rel=1e-9)
        ext = new[1][q] + (new[1][q] - new[0][q]) / 3.0
        assert r["real"][q] == pytest.approx(ext, rel=1e-9)
        assert g["error"][q] == pytest.approx(abs(new[1][q] - new[0][q]) / 3.0, rel=1e-9)
    # the old ladder (fold links 1.5 l_b: 546 and 1075 links), extrapolated here: the new answer within the
    # two error bars and 0.05%
    old = _levels(chi, lb, 1.5 * lb / a, kw, Lc, Mc)
    assert [x["links"] for x in old] == [546, 1075]
    for q in caps.QUANTITIES:
        ref = old[1][q] + (old[1][q] - old[0][q]) / 3.0
        err = abs(old[1][q] - old[0][q]) / 3.0
        assert abs(r["real"][q] - ref) <= g["error"][q] + err + 5e-4 * abs(ref), q
