"""The memory a new allocation may take: the resource guard's share of the machine.

Both the chain's size check (:mod:`snapping.simulate.problem`) and a run's memory
estimate (:func:`snapping.simulate.options.check_memory`) measure against
``MEMORY_MARGIN * _available_memory()``; they take both from here, so that neither
imports the other.
"""

from __future__ import annotations

import os

#: fraction of the available memory a run may plan to use (resource guard)
MEMORY_MARGIN = 0.8


def _available_memory() -> int | None:
    """Bytes of memory available to a new allocation (MemAvailable, else free pages); None if unknown."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None
