"""The continuum limit of the snap: graded chains refined level by level, extrapolated.

:func:`converge` runs the chain released from the catenary of separation ``chi`` at a
sequence of resolutions (the links of :func:`snapping.simulate.grading.fold_following`,
every length scale of the grading -- ``frac``, ``h_min``, ``h_max`` -- multiplied by
``ratio`` from one level to the next; masses lumped consistently), reads the peaks of
speed, acceleration, tension and curvature and the snapping time at each, estimates the
observed order of convergence and extrapolates (Richardson) to the string, with an
error bar from the spread of successive extrapolations.

Extrapolation (:func:`extrapolate`). With levels at resolutions ``h_k = h_0 r^k`` and a
quantity ``q_k = q_inf + C h_k^p + ...``, three successive levels give the order
``p = log(d_{k-1}/d_k)/log(1/r)`` (``d_k = q_k - q_{k-1}``) and the limit
``q_inf = q_k + d_k/(r^-p - 1)``. The error bar is the difference between the last two
such extrapolations (four levels or more), and never less than a tenth of the last
correction; with three levels it is the last correction itself. Successive differences
that change sign or do not shrink mean no asymptotic convergence: the verdict then says
so and the error bar is the spread of the last levels.

Example
-------
>>> import numpy as np
>>> from snapping.continuum import extrapolate
>>> h = 0.1 * 0.5 ** np.arange(5)
>>> e = extrapolate(h, 3.0 + 2.0 * h**2 - h**3)
>>> round(e["limit"], 6), round(e["order"], 2), e["converging"]
(3.0, 1.99, True)
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import time
from dataclasses import dataclass

import numpy as np
import xarray as xr

from . import _validate as V

__all__ = ["converge", "extrapolate", "level_parameters", "Convergence", "QUANTITIES"]

#: the peaks studied, and their names in a run's attributes
QUANTITIES = ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "t_snap_v")
#: the coarsest level's grading (fractions of the fold's radius, links at the free end, held arm)
FRAC0, H_MIN0, H_MAX0 = 0.04, 4e-6, 4e-3
#: most refinement levels, and the smallest length scales of the finest level (beyond, its chain
#: has more links than a run can hold)
MAX_LEVELS = 30
FINEST = {"frac": 1e-6, "h_min": 1e-15, "h_max": 1e-7}


def level_parameters(levels: int = 4, ratio: float = 0.5, *, frac0: float = FRAC0, h_min0: float = H_MIN0,
                     h_max0: float = H_MAX0, first: int = 0) -> list[dict]:
    """The grading parameters of each level: every length scale times ``ratio`` per level.

    >>> [p["frac"] for p in level_parameters(3)]
    [0.04, 0.02, 0.01]
    """
    levels = V.integer("levels", levels, 1, MAX_LEVELS)
    ratio = V.open_interval("ratio", ratio, 0.0, 1.0)
    first = V.integer("first", first, -20, 100)
    frac0 = V.open_interval("frac0", frac0, 0.0, 1.0)
    h_min0 = V.open_interval("h_min0", h_min0, 0.0, 1.0)
    h_max0 = V.open_interval("h_max0", h_max0, 0.0, 1.0)
    if h_max0 < h_min0:
        raise V.SnappingInputError(f"h_max0={h_max0!r} is out of range: must be >= h_min0={h_min0!r}")
    how = f"levels={levels}, ratio={ratio!r}, first={first}"
    try:
        out = [{"frac": frac0 * ratio**k, "h_min": h_min0 * ratio**k, "h_max": min(0.5, h_max0 * ratio**k)}
               for k in range(first, first + levels)]
    except (OverflowError, ZeroDivisionError):  # ratio**first beyond the doubles
        raise V.SnappingInputError(f"{how}: ratio**first={ratio!r}**{first} leaves the doubles (use first >= 0 "
                                   f"or a ratio closer to 1)") from None
    c, f = out[0], out[-1]
    if not c["frac"] < 1.0 or not c["h_min"] < 0.5:
        raise V.SnappingInputError(f"{how} with frac0={frac0!r}, h_min0={h_min0!r} make the coarsest level's "
                                   f"frac={c['frac']:.3g}, h_min={c['h_min']:.3g}: must be < 1 and < 0.5 (use a "
                                   f"larger first)")
    given = {"frac": frac0, "h_min": h_min0, "h_max": h_max0}
    for key, floor in FINEST.items():
        if not f[key] >= floor:
            raise V.SnappingInputError(f"{how} with {key}0={given[key]!r} make the finest level's "
                                       f"{key}={f[key]:.3g} < {floor:g} (too many links): use fewer levels, a "
                                       f"smaller first or a ratio closer to 1")
    return out


def extrapolate(h, q) -> dict:
    """Observed order, Richardson limit and error bar of ``q`` sampled at resolutions ``h``
    (decreasing by a constant ratio). Returns ``limit``, ``error``, ``order``,
    ``converging`` (bool) and ``digits`` (significant digits the error bar supports)."""
    h = np.asarray(V.float_array("h", h), dtype=float)
    q = np.asarray(V.float_array("q", q), dtype=float)
    if h.size != q.size or h.size < 2:
        raise V.SnappingInputError(f"extrapolate needs h and q of one length >= 2; got {h.size} and {q.size}")
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(h)) and np.all(h > 0)):
        raise V.SnappingInputError("extrapolate needs finite q and positive resolutions h")
    r = h[1:] / h[:-1]
    if not np.allclose(r, r[0], rtol=1e-9) or not 0.0 < r[0] < 1.0:
        raise V.SnappingInputError("extrapolate needs resolutions h decreasing by one constant ratio")
    r = float(r[0])
    d = np.diff(q)
    out = {"limit": float(q[-1]), "error": float(abs(d[-1])), "order": float("nan"), "converging": False}
    if q.size >= 3:
        ests, orders = [], []
        for k in range(2, q.size):
            d1, d2 = d[k - 2], d[k - 1]
            if d1 == 0.0 or d2 == 0.0 or np.sign(d1) != np.sign(d2) or abs(d2) >= abs(d1):
                ests.append(None)
                orders.append(float("nan"))
                continue
            p = math.log(abs(d1 / d2)) / math.log(1.0 / r)
            orders.append(p)
            ests.append(q[k] + d2 / (r ** -p - 1.0))
        if ests[-1] is not None:
            lim = float(ests[-1])
            err = abs(lim - q[-1])  # with three levels: the correction itself
            if len(ests) >= 2 and ests[-2] is not None:
                err = max(abs(lim - float(ests[-2])), 0.1 * abs(lim - q[-1]))
            out.update({"limit": lim, "error": float(err), "order": float(orders[-1]), "converging": True})
        else:
            out["error"] = float(np.ptp(q[-3:]))
    scale = abs(out["limit"]) if out["limit"] != 0.0 else 1.0
    out["digits"] = int(math.floor(-math.log10(out["error"] / scale))) if out["error"] > 0.0 else 16
    return out


@dataclass
class Convergence:
    """The result of :func:`converge`: ``dataset`` (dimension ``level``: links, grading,
    peaks, cost; attributes: for each quantity its ``*_limit``, ``*_error``, ``*_order``
    and a ``verdict``) and the run files of the levels (``paths``, when written)."""

    dataset: xr.Dataset
    paths: list

    def summary(self) -> dict:
        a = self.dataset.attrs
        out = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in a.items()}
        if out.get("body"):  # a line's body: its numbers (beta, drag, ...)
            from .simulate.body import summarize

            out["body"] = summarize(str(out["body"]))
        return out

    def table(self) -> str:
        ds = self.dataset
        lines = [f"continuum limit, chi = {ds.attrs['chi']:g} ({ds.attrs['lumping']} lumping, "
                 f"free end {ds.attrs['free_end']}"
                 + (f"; uniform chains with the body {self.summary()['body']}" if ds.attrs.get("body") else "")
                 + (f"; uniform extensible lines {ds.attrs['elastic']}" if ds.attrs.get("elastic") else "")
                 + "):",
                 f"{'level':>5} {'links':>7} {'frac':>8} {'h_min':>8} " + " ".join(f"{q:>13}" for q in QUANTITIES)
                 + f" {'wall s':>7} {'CPU s':>7}"]
        for k in range(ds.sizes["level"]):
            lines.append(f"{k:5d} {int(ds.n_links[k]):7d} {float(ds.frac[k]):8.3g} {float(ds.h_min[k]):8.2g} "
                         + " ".join(f"{float(ds[q][k]):13.8g}" for q in QUANTITIES) + f" {float(ds.wall_time[k]):7.2f}"
                         + f" {float(ds.cpu_time[k]):7.2f}")
        lines.append(f"{'limit':>32} " + " ".join(f"{ds.attrs[q + '_limit']:13.8g}" for q in QUANTITIES))
        lines.append(f"{'+-':>32} " + " ".join(f"{ds.attrs[q + '_error']:13.2g}" for q in QUANTITIES))
        lines.append(f"{'order':>32} " + " ".join(f"{ds.attrs[q + '_order']:13.3g}" if np.isfinite(ds.attrs[q + '_order'])
                                                  else f"{'-':>13}" for q in QUANTITIES))  # (not measured: "-")
        lines.append(f"verdict: {ds.attrs['verdict']}")
        return "\n".join(lines)

    def plot(self, path=None):
        """Peaks against resolution (the fold fraction ``frac``) with the limit and its band."""
        from .figures import convergence_figure

        return convergence_figure(self.dataset, path)


def _level_links(chi, params):
    """The link lengths of a level: fold-following (``frac``, ``h_min``, ``h_max``) or, with a
    body, ``n_links`` uniform links."""
    if "n_links" in params:
        return np.full(int(params["n_links"]), 1.0 / int(params["n_links"]))
    from .simulate import grading

    return grading.fold_following(chi, **params)


def _uniform_levels(levels: int, ratio: float, n0: int, first: int) -> list[dict]:
    """Uniform chains of ``n0 / ratio**k`` links (k = first, ...): whole numbers at a constant ratio."""
    levels = V.integer("levels", levels, 1, MAX_LEVELS)
    ratio = V.open_interval("ratio", ratio, 0.0, 1.0)
    n0 = V.integer("n0", n0, 1, 10**7)
    out = []
    for k in range(first, first + levels):
        x = n0 / ratio ** k
        n = int(round(x))
        if n < 1 or abs(n - x) > 1e-9 * x or n > 10**7:
            raise V.SnappingInputError(f"n0={n0}, ratio={ratio!r}, first={first}: level {k} would have {x:.6g} "
                                       f"links; with a body the levels are uniform chains of n0/ratio**k links, "
                                       f"whole numbers from 1 to 1e7 (e.g. ratio 0.5)")
        out.append({"n_links": n, "frac": 1.0 / n, "h_min": 1.0 / n, "h_max": 1.0 / n})
    return out


def _run_level(args):
    """One level's run (in a worker process): the graded chain, its peaks and cost."""
    chi, params, lumping, free_end, tol, path, body, *elastic = args
    from .simulate import Body, Links, Problem, load_run, run

    h = _level_links(chi, params)
    if elastic and elastic[0] is not None:  # the extensible line (snapping.sweep_elastic)
        from .sweep_elastic import level_row

        return level_row(chi, h, lumping, free_end, tol, path, elastic[0], *elastic[1:], body_d=body), path
    problem = Problem.catenary(chi, links=Links.graded(h, lumping=lumping, free_end=free_end), chords="exact",
                               body=None if body is None else Body.from_describe(body))
    if path is not None and os.path.isfile(path):
        try:
            ds = load_run(path)
            if (ds.attrs.get("status") == "completed" and "link_length" in ds.variables
                    and np.array_equal(ds.link_length.values, h) and float(ds.attrs["tol"]) == tol
                    and np.array_equal(ds.node_mass.values[:-1], problem.links.m)
                    and (json.loads(ds.attrs["body"]) if ds.attrs.get("body") else None) == body):
                return _level_row(ds, h, float("nan")), path  # resumed: this level is done (its CPU time unknown)
        except V.SnappingInputError:
            pass
    cpu = time.process_time()  # this process's CPU time (the runs are single-threaded): honest under load
    ds = run(problem, method="fast", tol=tol, progress=False, output=path, overwrite=True).dataset  # own files
    return _level_row(ds, h, time.process_time() - cpu), path


def _level_row(ds, h, cpu_time) -> dict:
    a = ds.attrs
    row = {q: float(a[q]) for q in QUANTITIES}
    row.update({"n_links": int(h.size), "wall_time": float(a["wall_time"]), "cpu_time": cpu_time,
                "n_rhs": int(a["n_rhs"]),
                "energy_drift": float(a["energy_drift"]), "link_drift": float(a["link_drift"])})
    return row


def converge(chi: float, *, levels: int = 4, ratio: float = 0.5, first: int = 0, lumping: str = "shared",
             free_end: str | None = None, tol: float = 1e-7, output=None, workers: int = 1,
             progress: bool | None = False, frac0: float = FRAC0, h_min0: float = H_MIN0,
             h_max0: float = H_MAX0, overwrite: bool = False, body=None, n0: int = 50,
             elastic=None, elastic_start: str | None = None) -> Convergence:
    """Refine graded chains from the catenary of separation ``chi`` and extrapolate the snap's
    peaks to the continuum (the string).

    Parameters
    ----------
    chi : float
        End separation of the catenary start, in (0, 1).
    levels : int
        Number of refinement levels (>= 3 for an order and a limit, >= 4 for an error bar
        from two extrapolations).
    ratio : float
        Factor of every length scale of the grading from one level to the next, in (0, 1).
        The error bar compares the extrapolations of the last two triples of levels, so the
        last four levels must all be in the asymptotic range; the cost is dominated by the
        finest (~``ratio**-2`` times the one before). A ratio closer to 1 from a finer
        ``first`` keeps four levels within a narrower, asymptotic range of resolutions for
        less cost: at chi = 0.05, ``ratio=2**-0.5, first=3`` (fractions 0.0141 to 0.005,
        33 759 links at the finest) reaches relative error bars <= 3.2e-4 in ~230 s of CPU,
        where ``ratio=0.5`` from level 0 needs a fifth level (67 490 links, 744 s in all):
        its coarsest level (fraction 0.04, order 1.5-1.8 there) inflates the 4-level error
        bars to 3e-3 and 4e-3 (``benchmarks/bench_continuum.py``).
    first : int
        Index of the coarsest level (0: ``frac0, h_min0, h_max0``; level k has every length
        scale times ``ratio**k``).
    lumping, free_end
        Mass lumping of the graded chains (:meth:`snapping.simulate.Links.graded`).
    tol : float
        Tolerance of the fast method (dop853) at every level. The default 1e-7 is the
        cheapest measured: on the fold-following chains the peaks at tol 1e-6, 1e-7 and
        1e-8 agree to 3e-8 (chi = 0.1, 7328 links) and 1e-10 (chi = 0.25, 4835 links),
        with 38 379 evaluations at 1e-7 against 54 104 at 1e-8 and 45 522 at 1e-6.
    output : path, optional
        Directory for the levels' run files (``level{k}.nc``) and ``convergence.nc``; a
        rerun reuses the levels already there (resumable).
    workers : int
        Levels run in parallel in this many processes.
    progress : bool or None
        One line per finished level on stderr.
    overwrite : bool
        Replace files in ``output`` named like a level (or ``convergence.nc``) that snapping did
        not write (default: refuse them before any run).
    body : Body, optional
        A line's body (:class:`snapping.simulate.Body`: bending stiffness, drag; numbers, the
        same at every level): the limit is then the rod's, whose fold has a finite radius
        (about sqrt(B/T)), and the levels are uniform chains of ``n0 / ratio**k`` links
        (k = ``first``, ...; the fold-following grading resolves the string's singular fold,
        whose smallest links a bending wave's explicit step could not afford). The
        resolution ``frac`` is then the link length 1/N.
    n0 : int
        Links of level 0 with a body (default 50).
    elastic : Elastic, optional
        The extensible line's links (:class:`snapping.simulate.elastic.Elastic` with numbers): the
        levels are uniform chains of ``n0 / ratio**k`` links as with a body, each run through
        :func:`snapping.simulate.elastic.solve` (:mod:`snapping.sweep_elastic`); ``kappa_peak``
        is the run's (the chain's discrete curvature on the rest lengths, branch stretchk).
    elastic_start : {"stretched", "matched", "unstretched"}, optional
        The extensible line's start (:func:`snapping.simulate.elastic.solve`'s ``start``;
        default ``"stretched"``), recorded in the Dataset's ``elastic_start`` attribute.

    Returns
    -------
    Convergence

    Examples
    --------
    >>> c = converge(0.5, levels=3, first=-2)          # coarse and quick
    >>> c.dataset.n_links.values.tolist(), round(c.dataset.attrs["v_peak_order"], 1)
    ([123, 189, 324], 1.4)
    """
    import sys

    from .estimates import check_chi

    chi = check_chi(chi)
    workers = V.integer("workers", workers, 1)
    first = V.integer("first", first, -20, 100)
    body_d = None
    if body is not None:
        from .sweep import _body_description

        from .simulate import Body

        body_d = _body_description(body, "body")
        if not Body.from_describe(body_d).active:  # (a body that changes nothing: the string's study)
            body_d = None
    elastic_d = None
    if elastic is not None:
        from .sweep_elastic import description

        elastic_d = description(elastic, "elastic")
        from .simulate.elastic import STARTS

        elastic_start = "stretched" if elastic_start is None else elastic_start
        if not isinstance(elastic_start, str) or elastic_start not in STARTS:
            raise V.SnappingInputError(f"elastic_start={elastic_start!r} is not one of {STARTS}")
    elif elastic_start is not None:
        raise V.SnappingInputError(f"elastic_start={elastic_start!r} is the extensible line's start: give elastic too")
    if body_d is not None or elastic_d is not None:
        params = _uniform_levels(levels, ratio, n0, first)
    else:
        params = level_parameters(levels, ratio, frac0=frac0, h_min0=h_min0, h_max0=h_max0, first=first)
    paths = [None] * len(params)
    # check every level's chain before any runs (bad input raises here, nothing written)
    from .simulate import Links, grading
    from .simulate.options import RunOptions, check_memory

    opts = RunOptions(tol=tol)
    for k, p in enumerate(params):
        h = _level_links(chi, p)
        Links.graded(h, lumping=lumping, free_end=free_end)
        try:  # (what simulate refuses: a level that would not fit in memory, e.g. at chi = 1e-100)
            check_memory(h.size, opts, chi=chi, method="fast")
        except V.SnappingInputError as exc:
            raise V.SnappingInputError(f"chi={chi!r}: level {first + k} of the study cannot run: {exc}") from None
    if not isinstance(overwrite, bool):
        raise V.SnappingInputError(f"overwrite={overwrite!r} must be True or False")
    from ._files import check_own_files, output_dir

    with contextlib.ExitStack() as stack:  # a new -o directory is removed again if the study fails before a file
        if output is not None:
            out = stack.enter_context(output_dir(output, name="output"))
            paths = [os.path.join(out, f"level{first + k}.nc") for k in range(len(params))]
            check_own_files(paths + [os.path.join(out, "convergence.nc")], name="output", overwrite=overwrite)
        jobs = [(chi, p, lumping, free_end, tol, path, body_d, elastic_d, elastic_start)
                for p, path in zip(params, paths)]
        t0 = time.perf_counter()
        rows = [None] * len(jobs)
        if workers == 1 or len(jobs) == 1:
            for k, job in enumerate(jobs):
                rows[k], _ = _run_level(job)
                if progress:
                    print(f"converge chi={chi:g}: level {k + 1}/{len(jobs)} ({rows[k]['n_links']} links) done in "
                          f"{rows[k]['wall_time']:.1f} s", file=sys.stderr, flush=True)
        else:
            from . import _workers

            def collect(args, result):
                k = jobs.index(args[0])
                rows[k], _ = result()
                if progress:
                    print(f"converge chi={chi:g}: level {k + 1}/{len(jobs)} done", file=sys.stderr, flush=True)

            # (workers leave with this process)
            _workers.run_all(min(workers, len(jobs)), _run_level, [(job,) for job in jobs], collect)
        ds = _dataset(chi, params, rows, lumping, free_end, tol, ratio, time.perf_counter() - t0)
        if body_d is not None or elastic_d is not None:
            ds.attrs["grading"] = "uniform"
            for k, d in (("body", body_d), ("elastic", elastic_d)):
                if d is not None:
                    ds.attrs[k] = json.dumps(d, sort_keys=True)
            if elastic_d is not None:
                ds.attrs["elastic_start"] = elastic_start
        if output is not None:
            from .simulate import save

            save(ds, os.path.join(out, "convergence.nc"), overwrite=True)  # the directory's own summary
        return Convergence(ds, [p for p in paths if p is not None])


def _dataset(chi, params, rows, lumping, free_end, tol, ratio, wall) -> xr.Dataset:
    lev = "level"
    data = {
        "n_links": (lev, np.array([r["n_links"] for r in rows]), {"long_name": "number of links", "units": "1"}),
        "frac": (lev, np.array([p["frac"] for p in params]),
                 {"long_name": "link length along the fold's path / its radius of curvature", "units": "1"}),
        "h_min": (lev, np.array([p["h_min"] for p in params]), {"long_name": "link length at the free end", "units": "1"}),
        "h_max": (lev, np.array([p["h_max"] for p in params]), {"long_name": "largest link length", "units": "1"}),
        "wall_time": (lev, np.array([r["wall_time"] for r in rows]), {"long_name": "wall time of the run", "units": "s"}),
        "cpu_time": (lev, np.array([r["cpu_time"] for r in rows]),
                     {"long_name": "CPU time of the run (its process; NaN where the level was resumed)", "units": "s"}),
        "n_rhs": (lev, np.array([r["n_rhs"] for r in rows]), {"long_name": "right-hand-side evaluations", "units": "1"}),
        "energy_drift": (lev, np.array([r["energy_drift"] for r in rows]), {"long_name": "max |E(t) - E(0)|", "units": "1"}),
        "link_drift": (lev, np.array([r["link_drift"] for r in rows]), {"long_name": "max relative link error", "units": "1"}),
    }
    from . import schema

    for q in QUANTITIES:
        data[q] = (lev, np.array([r[q] for r in rows]), {"long_name": schema.RESULT_ATTRS[q], "units": "1"})
    attrs = {"title": "snapping: continuum limit of the snap (graded chains, Richardson extrapolation)",
             "chi": chi, "lumping": lumping, "free_end": free_end or ("half" if lumping == "shared" else "whole"),
             "grading": "fold", "ratio": ratio, "tol": tol, "wall_time_total": wall}
    verdicts = []
    for q in QUANTITIES:
        if np.all(np.isnan(data[q][1])):  # not measured (the extensible line's curvature before branch stretchk)
            attrs.update({f"{q}_limit": np.nan, f"{q}_error": np.nan, f"{q}_order": np.nan, f"{q}_digits": 0})
            continue
        e = extrapolate(data["frac"][1], data[q][1]) if len(rows) >= 2 else \
            {"limit": float(data[q][1][-1]), "error": float("nan"), "order": float("nan"), "converging": False,
             "digits": 0}
        attrs[f"{q}_limit"] = e["limit"]
        attrs[f"{q}_error"] = e["error"]
        attrs[f"{q}_order"] = e["order"]
        attrs[f"{q}_digits"] = e["digits"]
        if q != "t_snap_v":
            verdicts.append(f"{q}: converged to {e['digits']} significant digits (order {e['order']:.2f})"
                            if e["converging"] else f"{q}: not converging over these levels")
    attrs["verdict"] = "; ".join(verdicts)
    return xr.Dataset(data, attrs=attrs)


# ---------------------------------------------------------------- the report section (snapping reproduce)
def _limit(ds, q) -> tuple[float, float]:
    return float(ds.attrs[q + "_limit"]), float(ds.attrs[q + "_error"])


def report_section(studies: dict, uniform: dict, finest: dict, fits: dict | None = None) -> list[str]:
    """Markdown lines of the report's "continuum limit" section.

    ``studies``: chi -> :class:`Convergence`; ``uniform``: chi -> the paper's run (its
    largest N) to compare with; ``finest``: chi -> the finest level's run Dataset (for
    delta_kappa_m); ``fits``: chi -> :func:`snapping.scaling.fit_run` of that run (Fig. 3's
    exponents refitted on the converged chain). Every verdict is computed from the numbers
    in its row."""
    from . import estimates

    lines = ["## The continuum limit", "",
             "Chains whose links follow the fold (`snapping.simulate.grading.fold_following`, masses lumped "
             "consistently, `snapping converge`), refined level by level (every length scale x 1/2) and "
             "extrapolated to the string (Richardson, observed order; error bar: the spread of the last two "
             "extrapolations).", "",
             "| chi | levels (links at the finest) | v limit | a limit | sigma limit | order v/a/sigma | "
             "paper's chain: N, offset of v/a/sigma from the limit | verdict |", "|---|---|---|---|---|---|---|---|"]
    chis = sorted(studies)
    for chi in chis:
        ds = studies[chi].dataset
        cells = [f"{_limit(ds, q)[0]:.6g} ± {_limit(ds, q)[1]:.1g}" for q in ("v_peak", "a_peak", "sigma_peak")]
        orders = "/".join(f"{float(ds.attrs[q + '_order']):.2f}" for q in ("v_peak", "a_peak", "sigma_peak"))
        u = uniform.get(chi)
        off = "-"
        if u is not None:
            off = f"N = {int(u.attrs['N'])}: " + ", ".join(
                f"{(float(u.attrs[q]) / _limit(ds, q)[0] - 1):+.2%}" for q in ("v_peak", "a_peak", "sigma_peak"))
        digits = min(int(ds.attrs[q + "_digits"]) for q in ("v_peak", "a_peak", "sigma_peak"))
        conv = all(np.isfinite(float(ds.attrs[q + "_order"])) for q in ("v_peak", "a_peak", "sigma_peak"))
        verdict = (f"converged: {digits} significant digits or more" if conv and digits >= 2 else
                   "not converged over these levels")
        lines.append(f"| {chi:g} | {ds.sizes['level']} ({int(ds.n_links[-1])}) | {cells[0]} | {cells[1]} | "
                     f"{cells[2]} | {orders} | {off} | {verdict} |")
    # a finite limit, and its scaling with chi
    lines += [""]
    if len(chis) >= 3:
        v = np.array([_limit(studies[c].dataset, "v_peak")[0] for c in chis])
        slope = float(np.polyfit(np.log(chis), np.log(v), 1)[0])
        lines.append(f"The limit is finite at every chi (the snap is regularised without discreteness); the "
                     f"converged peak speed scales as chi^{slope:.3f} over chi = {chis[0]:g} .. {chis[-1]:g} "
                     f"(least squares in log-log).")
    else:
        lines.append("The limit is finite at the chi studied (the snap is regularised without discreteness); "
                     "its scaling with chi needs three chi or more (`snapping reproduce --full`).")
    # which scale predicts the converged peaks
    lines += ["", "| chi | predicted / converged peaks (eq. estimates): delta_kappa0 | delta_c | delta_kappa_m | best |",
              "|---|---|---|---|---|"]
    for chi in chis:
        ds = studies[chi].dataset
        P = estimates.available_energy(chi)
        deltas = {"delta_kappa0": estimates.delta_kappa0(chi), "delta_c": estimates.delta_crude(chi)}
        f = finest.get(chi)
        if f is not None:
            try:
                deltas["delta_kappa_m"] = estimates.delta_kappa_m(f.t.values, f.kappa_max.values, f.s_kappa_max.values)
            except Exception:  # noqa: BLE001 - no crossing recorded
                pass
        cells, worst = [], {}
        for name in ("delta_kappa0", "delta_c", "delta_kappa_m"):
            if name not in deltas:
                cells.append("-")
                continue
            pr = estimates.whirling_rod(P, deltas[name])
            ratios = {k: pr[k] / _limit(ds, q)[0] for k, q in (("v", "v_peak"), ("a", "a_peak"),
                                                                 ("sigma", "sigma_peak"))}
            worst[name] = max(abs(math.log(r)) for r in ratios.values())
            cells.append(", ".join(f"{k} ×{r:.2f}" for k, r in ratios.items()))
        best = min(worst, key=worst.get)
        lines.append(f"| {chi:g} | {cells[0]} | {cells[1]} | {cells[2]} | {best} (worst factor "
                     f"{math.exp(worst[best]):.2f}) |")
    if fits:
        from . import scaling

        lines += ["", "Fig. 3's exponents refitted on the finest level of each study (does the late curvature "
                  "exponent -1/6 survive refinement?):", "",
                  "| chi (links) | quantity | exponent (t* = t*_chi) | reference | window t*-t | verdict |",
                  "|---|---|---|---|---|---|"]
        for chi in sorted(fits):
            for row in scaling.report_rows(fits[chi]):
                cells = [str(c).strip() for c in row]  # (the report's rows are padded for text)
                if cells[0] in ("v_max", "sigma_max", "kappa_max"):
                    lines.append(f"| {chi:g} ({int(studies[chi].dataset.n_links[-1])}) | {cells[0]} | {cells[1]} | "
                                 f"{cells[2]} | {cells[4]} | {cells[7]} |")
    return lines
