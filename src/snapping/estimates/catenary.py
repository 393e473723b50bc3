"""The catenary start and the paper's scales: geometry, available energy, the regularising
lengths delta and the whirling-rod peaks (no SI, no simulation); delta_kappa_m from a run."""

from __future__ import annotations

import math

import numpy as np

from .. import _validate as V

__all__ = ["check_chi", "catenary_parameter", "chi_from_parameter", "catenary_shape", "kappa_m0",
           "available_energy", "delta_kappa0", "delta_crude", "delta_N", "whirling_rod", "delta_kappa_m",
           "CHI_MIN", "N_MAX"]

# ----------------------------------------------------------------------- catenary
#: smallest end separation accepted: below it the scales of the catenary (delta_c ~ chi^(4/3))
#: and the whirling-rod peaks (~ delta^-2) leave the doubles
CHI_MIN = 1e-100


def check_chi(chi, name: str = "chi") -> float:
    """``chi`` as a float in [CHI_MIN, 1), or SnappingInputError naming ``name``."""
    chi = V.open_interval(name, chi, 0.0, 1.0)
    if chi < CHI_MIN:
        raise V.SnappingInputError(f"{name}={chi!r} is out of range: must lie in [{CHI_MIN:g}, 1) (a smaller "
                                   f"separation is the folded string, chi = 0: see snapping.ideal)")
    return chi


def _log_sinhc(b: float) -> float:
    """log(sinh(b)/b) for b > 0 without overflow or cancellation."""
    if b < 1e-4:
        return b * b / 6.0 - b**4 / 180.0
    if b > 20.0:
        return b - math.log(2.0 * b) + math.log1p(-math.exp(-2.0 * b))
    return math.log(math.sinh(b) / b)


def _dlog_sinhc(b: float) -> float:
    """d/db log(sinh(b)/b) = coth(b) - 1/b (> 0 for b > 0)."""
    if b < 1e-4:
        return b / 3.0 - b**3 / 45.0
    if b > 20.0:
        return 1.0 - 1.0 / b
    return 1.0 / math.tanh(b) - 1.0 / b


def _root_increasing(f, df, lo: float, hi: float, x0: float, rtol: float, maxiter: int = 500) -> float:
    """The root of the increasing function ``f`` in [lo, hi] (f(lo) <= 0 <= f(hi)): Newton steps
    kept inside a shrinking bracket, bisection where a step leaves it (no scipy: importing
    scipy.optimize costs most of a second, more than a table query)."""
    b = min(max(x0, lo), hi)
    for _ in range(maxiter):
        fb = f(b)
        if fb == 0.0:
            return b
        if fb < 0.0:
            lo = b
        else:
            hi = b
        d = df(b)
        nb = b - fb / d if d > 0.0 else math.nan
        if not lo < nb < hi:
            nb = 0.5 * (lo + hi)
        if abs(nb - b) <= rtol * abs(nb) or hi - lo <= rtol * hi:
            return nb
        b = nb
    return b


def catenary_parameter(chi: float) -> float:
    """Catenary parameter ``a`` of a unit-length string with end separation ``chi``.

    Solves ``1 = 2 a sinh(chi / (2 a))`` (the paper, after Lockwood) for a > 0.
    Written in ``b = chi/(2a)`` as ``log(sinh(b)/b) = -log(chi)``, which is
    monotone in b and solved by bracketed root finding, robust as chi -> 0
    (a -> 0, b ~ log(1/chi)) and chi -> 1 (a -> inf, b ~ sqrt(6 (1 - chi))).

    Parameters
    ----------
    chi : float
        End-to-end separation over length, in the open interval (0, 1).

    Returns
    -------
    float
        ``a``; the initial maximum curvature is ``kappa_m(0) = 1/a``.

    Examples
    --------
    >>> a = catenary_parameter(0.1)
    >>> abs(2 * a * math.sinh(0.1 / (2 * a)) - 1) < 1e-13
    True
    """
    chi = check_chi(chi)
    target = -math.log(chi)
    # log(sinh b / b) ~ b^2/6 for small b and ~ b - log(2b) for large b.
    hi = max(1.0, 2.0 * (target + math.log(2.0 * target + 2.0)) + 2.0)
    guess = math.sqrt(6.0 * target) if target < 1.0 else target + math.log(2.0 * target)
    b = _root_increasing(lambda bb: _log_sinhc(bb) - target, _dlog_sinhc, 0.0, hi, guess, rtol=4 * np.finfo(float).eps)
    if b == 0.0:  # chi so close to 1 that the root underflows: use the series
        b = math.sqrt(6.0 * target)
    return chi / (2.0 * b)


def chi_from_parameter(a: float) -> float:
    """End separation chi of the unit-length catenary with parameter ``a`` (inverse of
    :func:`catenary_parameter`): ``chi = 2 a asinh(1/(2a))``.

    >>> round(chi_from_parameter(catenary_parameter(0.3)), 12)
    0.3
    """
    a = V.positive("a", a)
    chi = 2.0 * a * math.asinh(1.0 / (2.0 * a))
    if not CHI_MIN <= chi < 1.0:  # (a huge: chi rounds to 1; a tiny: chi below CHI_MIN)
        raise V.SnappingInputError(f"a={a!r} is out of range: the catenary's chi = {chi!r} must lie in "
                                   f"[{CHI_MIN:g}, 1), i.e. a in [{_A_MIN:.3g}, {_A_MAX:.3g}]")
    return chi


#: the catenary parameters of chi = CHI_MIN and of the largest chi below 1 (where chi rounds to 1)
_A_MIN = catenary_parameter(CHI_MIN)
_A_MAX = catenary_parameter(float(np.nextafter(1.0, 0.0)))


def catenary_shape(s, chi: float):
    """Initial shape r(s) of the paper: the catenary from the pin (s = 0, origin)
    to the free end (s = 1, at (chi, 0)).

    ``x(s) = a asinh((s - 1/2)/a) + chi/2``,
    ``y(s) = sqrt(a^2 + 1/4) - sqrt(a^2 + (s - 1/2)^2)`` (downward).

    Parameters
    ----------
    s : array_like
        Arclength(s) in [0, 1].
    chi : float
        End separation in (0, 1).

    Returns
    -------
    x, y : ndarray
        Components along e1 and e2 (gravity direction).

    Examples
    --------
    >>> x, y = catenary_shape([0.0, 1.0], 0.25)
    >>> [round(float(v), 12) + 0.0 for v in (*x, *y)]
    [0.0, 0.25, 0.0, 0.0]
    """
    a = catenary_parameter(chi)
    s = V.float_array("s", s)
    if s.size and (not np.all(np.isfinite(s)) or s.min() < 0.0 or s.max() > 1.0):
        raise V.SnappingInputError(f"s must lie in [0, 1]; got values in [{s.min()!r}, {s.max()!r}]")
    u = s - 0.5
    x = a * np.arcsinh(u / a) + 0.5 * chi
    # sqrt(a^2+1/4) - sqrt(a^2+u^2) = (1/4 - u^2)/(sqrt(a^2+1/4)+sqrt(a^2+u^2)): no cancellation
    y = (0.25 - u * u) / (math.sqrt(a * a + 0.25) + np.sqrt(a * a + u * u))
    return x, y


def kappa_m0(chi: float) -> float:
    """Initial maximum curvature kappa_m(0) = 1/a of the catenary (at its bottom, s = 1/2).

    >>> round(kappa_m0(0.25), 4)
    26.1104
    """
    return 1.0 / catenary_parameter(chi)


def available_energy(chi: float) -> float:
    """Available energy P(chi): potential energy of the catenary minus that of the
    vertically hanging string (paper, section "Regularization is not by discreteness").

    With the potential -integral y ds (y downward, rho = g = 1),
    ``P = 1/2 - integral_0^1 y ds`` and, integrating the catenary in closed form,
    ``P = 1/2 - (sqrt(a^2 + 1/4) - a chi)/2``. Limits: P -> 1/4 as chi -> 0 (the
    folded string), P -> 1/2 as chi -> 1 (the horizontal string).

    >>> round(available_energy(0.25), 6)
    0.254055
    >>> round(available_energy(1e-9), 9), round(available_energy(1 - 1e-9), 3)
    (0.25, 0.5)
    """
    a = catenary_parameter(chi)
    # sqrt(a^2+1/4) - a chi = (sqrt(a^2+1/4) - a) + a (1 - chi), the first term without cancellation
    sag = 0.25 / (math.sqrt(a * a + 0.25) + a)
    return 0.5 - 0.5 * (sag + a * (1.0 - chi))


# ------------------------------------------------------------------------- scales
def delta_kappa0(chi: float) -> float:
    """delta_kappa_m(0) = (pi/2)/kappa_m(0): a terminal quarter circle of the initial curvature.

    >>> round(delta_kappa0(0.25), 6)
    0.06016
    """
    return 0.5 * math.pi / kappa_m0(chi)


def delta_crude(chi: float) -> float:
    """The crude scale delta_c = (1/2) (pi/kappa_m(0))^(4/3) (paper eq. deltacrude).

    Derivation (checked in the tests): the front distance from the end,
    (1/2) (tau/t*)^(2/3), meets the curvature scale (pi/2) kappa_m(0)^-1 (tau/t*)^(1/6)
    at tau/t* = (pi/kappa_m(0))^2, where both equal delta_c.

    >>> round(delta_crude(0.25), 6)
    0.0297
    """
    return 0.5 * (math.pi / kappa_m0(chi)) ** (4.0 / 3.0)


#: most links of a chain (delta_N = 1/N and its peaks stay within the doubles)
N_MAX = 10**15


def delta_N(N: int) -> float:
    """delta_N = 1/N, the only scale if discreteness regularised the snap.

    >>> delta_N(2000)
    0.0005
    """
    N = V.integer("N", N, 1)
    if N > N_MAX:
        raise V.SnappingInputError(f"N={N} is out of range: at most {N_MAX:g} links")
    return 1.0 / N


def whirling_rod(P: float, delta: float) -> dict[str, float]:
    """Peak values of a rigid rod of length delta whirling about s = 1 - delta with
    kinetic energy P (paper eq. estimates).

    ``v = (6 P/delta)^(1/2)``, ``a = v^2/delta``, ``sigma = v^2/2``
    (from P = omega^2 delta^3 / 6 and v = omega delta).

    >>> whirling_rod(0.25, 0.5)
    {'v': 1.7320508075688772, 'a': 5.999999999999999, 'sigma': 1.4999999999999998}
    """
    P = V.positive("P", P)
    delta = V.positive("delta", delta)
    v = math.sqrt(6.0 * P / delta)
    out = {"v": v, "a": v * v / delta, "sigma": 0.5 * v * v}
    if not all(1e-300 < x < 1e300 for x in out.values()):
        raise V.SnappingInputError(f"P={P!r} with delta={delta!r} is out of range: the peaks {out} leave the "
                                   f"doubles (P/delta and P/delta^2 must lie in (1e-300, 1e300))")
    return out


# =============================================================================
# delta_kappa_m: the regularising scale measured on a run (snapping.scaling, issue #4).
# Appended section; takes arrays extracted from a run, never a Dataset.
# =============================================================================
def delta_kappa_m(t, kappa_max, s_kappa_max, *, return_time: bool = False):
    """The scale delta_kappa_m where the curvature peak's distance from the free end
    meets the quarter circle of the peak curvature (paper, "Amplification estimates").

    The front (the fold, traced by the arclength of the curvature maximum
    ``s(kappa_m)``) approaches the free end while the length ``(pi/2)/kappa_m``
    shrinks slowly; the whirling of the free end starts when

        1 - s(kappa_m) = (pi/2) kappa_m^(-1),

    and delta_kappa_m is their common value there (paper Fig. 4(a), black
    circles). The first sign change of ``1 - s(kappa_m) - (pi/2)/kappa_m`` from
    positive to non-positive is located by linear interpolation in time between
    the two recorded steps around it.

    Parameters
    ----------
    t : array_like
        Recorded times (increasing), e.g. a run's ``t``.
    kappa_max : array_like
        Maximum curvature over the chain at those times (``kappa_max``, > 0).
    s_kappa_max : array_like
        Arclength from the pin of the curvature maximum (``s_kappa_max``, in [0, 1]).
    return_time : bool
        Also return the time of the crossing.

    Returns
    -------
    float or (float, float)
        delta_kappa_m, and the crossing time if ``return_time``.

    Raises
    ------
    SnappingInputError
        Arrays of different lengths or non-finite values, or no crossing in the
        record (the run stopped before the front reached the end region).

    Examples
    --------
    >>> t = np.linspace(0.0, 1.0, 11)
    >>> s = 0.5 + 0.5 * t                  # front reaching the end at t = 1
    >>> kap = np.full_like(t, 4 * np.pi)   # (pi/2)/kappa = 0.125
    >>> round(delta_kappa_m(t, kap, s), 12)
    0.125
    """
    t = V.float_array("t", t)
    k = V.float_array("kappa_max", kappa_max)
    s = V.float_array("s_kappa_max", s_kappa_max)
    if not (t.ndim == k.ndim == s.ndim == 1 and t.size == k.size == s.size):
        raise V.SnappingInputError(
            f"t, kappa_max and s_kappa_max must be 1-D arrays of one length; got shapes {t.shape}, {k.shape}, {s.shape}"
        )
    ok = np.isfinite(t) & np.isfinite(k) & np.isfinite(s) & (k > 0)
    t, k, s = t[ok], k[ok], s[ok]
    if t.size < 2:
        raise V.SnappingInputError(f"kappa_max has {t.size} finite positive samples; at least 2 are needed")
    if s.min() < -1e-9 or s.max() > 1.0 + 1e-9:
        raise V.SnappingInputError(
            f"s_kappa_max must lie in [0, 1]; got values in [{s.min()!r}, {s.max()!r}]"
        )
    d_front = 1.0 - s
    d_curv = 0.5 * math.pi / k
    g = d_front - d_curv
    pos = np.nonzero(g > 0)[0]
    if pos.size == 0:
        raise V.SnappingInputError(
            "1 - s_kappa_max is never larger than (pi/2)/kappa_max: the record has no approach of the "
            "curvature peak towards the free end"
        )
    after = np.nonzero(g[pos[0]:] <= 0)[0]
    if after.size == 0:
        raise V.SnappingInputError(
            f"1 - s_kappa_max never falls to (pi/2)/kappa_max (smallest gap {g.min():.3g} > 0 at "
            f"t = {t[np.argmin(g)]:.6g}): the run stopped before the curvature peak neared the free end"
        )
    j = pos[0] + after[0]
    i = j - 1
    f = g[i] / (g[i] - g[j])  # in (0, 1]
    t_c = t[i] + f * (t[j] - t[i])
    delta = d_curv[i] + f * (d_curv[j] - d_curv[i])
    return (float(delta), float(t_c)) if return_time else float(delta)
