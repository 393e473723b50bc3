"""Regime studies: what caps the snap of a real body (issue 24, item 2).

:func:`regimes` scans one mechanism's nondimensional number (:mod:`snapping.dimensionless`)
against the end separation chi. Every cell (chi, number) is a continuum study like
:func:`snapping.continuum.converge`: the same problem at ``levels`` resolutions, each
peak (speed, acceleration, tension, curvature, snapping time) extrapolated to the
continuum (:func:`snapping.continuum.extrapolate`: observed order, Richardson limit, error
bar). Beside the cells, the ideal chain's continuum limit at each chi (number = 0,
fold-following graded chains: the limit the paper quotes) and each peak's ratio to it.

Mechanisms (:data:`MECHANISMS`) and their resolutions:

* ``bending``: ``Body(bending=beta)`` from the rest start (the bent line's equilibrium), on
  the ideal's fold-following levels with the free end's links floored at
  ``BEND_FLOOR * frac * sqrt(beta)`` (the rod's fold cannot be thinner than its bending length
  ``sqrt(B/T)``, so links below a fraction of it buy nothing) and a grid damping: Kelvin-Voigt
  ``eta_i = zeta sqrt(B) hn_i^2 / 2`` per node (``hn_i`` its shorter link), which gives the
  shortest wave at every node the damping ratio ``zeta`` (``damping``, default 1) and vanishes
  as h^2 with the links, so the continuum extrapolation removes it (checked: the limits at
  zeta 0.5, 1 and 2 agree within their error bars, ``benchmarks/bench_regimes.py``). Run with
  RODAS4 (L-stable: the damped grid-scale waves do not limit its steps); its acceleration and tension peaks
  the snap's without the release's grid-scale spike at t = 0 (``"peaks": "snap"``,
  :func:`snapping.simulate.snap_window.run_snap_peaks`). ``converged`` = 0 where the finest links do not
  resolve the bending length at the fold (``bending_resolution`` < 1, :mod:`snapping.regimes_resolution`):
  pre-asymptotic levels, whose extrapolation can look converged without being so.
* ``drag`` (normal number d, tangential ``d * pi C_t / C_n`` with the default coefficients
  of :mod:`snapping.units`), ``drag-normal``, ``drag-tangential``: ``Body(drag_...)``;
  fold-following graded chains (the ideal's own levels: number -> 0 is the ideal limit).
* ``end-mass``: a point mass ``M_end / (lambda L)`` at the free end (``tip_mass``); fold-following graded chains.
* ``stretching``: the extensible line (:func:`snapping.simulate.elastic.solve`, from the start
  ``start``, default ``STRETCH_START`` = ``"matched"``: at rest at the catenary, stretched to the
  rigid chain's tensions just after release, so that no release wave rings; or ``"stretched"``) of wave
  speed c; the number scanned is the *inverse* stretching number ``sqrt(g L)/c`` (number -> 0 is the
  inextensible ideal, as for the other mechanisms); fold-following graded levels. Run with RODAS4 (``STRETCH_METHOD``:
  in link coordinates by default, the shipped study's; ``method="rodas4"`` in node coordinates) and the
  elastic grid damping ``damping`` (the shortest longitudinal mode's damping ratio, a link damping
  ``zeta h sqrt(EA lambda)`` vanishing with h, so the continuum extrapolation removes it), its acceleration
  and tension peaks the snap's (``a_peak_snap``, ``sigma_peak_snap``: :mod:`snapping.simulate.snap_window`;
  the key says ``"peaks": "snap"``), the stop rule armed at ``STRETCH_STOP_FLOOR``
  (:mod:`snapping.regimes_spec` says why each setting: undamped, the tip links ring).

One task per (cell, level) run, on local processes (:func:`snapping._workers.run_all`) or a Dask
cluster (``scheduler``). The study file ``out`` is rewritten (atomically) after every run: a rerun
computes only the runs missing; a file holding another study (key: mechanism, grid, accuracy) is refused.

Example
-------
>>> ds = regimes("end-mass", [0.5], [1e-3], progress=False)  # doctest: +SKIP
>>> float(ds.v_peak_ratio.sel(chi=0.5, number=1e-3))  # doctest: +SKIP
"""

from __future__ import annotations

import contextlib
import functools
import json
import math
import os
import time

import numpy as np
import xarray as xr

from . import _validate as V
from .continuum import QUANTITIES, _uniform_levels, level_parameters
from .regimes_files import BUNDLED, bundled_study, load_study  # noqa: F401 (re-exported: the public names)
from .regimes_spec import (ACCURACY, BEND_PEAKS_KEY, CHAIN_COST_PARTS, CHAIN_EXTRA_PEAKS, BEND_SNAP_PEAKS, MECHANISMS, NUMBER_MAX, STRETCH_DAMPING, STRETCH_MAX_RHS, STRETCH_METHOD,
                           STRETCH_EXTRA_PEAKS, STRETCH_MAX_RHS_LINKS, STRETCH_METHODS, STRETCH_PEAK_ATTRS, STRETCH_PEAKS_KEY, STRETCH_START, STRETCH_STOP_FLOOR, STRETCH_TIP_TIME,
                           STRETCH_TOL_C, stretch_tip_floor, stretch_tol)

__all__ = ["regimes", "MECHANISMS", "ACCURACY", "load_study", "cell_problem", "cell_links", "eta_grid", "BEND_FLOOR", "bundled_study", "BUNDLED",
           "GRID_DAMPING"]

#: bending: the free end's links are at least this times the level's fold fraction times sqrt(beta)
BEND_FLOOR = 0.25
#: bending: the damping ratio of the shortest wave at every node (the grid damping, vanishing as h^2)
GRID_DAMPING = 1.0


def eta_grid(h, beta: float, zeta: float) -> np.ndarray:
    """Per-node Kelvin-Voigt damping giving each node's shortest bending wave the damping
    ratio ``zeta``: ``omega_i ~ 4 sqrt(B) / hn_i^2`` and ``zeta_i = 2 eta_i / (hn_i^2 sqrt(B))``
    (:mod:`snapping.simulate.stiffness`), so ``eta_i = zeta sqrt(B) hn_i^2 / 2`` (``hn_i`` the
    node's shorter link; index 0 the free end, N + 1 values)."""
    h = np.asarray(h, dtype=float)
    hn = np.empty(h.size + 1)
    hn[0], hn[-1] = h[0], h[-1]
    hn[1:-1] = np.minimum(h[:-1], h[1:])
    return 0.5 * zeta * math.sqrt(beta) * hn**2

# the mechanisms, accuracy presets and NUMBER_MAX live in snapping.regimes_spec (light: the CLI
# builds its parser from them without importing xarray)


def _drag_ratio() -> float:
    from . import units

    return math.pi * units.CD_TANGENTIAL / units.CD_NORMAL


def cell_links(chi: float, mechanism: str, number: float, level: dict, method: str | None = None) -> np.ndarray:
    """The link lengths of one run (:func:`cell_problem`'s), free end first. ``method``: the
    stretching run's elastic method (``"rodas4-links"``: the free end's links floored at
    ``STRETCH_TIP_TIME * c``, :func:`snapping.regimes_spec.stretch_tip_floor`)."""
    from .simulate import grading

    if "n_links" in level:
        return np.full(int(level["n_links"]), 1.0 / int(level["n_links"]))
    h_min = level["h_min"]
    if mechanism == "bending" and number > 0:
        h_min = max(h_min, BEND_FLOOR * level["frac"] * math.sqrt(number))
    elif mechanism == "stretching" and number > 0:
        h_min = max(h_min, stretch_tip_floor(1.0 / number, method))
    return grading.fold_following(chi, frac=level["frac"], h_min=h_min, h_max=max(level["h_max"], h_min))


@functools.lru_cache(maxsize=256)
def _finest_links(chi: float, number: float, levels: int, first: int, n0: int, ratio: float, grading: str):
    level = _levels(grading, {"levels": levels, "first": first, "n0": n0}, ratio)[-1]
    return cell_links(chi, "bending", number, level)


def _mark(ds: xr.Dataset) -> None:
    """The per-cell ``converged`` flag and, for bending, ``bending_resolution`` (the finest level's
    l_B / h_fold; an escalated cell's finest level is its last run): :mod:`snapping.regimes_resolution`."""
    from .regimes_escalate import prefix
    from .regimes_resolution import BEND_RESOLVED, bending_resolution, converged

    res = None
    if ds.attrs["mechanism"] == "bending":
        a = ds.attrs
        res = np.full((ds.sizes["chi"], ds.sizes["number"]), np.nan)
        for i, chi in enumerate(ds.chi.values):
            sig, kap = float(ds["sigma_peak_ideal"].values[i]), float(ds["kappa_peak_ideal"].values[i])
            if not (np.isfinite(sig) and np.isfinite(kap)):
                continue
            for j, beta in enumerate(ds.number.values):
                n = max(int(a["levels"]), prefix(ds["v_peak_level"].values[i, j]))  # an escalated cell: its finest
                h = _finest_links(float(chi), float(beta), n, int(a["first"]), int(a["n0"]), float(a["ratio"]), a["grading"])
                res[i, j] = bending_resolution(h, float(beta), sig, kap)
        ds["bending_resolution"] = (("chi", "number"), res, {
            "long_name": "bending length sqrt(beta/sigma_peak_ideal) over the finest level's link at the ideal fold "
                         "(arclength 1/kappa_peak_ideal from the free end)"})
    ds["converged"] = (("chi", "number"), converged(ds["v_peak_order"].values, res, value=ds["v_peak"].values,
                                                    error=ds["v_peak_error"].values).astype(np.int8), {
        "long_name": "1: the cell's levels converge (v_peak's observed order is finite, or its levels agree to 0.1%)"
                     + (f" and resolve the bending length at the fold (bending_resolution >= {BEND_RESOLVED:g})"
                        if res is not None else "") + "; 0: not converged, its limit is not the continuum's"})


def cell_problem(chi: float, mechanism: str, number: float, level: dict, lumping: str = "shared",
                 damping: float = GRID_DAMPING, method: str | None = None):
    """The problem of one run: the catenary of separation ``chi`` with the mechanism at
    ``number`` (0 or ``mechanism=None``: the ideal chain, fold-graded) at the resolution
    ``level`` (``n_links``: a uniform chain; else the fold-following grading; bending: its
    free end's links floored at ``BEND_FLOOR frac sqrt(beta)``, grid damping ratio ``damping``).
    Stretching: the (inextensible) problem whose links the elastic line takes (``method``
    ``"rodas4-links"``: its free end's links floored at ``STRETCH_TIP_TIME * c``)."""
    from .simulate import Body, Links, Problem

    h = cell_links(chi, mechanism, number, level, method)
    body, tip = None, 0.0
    if mechanism == "bending" and number > 0:
        body = Body(bending=number, damping=eta_grid(h, number, damping) if damping > 0 else 0.0)
    elif mechanism == "drag" and number > 0:
        body = Body(drag_normal=number, drag_tangential=number * _drag_ratio())
    elif mechanism == "drag-normal" and number > 0:
        body = Body(drag_normal=number)
    elif mechanism == "drag-tangential" and number > 0:
        body = Body(drag_tangential=number)
    elif mechanism == "end-mass":
        tip = float(number)
    return Problem.catenary(chi, links=Links.graded(h, lumping=lumping, tip_mass=tip), chords="exact", body=body)


def _run_task(chi, mechanism, number, level, tol, damping=GRID_DAMPING, start=STRETCH_START, method=STRETCH_METHOD):
    """Worker: one run of one cell at one level; its peaks and cost (no file: the study keeps them).
    ``start``, ``method``: the elastic line's (stretching only)."""
    from .simulate import run

    problem = cell_problem(chi, mechanism, number, level, damping=damping, method=method)
    cpu = time.process_time()
    if mechanism == "stretching" and number > 0:
        from .simulate.elastic import Elastic, solve

        from . import _workers

        with _workers.nothing_to_save():  # (an interrupted study does not wait for it: the study keeps no part of it)
            ds = solve(problem, Elastic.from_wave_speed(1.0 / number, grid_damping=damping),
                       tol=stretch_tol(tol, 1.0 / number), method=method, stop_floor=STRETCH_STOP_FLOOR,
                       start=start, max_rhs=STRETCH_MAX_RHS_LINKS if method == "rodas4-links" else STRETCH_MAX_RHS
                       ).dataset
    else:
        method = "rodas4" if (mechanism == "bending" and number > 0 and damping > 0) else "fast"
        ds = run(problem, method=method, tol=tol, progress=False).dataset
    a = ds.attrs
    if a.get("status") != "completed":
        raise RuntimeError(f"chi={chi:g} {mechanism}={number:g} ({problem.links.N} links): run {a.get('status')}: "
                           f"{a.get('stop_reason', '')}" + (f" ({a['peak_note']})" if a.get("peak_note") else ""))
    row = {q: float(a.get(q, float("nan"))) for q in QUANTITIES + CHAIN_EXTRA_PEAKS}  # (an elastic run's too: branch stretchapp)
    if mechanism == "stretching" and number > 0:  # the snap's peaks, not the slack fold's / recoil's after it
        row.update({q: float(a[name]) for q, name in STRETCH_PEAK_ATTRS.items() if name in a})
        row.update({q: float(a[name]) for q, name in STRETCH_EXTRA_PEAKS.items() if name in a})
    elif mechanism == "bending" and number > 0:  # the snap's, not the release's grid-scale spike at t = 0
        from .simulate.snap_window import run_snap_peaks
        row.update({q: v for q, v in run_snap_peaks(ds).items() if q in BEND_SNAP_PEAKS})
    row.update({"n_links": problem.links.N, "n_rhs": int(a["n_rhs"]), "cpu_time": time.process_time() - cpu})
    row.update({q: float(a[q]) for q in CHAIN_COST_PARTS if q in a})  # (regimes_spec.CHAIN_COST_PARTS)
    return row


def _levels(grading: str, acc: dict, ratio: float) -> list[dict]:
    if grading == "uniform":
        return _uniform_levels(acc["levels"], ratio, acc["n0"], 0)
    return level_parameters(acc["levels"], ratio, first=acc["first"])


def _numbers(numbers) -> list[float]:
    if isinstance(numbers, (int, float)):
        numbers = [numbers]
    if isinstance(numbers, (str, bytes, dict)) or not hasattr(numbers, "__iter__"):
        raise V.SnappingInputError(f"numbers={numbers!r} is not a list of values")
    out = []
    for x in numbers:
        v = V.real("numbers", x)
        if not (math.isfinite(v) and 0.0 < v <= NUMBER_MAX):
            raise V.SnappingInputError(f"numbers: {v!r} is out of range: each must lie in (0, {NUMBER_MAX:g}] "
                                       f"(the ideal, number 0, is computed anyway)")
        out.append(v)
    if not out or len(set(out)) != len(out):
        raise V.SnappingInputError(f"numbers={list(numbers)!r}: give one or more distinct values")
    return sorted(out)


def _study_key(mechanism, chis, numbers, acc, ratio) -> str:
    return json.dumps({"mechanism": mechanism, "chi": chis, "number": numbers, "ratio": ratio, **acc},
                      sort_keys=True)


def _extra(mechanism) -> tuple:
    """The peaks a study of ``mechanism`` keeps beside QUANTITIES: ``kappa_peak_approach`` (the approach's curvature
    peak without the free end's node layer, :data:`snapping.regimes_spec.CHAIN_EXTRA_PEAKS`; the elastic line's
    too since branch stretchapp), after stretching's STRETCH_EXTRA_PEAKS."""
    return tuple(STRETCH_EXTRA_PEAKS) + CHAIN_EXTRA_PEAKS if mechanism == "stretching" else CHAIN_EXTRA_PEAKS


def _empty(mechanism, chis, numbers, levels, ideal_levels, key, acc, ratio) -> xr.Dataset:
    nc, nn, nl = len(chis), len(numbers), len(levels)
    data = {}
    for q in QUANTITIES + _extra(mechanism) + ("n_rhs", "cpu_time") + CHAIN_COST_PARTS:  # (stretching's too: stretchapp)
        data[f"{q}_level"] = (("chi", "number", "level"), np.full((nc, nn, nl), np.nan))
        data[f"{q}_ideal_level"] = (("chi", "level"), np.full((nc, nl), np.nan))
    data["n_links_level"] = (("chi", "number", "level"), np.full((nc, nn, nl), np.nan))
    data["n_links_ideal_level"] = (("chi", "level"), np.full((nc, nl), np.nan))
    data["resolution"] = ("level", np.array([p["frac"] for p in levels]),
                          {"long_name": "resolution of a cell's level: link length (uniform) or fold fraction"})
    data["resolution_ideal"] = ("level", np.array([p["frac"] for p in ideal_levels]),
                                {"long_name": "fold fraction of the ideal chain's levels (fold-following)"})
    name, grading, what = MECHANISMS[mechanism]
    attrs = {"title": "snapping: regime study (peaks against a mechanism's number, continuum-extrapolated)",
             "regimes_study": key, "mechanism": mechanism, "number_name": name, "mechanism_description": what,
             "grading": grading, "ratio": ratio, "status": "partial", **{k: acc[k] for k in acc}}
    if mechanism == "drag":
        attrs["drag_tangential_ratio"] = _drag_ratio()
    return xr.Dataset(data, coords={"chi": ("chi", np.array(chis, float)), "number": ("number", np.array(numbers)),
                                    "level": ("level", np.arange(nl))}, attrs=attrs)


def _finish(ds: xr.Dataset) -> xr.Dataset:
    """The limits, error bars, orders and ratios of every cell whose levels are all done."""
    from .regimes_escalate import extrapolate_prefix, mark_levels_run

    nc, nn = ds.sizes["chi"], ds.sizes["number"]
    base = int(ds.attrs["levels"])  # the levels every cell runs (more: an escalating study's, regimes_escalate)
    for q in QUANTITIES + tuple(q for q in _extra(ds.attrs["mechanism"]) if f"{q}_level" in ds):
        lim, err, order = (np.full((nc, nn), np.nan) for _ in range(3))
        ilim, ierr = np.full(nc, np.nan), np.full(nc, np.nan)
        for i in range(nc):
            e = extrapolate_prefix(ds.resolution_ideal.values, ds[f"{q}_ideal_level"].values[i], base)
            if e is not None:
                ilim[i], ierr[i] = e["limit"], e["error"]
            for j in range(nn):
                e = extrapolate_prefix(ds.resolution.values, ds[f"{q}_level"].values[i, j], base)
                if e is not None:
                    lim[i, j], err[i, j], order[i, j] = e["limit"], e["error"], e["order"]
        ds[q] = (("chi", "number"), lim, {"long_name": f"continuum limit of {q}"})
        ds[f"{q}_error"] = (("chi", "number"), err, {"long_name": f"error bar of {q}"})
        ds[f"{q}_order"] = (("chi", "number"), order, {"long_name": f"observed order of convergence of {q}"})
        ds[f"{q}_ideal"] = ("chi", ilim, {"long_name": f"ideal chain's continuum limit of {q} (number 0)"})
        ds[f"{q}_ideal_error"] = ("chi", ierr)
        r = lim / ilim[:, None]
        ds[f"{q}_ratio"] = (("chi", "number"), r, {"long_name": f"{q} / the ideal's"})
        ds[f"{q}_ratio_error"] = (("chi", "number"),
                                  np.abs(r) * np.hypot(err / lim, (ierr / ilim)[:, None]))
    _mark(ds)
    done = (np.isfinite(ds["v_peak_level"].values[:, :, :base]).all()
            and np.isfinite(ds["v_peak_ideal_level"].values[:, :base]).all())
    if ds.sizes["level"] > base:  # an escalating study: the levels each cell ran, and whether any is owed
        done = not mark_levels_run(ds, base) and done
    ds.attrs["status"] = "complete" if done else "partial"
    return ds


def regimes(mechanism: str, chis, numbers, *, accuracy: str = "coarse", levels: int | None = None,
            first: int | None = None, n0: int | None = None, ratio: float = 0.5, tol: float | None = None,
            damping: float | None = None, start: str = STRETCH_START, method: str | None = None, workers: int = 1, scheduler=None, out=None,
            progress: bool = True, escalate: float | None = None, extra_levels: int | None = None,
            escalate_max_rhs: int | None = None) -> xr.Dataset:
    """Continuum-extrapolated peaks of the snap over chi x one mechanism's number.

    Parameters
    ----------
    mechanism : str
        One of :data:`MECHANISMS`.
    chis : sequence of float
        End separations, each in (0, 1).
    numbers : sequence of float
        The mechanism's number (:mod:`snapping.dimensionless`), each > 0 (the ideal, 0, is
        always computed, fold-graded).
    accuracy : str
        A preset of :data:`ACCURACY` (``coarse``: 3 fold-graded levels, 193-639 links at chi = 0.25).
    levels, first, n0, tol
        Override the preset: refinement levels, the first fold-graded level (as
        :func:`snapping.continuum.level_parameters`), links of the first uniform level, the
        fast method's tolerance.
    ratio : float
        Resolution ratio from one level to the next.
    damping : float, optional
        Bending (default ``GRID_DAMPING``, 1): the grid damping ratio of every node's shortest wave (vanishing as h^2,
        see the module; 0: none, the fast method's choice instead of RODAS4). Stretching: the
        elastic grid damping ratio of the shortest longitudinal mode (default ``STRETCH_DAMPING``, 4).
    start : {"matched", "stretched", "unstretched"}
        Stretching only: the elastic line's start (:func:`snapping.simulate.elastic.solve`), attribute
        ``elastic_start`` (in the study's key unless ``"stretched"``, so a stop-29 file resumes).
    method : {"rodas4", "rodas4-links"}, optional
        Stretching only: the elastic line's method (default ``STRETCH_METHOD``, ``"rodas4-links"``: RODAS4 in
        link coordinates; ``"rodas4"``: node coordinates). Attribute ``elastic_method``, in the study's key.
    workers : int
        Local worker processes (the sweep's, :mod:`snapping._workers`).
    scheduler : str or dask.distributed.Client, optional
        Run on this Dask cluster instead.
    out : path, optional
        The study file (netCDF), rewritten after each run; reused when it holds this study.
    progress : bool
        A progress bar (runs done).
    escalate : float, optional
        A cell whose v_peak, a_peak or sigma_peak error bar is above this fraction of its limit runs
        one more level, up to ``extra_levels`` (default 1) more (:mod:`snapping.regimes_escalate`; the
        ideal at that chi too). Both are in the study's key. None (the default): every cell runs ``levels``.
    escalate_max_rhs : int, optional
        With ``escalate``: a cell whose last level took more right-hand-side evaluations in its integration
        (n_rhs less ``n_rhs_approach``) is not escalated (``escalation_capped``; in the study's key). None: no cap.

    Returns
    -------
    xarray.Dataset
        Dimensions chi, number, level: ``{q}_level`` (each run's peak), ``{q}`` (limit),
        ``{q}_error``, ``{q}_order``, ``{q}_ideal`` (+ ``_error``, per chi), ``{q}_ratio``
        (+ ``_error``) for q in :data:`snapping.continuum.QUANTITIES`; ``converged`` (per cell, 1/0:
        :mod:`snapping.regimes_resolution`) and, bending, ``bending_resolution``.

    Raises
    ------
    SnappingInputError
        Bad input, or ``out`` holding another study or another program's file, before any run.
    """
    from tqdm.auto import tqdm

    from .estimates import check_chi

    if mechanism not in MECHANISMS:
        raise V.SnappingInputError(f"mechanism={mechanism!r} is not one of {sorted(MECHANISMS)}")
    if not isinstance(accuracy, str) or accuracy not in ACCURACY:
        raise V.SnappingInputError(f"accuracy={accuracy!r} is not one of {sorted(ACCURACY)}")
    acc = dict(ACCURACY[accuracy])
    for k, v in (("levels", levels), ("first", first), ("n0", n0), ("tol", tol)):
        if v is not None:
            acc[k] = v
    acc["levels"] = V.integer("levels", acc["levels"], 2, 12)
    acc["first"] = V.integer("first", acc["first"], -20, 20)
    acc["n0"] = V.integer("n0", acc["n0"], 2, 10**6)
    acc["tol"] = V.open_interval("tol", acc["tol"], 0.0, 1e-2)
    ratio = V.open_interval("ratio", ratio, 0.0, 1.0)
    if damping is None:
        damping = STRETCH_DAMPING if mechanism == "stretching" else GRID_DAMPING
    damping = V.real("damping", damping)
    if not (math.isfinite(damping) and 0.0 <= damping <= 100.0):
        raise V.SnappingInputError(f"damping={damping!r} is out of range: the grid damping ratio must lie in [0, 100]")
    if mechanism in ("bending", "stretching"):
        acc["damping"] = damping
    if mechanism == "bending":  # (a file of the run's peaks, before branch snapbend, is not resumed)
        acc["peaks"] = BEND_PEAKS_KEY
    if mechanism == "stretching":
        from .simulate.elastic_model import STARTS

        if not isinstance(start, str) or start not in STARTS:
            raise V.SnappingInputError(f"start={start!r} is not one of {STARTS} (the elastic line's starts)")
        method = STRETCH_METHOD if method is None else method
        if not isinstance(method, str) or method not in STRETCH_METHODS:
            raise V.SnappingInputError(f"method={method!r} is not one of {STRETCH_METHODS} (a stretching study's "
                                       f"elastic methods)")
        acc.update(elastic_method=method, stop_floor=STRETCH_STOP_FLOOR, peaks=STRETCH_PEAKS_KEY)
        if method == "rodas4-links":  # its tip links floored (regimes_spec.stretch_tip_floor)
            acc["tip_time"] = STRETCH_TIP_TIME
        if start != "stretched":  # (the stop-29 study's key, run from "stretched", had no start)
            acc["elastic_start"] = start
            acc["tol_c"] = STRETCH_TOL_C  # stiffer lines' runs at tol (tol_c/c)^2 (regimes_spec.stretch_tol)
    elif method is not None:
        raise V.SnappingInputError(f"method={method!r}: the elastic method is for the stretching mechanism only, "
                                   f"not {mechanism!r}")
    from .regimes_escalate import settings
    acc.update(settings(escalate, extra_levels, escalate_max_rhs))
    workers = V.integer("workers", workers, 1)
    if isinstance(chis, (int, float)):
        chis = [chis]
    chis = sorted(check_chi(c) for c in chis)
    if not chis or len(set(chis)) != len(chis):
        raise V.SnappingInputError(f"chis={chis!r}: give one or more distinct values")
    numbers = _numbers(numbers)
    grading = MECHANISMS[mechanism][1]
    all_levels = dict(acc, levels=acc["levels"] + acc.get("extra_levels", 0))
    levels_p = _levels(grading, all_levels, ratio)
    ideal_p = _levels("fold", all_levels, ratio)
    key = _study_key(mechanism, chis, numbers, acc, ratio)
    ds = _empty(mechanism, chis, numbers, levels_p, ideal_p, key, acc, ratio)
    lock = None
    if out is not None:
        from ._files import check_output, locked

        out = V.file_path("out", out)
        if os.path.lexists(out):
            check_output(out, name="out", overwrite=True)  # a regular file
            try:
                old = load_study(out)
            except V.SnappingInputError:
                raise V.SnappingInputError(f"out={out!r} exists and is not a regime study: it is not replaced "
                                           f"(give another path)") from None
            if old.attrs["regimes_study"] != key:
                raise V.SnappingInputError(f"out={out!r} holds another study ({old.attrs['regimes_study']}); "
                                           f"this one is {key}: give another path (it is not replaced)")
            ds = old
        lock = locked(out, name="out")
    if mechanism == "stretching":
        ds.attrs["elastic_start"] = start
    # the runs still to do: (chi index, number index or None for the ideal, level index)
    todo = []
    for i, chi in enumerate(chis):
        for k in range(acc["levels"]):  # the base levels (an escalating study's further ones: below)
            if not np.isfinite(ds["v_peak_ideal_level"].values[i, k]):
                todo.append((i, None, k))
            for j in range(len(numbers)):
                if not np.isfinite(ds["v_peak_level"].values[i, j, k]):
                    todo.append((i, j, k))
    def prev_cost(t):  # the cell's CPU time at the level before (done): cheap cells first within a level
        i, j, k = t
        if k == 0:
            return 0.0
        c = ds["cpu_time_ideal_level"].values[i, k - 1] if j is None else ds["cpu_time_level"].values[i, j, k - 1]
        return float(c) if np.isfinite(c) else math.inf

    todo.sort(key=lambda t: (t[2], prev_cost(t), t[0], -1 if t[1] is None else t[1]))  # coarse levels first
    calls = {}

    def add_calls(runs):
        for t in runs:
            i, j, k = t
            if j is None:
                calls[t] = (chis[i], None, 0.0, ideal_p[k], acc["tol"])
            else:
                calls[t] = (chis[i], mechanism, numbers[j], levels_p[k], acc["tol"], damping, start,
                            acc.get("elastic_method", STRETCH_METHOD))

    add_calls(todo)
    for args in calls.values():  # every run's problem is checked before any starts
        cell_problem(*args[:4], damping=damping, method=args[7] if len(args) > 7 else None)

    bar = tqdm(total=len(ds.chi) * (len(numbers) + 1) * acc["levels"], initial=0, desc=f"regimes {mechanism}",
               unit="run", disable=not progress)
    bar.update(bar.total - len(todo))
    failures = []

    def save():
        if out is not None:
            from .sweep_files import atomic_to_netcdf

            atomic_to_netcdf(_finish(ds.copy()), out)

    def collect(t, result):
        try:
            row = result()
        except Exception as exc:  # noqa: BLE001 - reported after the other runs
            failures.append(f"{calls[t][1] or 'ideal'} chi={calls[t][0]:g} number={calls[t][2]:g} level {t[2]}: "
                            f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}")
            bar.update(1)
            return
        i, j, k = t
        if j is None and mechanism == "stretching":  # the ideal chain (inextensible: never slack): its taut snap's tension is its run's
            row = {**row, **{q: row["sigma_peak"] for q in STRETCH_EXTRA_PEAKS}}
        for q, v in row.items():
            name = f"{q}_ideal_level" if j is None else f"{q}_level"
            if name not in ds:  # (a study file from before the name: its earlier runs have none)
                continue
            if j is None:
                ds[name].values[i, k] = v
            else:
                ds[name].values[i, j, k] = v
        save()
        bar.update(1)

    def execute(todo):
        if scheduler is not None and todo:
            from dask.distributed import as_completed as dask_completed

            from .sweep_run import _client_for

            client, owned = _client_for(scheduler)
            futures = {}
            try:
                futures = {client.submit(_run_task, *calls[t], pure=False): t for t in todo}
                for fut in dask_completed(futures):
                    collect(futures[fut], fut.result)
            except BaseException:
                client.cancel(list(futures))
                raise
            finally:
                if owned:
                    client.close()
        elif workers > 1 and len(todo) > 1:
            from . import _workers

            order = list(todo)
            _workers.run_all(min(workers, len(todo)), _run_task, [calls[t] for t in order],
                             lambda args, res: collect(order[[calls[t] for t in order].index(args)], res))
        else:
            for t in todo:
                collect(t, lambda t=t: _run_task(*calls[t]))

    with lock if lock is not None else contextlib.nullcontext():
        try:
            execute(todo)
            tried = set()
            while "escalate" in acc:  # the cells over the target run their next level, round by round
                from .regimes_escalate import next_round

                more = next_round(ds, acc["escalate"], acc["levels"], tried, acc.get("escalate_max_rhs"))
                if not more:
                    break
                add_calls(more)
                bar.total += len(more)
                bar.refresh()
                execute(more)
        finally:
            bar.close()
        ds = _finish(ds)
        if out is not None:
            from .sweep_files import atomic_to_netcdf

            atomic_to_netcdf(ds, out)
    if failures:
        raise RuntimeError(f"{len(failures)} run(s) of the study failed (the others are kept"
                           + (f" in {out}" if out else "") + "): " + "; ".join(failures[:5]))
    return ds
