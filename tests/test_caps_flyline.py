"""The fly line's design answer made cheaper (branch flyline, issue 24): a tapered line's runs read
their profiles once (node arrays), its link masses come from one vectorized density call, and the
grading asks the full run on N links before the run without bending on 2N. Each checked against
the way it was made before (the scalar calls, the old order of the grading's questions), written
out here, and the masses against their integral in closed form. No runs: ~1 s."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from snapping import caps, caps_runs, lines
from snapping._validate import SnappingInputError
from snapping.simulate import Body, Links


def test_vectorized_density_gives_the_scalar_masses_bit_for_bit_and_the_integral():
    h = np.random.default_rng(3).uniform(0.2, 1.0, 37)
    h /= h.sum()
    scalar = Links.from_density(h, lambda s: 1.0 + 3.0 * s * s)
    vec = Links.from_density(h, lambda s: 1.0 + 3.0 * s * s, vectorized=True)
    assert np.array_equal(scalar.m, vec.m)
    # the link masses in closed form: int_a^b (1 + 3 s^2) ds = (b - a) + b^3 - a^3 (s from the held end),
    # lumped "shared": node j (index 0 the free end; the held end's is not a mass) half of links j and j - 1
    e = np.concatenate([[0.0], np.cumsum(h[::-1])])
    mu = ((e[1:] - e[:-1]) + e[1:] ** 3 - e[:-1] ** 3)[::-1]
    m = 0.5 * mu
    m[1:] += 0.5 * mu[:-1]
    assert np.allclose(vec.m, m, rtol=1e-13, atol=0.0)
    with pytest.raises(SnappingInputError, match="density"):
        Links.from_density(h, lambda s: np.ones(3), vectorized=True)  # not one value per s
    with pytest.raises(SnappingInputError, match="density"):
        Links.from_density(h, lambda s: 1.0 - 2.0 * s, vectorized=True)  # not > 0 on the chain


def _body_by_calls(sp):
    kw = {"ei": sp.ei, "diameter": sp.diameter, "cd_normal": sp.cd_normal, "cd_tangential": sp.cd_tangential,
          "air_density": sp.air_density, "tip_drag_area": sp.tip_drag_area}
    return Body.from_si(sp.length, sp.mass, sp.g, **kw)


@pytest.mark.parametrize("name", ["fly-line", "bullwhip"])
def test_tapered_problem_reads_its_profiles_once_with_the_same_numbers(name):
    sp = caps.spec(name)
    ln, L = sp.line, sp.length
    on = tuple(m for m in caps.MECHANISMS[:-1] if sp.has(m))
    assert "taper" in on and callable(sp.ei) and callable(sp.diameter)
    lb = caps_runs.bending_length(sp)
    for h in (caps_runs.graded_h(0.1, lb, 0), np.full(150, 1.0 / 150)):
        p = caps_runs.problem(sp, 0.1, h.size, on, h=h if h.size != 150 else None)
        # the masses as the scalar density gave them: one call per quadrature point
        lam = sp.mass / L
        ref = Links.from_density(h, lambda u: ln.mass_per_length * ln.ratio(L * (1.0 - u), L) ** 2 / lam,
                                 tip_mass=sp.end_mass / sp.mass)
        assert np.array_equal(p.links.m, ref.m)
        # every profile a node array (read once), equal bit for bit to the functions' values at the nodes
        body = _body_by_calls(sp)
        for k in ("bending", "drag_normal", "drag_tangential"):
            v = getattr(p.body, k)
            assert isinstance(v, np.ndarray) and np.array_equal(v, body.node_values(k, h))
        # and the free end's bending number by hand: EI(0) r(0)^4 / (lambda g L^3), at the free-end node
        r0 = ln.ratio(0.0, L)
        assert p.body.bending[0] == pytest.approx(ln.ei * r0 ** 4 / (lam * sp.g * L ** 3), rel=1e-12)
    # the grid-damped problem keeps them (the damping computed from the same numbers)
    h = caps_runs.graded_h(0.1, lb, 0)
    p = caps_runs.problem(sp, 0.1, h.size, on, damping=0.01, omega_min=0.0, h=h)
    assert isinstance(p.body.bending, np.ndarray) and np.array_equal(p.body.bending,
                                                                     _body_by_calls(sp).node_values("bending", h))
    assert np.all(p.body.damping[1:-1] > 0.0)


def test_taper_stations_made_once_and_lists_still_taken():
    ln = lines.get("fly-line")
    x = np.linspace(0.0, ln.length, 50)
    xs, rs = (np.asarray(c, dtype=float) for c in zip(*ln.taper))
    assert np.array_equal(ln.ratio(x), np.interp(x, xs * (ln.length if ln.taper_units == "fraction" else 1.0), rs))
    a, b = lines._stations(ln.taper)
    assert a is lines._stations(ln.taper)[0] and not a.flags.writeable and not b.flags.writeable
    listed = lines.Line(**{**{k: getattr(ln, k) for k in ln.__dataclass_fields__},
                           "taper": [list(t) for t in ln.taper]})
    assert np.array_equal(listed.ratio(x), ln.ratio(x))


class _Fake:
    """Uniform runs faked: kappa_peak from ``k`` ({(on, N): curvature peak x link}); each asked logged."""

    def __init__(self, sp, k):
        self.sp, self.chi, self.k, self.log = sp, 0.1, k, []

    def get(self, on, N):
        self.log.append((tuple(on), N))
        return {"kappa_peak": self.k[(tuple(on), N)] * N}


def _old_order(runs, N, present):
    """The grading's questions in their order before (the run without bending on 2N before the full run on N)."""
    lb = caps_runs.bending_length(runs.sp)
    kh, kh2, where = None, None, "without bending"
    if 0.0 < lb < caps_runs.GRADE_LINKS / N:
        bare = tuple(m for m in present if m != "bending")
        kh = runs.get(bare, N)["kappa_peak"] / N
        if kh < caps_runs.COLLAPSE:
            kh2 = runs.get(bare, 2 * N)["kappa_peak"] / (2 * N)
            if kh2 < kh:
                kf = runs.get(tuple(present), N)["kappa_peak"] / N
                if kf >= caps_runs.COLLAPSE:
                    kh, kh2, where = kf, None, "with bending"
                elif lb * N < 1.0:
                    kh, kh2, where = kf, runs.get(tuple(present), 2 * N)["kappa_peak"] / (2 * N), "with bending"
    used, _ = caps_runs.grading_rule(lb, 1.0 / N, kh, where, halved=kh2)
    return used, kh, kh2, where


def test_grading_asks_the_full_run_first_and_decides_as_before():
    sp = caps.spec("fly-line")
    on = tuple(m for m in caps.MECHANISMS[:-1] if sp.has(m))
    bare = tuple(m for m in on if m != "bending")
    seen = set()
    for N in (100, 1000):  # the bending length 0.11 and 1.1 links
        for kh, kh2, kf, kf2 in itertools.product((0.6, 2.0), (0.3, 0.9), (0.5, 1.8), (0.4, 0.7)):
            k = {(bare, N): kh, (bare, 2 * N): kh2, (on, N): kf, (on, 2 * N): kf2}
            new, old = _Fake(sp, k), _Fake(sp, k)
            g = caps_runs.grading_for(new, N, list(on))
            used, c, c2, where = _old_order(old, N, list(on))
            assert g["used"] == used
            seen.add(used)
            g2 = kh < caps_runs.COLLAPSE and kh2 >= kh  # the old order stopped at bare on 2N ...
            if not (g2 and kf >= caps_runs.COLLAPSE):  # ... where the new asks the full run first: else the same
                assert (g["collapse"], g["halved"], g["collapse_run"]) == (c, c2, where)
            if kh < caps_runs.COLLAPSE:
                assert new.log[:2] == [(bare, N), (on, N)]
                if kf >= caps_runs.COLLAPSE:  # the full run collapses: no run without bending on 2N
                    assert new.log == [(bare, N), (on, N)] and g["collapse"] == kf
                    assert "with bending" in g["why"]
            else:
                assert new.log == [(bare, N)]
            assert set(new.log) <= set(old.log) | {(on, N)}
    assert seen == {True, False}
    assert math.isclose(caps_runs.COLLAPSE, math.pi / 2)
