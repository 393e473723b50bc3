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
    chords ``exact``, the method's tol).
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

        for chi in self.chi:  # every run's inputs, checked before any starts
            for N in self.N:
                check_inputs(chi, N, **self.options)

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
