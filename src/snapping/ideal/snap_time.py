"""The ideal snapping time t* = 2 E(pi/4 | 2) = agm(1, sqrt 2): to any number of digits by four
closed forms (:func:`t_star_mp`, :func:`t_star_str`), and as a double and a double-double
(:data:`T_STAR`, ``_T_HI + _T_LO``).
"""

from __future__ import annotations

import mpmath

from .. import _validate as V
from .._validate import SnappingInputError


T_STAR_METHODS = ("ellipe", "carlson", "agm", "gamma")
_MAX_DIGITS = 100_000
_ELLIPE_MAX_DIGITS = 1000  # summary() switches to the (identical, faster) agm form beyond this


def t_star_mp(digits: int = 30, method: str = "ellipe") -> mpmath.mpf:
    """The ideal snapping time t* = 2 E(pi/4 | 2) to ``digits`` significant digits.

    Paper eq. for t* (after eq. shockvelocity)::

        t* = int_{1/2}^{1} 2 sqrt(2(1-s0)/(1-4(1-s0)^2)) ds0
           = int_0^{1/sqrt 2} 2 sqrt((1-2 z^2)/(1-z^2)) dz = 2 E(pi/4 | 2).

    E(phi | m) is the incomplete elliptic integral of the second kind with
    parameter m = 2 (so m sin^2 phi = 1 at the upper limit: a boundary case at
    which, e.g., ``scipy.special.ellipeinc(pi/4, 2)`` returns NaN; mpmath's
    ``ellipe(phi, m)`` and Carlson's ``elliprf``/``elliprd`` do not).
    Equivalent closed forms (all give the same number; the tests check them
    against each other and against direct quadrature):

    * ``"ellipe"``: ``2 * mpmath.ellipe(pi/4, 2)`` (the paper's form),
    * ``"carlson"``: ``2 [s R_F(c^2, 0, 1) - (2/3) s^3 R_D(c^2, 0, 1)]`` with
      ``s = c = 1/sqrt 2`` (Carlson form of E(phi|m) with 1 - m sin^2 phi = 0),
    * ``"agm"``: ``agm(1, sqrt 2)``, the reciprocal of Gauss's constant
      (t* = int_0^{pi/2} sqrt(sin th) d th = B(3/4, 1/2)/2 with x = sin(th)/2),
    * ``"gamma"``: ``2 sqrt(pi) Gamma(3/4) / Gamma(1/4)``.

    ``ellipe`` and ``carlson`` slow down beyond ~1000 digits; ``agm`` is fastest.

    Parameters
    ----------
    digits : int
        Significant decimal digits, in [1, 100000]. The value is computed with
        10 guard digits and rounded.
    method : str
        One of ``"ellipe"``, ``"carlson"``, ``"agm"``, ``"gamma"``.

    Returns
    -------
    mpmath.mpf
        t*, rounded to ``digits`` significant digits (an mpf at that precision;
        print it with ``mpmath.nstr(value, digits)`` or use :func:`t_star_str`,
        since ``print`` uses mpmath's global precision).

    Raises
    ------
    SnappingInputError
        If ``digits`` is not an integer in [1, 100000] or ``method`` is unknown.

    Examples
    --------
    >>> import mpmath
    >>> mpmath.nstr(t_star_mp(30), 30)
    '1.19814023473559220743992249228'
    >>> t_star_mp(40, "agm") == t_star_mp(40, "carlson")
    True
    """
    digits = V.integer("digits", digits, minimum=1, maximum=_MAX_DIGITS)
    if method not in T_STAR_METHODS:
        raise SnappingInputError(f"method={method!r} is not one of {', '.join(T_STAR_METHODS)}")
    with mpmath.workdps(digits + 10):
        if method == "ellipe":
            value = 2 * mpmath.ellipe(mpmath.pi / 4, 2)
        elif method == "carlson":
            s = 1 / mpmath.sqrt(2)
            value = 2 * (s * mpmath.elliprf(s * s, 0, 1) - mpmath.mpf(2) / 3 * s**3 * mpmath.elliprd(s * s, 0, 1))
        elif method == "agm":
            value = mpmath.agm(1, mpmath.sqrt(2))
        else:
            value = 2 * mpmath.sqrt(mpmath.pi) * mpmath.gamma(mpmath.mpf(3) / 4) / mpmath.gamma(mpmath.mpf(1) / 4)
        value = mpmath.re(value)
    with mpmath.workdps(digits):
        return +value  # round to the requested precision


def t_star_str(digits: int = 30) -> str:
    """t* = 2 E(pi/4 | 2) as a decimal string with exactly ``digits`` significant digits.

    Uses ``mpmath.ellipe`` (the paper's form) up to 1000 digits and the
    identical, faster agm(1, sqrt 2) beyond (see :func:`t_star_mp`).

    Parameters
    ----------
    digits : int
        Significant digits, in [1, 100000].

    Returns
    -------
    str
        Correctly rounded decimal string.

    Examples
    --------
    >>> t_star_str(6), t_star_str(40)
    ('1.19814', '1.198140234735592207439922492280323878227')
    """
    digits = V.integer("digits", digits, minimum=1, maximum=_MAX_DIGITS)
    method = "ellipe" if digits <= _ELLIPE_MAX_DIGITS else "agm"
    with mpmath.workdps(digits + 10):
        return mpmath.nstr(t_star_mp(digits, method), digits, strip_zeros=False).rstrip(".")


with mpmath.workdps(60):
    _T_MP = mpmath.agm(1, mpmath.sqrt(2))
    _T_HI = float(_T_MP)
    _T_LO = float(_T_MP - _T_HI)  # t* = _T_HI + _T_LO in double-double
    _T_STR = mpmath.nstr(_T_MP, 21)

#: t* = 2 E(pi/4 | 2) as the nearest double (paper eq. for t*).
T_STAR: float = _T_HI


def t_star() -> float:
    """The ideal snapping time t* = 2 E(pi/4 | 2) as a float (paper eq. for t*).

    See :func:`t_star_mp` for arbitrary precision and the closed forms.

    Returns
    -------
    float
        1.1981402347355923 (the double nearest to t*; t* itself is
        1.19814023473559220744..., so this double lies just above t*).

    Examples
    --------
    >>> t_star()
    1.1981402347355923
    """
    return T_STAR
