"""The shipped table of computed snaps: peaks of the fast exact method, interpolated.

The file ``snapping/data/snap_table.nc`` (built by :mod:`snapping.table.build`, whose
command, CPU time and machine are in its attributes) holds, over a grid of end
separations chi (0.05 to 0.9) x numbers of links N (10 to 10000, the paper's 229 among
them) x tip-mass ratios (0 to 1, for N up to ``n_tip_max``), the peak speed,
acceleration and tension of the free end's snap, the peak curvature, the snapping time
and the regularising scale delta_kappa_m, each from one run of
:func:`snapping.simulate.run` (method ``fast``: exactly inextensible, tol 1e-6).

:func:`lookup` interpolates them (cubic splines of the logarithm of each quantity in
log chi, log N and asinh(tip_mass / 0.001)) in well under a millisecond, with an
error bound: at each grid point, the sum over the axes of the relative error of a
spline through the line's other points (leave one out, i.e. at twice the grid
spacing: an overestimate for smooth data, the real size for data with wiggles);
the bound of a query is the largest of the bounds at the corners of its cell.

Everything is nondimensional (length L, mass M, g: speed sqrt(g L), acceleration g,
tension M g, time sqrt(L/g)); :mod:`snapping.estimates` and :mod:`snapping.design`
convert to SI.

>>> p = lookup(0.25, 229)                       # the paper's chain at chi = 0.25
>>> round(p.values["v_peak"], 1), p.errors["v_peak"] < 0.02
(8.3, True)
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _validate as V

__all__ = ["TABLE_FILE", "QUANTITIES", "ERROR_QUANTITIES", "OutsideTable", "Table", "TablePeaks", "load_table",
           "lookup", "leave_one_out", "TIP_SCALE"]

#: the shipped table (package data)
TABLE_FILE = Path(__file__).resolve().parent.parent / "data" / "snap_table.nc"

#: the interpolated quantities (all positive)
QUANTITIES = ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "t_snap_v", "delta_kappa_m")
#: the quantities with a stored error bound
ERROR_QUANTITIES = ("v_peak", "a_peak", "sigma_peak", "t_snap_v")

#: the tip-mass axis is interpolated in asinh(tip_mass / TIP_SCALE): log-like above 0.001, linear through 0
TIP_SCALE = 1e-3


class OutsideTable(V.SnappingInputError):
    """A query outside the table's range (names the input and the range)."""


def _coords(chi, N, tip):
    return np.log(np.asarray(chi, float)), np.log(np.asarray(N, float)), np.arcsinh(np.asarray(tip, float) / TIP_SCALE)


def _axes(ds, tip: bool):
    """The interpolation axes (log chi, log N[, asinh tip]) of the tip-free or the tip-mass part."""
    x, y, z = _coords(ds["chi"].values, ds["N"].values, ds["tip_mass"].values)
    if not tip:
        return (x, y)
    keep = ds["N"].values <= int(ds.attrs["n_tip_max"])
    return (x, y[keep], z)


def _part(ds, q: str, tip: bool) -> np.ndarray:
    """log of quantity ``q`` on the grid of the tip-free (chi, N) or tip-mass (chi, N <= n_tip_max, tip) part."""
    a = ds[q].values
    if not tip:
        return np.log(a[:, :, 0])
    keep = ds["N"].values <= int(ds.attrs["n_tip_max"])
    return np.log(a[:, keep, :])


def _loo_axis(axis_x: np.ndarray, vals: np.ndarray, axis: int) -> np.ndarray:
    """Relative error at each grid point of a cubic spline along ``axis`` through the other points
    of its line (interior points; the ends take their neighbour's)."""
    from scipy.interpolate import make_interp_spline

    v = np.moveaxis(vals, axis, -1)
    out = np.full(v.shape, np.nan)
    n = axis_x.size
    for idx in np.ndindex(v.shape[:-1]):
        line = v[idx]
        if not np.all(np.isfinite(line)):
            continue
        for m in range(1, n - 1):
            keep = np.arange(n) != m
            k = min(3, keep.sum() - 1)
            pred = make_interp_spline(axis_x[keep], line[keep], k=k)(axis_x[m])
            out[idx + (m,)] = abs(math.expm1(float(pred - line[m])))
        out[idx + (0,)] = out[idx + (1,)]
        out[idx + (n - 1,)] = out[idx + (n - 2,)]
    return np.moveaxis(out, -1, axis)


def leave_one_out(ds, q: str, *, tip: bool) -> np.ndarray:
    """The leave-one-out error bound of quantity ``q`` at every grid point of the
    tip-free (``tip=False``: shape (chi, N)) or tip-mass part (shape (chi, N <= n_tip_max, tip)):
    the sum over the axes of the relative error of the cubic spline along that axis
    through the line's other points."""
    axes = _axes(ds, tip)
    vals = _part(ds, q, tip)
    return sum(_loo_axis(ax, vals, i) for i, ax in enumerate(axes))


@dataclass
class TablePeaks:
    """The interpolated table at one point: ``values[q]`` (nondimensional) and
    ``errors[q]`` (relative error bound, for :data:`ERROR_QUANTITIES`)."""

    chi: float
    N: int
    tip_mass: float
    values: dict = field(default_factory=dict)
    errors: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"chi": self.chi, "N": self.N, "tip_mass": self.tip_mass, "values": dict(self.values),
                "errors": dict(self.errors)}


class Table:
    """The table of computed snaps (a netCDF file written by :mod:`snapping.table.build`)."""

    def __init__(self, ds, path: str = "(in memory)"):
        missing = [q for q in QUANTITIES if q not in ds] + [a for a in ("n_tip_max",) if a not in ds.attrs]
        if missing:
            raise V.SnappingInputError(f"{path} is not a table of computed snaps: {missing} missing")
        self.ds = ds
        self.path = path
        self.chi = ds["chi"].values
        self.N = ds["N"].values
        self.tip = ds["tip_mass"].values
        self.n_tip_max = int(ds.attrs["n_tip_max"])
        self._interp: dict = {}

    # -- ranges
    @property
    def ranges(self) -> dict:
        """The table's ranges: chi, N, tip_mass, and the largest N with a tip mass."""
        return {"chi": (float(self.chi[0]), float(self.chi[-1])), "N": (int(self.N[0]), int(self.N[-1])),
                "tip_mass": (float(self.tip[0]), float(self.tip[-1])), "n_tip_max": self.n_tip_max}

    def check(self, chi, N, tip_mass=0.0) -> None:
        """Raise :class:`OutsideTable` (naming the input and the range) unless the point is inside."""
        r = self.ranges
        chi_a, N_a, tip_a = (np.atleast_1d(np.asarray(v, float)) for v in (chi, N, tip_mass))
        for name, a, (lo, hi) in (("chi", chi_a, r["chi"]), ("links", N_a, r["N"]),
                                  ("tip_mass", tip_a, r["tip_mass"])):
            bad = a[~((a >= lo) & (a <= hi))]
            if bad.size:
                raise OutsideTable(f"{name}={float(bad[0]):g} is outside the table of computed snaps: it covers "
                                   f"{name} in [{lo:g}, {hi:g}]")
        if np.any((tip_a > 0) & (N_a > self.n_tip_max)):
            raise OutsideTable(f"tip_mass={float(tip_a.max()):g} with links={int(N_a.max())}: the table has tip "
                               f"masses only for links <= {self.n_tip_max} (tip_mass 0 for up to {r['N'][1]})")

    # -- interpolation
    def _interpolator(self, q: str, tip: bool):
        key = (q, tip)
        if key not in self._interp:
            from scipy.interpolate import RegularGridInterpolator

            self._interp[key] = RegularGridInterpolator(_axes(self.ds, tip), _part(self.ds, q, tip),
                                                        method="cubic", bounds_error=False, fill_value=None)
        return self._interp[key]

    def _bound(self, q: str, tip: bool, pts: np.ndarray) -> np.ndarray:
        """The largest node error bound over the corners of each point's cell."""
        if tip:
            err = self.ds[f"{q}_error"].values[:, self.N <= self.n_tip_max, :]
        else:
            err = self.ds[f"{q}_error_notip"].values
        axes = _axes(self.ds, tip)
        lo = [np.clip(np.searchsorted(ax, pts[:, d], side="right") - 1, 0, ax.size - 2) for d, ax in enumerate(axes)]
        out = np.zeros(pts.shape[0])
        for corner in np.ndindex(*(2,) * len(axes)):
            out = np.maximum(out, err[tuple(lo[d] + corner[d] for d in range(len(axes)))])
        return out

    def values(self, q: str, chi, N, tip_mass=0.0, *, with_error: bool = False):
        """Quantity ``q`` interpolated at (chi, N, tip_mass) (arrays broadcast), and its
        relative error bound if ``with_error``. Checked to lie inside the table."""
        if q not in QUANTITIES:
            raise V.SnappingInputError(f"quantity={q!r} is not one of {QUANTITIES}")
        self.check(chi, N, tip_mass)
        chi_b, N_b, tip_b = np.broadcast_arrays(*(np.asarray(v, float) for v in (chi, N, tip_mass)))
        shape = chi_b.shape
        x, y, z = (c.ravel() for c in _coords(chi_b, N_b, tip_b))
        out = np.empty(x.size)
        err = np.full(x.size, np.nan)
        for tip in (False, True):
            sel = (z > 0) if tip else (z == 0)
            if not sel.any():
                continue
            pts = np.column_stack((x[sel], y[sel], z[sel]) if tip else (x[sel], y[sel]))
            out[sel] = np.exp(self._interpolator(q, tip)(pts))
            if with_error and q in ERROR_QUANTITIES:
                err[sel] = self._bound(q, tip, pts)
        out, err = out.reshape(shape), err.reshape(shape)
        if not shape:
            out, err = float(out), float(err)
        return (out, err) if with_error else out

    def lookup(self, chi: float, N: int, tip_mass: float = 0.0) -> TablePeaks:
        """Every quantity at one point, with the error bounds."""
        chi = V.real("chi", chi)
        N = V.integer("links", N, 1)
        tip_mass = V.real("tip_mass", tip_mass)
        peaks = TablePeaks(chi=chi, N=N, tip_mass=tip_mass)
        for q in QUANTITIES:
            v, e = self.values(q, chi, N, tip_mass, with_error=True)
            peaks.values[q] = v
            if q in ERROR_QUANTITIES:
                peaks.errors[q] = e
        return peaks


@functools.lru_cache(maxsize=4)
def _load(path: str) -> Table:
    import xarray as xr

    from .._files import check_input

    path = check_input(path, name="table")
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return Table(ds.load(), path)


def load_table(path=None) -> Table:
    """The table of computed snaps (default: the shipped one; loaded once)."""
    return _load(str(TABLE_FILE if path is None else V.file_path("path", path)))


def lookup(chi: float, N: int, tip_mass: float = 0.0) -> TablePeaks:
    """The shipped table's peaks at (chi, N, tip_mass) with their error bounds
    (:meth:`Table.lookup`); :class:`OutsideTable` outside its range."""
    return load_table().lookup(chi, N, tip_mass)
