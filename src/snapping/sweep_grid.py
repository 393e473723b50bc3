"""The grid of a sweep: every combination of chi and N with the same run options (:class:`Grid`).

Its values are checked (and every run's inputs, before any run starts); it names each run's
file (the options' hash in the name) and is stored as JSON in a combined sweep file
(:func:`grid_key`).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import _validate as V


def _check_values(name: str, values, check) -> list:
    if values is None:
        raise V.SnappingInputError(f"{name} grid is empty: give at least one value")
    if isinstance(values, (int, float, np.number)):
        values = [values]
    if isinstance(values, (str, bytes, dict)) or not hasattr(values, "__iter__"):
        raise V.SnappingInputError(f"{name}={values!r} is not a list of values")
    values = [check(name, v) for v in values]
    if not values:
        raise V.SnappingInputError(f"{name} grid is empty: give at least one value")
    dup = sorted({v for v in values if values.count(v) > 1})
    if dup:
        raise V.SnappingInputError(f"{name} grid has duplicate values {dup}: give each value once")
    return values


@dataclass
class Grid:
    """A grid of runs: every combination of ``chi`` and ``N``, with the same ``options``
    (any other keyword of :func:`snapping.simulate.run`, e.g. ``tol``, ``method``); what
    ``options`` leaves out takes :func:`snapping.simulate.run`'s default (method ``fast``,
    chords ``exact``, the method's tol). ``options["body"]``: a line's body
    (:class:`snapping.simulate.Body` with numbers, not per-node profiles), the same at every
    point: each run is ``Problem.catenary(chi, N, chords=..., body=...)``; it is kept as its
    description (:meth:`~snapping.simulate.Body.describe`), which names the run files.
    ``options["elastic"]``: the extensible line's links (:class:`snapping.simulate.elastic.Elastic`
    with numbers), each run through :func:`snapping.simulate.elastic.solve`
    (:mod:`snapping.sweep_elastic`, whose options it takes).
    """

    chi: list
    N: list
    options: dict = field(default_factory=dict)

    def __post_init__(self):
        from .estimates import check_chi

        self.chi = _check_values("chi", self.chi, lambda n, v: check_chi(v, n))
        self.N = _check_values("N", self.N, lambda n, v: V.integer(n, v, 1))
        if not isinstance(self.options, dict):
            raise V.SnappingInputError(f"options={self.options!r} must be a dict of keywords of simulate.run")
        json.dumps(self.options, default=str)  # options must be describable in a file name hash
        from .simulate.driver import check_inputs

        if "output" in self.options:
            raise V.SnappingInputError("options must not contain 'output': the sweep names each run's file")
        if "body" in self.options:  # a line's body, the same at every grid point: kept as its description
            self.options = {**self.options, "body": _body_description(self.options["body"])}
        if "elastic" in self.options:  # the extensible line (snapping.sweep_elastic): its links' description
            from . import sweep_elastic

            self.options = {**self.options, "elastic": sweep_elastic.description(self.options["elastic"])}
            for chi in self.chi:
                for N in self.N:
                    sweep_elastic.solve_kwargs(dict(chi=chi, N=N, **self.options))
            return

        for chi in self.chi:  # every run's inputs, checked before any starts
            for N in self.N:
                check_inputs(**_run_kwargs(dict(chi=chi, N=N, **self.options)))

    def points(self) -> list[dict]:
        """One dict of run keywords per grid point."""
        return [dict(chi=c, N=n, **self.options) for c in self.chi for n in self.N]

    def _tag(self) -> str:
        if not self.options:
            return ""
        blob = json.dumps(self.options, sort_keys=True, default=str).encode()
        return "_" + hashlib.sha1(blob).hexdigest()[:8]

    def path(self, out_dir, chi: float, N: int) -> Path:
        """The file of the run (chi, N) in ``out_dir``."""
        return Path(out_dir) / f"run_chi{chi:g}_N{N}{self._tag()}.nc"

    def paths(self, out_dir) -> list[Path]:
        return [self.path(out_dir, p["chi"], p["N"]) for p in self.points()]


def grid_key(grid: Grid) -> str:
    """The grid as a JSON string (chi, N, options), stored in a combined sweep file as
    attribute ``sweep_grid``."""
    return json.dumps({"chi": [float(c) for c in grid.chi], "N": [int(n) for n in grid.N],
                       "options": grid.options}, sort_keys=True, default=str)


def _body_description(body, name: str = "options['body']") -> dict:
    """The description (:meth:`snapping.simulate.Body.describe`) of a sweep's body (a Body or
    a description), checked to be one that every chain of the grid can take."""
    from .simulate import Body

    if isinstance(body, dict):
        body = Body.from_describe(body)
    if not isinstance(body, Body):
        raise V.SnappingInputError(f"{name}={type(body).__name__} is not a snapping.simulate.Body")
    d = body.describe()
    if any(isinstance(v, (list, dict)) for k, v in d.items() if k not in ("wind", "clamp")):
        raise V.SnappingInputError(f"{name}: a body refined or swept over N takes numbers (the same at every N), "
                                   f"not per-node arrays or functions of s; run such bodies one by one")
    return d


def _run_kwargs(params: dict) -> dict:
    """The keywords of :func:`snapping.simulate.run` for one grid point: with a ``body``, the
    problem ``Problem.catenary(chi, N, chords=..., body=...)`` in place of chi, N and chords."""
    if "body" not in params:
        return params
    from .simulate import Body, Problem

    kw = dict(params)
    body = Body.from_describe(kw.pop("body"))
    chi, N, chords = kw.pop("chi"), kw.pop("N"), kw.pop("chords", None)
    kw["problem"] = Problem.catenary(chi, N, chords=chords or "exact", body=body)
    return kw
