"""Start shapes: exact-chord placement on curves, the catenary between unequal
supports, shape validation, and the available energy / maximum curvature of any
discrete shape (snapping.simulate.shapes and the shape functions of
snapping.estimates).

Every expected value is a closed form or a convergence order derived in the
test, never a number copied from the code's own output.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from scipy.integrate import quad

from snapping import estimates as E
from snapping import shape_estimates as SE
from snapping._validate import SnappingInputError
from snapping.simulate.chain import curvature_profile, initial_state
from snapping.simulate.shapes import catenary_between, check_curve, place_on_curve


def chords(x, y):
    return np.hypot(np.diff(x), np.diff(y))


def circle(R):
    """Circle of radius R through the origin, tangent to +e1 there, bending towards +y, by arclength."""
    return lambda s: (R * math.sin(s / R), R * (1.0 - math.cos(s / R)))


def orders(errs):
    """Observed orders log2(e_N / e_2N) for errors at N, 2N, 4N, ..."""
    e = np.abs(np.asarray(errs, dtype=float))
    return np.log2(e[:-1] / e[1:])


def level_catenary_nodes(chi, N):
    """The paper's catenary sampled at equal arclength 1/N (node order: 0 = free end)."""
    s = (N - np.arange(N + 1)) / N
    x, y = E.catenary_shape(s, chi)
    return np.asarray(x, float), np.asarray(y, float), s


def lumped(h, lam_mid):
    """Node masses: each node's share of its two links, m_0 = (lam h)_0/2, m_i = ((lam h)_{i-1} + (lam h)_i)/2."""
    w = lam_mid * h
    m = np.zeros(h.size + 1)
    m[:-1] += 0.5 * w
    m[1:] += 0.5 * w
    return m


# =============================================================================
# place_on_curve
# =============================================================================
def test_circle_unequal_links_closed_form():
    """On a circle of radius R a chord h subtends the angle 2 asin(h/2R): node i sits at
    angle phi_i = sum_{j >= i} 2 asin(h_j/2R) from the pin."""
    R = 0.7
    rng = np.random.default_rng(12)
    h = rng.uniform(0.01, 0.06, size=40)
    x, y = place_on_curve(circle(R), h)
    assert x.shape == y.shape == (41,)
    assert x[-1] == 0.0 and y[-1] == 0.0                         # the pin, exactly
    np.testing.assert_allclose(chords(x, y), h, rtol=0, atol=2e-15)
    np.testing.assert_allclose(np.hypot(x, y - R), R, rtol=0, atol=2e-15)   # on the circle
    phi = np.concatenate([np.cumsum((2 * np.arcsin(h / (2 * R)))[::-1])[::-1], [0.0]])
    np.testing.assert_allclose(x, R * np.sin(phi), rtol=0, atol=1e-14)
    np.testing.assert_allclose(y, R * (1 - np.cos(phi)), rtol=0, atol=1e-14)


def test_equal_links_reproduce_initial_state_exact_chords():
    """For h = 1/N on the paper's catenary the walk is chain.initial_state(chords="exact")."""
    chi, N = 0.25, 50
    st = initial_state(chi, N, chords="exact")
    x, y = place_on_curve(catenary_between(chi, 0.0), np.full(N, 1.0 / N))
    np.testing.assert_allclose(x, st.x, rtol=0, atol=2e-15)
    np.testing.assert_allclose(y, st.y, rtol=0, atol=2e-15)


def test_polyline_on_circle():
    """A finely sampled circle arc as a polyline: chords exact, nodes on the circle to the
    spline's accuracy (O(spacing^4))."""
    R, arc = 0.7, 1.2
    t = np.linspace(0.0, arc, 4001)
    poly = (R * np.sin(t / R), R * (1 - np.cos(t / R)))
    h = np.random.default_rng(3).uniform(0.02, 0.05, size=25)
    h *= 1.1 / h.sum()                                           # uses 1.1 of the 1.2 available
    x, y = place_on_curve(poly, h)
    assert x[-1] == 0.0 and y[-1] == 0.0
    np.testing.assert_allclose(chords(x, y), h, rtol=0, atol=2e-15)
    np.testing.assert_allclose(np.hypot(x, y - R), R, rtol=0, atol=1e-10)


def test_polyline_extrapolated_along_end_tangent():
    """sum(h) equal to the polyline's length needs a little more curve (chords < arcs): the
    walk continues along the end tangent, so the free end lies on that tangent line."""
    R, arc = 0.7, 1.2
    t = np.linspace(0.0, arc, 2001)
    poly = (R * np.sin(t / R), R * (1 - np.cos(t / R)))
    N = 30
    x, y = place_on_curve(poly, np.full(N, arc / N))
    np.testing.assert_allclose(chords(x, y), arc / N, rtol=0, atol=2e-15)
    ex, ey = R * math.sin(arc / R), R * (1 - math.cos(arc / R))       # end of the arc
    tx, ty = math.cos(arc / R), math.sin(arc / R)                     # its tangent
    along = (x[0] - ex) * tx + (y[0] - ey) * ty
    assert 0 < along < 0.01 * arc
    assert abs((x[0] - ex) * ty - (y[0] - ey) * tx) < 1e-9            # on the tangent line


def test_two_point_polyline_is_straight():
    x, y = place_on_curve(([0.0, 0.0], [0.0, 1.0]), np.full(4, 0.25))
    np.testing.assert_allclose(x, 0.0, atol=1e-15)
    np.testing.assert_allclose(y, [1.0, 0.75, 0.5, 0.25, 0.0], rtol=0, atol=1e-15)


def test_origin_tolerance():
    """curve(0) within 1e-12 of the length of the origin is accepted; the pin is set to (0, 0)."""
    x, y = place_on_curve(lambda s: (s, 5e-13), [0.5, 0.5])
    assert x[-1] == 0.0 and y[-1] == 0.0
    with pytest.raises(SnappingInputError, match="origin"):
        place_on_curve(lambda s: (s, 1e-6), [0.5, 0.5])
    with pytest.raises(SnappingInputError, match="origin"):
        place_on_curve(([1e-6, 1.0], [0.0, 0.0]), [0.5])


@pytest.mark.parametrize("h, pattern", [
    ([], r"^h must"), ([[0.1, 0.2]], r"^h must"), ([0.1, 0.0], r"h\[1\]=0\.0"),
    ([0.1, -0.2], r"h\[1\]=-0\.2"), ([np.nan], r"h\[0\]=nan"), ([np.inf], r"h\[0\]=inf"), ("ab", r"^h="),
])
def test_bad_h(h, pattern):
    with pytest.raises(SnappingInputError, match=pattern):
        place_on_curve(circle(1.0), h)


def test_bad_curve():
    with pytest.raises(SnappingInputError, match="curve=3"):
        place_on_curve(3, [0.1])
    with pytest.raises(SnappingInputError, match="curve"):
        place_on_curve(([0, 1], [0, 0], [0, 0]), [0.1])
    with pytest.raises(SnappingInputError, match=r"curve\(.*not finite"):
        place_on_curve(lambda s: (s, math.nan if s > 0.05 else 0.0), [0.1])
    with pytest.raises(SnappingInputError, match="curve.*two real numbers"):
        place_on_curve(lambda s: s, [0.1])
    with pytest.raises(SnappingInputError, match="curve polyline"):
        place_on_curve(([0.0, 1.0, 2.0], [0.0, 0.0]), [0.1])
    with pytest.raises(SnappingInputError, match="curve polyline points 1 and 2 coincide"):
        place_on_curve(([0.0, 1.0, 1.0], [0.0, 0.0, 0.0]), [0.1])
    with pytest.raises(SnappingInputError, match="curve polyline point 1"):
        place_on_curve(([0.0, np.nan], [0.0, 0.0]), [0.1])


def test_chord_not_found():
    """A circle of radius 0.01 never reaches chord 0.1; a polyline of length 1 holds
    sum(h) = 1.005 (0.5 % extrapolation) but not 1.02."""
    with pytest.raises(SnappingInputError, match=r"h\[0\]=0\.1.*s_max"):
        place_on_curve(circle(0.01), [0.1])
    line = ([0.0, 1.0], [0.0, 0.0])
    x, _ = place_on_curve(line, [0.5, 0.505])
    assert abs(x[0] - 1.005) < 1e-15
    with pytest.raises(SnappingInputError, match=r"h\[0\]"):
        place_on_curve(line, [0.5, 0.52])
    with pytest.raises(SnappingInputError, match="s_max"):
        place_on_curve(line, [0.5], s_max=1.5)
    with pytest.raises(SnappingInputError, match="s_max"):
        place_on_curve(circle(1.0), [0.5], s_max=-1.0)
    with pytest.raises(SnappingInputError, match=r"h\[0\]"):      # callable limited by s_max
        place_on_curve(circle(1.0), [0.5, 0.5], s_max=0.9)


# =============================================================================
# catenary_between
# =============================================================================
@pytest.mark.parametrize("chi", [1e-3, 0.01, 0.1, 0.25, 0.5, 0.9, 0.999])
def test_level_case_is_the_paper_catenary(chi):
    s = np.linspace(0.0, 1.0, 201)
    x, y = catenary_between(chi, 0.0)(s)
    xe, ye = E.catenary_shape(s, chi)
    np.testing.assert_allclose(x, xe, rtol=0, atol=1e-12)
    np.testing.assert_allclose(y, ye, rtol=0, atol=1e-12)


CASES = [(0.6, 0.3, 1.0), (0.6, -0.4, 1.0), (1.2, -0.8, 2.5), (0.2, 0.9, 1.0), (0.5, -0.85, 1.0),
         (1e-6, 0.5, 1.0), (0.999 * math.sqrt(1 - 0.3**2), 0.3, 1.0), (0.3, 0.0, 0.7)]


@pytest.mark.parametrize("dx, dy, L", CASES)
def test_ends_at_the_supports(dx, dy, L):
    cat = catenary_between(dx, dy, L)
    assert cat(0.0) == (0.0, 0.0)
    xe, ye = cat(L)
    assert abs(xe - dx) < 1e-12 * L and abs(ye - dy) < 1e-12 * L


def fd(cat, s, eps):
    """x, y and their first two s-derivatives by fourth-order central differences."""
    (x2, y2), (x1, y1), (x0, y0), (xm1, ym1), (xm2, ym2) = (cat(s + k * eps) for k in (2, 1, 0, -1, -2))
    d1 = lambda f2, f1, fm1, fm2: (-f2 + 8 * f1 - 8 * fm1 + fm2) / (12 * eps)
    d2 = lambda f2, f1, f0, fm1, fm2: (-f2 + 16 * f1 - 30 * f0 + 16 * fm1 - fm2) / (12 * eps**2)
    return (x0, y0, d1(x2, x1, xm1, xm2), d1(y2, y1, ym1, ym2),
            d2(x2, x1, x0, xm1, xm2), d2(y2, y1, y0, ym1, ym2))


@pytest.mark.parametrize("dx, dy, L", [(0.6, 0.3, 1.0), (0.6, -0.4, 1.0), (1.2, -0.8, 2.5)])
def test_arclength_parametrisation(dx, dy, L):
    """|r'(s)| = 1 and the quadrature of |r'| over [0, L] is L."""
    cat = catenary_between(dx, dy, L)
    speed = lambda s: math.hypot(*fd(cat, s, 1e-6)[2:4])
    s = np.linspace(0.0, L, 51)
    assert max(abs(speed(v) - 1.0) for v in s) < 1e-8
    total, _ = quad(speed, 0.0, L, epsabs=1e-12, limit=200)
    assert abs(total - L) < 1e-8


@pytest.mark.parametrize("dx, dy, L", [(0.6, 0.3, 1.0), (0.6, -0.4, 1.0), (1.2, -0.8, 2.5), (0.3, 0.5, 1.0)])
def test_catenary_ode_and_sag(dx, dy, L):
    """As a graph y(x) (y down) the catenary solves y'' = -sqrt(1 + y'^2)/a with one
    constant a, and that a solves sqrt(L^2 - dy^2) = 2 a sinh(dx/(2a)); it sags: every
    interior point lies below (at larger y than) the chord between the supports."""
    cat = catenary_between(dx, dy, L)
    s = np.linspace(0.05 * L, 0.95 * L, 37)
    x, y, xs, ys, xss, yss = fd(cat, s, 1e-3 * L)
    assert np.all(xs > 0)                                        # a graph over x
    yx = ys / xs
    yxx = (xs * yss - ys * xss) / xs**3
    ratio = yxx / np.sqrt(1 + yx**2)                              # = -1/a
    assert np.all(ratio < 0)
    np.testing.assert_allclose(ratio, ratio.mean(), rtol=1e-6)
    a = -1.0 / ratio.mean()
    assert abs(2 * a * math.sinh(dx / (2 * a)) - math.sqrt(L**2 - dy**2)) < 1e-8 * L
    assert abs(a - cat.a) < 1e-8 * a
    assert np.all(y > dy * x / dx)                               # sags towards +y
    # curvature of the parametrised curve |x' y'' - y' x''| against the closed form
    np.testing.assert_allclose(np.abs(xs * yss - ys * xss), cat.curvature(s), rtol=1e-6)


def test_scaling_with_length():
    """Lengths scale: catenary_between(L dx, L dy, L)(L s) = L catenary_between(dx, dy)(s)."""
    s = np.linspace(0, 1, 11)
    L = 3.7
    x1, y1 = catenary_between(0.4, -0.3)(s)
    xL, yL = catenary_between(0.4 * L, -0.3 * L, L)(L * s)
    np.testing.assert_allclose(xL, L * x1, rtol=0, atol=1e-14 * L)
    np.testing.assert_allclose(yL, L * y1, rtol=0, atol=1e-14 * L)


def test_exact_chords_on_unequal_supports():
    """The walk with h = 1/N ends a little beyond the support (chords < arcs) and the
    shape is valid."""
    cat = catenary_between(0.5, 0.4)
    N = 100
    x, y = place_on_curve(cat, np.full(N, 1.0 / N))
    np.testing.assert_allclose(chords(x, y), 1.0 / N, rtol=0, atol=2e-15)
    check_curve(x, y)
    assert 0 < math.hypot(x[0] - 0.5, y[0] - 0.4) < 1e-3


@pytest.mark.parametrize("args, pattern", [
    ((0.0, 0.1), r"dx=0\.0"), ((-0.5, 0.1), r"dx=-0\.5"), ((0.5, math.nan), r"dy=nan"),
    ((0.5, 0.1, 0.0), r"length=0\.0"), ((0.8, 0.6, 1.0), r"dx=0\.8, dy=0\.6.*sqrt\(dx\^2 \+ dy\^2\).*length"),
    ((0.9, 0.5), r"dx=0\.9, dy=0\.5.*< length"), ((0.1, -1.0), r"dy=-1\.0.*< length"),
])
def test_catenary_between_errors(args, pattern):
    with pytest.raises(SnappingInputError, match=pattern):
        catenary_between(*args)


def test_catenary_between_s_range():
    cat = catenary_between(0.5, 0.1)
    cat(np.array([-1.0, 2.0]))                                   # the analytic curve beyond the ends
    with pytest.raises(SnappingInputError, match=r"^s must"):
        cat(2.5)
    with pytest.raises(SnappingInputError, match=r"^s must"):
        cat(np.array([0.1, np.nan]))


# =============================================================================
# check_curve
# =============================================================================
def test_valid_shapes_pass():
    x, y, _ = level_catenary_nodes(0.01, 2000)                   # nearly folded, both branches close
    xo, yo = check_curve(x, y)
    assert xo.dtype == float and np.array_equal(xo, x)
    th = np.linspace(0, 12 * np.pi, 3001)
    r = 0.05 + th / (12 * np.pi)
    check_curve(r * np.cos(th), r * np.sin(th), name="spiral")
    check_curve([0.0, 1.0], [0.0, 0.0])


def test_crossing_names_the_links_and_the_shape():
    x, y = [0.0, 1.0, 1.0, 0.0, 0.5], [0.5, 0.5, 0.0, 0.0, 1.0]   # link 3 crosses link 0 at (0.25, 0.5)
    with pytest.raises(SnappingInputError, match=r"^start: links 0 and 3 \(nodes 0-1 and 3-4\) intersect"):
        check_curve(x, y, name="start")


def test_touching_and_folding_back():
    # node 4 = (1, 0) lies on link 0 from (0, 0) to (2, 0): links 0 and 3 touch
    with pytest.raises(SnappingInputError, match="links 0 and 3"):
        check_curve([0.0, 2.0, 2.0, 1.0, 1.0], [0.0, 0.0, 1.0, 1.0, 0.0])
    # link 1 folds back onto link 0 (turning angle pi)
    with pytest.raises(SnappingInputError, match="links 0 and 1 fold back"):
        check_curve([0.0, 1.0, 0.5], [0.0, 0.0, 0.0])
    # collinear, non-adjacent and overlapping: links 0 and 4 share [0, 1] of the x axis
    with pytest.raises(SnappingInputError, match="links 0 and 4"):
        check_curve([0.0, 2.0, 2.0, -1.0, -1.0, 1.0], [0.0, 0.0, -1.0, -1.0, 0.0, 0.0])


def test_check_curve_input_errors():
    with pytest.raises(SnappingInputError, match="^shape: x and y"):
        check_curve([0.0, 1.0], [0.0, 1.0, 2.0])
    with pytest.raises(SnappingInputError, match="^init: x and y"):
        check_curve([0.0], [0.0], name="init")
    with pytest.raises(SnappingInputError, match="^shape: node 2 .* not finite"):
        check_curve([0.0, 1.0, np.inf], [0.0, 0.0, 1.0])
    with pytest.raises(SnappingInputError, match="^shape: nodes 1 and 2 coincide"):
        check_curve([0.0, 1.0, 1.0, 2.0], [0.0, 1.0, 1.0, 0.0])


def _orient_exact(a, b, c):
    ax, ay, bx, by, cx, cy = (Fraction(float(v)) for v in (*a, *b, *c))
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


def _meet_exact(p1, p2, p3, p4):
    """Closed segments p1p2 and p3p4 share a point (exact rational arithmetic)."""
    d1, d2 = _orient_exact(p3, p4, p1), _orient_exact(p3, p4, p2)
    d3, d4 = _orient_exact(p1, p2, p3), _orient_exact(p1, p2, p4)
    if d1 * d2 < 0 and d3 * d4 < 0:
        return True

    def on(a, b, p):
        return min(a[0], b[0]) <= p[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])

    return ((d1 == 0 and on(p3, p4, p1)) or (d2 == 0 and on(p3, p4, p2))
            or (d3 == 0 and on(p1, p2, p3)) or (d4 == 0 and on(p1, p2, p4)))


def _brute_bad(x, y):
    """All pairs, exact: a zero link, a fold-back of consecutive links, or non-adjacent links meeting."""
    P = list(zip(x, y))
    n = len(P) - 1
    if any(P[i] == P[i + 1] for i in range(n)):
        return True
    for i in range(n - 1):
        d1 = (P[i + 1][0] - P[i][0], P[i + 1][1] - P[i][1])
        d2 = (P[i + 2][0] - P[i + 1][0], P[i + 2][1] - P[i + 1][1])
        if d1[0] * d2[1] - d1[1] * d2[0] == 0 and d1[0] * d2[0] + d1[1] * d2[1] < 0:
            return True
    return any(_meet_exact(P[i], P[i + 1], P[j], P[j + 1]) for i in range(n) for j in range(i + 2, n))


@pytest.mark.parametrize("grid", [False, True])
def test_agrees_with_brute_force(grid):
    """Random small walks (continuous, and on an integer grid for touching/collinear
    cases): check_curve raises exactly when the exact all-pairs test finds a defect,
    and a reported pair of links does meet."""
    rng = np.random.default_rng(7 if grid else 8)
    seen = {True: 0, False: 0}
    for _ in range(300):
        n = int(rng.integers(3, 12))
        if grid:
            x, y = rng.integers(0, 5, n).astype(float), rng.integers(0, 5, n).astype(float)
        else:
            x, y = np.cumsum(rng.normal(size=n)), np.cumsum(rng.normal(size=n))
        bad = _brute_bad(x, y)
        seen[bad] += 1
        try:
            check_curve(x, y)
            raised = None
        except SnappingInputError as e:
            raised = str(e)
        assert (raised is not None) == bad, (x, y, raised)
        if raised and "intersect" in raised:
            i, j = (int(v) for v in raised.split("links ")[1].split(" (")[0].split(" and "))
            assert j >= i + 2 and _meet_exact((x[i], y[i]), (x[i + 1], y[i + 1]), (x[j], y[j]), (x[j + 1], y[j + 1]))
    assert seen[True] > 20 and seen[False] > 20


# =============================================================================
# estimates: available energy and maximum curvature of any discrete shape
# =============================================================================
def test_available_energy_shape_closed_forms():
    """Straight horizontal chain, uniform: P = sum m_i s_i is the trapezoidal rule of
    int_0^1 s ds, exact for a linear integrand: 1/2 (the paper's chi -> 1 limit) for any N.
    Hanging straight down: 0. Translating the chain does not change P; P is linear in g."""
    for N in (1, 2, 7, 64):
        s = (N - np.arange(N + 1)) / N
        m = lumped(np.full(N, 1.0 / N), 1.0)
        assert abs(SE.available_energy_shape(s, np.zeros(N + 1), m) - 0.5) < 1e-15
        assert abs(SE.available_energy_shape(np.zeros(N + 1), s, m)) < 1e-15
    x, y, _ = level_catenary_nodes(0.3, 20)
    m = lumped(np.full(20, 1 / 20), 1.0)
    P = SE.available_energy_shape(x, y, m)
    assert abs(SE.available_energy_shape(x + 0.3, y - 0.7, m) - P) < 1e-15
    assert abs(SE.available_energy_shape(x, y, m, g=9.81) - 9.81 * P) < 1e-14


@pytest.mark.parametrize("chi", [0.25, 0.5])
def test_available_energy_uniform_catenary_second_order(chi):
    """Catenary sampled at arclength 1/N, masses lumped (total mass 1): P_N - P(chi)
    = C / N^2 + O(N^-4) with, from Euler-Maclaurin (trapezoidal rule of f = s - y(s):
    (h^2/12)(f'(1) - f'(0)), f'(1) - f'(0) = 1/sqrt(a^2 + 1/4)) and the chord deficit
    (cumulative chords s_i fall short of arclength by (h^2/24) int_0^s kappa^2, giving
    -(h^2/24) int_0^1 (1 - s) kappa^2 ds = -(h^2/48) int_0^1 kappa^2 ds by symmetry),
    with kappa = a/(a^2 + (s - 1/2)^2):

        C = 1/(12 sqrt(a^2 + 1/4)) - [ (1/2)/(a^2 + 1/4) + atan(1/(2a))/a ] / 48.
    """
    a = E.catenary_parameter(chi)
    C = 1 / (12 * math.sqrt(a * a + 0.25)) - (0.5 / (a * a + 0.25) + math.atan(1 / (2 * a)) / a) / 48
    P = E.available_energy(chi)
    Ns = [64, 128, 256, 512]
    errs = []
    for N in Ns:
        x, y, _ = level_catenary_nodes(chi, N)
        errs.append(SE.available_energy_shape(x, y, lumped(np.full(N, 1.0 / N), 1.0)) - P)
    np.testing.assert_allclose(orders(errs), 2.0, atol=0.01)
    assert abs(errs[-1] * Ns[-1] ** 2 / C - 1) < 1e-3


def test_available_energy_exact_chords_second_order():
    """Nodes placed with exact chords 1/N (place_on_curve): also second order."""
    chi = 0.5
    P = E.available_energy(chi)
    cat = catenary_between(chi, 0.0)
    errs = []
    for N in (32, 64, 128, 256):
        x, y = place_on_curve(cat, np.full(N, 1.0 / N))
        errs.append(SE.available_energy_shape(x, y, lumped(np.full(N, 1.0 / N), 1.0)) - P)
    np.testing.assert_allclose(orders(errs), 2.0, atol=0.05)


def test_available_energy_tapered_chain_second_order():
    """Mass per length lambda(s) = 2 (1 - s) (total mass 1) on the level catenary,
    link masses lambda(s_mid) h (exact for a linear lambda), lumped to the nodes:
    P_N -> int_0^1 lambda(s) (s - y(s)) ds at second order."""
    chi = 0.5
    lam = lambda s: 2.0 * (1.0 - s)
    exact, _ = quad(lambda s: lam(s) * (s - float(E.catenary_shape(s, chi)[1])), 0.0, 1.0,
                    epsabs=1e-13, epsrel=1e-13, limit=200)
    errs = []
    for N in (32, 64, 128, 256, 512):
        x, y, s = level_catenary_nodes(chi, N)
        h = np.full(N, 1.0 / N)
        m = lumped(h, lam(0.5 * (s[:-1] + s[1:])))
        assert abs(m.sum() - m[-1] - (1.0 - lam(0.5 / N) / (2 * N))) < 1e-14   # all but the pin's share
        errs.append(SE.available_energy_shape(x, y, m) - exact)
    np.testing.assert_allclose(orders(errs), 2.0, atol=0.05)


@pytest.mark.parametrize("chi", [0.25, 0.5])
def test_kappa_m0_shape_catenary_closed_form_and_order(chi):
    """Catenary at arclength 1/N, N even: the maximum is at the vertex node, whose
    neighbours are at Dx = a asinh(h/a), Dy = sqrt(a^2 + h^2) - a on either side, so
    kappa = 2 atan(Dy/Dx) / hypot(Dx, Dy) exactly; expanding, kappa = 1/a - h^2/(8 a^3) + O(h^4)."""
    a = E.catenary_parameter(chi)
    Ns = [128, 256, 512, 1024]
    errs = []
    for N in Ns:
        x, y, _ = level_catenary_nodes(chi, N)
        k = SE.kappa_m0_shape(x, y)
        h = 1.0 / N
        Dx, Dy = a * math.asinh(h / a), h * h / (math.sqrt(a * a + h * h) + a)
        assert abs(k - 2 * math.atan(Dy / Dx) / math.hypot(Dx, Dy)) < 1e-15 * N * N   # rounding ~ eps/h^2
        errs.append(k - E.kappa_m0(chi))
    np.testing.assert_allclose(orders(errs), 2.0, atol=0.02)
    assert abs(errs[-1] * Ns[-1] ** 2 * (-8 * a**3) - 1) < 5e-3


def test_kappa_m0_shape_circle_unequal_links():
    """Nodes on a circle of radius R with chords h_j: the turning angle at node i is
    asin(h_{i-1}/2R) + asin(h_i/2R), divided by (h_{i-1} + h_i)/2."""
    R = 0.4
    h = np.random.default_rng(5).uniform(0.01, 0.2, size=12)
    x, y = place_on_curve(circle(R), h)
    q = np.arcsin(h / (2 * R))
    expected = np.max((q[:-1] + q[1:]) / (0.5 * (h[:-1] + h[1:])))
    assert abs(SE.kappa_m0_shape(x, y) - expected) < 1e-12


def test_kappa_m0_shape_equal_links_matches_paper_curvature():
    """For equal links 1/N it is the maximum of the paper's |N (theta_{k+1} - theta_k)|."""
    st = initial_state(0.3, 60, chords="exact")
    assert abs(SE.kappa_m0_shape(st.x, st.y) - np.nanmax(np.abs(curvature_profile(st.x, st.y)))) < 1e-9
    assert SE.kappa_m0_shape([1.0, 0.0], [0.0, 0.0]) == 0.0                   # one link, no joint
    assert SE.kappa_m0_shape([0.0, 0.0, 0.0], [2.0, 1.0, 0.0]) == 0.0         # straight


def test_shape_estimates_errors():
    x, y = [1.0, 0.5, 0.0], [0.0, 0.0, 0.0]
    with pytest.raises(SnappingInputError, match="^m must hold one mass per node"):
        SE.available_energy_shape(x, y, [0.5, 0.5])
    with pytest.raises(SnappingInputError, match=r"^m\[1\]=-0\.5"):
        SE.available_energy_shape(x, y, [0.25, -0.5, 0.25])
    with pytest.raises(SnappingInputError, match=r"^g=0\.0"):
        SE.available_energy_shape(x, y, [0.25, 0.5, 0.25], g=0.0)
    for f in (lambda a, b: SE.available_energy_shape(a, b, [1.0, 1.0]), SE.kappa_m0_shape):
        with pytest.raises(SnappingInputError, match="^x and y"):
            f([0.0, 1.0], [0.0])
        with pytest.raises(SnappingInputError, match="^nodes 0 and 1 coincide"):
            f([0.0, 0.0], [0.0, 0.0])
        with pytest.raises(SnappingInputError, match="^node 1 .* not finite"):
            f([0.0, np.nan], [0.0, 0.0])
