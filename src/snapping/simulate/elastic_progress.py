"""The progress display of one extensible-line run (:func:`snapping.simulate.elastic.solve`):
the rigid chain's bar (:func:`snapping.simulate.progress_lines.open_bar`: the same option
``progress``, the same rules, ``t`` out of ``t_end`` or of the estimated snap), with the steps
and rejected steps taken.

The compiled RODAS4 loops (:mod:`snapping.simulate.elastic_advance`) return to Python when
their record buffer is full; with a bar shown, :class:`Chunks` hands them a shorter buffer,
sized from the measured wall time per step so that a call lasts about :data:`CHUNK_SECONDS`
(the rigid chain's loops return every so many node-evaluations, to the same end). A return is
a step boundary with the whole state in the loop's arrays, so the run's numbers do not depend
on where it returns: with or without the bar they are the same, bit for bit. Without a bar
the buffer is the full :data:`elastic_advance.ROWS`, as before.
"""

from __future__ import annotations

import time

from .progress_lines import open_bar

__all__ = ["open_run_bar", "show", "Chunks", "CHUNK_SECONDS"]

#: wall seconds one call into the compiled loop aims at while a bar is shown
CHUNK_SECONDS = 0.2
#: steps of the first call with a bar (then set from the measured time per step)
FIRST_CHUNK = 16
#: the most a chunk grows from one call to the next
GROWTH = 4


def expected_snap(problem):
    """The rigid chain's estimated snap time (:func:`snapping.simulate.driver.expected_snap_time`)
    for a line released at rest from the catenary of ``problem.chi``, N equal links, its held end
    fixed, g = 1, no tip mass; None otherwise (the bar then shows ``t`` alone)."""
    import numpy as np

    from .driver import expected_snap_time

    links = problem.links
    if (problem.chi is None or problem.start.get("kind") != "catenary" or problem.start.get("velocities")
            or not problem.pin.is_fixed or problem.gravity != 1.0 or links.tip_mass != 0.0
            or not np.all(links.h == links.h[0])):
        return None
    return expected_snap_time({"chi": float(problem.chi), "initial": "catenary"})


def open_run_bar(problem, method: str, t_end, progress):
    """The bar of a run (None when ``progress`` is False): ``t`` out of ``t_end``, or of the
    estimated snap time of an automatic run (:func:`expected_snap`)."""
    desc = f"extensible line N={problem.N} ({method})"
    return open_bar(desc, progress=progress, t_end=t_end, expected=None if t_end else expected_snap(problem))


def show(bar, t: float, steps: int, rejected, v_max: float, dt: float) -> None:
    """Move ``bar`` to ``t``, with the speed, the last step and the counts of steps (and of
    rejected steps, when the method counts them) in its postfix."""
    if bar is None:
        return
    bar.update(t - bar.n)
    rej = "" if rejected is None else f" rejected={int(rejected)}"
    bar.set_postfix_str(f"v_max={v_max:.4g} dt={dt:.3g} steps={int(steps)}{rej}", refresh=False)


class Chunks:
    """The record rows (steps) a call into the compiled loop may take: all of the buffer
    (``rows``) without a bar; with one, :data:`FIRST_CHUNK`, then as many as take about
    :data:`CHUNK_SECONDS` at the measured wall time per step."""

    def __init__(self, bar, rows: int, short: bool = False):
        self.max = int(rows)
        self.adapt = bar is not None or bool(short)  # (short: a checkpointed run, its chunks as a bar's)
        self.rows = min(FIRST_CHUNK, self.max) if self.adapt else self.max
        self.t0 = time.perf_counter()

    def start(self) -> int:
        self.t0 = time.perf_counter()
        return self.rows

    def done(self, steps: int) -> None:
        """After a call that took ``steps`` steps."""
        if not self.adapt or steps <= 0:
            return
        per = max(time.perf_counter() - self.t0, 1e-9) / steps
        self.rows = max(1, min(self.max, GROWTH * self.rows, int(CHUNK_SECONDS / per)))
