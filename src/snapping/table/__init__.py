"""The shipped table of computed snaps: peaks of the fast exact method, interpolated.

The file ``snapping/data/snap_table.nc`` (built by :mod:`snapping.table.build`, whose
command, CPU time and machine are in its attributes) holds, over a grid of end
separations chi (0.05 to 0.9) x numbers of links N (every N from 10 to 48, then about
2^(1/4) apart up to 1800 and sqrt(2) apart to 10000; the paper's 229 among them) x
tip-mass ratios (0 to 1, for N up to ``n_tip_max``), the peak speed, acceleration and
tension of the snap, the snapping time, the regularising scale delta_kappa_m and the
run's CPU time, each from one run of :func:`snapping.simulate.run` (method ``fast``:
exactly inextensible, tol 1e-6).

:func:`lookup` interpolates them (tensor-product piecewise cubics, 4-point Lagrange,
of the logarithm of each quantity in log chi, log N and asinh(tip_mass / 0.001)) in a
millisecond or so, with an error bound: along each axis where the query is not on a
grid point, the largest leave-one-out error of that axis at the corners of its cell
(the relative error, at a grid point, of the same interpolation through the line's
other points: the interpolation at twice the spacing, an overestimate for smooth peaks
and the real size of wiggles), summed over the axes, times :data:`BOUND_FACTOR`. A point
on the grid is exact.

Everything is nondimensional (length L, mass M, g: speed sqrt(g L), acceleration g,
tension M g, time sqrt(L/g)); :mod:`snapping.estimates` and :mod:`snapping.design`
convert to SI.

>>> p = lookup(0.25, 229)                       # the paper's chain at chi = 0.25
>>> round(p.values["v_peak"], 1), p.errors["v_peak"] < 0.02
(8.3, True)
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _validate as V

__all__ = ["TABLE_FILE", "QUANTITIES", "ERROR_QUANTITIES", "OutsideTable", "Table", "TablePeaks", "load_table",
           "lookup", "leave_one_out", "TIP_SCALE", "BOUND_FACTOR", "BOUND_TRUST", "FEW_LINKS"]

#: the shipped table (package data)
TABLE_FILE = Path(__file__).resolve().parent.parent / "data" / "snap_table.nc"

#: the interpolated quantities (all positive; cpu_s: the CPU time of the run, what a simulation of the point costs)
QUANTITIES = ("v_peak", "a_peak", "sigma_peak", "t_snap_v", "delta_kappa_m", "cpu_s")
#: the quantities with an error bound
ERROR_QUANTITIES = ("v_peak", "a_peak", "sigma_peak", "t_snap_v")

#: the error bound is this many times the leave-one-out errors: the peaks of a discrete chain carry a
#: wiggle of a link's period (the tension at small chi: +-1.5% from one N to the next), which a query
#: between grid points can meet with either sign (calibrated with benchmarks/bench_table.py)
BOUND_FACTOR = 2.0

#: the largest relative error bound that still bounds anything: above it the snap changes character
#: near the point (e.g. a later, larger event of a heavy tip mass between the grid points), and the
#: bound itself can fail (snapping.design treats such a point as unknown)
BOUND_TRUST = 0.5

#: chains of at most this many links snap erratically from one separation to the next: their peaks
#: jump between the table's chi points, where the leave-one-out bound cannot see it (a run costs ms)
FEW_LINKS = 48

#: the tip-mass axis is interpolated in asinh(tip_mass / TIP_SCALE): log-like above 0.001, linear through 0
TIP_SCALE = 1e-3


class OutsideTable(V.SnappingInputError):
    """A query outside the table's range (names the input and the range)."""


def _num(x) -> str:
    """A number as the user would type it: an integer as an integer (``1000000``, not ``1e+06``)."""
    x = float(x)
    return str(int(x)) if x.is_integer() and abs(x) < 1e16 else f"{x:g}"


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
    a = np.asarray(ds[q].values, float)
    if not tip:
        return np.log(a[:, :, 0])
    keep = ds["N"].values <= int(ds.attrs["n_tip_max"])
    return np.log(a[:, keep, :])


def _lagrange(nodes: np.ndarray, x) -> np.ndarray:
    """Weights of the Lagrange polynomial through ``nodes`` (..., 4) at ``x`` (broadcasting to
    ``nodes[..., 0]``, or with a trailing axis of length 1)."""
    x = np.asarray(x, float)
    if x.ndim and x.shape[-1] == 1 and x.ndim == nodes.ndim:
        x = x[..., 0]
    w = np.ones(nodes.shape)
    for j in range(nodes.shape[-1]):
        for k in range(nodes.shape[-1]):
            if k != j:
                w[..., j] *= (x - nodes[..., k]) / (nodes[..., j] - nodes[..., k])
    return w


def _stencil(ax: np.ndarray, x: np.ndarray):
    """The 4 nodes of ``ax`` around each ``x`` (one-sided at the ends) and their cubic Lagrange
    weights; a point on a node gets that node alone (weight 1)."""
    n = ax.size
    i = np.clip(np.searchsorted(ax, x, side="right") - 1, 0, n - 2)
    start = np.clip(i - 1, 0, n - 4)
    idx = start[:, None] + np.arange(4)
    w = _lagrange(ax[idx], x[:, None])
    on = np.isclose(ax[idx], x[:, None], rtol=0.0, atol=1e-12)
    hit = on.any(axis=1)
    w[hit] = on[hit].astype(float)
    return idx, w, i, hit


def _interp(vals: np.ndarray, axes, pts: np.ndarray) -> np.ndarray:
    """Tensor-product piecewise-cubic (4-point Lagrange) interpolation of ``vals`` (grid, k) at
    ``pts`` (m, d): shape (m, k)."""
    st = [_stencil(ax, pts[:, d]) for d, ax in enumerate(axes)]
    out = np.zeros((pts.shape[0], vals.shape[-1]))
    for corner in np.ndindex(*(4,) * len(axes)):
        w = np.ones(pts.shape[0])
        for d, c in enumerate(corner):
            w = w * st[d][1][:, c]
        term = w[:, None] * vals[tuple(st[d][0][:, c] for d, c in enumerate(corner))]
        out += np.where(w[:, None] == 0.0, 0.0, term)  # (a node of weight 0 may be a hole: NaN)
    return out


def _loo_axis(ax: np.ndarray, vals: np.ndarray, axis: int) -> np.ndarray:
    """Relative error at each grid point of the 4-point interpolant along ``axis`` through the
    nearest other points of its line (the interpolant at twice the spacing; the two end points
    take their neighbour's)."""
    v = np.moveaxis(vals, axis, 0)
    n = ax.size
    out = np.full(v.shape, np.nan)
    for m in range(1, n - 1):
        others = [k for k in range(n) if k != m]
        pos = min(max(m - 2, 0), len(others) - 4)  # the 4 others nearest to m
        use = others[pos:pos + 4]
        w = _lagrange(ax[use], np.float64(ax[m]))
        pred = np.tensordot(w, v[use], axes=(0, 0))
        out[m] = np.abs(np.expm1(pred - v[m]))
    out[0], out[n - 1] = out[1], out[n - 2]
    return np.moveaxis(out, 0, axis)


def leave_one_out(ds, q: str, *, tip: bool) -> list:
    """The leave-one-out error of quantity ``q`` along each axis, at every grid point of the
    tip-free (``tip=False``: arrays of shape (chi, N)) or tip-mass part (shape (chi, N <=
    n_tip_max, tip)): the relative error, along that axis, of the interpolant through the
    line's other points (NaN where a line has a hole)."""
    axes = _axes(ds, tip)
    vals = _part(ds, q, tip)
    return [_loo_axis(ax, vals, i) for i, ax in enumerate(axes)]


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

    def check(self, chi, links, tip_mass=0.0) -> None:
        """Raise :class:`OutsideTable` (naming the input and the range) unless the point is inside."""
        r = self.ranges
        chi_a, N_a, tip_a = (np.atleast_1d(V.float_array(n, v)) for n, v in (("chi", chi), ("links", links),
                                                                              ("tip_mass", tip_mass)))
        try:
            np.broadcast_shapes(chi_a.shape, N_a.shape, tip_a.shape)
        except ValueError:
            raise V.SnappingInputError(f"chi, links and tip_mass do not broadcast together: shapes {chi_a.shape}, "
                                       f"{N_a.shape} and {tip_a.shape}") from None
        frac = N_a[np.isfinite(N_a) & (N_a != np.round(N_a))]
        if frac.size:  # a chain has a whole number of links: never interpolated between two
            raise V.SnappingInputError(f"links={float(frac[0])!r} is not an integer (a number of links)")
        for name, a, (lo, hi) in (("chi", chi_a, r["chi"]), ("links", N_a, r["N"]),
                                  ("tip_mass", tip_a, r["tip_mass"])):
            bad = a[~((a >= lo) & (a <= hi))]
            if bad.size:
                raise OutsideTable(f"{name}={_num(bad[0])} is outside the table of computed snaps, which covers "
                                   f"[{_num(lo)}, {_num(hi)}]")
        if np.any((tip_a > 0) & (N_a > self.n_tip_max)):
            raise OutsideTable(f"tip_mass={float(tip_a.max()):g} with links={int(N_a.max())}: the table has tip "
                               f"masses only for links <= {self.n_tip_max} (tip_mass 0 for up to {r['N'][1]})")

    # -- interpolation
    def _stacked(self, tip: bool):
        """(axes, log values stacked over :data:`QUANTITIES` on a last axis, per-axis
        leave-one-out errors of :data:`ERROR_QUANTITIES` stacked the same way), computed once."""
        if tip not in self._interp:
            axes = _axes(self.ds, tip)
            vals = np.stack([_part(self.ds, q, tip) for q in QUANTITIES], axis=-1)
            ie = [QUANTITIES.index(q) for q in ERROR_QUANTITIES]
            errs = [_loo_axis(ax, vals[..., ie], i) for i, ax in enumerate(axes)]
            self._interp[tip] = (axes, vals, errs)
        return self._interp[tip]

    @staticmethod
    def _bound(axes, errs, pts: np.ndarray) -> np.ndarray:
        """The error bound at each point (m, k): over the axes along which it is not on a node,
        the sum of the largest leave-one-out error of that axis at the corners of its cell."""
        st = [_stencil(ax, pts[:, d]) for d, ax in enumerate(axes)]
        corners = []
        for corner in np.ndindex(*(2,) * len(axes)):
            corners.append(tuple(np.where(st[k][3], np.argmax(st[k][1], axis=1) + st[k][0][:, 0], st[k][2] + corner[k])
                                 for k in range(len(axes))))
        out = np.zeros((pts.shape[0], errs[0].shape[-1]))
        for d, err in enumerate(errs):
            worst = np.max([err[idx] for idx in corners], axis=0)
            out += np.where(st[d][3][:, None], 0.0, worst)
        return BOUND_FACTOR * out

    def evaluate(self, chi, links, tip_mass=0.0):
        """Every quantity at the points (chi, links, tip_mass) (arrays broadcast, checked to lie
        inside the table): ``(values, errors)``, dicts of arrays by quantity (errors: relative
        bounds of :data:`ERROR_QUANTITIES`)."""
        self.check(chi, links, tip_mass)
        chi_b, N_b, tip_b = np.broadcast_arrays(*(np.asarray(v, float) for v in (chi, links, tip_mass)))
        shape = chi_b.shape
        x, y, z = (c.ravel() for c in _coords(chi_b, N_b, tip_b))
        out = np.full((x.size, len(QUANTITIES)), np.nan)
        err = np.full((x.size, len(ERROR_QUANTITIES)), np.nan)
        for tip in (False, True):
            sel = (z > 0) if tip else (z == 0)
            if not sel.any():
                continue
            pts = np.column_stack((x[sel], y[sel], z[sel]) if tip else (x[sel], y[sel]))
            axes, vals, errs = self._stacked(tip)
            out[sel] = np.exp(_interp(vals, axes, pts))
            err[sel] = self._bound(axes, errs, pts)
        values = {q: out[:, i].reshape(shape) for i, q in enumerate(QUANTITIES)}
        errors = {q: err[:, i].reshape(shape) for i, q in enumerate(ERROR_QUANTITIES)}
        return values, errors

    def values(self, q: str, chi, links, tip_mass=0.0, *, with_error: bool = False):
        """Quantity ``q`` interpolated at (chi, links, tip_mass) (arrays broadcast), and its
        relative error bound if ``with_error`` (NaN for a quantity without one)."""
        if q not in QUANTITIES:
            raise V.SnappingInputError(f"quantity={q!r} is not one of {QUANTITIES}")
        values, errors = self.evaluate(chi, links, tip_mass)
        v = values[q]
        e = errors.get(q, np.full(v.shape, np.nan))
        if not v.shape:
            v, e = float(v), float(e)
        return (v, e) if with_error else v

    def lookup(self, chi: float, links: int, tip_mass: float = 0.0) -> TablePeaks:
        """Every quantity at one point (``links``: the number of links N), with the error bounds."""
        chi = V.real("chi", chi)
        N = V.integer("links", links, 1)
        tip_mass = V.real("tip_mass", tip_mass)
        values, errors = self.evaluate(chi, N, tip_mass)
        return TablePeaks(chi=chi, N=N, tip_mass=tip_mass, values={q: float(v) for q, v in values.items()},
                          errors={q: float(e) for q, e in errors.items()})


class _Variable:
    """One variable of a :class:`_NetcdfFile`: its ``values`` and ``attrs``, as xarray names them."""

    def __init__(self, values: np.ndarray, attrs: dict):
        self.values, self.attrs = values, attrs


class _NetcdfFile:
    """The parts of an xarray Dataset that :class:`Table` reads (``ds[name].values``, ``ds.attrs``,
    ``name in ds``), read with netCDF4 alone: importing xarray (with pandas and dask) costs about
    half a second, a hundred times a table query. Fill values read as NaN, as xarray decodes them."""

    def __init__(self, path: str):
        import netCDF4

        with netCDF4.Dataset(path) as nc:
            self.attrs = {a: nc.getncattr(a) for a in nc.ncattrs()}
            self._vars = {}
            for name, var in nc.variables.items():
                data = var[...]
                if np.ma.isMaskedArray(data):
                    data = data.filled(np.nan) if data.dtype.kind == "f" else data.data
                self._vars[name] = _Variable(np.asarray(data), {a: var.getncattr(a) for a in var.ncattrs()})

    def __contains__(self, name) -> bool:
        return name in self._vars

    def __getitem__(self, name) -> _Variable:
        return self._vars[name]


@functools.lru_cache(maxsize=4)
def _load(path: str) -> Table:
    from .._files import check_input

    path = check_input(path, name="table")
    try:
        return Table(_NetcdfFile(path), path)
    except (OSError, ValueError, KeyError, IndexError, RuntimeError) as exc:  # not a table file: named, one line
        if isinstance(exc, V.SnappingInputError):
            raise
        why = (str(exc).strip().splitlines() or [type(exc).__name__])[0][:160]
        raise V.SnappingInputError(f"table={path!r} cannot be read as a snapping table (netCDF4 with chi, N and "
                                   f"the peaks): {type(exc).__name__}: {why}") from None


def load_table(path=None) -> Table:
    """The table of computed snaps (default: the shipped one; loaded once)."""
    return _load(str(TABLE_FILE if path is None else V.file_path("path", path)))


def lookup(chi: float, links: int, tip_mass: float = 0.0) -> TablePeaks:
    """The shipped table's peaks at (chi, links, tip_mass) with their error bounds
    (:meth:`Table.lookup`); :class:`OutsideTable` outside its range."""
    return load_table().lookup(chi, links, tip_mass)
