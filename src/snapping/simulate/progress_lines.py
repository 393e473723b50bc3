"""Progress as plain lines, for a run whose stderr is not a terminal (a log file, a pipe,
a batch job): the tqdm bar is off there, so without these lines a long run says nothing
until it ends. A run shorter than :data:`EVERY` seconds prints nothing; a longer one prints a
line every :data:`EVERY` seconds (the first says why) and one when it stops. The same calls as
the tqdm bar (``update``, ``set_postfix_str``, ``close``)."""

from __future__ import annotations

import sys
import time

#: seconds between two progress lines
EVERY = 10.0


class LineProgress:
    """A progress "bar" that prints ``desc: t=..., <postfix>, <elapsed> s`` lines to ``file``."""

    def __init__(self, desc: str, total=None, initial: float = 0.0, *, estimated: bool = False, every=None,
                 file=None):
        self.desc, self.total, self.n, self.estimated = desc, total, float(initial), estimated
        self.every = EVERY if every is None else float(every)
        self.file = file or sys.stderr
        self.postfix = ""
        self.t0 = self.last = time.monotonic()
        self.printed = 0

    def _print(self, text: str) -> None:
        try:
            print(f"{self.desc}: {text}", file=self.file, flush=True)
        except (OSError, ValueError):  # a closed or full stderr: progress is not worth a failure
            pass

    def _line(self) -> str:
        of = "" if not self.total else f"/{'~' if self.estimated else ''}{self.total:.4g}"
        post = f", {self.postfix}" if self.postfix else ""
        return f"t={self.n:.6g}{of}{post}, {time.monotonic() - self.t0:.0f} s"

    def update(self, n: float = 1) -> None:
        self.n += n
        if self.estimated and self.total is not None and self.n > self.total:
            self.total = self.n
        now = time.monotonic()
        if now - self.last >= self.every:
            self.last = now
            if not self.printed:
                of = "" if not self.total else f" (of t={self.total:.4g}{', the estimated snap' if self.estimated else ''})"
                self._print(f"running{of}; a line every {self.every:g} s (stderr is not a terminal: no progress bar)")
            self.printed += 1
            self._print(self._line())

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        self.postfix = s

    def close(self) -> None:
        if self.printed:
            self._print(f"stopped at {self._line()}")


def _isatty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def open_bar(desc: str, *, progress, t_end=None, expected=None, initial: float = 0.0, line_desc=None):
    """The progress display of one run in simulated time, the same for every method (the rigid
    chain's driver and the extensible line's :func:`snapping.simulate.elastic.solve`): None when
    ``progress`` is False; with ``progress=None`` and stderr not a terminal, a
    :class:`LineProgress` (``line_desc``, default ``desc``); else a tqdm bar on stderr (shown on a
    terminal only when ``progress`` is None) of ``t`` out of ``t_end``, or out of the ``expected``
    snap time (an estimate, raised when ``t`` passes it), or of ``t`` alone."""
    if progress is False:
        return None
    if progress is None and not _isatty(sys.stderr):  # a log or a pipe: lines every ~10 s, not a bar
        return LineProgress(line_desc or desc, total=t_end or expected, initial=initial, estimated=not t_end)
    from tqdm.auto import tqdm

    if t_end:
        fmt = "{desc}: t={n:.5f}/{total:.5f} {bar} [{elapsed}<{remaining}]{postfix}"
    elif expected:
        fmt = "{desc}: t={n:.5f}/~{total:.4f} (estimated snap) {bar} [{elapsed}<{remaining}]{postfix}"
    else:
        fmt = "{desc}: t={n:.5f} [{elapsed}]{postfix}"

    class _Bar(tqdm):  # an estimated total is raised when t passes it (no bar beyond 100%)
        def update(self, n=1):
            if expected and self.total is not None and self.n + n > self.total:
                self.total = self.n + n
            return super().update(n)

    return _Bar(total=t_end or expected, initial=initial, file=sys.stderr, disable=None if progress is None else False,
                unit="t", desc=desc, dynamic_ncols=True, bar_format=fmt)
