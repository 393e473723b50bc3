"""Input checks shared by every public function.

Every check raises :class:`SnappingInputError` (a ``ValueError``) whose message
names the parameter, the offending value and the valid range, so that the
command line can print it as one line and exit with status 2.
"""

from __future__ import annotations

import math
import numbers

__all__ = ["SnappingInputError", "real", "positive", "open_interval", "integer", "float_array", "file_path",
           "run_dataset", "nonnegative"]


class SnappingInputError(ValueError):
    """Bad input to a public function: names the parameter, the value and the valid range."""


def _as_float(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        try:
            import numpy as np

            if isinstance(value, np.ndarray) and value.ndim == 0:
                value = value.item()
            else:
                raise TypeError
        except TypeError:
            raise SnappingInputError(
                f"{name}={value!r} is not a real number (expected a finite float)"
            ) from None
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise SnappingInputError(f"{name}={value!r} is not a real number (expected a finite float)")
    try:
        x = float(value)
    except OverflowError:  # an integer beyond the doubles (10**400)
        raise SnappingInputError(f"{name}={_short(value)} is too large: must be a finite float "
                                 f"(|x| < 1.8e308)") from None
    if not math.isfinite(x):
        raise SnappingInputError(f"{name}={x!r} must be a finite real number")
    return x


def real(name: str, value) -> float:
    """Return ``value`` as a finite float, or raise naming ``name``.

    >>> real("t", 3)
    3.0
    >>> real("t", float("nan"))
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: t=nan must be a finite real number
    >>> real("t", True)          # a bool is not a number here
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: t=True is not a real number (expected a finite float)
    """
    return _as_float(name, value)


def positive(name: str, value) -> float:
    """Return ``value`` as a float in (0, inf), or raise naming ``name``.

    >>> positive("tol", 1e-8)
    1e-08
    >>> positive("tol", 0)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: tol=0.0 is out of range: must be > 0
    """
    x = _as_float(name, value)
    if not x > 0.0:
        raise SnappingInputError(f"{name}={x!r} is out of range: must be > 0")
    return x


def open_interval(name: str, value, lo: float, hi: float) -> float:
    """Return ``value`` as a float in the open interval (lo, hi), or raise naming ``name``.

    >>> open_interval("chi", 0.25, 0.0, 1.0)
    0.25
    >>> open_interval("chi", 1.0, 0.0, 1.0)      # the end points are excluded
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: chi=1.0 is out of range: must lie in the open interval (0, 1)
    """
    x = _as_float(name, value)
    if not lo < x < hi:
        raise SnappingInputError(f"{name}={x!r} is out of range: must lie in the open interval ({lo:g}, {hi:g})")
    return x


def nonnegative(name: str, value) -> float:
    """Return ``value`` as a float in [0, inf), or raise naming ``name``.

    >>> nonnegative("max_seconds", -1)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: max_seconds=-1.0 is out of range: must be >= 0
    """
    x = _as_float(name, value)
    if not x >= 0.0:
        raise SnappingInputError(f"{name}={x!r} is out of range: must be >= 0")
    return abs(x)  # (-0.0 is 0)


#: the largest integer accepted when no maximum is given (a count beyond it cannot be meant)
MAX_INTEGER = 2**53


def integer(name: str, value, minimum: int = 1, maximum: int | None = None) -> int:
    """Return ``value`` as an int in [minimum, maximum] (maximum default :data:`MAX_INTEGER`),
    or raise naming ``name``.

    >>> integer("N", 200.0)       # an integral float is accepted
    200
    >>> integer("N", 2.5)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: N=2.5 is not an integer
    >>> integer("levels", 9, 1, 8)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: levels=9 is out of range: must be an integer in [1, 8]
    """
    if isinstance(value, bool):
        raise SnappingInputError(f"{name}={value!r} is not an integer")
    if isinstance(value, numbers.Integral):
        n = int(value)
    elif isinstance(value, numbers.Real) and math.isfinite(float(value)) and float(value).is_integer():
        n = int(value)
    else:
        raise SnappingInputError(f"{name}={value!r} is not an integer")
    hi = "inf" if maximum is None else str(maximum)
    if n < minimum or (maximum is not None and n > maximum):
        raise SnappingInputError(f"{name}={_short(n)} is out of range: must be an integer in [{minimum}, {hi}]")
    if maximum is None and n > MAX_INTEGER:
        raise SnappingInputError(f"{name}={_short(n)} is out of range: too large (at most 2**53 = {MAX_INTEGER})")
    return n


def _short(value) -> str:
    if isinstance(value, int) and abs(value) > 10**30:
        return f"{'-' if value < 0 else ''}10**{len(str(abs(value))) - 1}..."
    r = repr(value)
    return r if len(r) <= 60 else r[:57] + "..."


def float_array(name: str, value):
    """Return ``value`` as a float ndarray, or raise naming ``name`` (strings, objects, ragged lists).

    >>> float_array("s", [0, 0.5, 1])
    array([0. , 0.5, 1. ])
    >>> float_array("s", [[0.0, 1.0], [2.0]])
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: s=[[0.0, 1.0], [2.0]] is not an array of real numbers
    """
    import numpy as np

    if isinstance(value, (str, bytes, dict)):
        raise SnappingInputError(f"{name}={_short(value)} is not an array of real numbers")
    try:
        if np.asarray(value).dtype.kind == "b":  # True/False are not numbers here (as in real)
            raise SnappingInputError(f"{name}={_short(value)} holds True/False: expected real numbers")
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, SnappingInputError):
            raise
        raise SnappingInputError(f"{name}={_short(value)} is not an array of real numbers") from None
    except OverflowError:  # an integer beyond the doubles (10**400)
        raise SnappingInputError(f"{name}={_short(value)} holds a number too large for a float (|x| < 1.8e308)") \
            from None


def file_path(name: str, value) -> str:
    """Return ``value`` as a non-empty path string, or raise naming ``name``.

    >>> file_path("output", "run.nc")
    'run.nc'
    >>> file_path("output", "")
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: output='' is not a file path
    """
    import os

    if isinstance(value, bytes) or not isinstance(value, (str, os.PathLike)):
        raise SnappingInputError(f"{name}={_short(value)} is not a file path")
    p = os.fspath(value)
    if not isinstance(p, str) or not p:
        raise SnappingInputError(f"{name}={_short(value)} is not a file path")
    return p


#: range of a chain's length [m], mass [kg] and g [m/s^2]: beyond, its SI values leave the doubles
SI_SCALE_RANGE = (1e-30, 1e30)


def si_scales(length, mass, g) -> tuple[float, float, float]:
    """``(length, mass, g)`` of a chain in SI as floats, each positive and within
    :data:`SI_SCALE_RANGE`, or raise naming the one that is not.

    >>> si_scales(1.022, 0.0208, 9.81)
    (1.022, 0.0208, 9.81)
    >>> si_scales(1.0, -1.0, 9.81)
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: mass=-1.0 is out of range: must be > 0
    """
    lo, hi = SI_SCALE_RANGE
    out = []
    for name, unit, value in (("length", "m", length), ("mass", "kg", mass), ("g", "m/s^2", g)):
        x = positive(name, value)
        if not lo <= x <= hi:
            raise SnappingInputError(f"{name}={x!r} {unit} is out of range: must lie in [{lo:g}, {hi:g}] "
                                     f"(beyond, the SI values leave the doubles)")
        out.append(x)
    return tuple(out)


def run_dataset(name: str, ds, *, sweep: bool = False):
    """``ds`` if it is a snapping run Dataset (with ``sweep=True``: or a combined sweep of runs,
    over ``chi`` and ``N``); else SnappingInputError saying what it is instead: not a Dataset
    (a path: open it with ``snapping.simulate.load_run``), another program's Dataset (no time
    ``t`` along ``step`` or no attributes ``method`` and ``N``), or a sweep where one run is
    expected. One check for every public function that takes a run.

    >>> run_dataset("ds", "run.nc")
    Traceback (most recent call last):
    ...
    snapping._validate.SnappingInputError: ds='run.nc' is a path, not a run Dataset: open it with snapping.simulate.load_run
    """
    import os

    import xarray as xr

    if isinstance(ds, (str, bytes, os.PathLike)):
        raise SnappingInputError(f"{name}={_short(ds)} is a path, not a run Dataset: open it with "
                                 f"snapping.simulate.load_run")
    if not isinstance(ds, xr.Dataset):
        raise SnappingInputError(f"{name}={_short(ds) if ds is None else type(ds).__name__} is not a run Dataset "
                                 f"(expected an xarray.Dataset from snapping.simulate)")
    is_sweep = "chi" in ds.dims and "N" in ds.dims
    if is_sweep and not sweep:
        raise SnappingInputError(f"{name} is a combined sweep (dimensions chi={ds.sizes['chi']}, N={ds.sizes['N']}), "
                                 f"not one run: give one run (its file, opened with snapping.simulate.load_run)")
    if is_sweep:
        return ds
    has_t = "t" in ds.variables and "step" in ds["t"].dims
    if not has_t or "method" not in ds.attrs or "N" not in ds.attrs:
        raise SnappingInputError(f"{name} is not a snapping run Dataset (no time 't' along 'step' or no attributes "
                                 f"'method' and 'N'; variables: {sorted(map(str, ds.variables))[:6]})")
    return ds
