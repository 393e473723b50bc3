"""The extensible line in a sweep or a convergence study: a grid point's run through
:func:`snapping.simulate.elastic.solve` instead of :func:`snapping.simulate.run`.

A grid with ``options["elastic"]`` (an :class:`~snapping.simulate.elastic.Elastic` with numbers,
or its description) runs, at each (chi, N), the uniform line of N links with the consistent
("shared") lumped masses released from the catenary of chi, made of those links: exactly what
``snapping simulate --chi CHI --N N --stretching C`` runs. Its other options are those of
:func:`~snapping.simulate.elastic.solve` (:data:`OPTIONS`); ``method`` is ``"radau"``
(``"fast"`` means it), ``"dop853"``, ``"rodas4"`` or ``"rodas4-links"``; ``options["body"]`` (a
:class:`~snapping.simulate.Body` or its description) rides on the line (:mod:`snapping.simulate.elastic_body`;
methods radau, dop853, rodas4), as ``snapping simulate --stretching C --bending B`` runs it.

Example
-------
>>> from snapping.sweep_elastic import problem_of, solve_kwargs
>>> from snapping.simulate.elastic import Elastic
>>> kw = solve_kwargs({"chi": 0.25, "N": 8, "elastic": Elastic(ea=900.0), "tol": 1e-6})
>>> kw["problem"].links.N, kw["elastic"].ea, kw["tol"]
(8, 900.0, 1e-06)
"""

from __future__ import annotations

import numpy as np

from . import _validate as V, _workers

__all__ = ["OPTIONS", "description", "problem_of", "solve_kwargs", "run_point", "with_body"]

#: the grid options an elastic run takes (besides chi, N and elastic)
OPTIONS = ("tol", "method", "t_end", "stop_fraction", "t_end_max", "snapshot_times", "chords", "start", "body")
#: the sweep's default tolerance of an elastic run (the CLI's)
DEFAULT_TOL = 1e-6


def description(elastic, name: str = "options['elastic']") -> dict:
    """The description (:meth:`Elastic.describe`) of a grid's elastic links (an Elastic or its
    description), checked to hold numbers the same at every N (no per-link arrays)."""
    from .simulate.elastic import Elastic

    if isinstance(elastic, (dict, str)):
        elastic = Elastic.from_describe(elastic)
    if not isinstance(elastic, Elastic):
        raise V.SnappingInputError(f"{name}={type(elastic).__name__} is not a snapping.simulate.elastic.Elastic")
    d = elastic.describe()
    if isinstance(d["ea"], list) or isinstance(d["damping"], list):
        raise V.SnappingInputError(f"{name}: elastic links refined or swept over N take numbers (the same at every "
                                   f"N), not one value per link; run such lines one by one")
    return d


def problem_of(chi: float, N: int, chords: str | None = None, lumping: str = "shared", free_end=None, h=None):
    """The line of a grid point: ``N`` uniform links (or the lengths ``h``) with consistent lumped
    masses, from the catenary of ``chi`` (``snapping simulate --stretching``'s problem)."""
    from .simulate.problem import Links, Problem

    links = (Links.uniform(N, lumping=lumping) if h is None else
             Links.graded(h, lumping=lumping, free_end=free_end))
    return Problem.catenary(chi, links=links, chords=chords or "exact")


def solve_kwargs(params: dict) -> dict:
    """The keywords of :func:`snapping.simulate.elastic.solve` for one grid point, checked
    (SnappingInputError naming the option) before any run."""
    from .simulate.elastic import METHODS, STARTS, Elastic

    kw = dict(params)
    chi, N, el = kw.pop("chi"), kw.pop("N"), kw.pop("elastic")
    other = sorted(k for k in kw if k not in OPTIONS)
    if other:
        raise V.SnappingInputError(f"options {other} do not apply to the extensible line (elastic); its options: "
                                   f"{list(OPTIONS)}")
    method = kw.pop("method", "radau")
    method = {None: "radau", "fast": "radau", "stiff": "rodas4"}.get(method, method)
    if not isinstance(method, str) or method.lower() not in METHODS:
        raise V.SnappingInputError(f"method={method!r} is not one of {('fast',) + tuple(METHODS)} (the elastic "
                                   f"line's methods)")
    tol = V.positive("tol", kw.pop("tol", DEFAULT_TOL) or DEFAULT_TOL)
    if not 1e-13 <= tol <= 1e-2:
        raise V.SnappingInputError(f"tol={tol!r} is out of range: must lie in [1e-13, 1e-2]")
    chords = kw.pop("chords", None)
    if chords not in (None, "exact", "arclength"):
        raise V.SnappingInputError(f"chords={chords!r} is not one of ('exact', 'arclength')")
    if kw.get("start", "stretched") not in STARTS:
        raise V.SnappingInputError(f"start={kw['start']!r} is not one of {STARTS}")
    if kw.get("t_end") is not None:
        kw["t_end"] = V.positive("t_end", kw["t_end"])
    elastic = Elastic.from_describe(el) if isinstance(el, (dict, str)) else el
    problem = with_body(problem_of(chi, V.integer("N", N, 1), chords), kw.pop("body", None), method.lower())
    return {"problem": problem, "elastic": elastic, "method": method.lower(), "tol": tol, **kw}


def with_body(problem, body, method: str):
    """``problem`` carrying the line's ``body`` (a :class:`~snapping.simulate.Body` or its description; None:
    none), refused by name where ``method`` steps no body (:data:`snapping.simulate.elastic_body.BODY_METHODS`)."""
    if body is None:
        return problem
    from .simulate import Body
    from .simulate.elastic_body import BODY_METHODS

    body = Body.from_describe(body) if isinstance(body, (dict, str)) else body
    if body.active and method not in BODY_METHODS:
        raise V.SnappingInputError(f"method={method!r} steps no body on the extensible line: with a body (bending, "
                                   f"drag) its methods are {BODY_METHODS} ('fast' is radau)")
    return problem.with_body(body)


def run_point(params: dict, path) -> str:
    """Worker: one grid point's elastic run, saved to ``path`` atomically (never resumed: an
    unfinished file is run again). Returns the path."""
    from .simulate.elastic import solve
    from .sweep_files import atomic_to_netcdf

    with _workers.nothing_to_save():  # (an interrupted sweep does not wait for it: it would be run again)
        r = solve(**solve_kwargs(params))
    atomic_to_netcdf(r.dataset, path, overwrite=True)  # the sweep owns its run files
    return str(path)


def file_bytes(params: dict) -> int:
    """A generous size of a grid point's run file: the per-step record (about 300 steps of 21
    doubles) and the profiles of the snapshots (12 variables of N + 1 values each)."""
    n_snap = 4 + len(np.atleast_1d(params.get("snapshot_times", ())))
    return int(8 * (3000 * 21 + n_snap * 12 * (int(params["N"]) + 1)) + 100_000)


def level_row(chi, h, lumping, free_end, tol, path, elastic_d, start: str = "stretched", body_d=None) -> dict:
    """One level of :func:`snapping.continuum.converge` for the extensible line: the line of links
    ``h`` from the catenary of ``chi`` to the snap, its peaks (``kappa_peak``: the run's largest
    curvature, the chain's, on the rest lengths) and cost (``link_drift`` NaN: not measured), from
    the elastic ``start``. A completed run of the same level and start at ``path`` is reused (not one
    written before the runs recorded kappa_peak: it is run again)."""
    import json
    import os
    import time

    from .simulate.dataset import load_run
    from .simulate.elastic import Elastic, solve

    problem = with_body(problem_of(chi, len(h), lumping=lumping, free_end=free_end, h=h), body_d, "radau")
    elastic = Elastic.from_describe(elastic_d)
    ds, cpu = None, float("nan")
    if path is not None and os.path.isfile(path):
        try:
            old = load_run(path)
            if (old.attrs.get("status") == "completed" and old.attrs.get("model") == "elastic"
                    and "kappa_peak" in old.attrs  # (a run from before the line recorded its curvature)
                    and np.array_equal(old.link_length.values, h) and float(old.attrs["tol"]) == tol
                    and old.attrs.get("start", "stretched") == start
                    and json.loads(old.attrs.get("problem", "{}")).get("body") == problem.describe().get("body")
                    and np.array_equal(old.node_mass.values[:-1], problem.links.m)
                    and json.loads(old.attrs["elastic"]) == json.loads(json.dumps(elastic_d, sort_keys=True))):
                ds = old  # resumed: this level is done (its CPU time unknown)
        except (V.SnappingInputError, KeyError, AttributeError, ValueError):
            pass
    if ds is None:
        cpu0 = time.process_time()
        with _workers.nothing_to_save():
            ds = solve(problem, elastic, tol=tol, start=start).dataset
        cpu = time.process_time() - cpu0
        if path is not None:
            from .sweep_files import atomic_to_netcdf

            atomic_to_netcdf(ds, path, overwrite=True)
    a = ds.attrs
    if a.get("peak_note"):
        import sys

        print(f"level_row chi={chi:g} ({len(h)} links): elastic run {a.get('status')}: {a['peak_note']}",
              file=sys.stderr, flush=True)
    row = {q: float(a[q]) if q in a else float("nan") for q in ("v_peak", "a_peak", "sigma_peak", "kappa_peak",
                                                                  "t_snap_v")}
    row.update({"n_links": int(len(h)), "wall_time": float(a["wall_time"]), "cpu_time": cpu, "n_rhs": int(a["n_rhs"]),
                "energy_drift": float(a["energy_drift"]), "link_drift": float("nan"),
                "status": str(a.get("status", "")), "peak_note": str(a.get("peak_note", ""))})
    return row
