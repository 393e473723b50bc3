"""A sweep's failed runs: what a worker reports of a run that raised, :class:`RunFailure`,
:class:`SweepFailed` and the table that prints them (:func:`failure_table`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


def _one_line(text) -> str:
    """The first line of a message, at most 300 characters."""
    line = (str(text).strip().splitlines() or [""])[0]
    return line if len(line) <= 300 else line[:297] + "..."


def _existing(path) -> str | None:
    return str(path) if path is not None and Path(path).is_file() else None


def _failure_of(exc: BaseException, path: str) -> dict:
    """What a worker reports of a run that raised ``exc``: its failure kind, one-line
    message and the file it left (if any). Plain values: they cross process boundaries."""
    from .simulate.errors import SimulationError

    if isinstance(exc, SimulationError):
        ds = exc.dataset
        msg = ds.attrs.get("stop_reason") if ds is not None and ds.attrs.get("stop_reason") else str(exc)
        return {"kind": exc.kind or "simulation", "message": _one_line(msg), "file": _existing(exc.path or path)}
    msg = _one_line(exc) or type(exc).__name__
    if type(exc).__name__ == "BrokenProcessPool" and not str(exc).startswith("a worker process could not run"):
        msg = ("a worker process died (killed, out of memory, or, in a script, a sweep not started under "
               "`if __name__ == \"__main__\":`, whose workers re-run the script)")
    return {"kind": type(exc).__name__, "message": msg, "file": _existing(path)}


@dataclass
class RunFailure:
    """One run of a sweep that did not complete.

    Attributes
    ----------
    chi, N : float, int
        The grid point.
    options : dict
        The grid's run options (the same for every run of the grid).
    kind : str
        Why: the failure kind of a numerical failure (``SimulationError.kind``:
        'step_size', 'rejections', 'non_finite', 'link_drift', 'energy_drift'), or
        the exception's type name for anything else (e.g. 'SnappingInputError' for an
        option that is only refused at run time, 'BrokenProcessPool' for a worker that died).
    message : str
        One line saying what happened (the run's ``stop_reason`` for a numerical failure).
    file : str or None
        The run's file as it was left (status 'failed', what was computed until the
        failure), or None when there is none.
    """

    chi: float
    N: int
    options: dict
    kind: str
    message: str
    file: str | None = None

    def to_dict(self) -> dict:
        return {"chi": self.chi, "N": self.N, "options": dict(self.options), "kind": self.kind,
                "message": self.message, "file": self.file}


def failure_table(failures) -> str:
    """The failed runs of a sweep as an aligned text table (one row per run)."""
    rows = [("chi", "N", "options", "failure", "file", "message")]
    for f in failures:
        opts = ", ".join(f"{k}={v!r}" for k, v in sorted(f.options.items())) or "-"
        rows.append((f"{f.chi:g}", str(f.N), opts, f.kind, f.file or "(none)", f.message))
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    return "\n".join("  " + "  ".join(c.ljust(w) for c, w in zip(r[:5], widths)) + "  " + r[5] for r in rows).rstrip()


class SweepFailed(RuntimeError):
    """Some runs of a sweep failed; every other run completed and was saved.

    Raised by :func:`run_sweep` after all runs have been tried (it is a
    ``RuntimeError``, as the sweep's failures always were).

    Attributes
    ----------
    failures : list of RunFailure
        The runs that did not complete: which (chi, N, options), the failure kind, a
        one-line message and the run's partial file, if any (:func:`failure_table`
        prints them).
    paths : list of Path
        The files of the runs that completed (every grid point but the failed ones),
        ready for :func:`combine`.
    n_runs : int
        The runs of the grid.
    """

    def __init__(self, failures: list, paths: list, n_runs: int):
        self.failures = list(failures)
        self.paths = list(paths)
        self.n_runs = int(n_runs)
        first = "; ".join(f"chi={f.chi:g} N={f.N}: {f.kind}: {f.message}" for f in self.failures[:3])
        more = f"; and {len(self.failures) - 3} more" if len(self.failures) > 3 else ""
        super().__init__(f"{len(self.failures)} of {self.n_runs} runs failed ({first}{more}); the other runs are "
                         f"saved; rerun the sweep to retry only the failed ones")

    def table(self) -> str:
        """The failed runs as text (:func:`failure_table`)."""
        return failure_table(self.failures)
