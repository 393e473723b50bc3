"""The order of the test files when the suite runs on several processes (pytest-xdist).

The README's test command is ``pytest -q -n 2 --dist loadfile --no-loadscope-reorder``: each
worker takes whole files (so a file's module fixtures, the docs build among them, run once),
one at a time, in the order collected. The slowest files go first (longest first), so that
the two workers end together instead of one waiting while the other runs a long file picked
last. (xdist's own reordering, by the number of tests, would put these files with few but
long tests last.) The times: ``--durations`` of a cold run (numba caches empty), in
CHANGELOG.md. A plain ``pytest`` (no ``-n``) keeps the files' alphabetical order.
"""

from __future__ import annotations

import os

#: the slowest files, roughly slowest first: the sums of their tests' ``--durations`` in one cold run on
#: one process (numba caches empty, 2 cores shared, load ~4; CHANGELOG.md, `fastsuite`)
SLOWEST_FIRST = (
    "test_caps.py",           # ~155 s: the stretching levels' elastic runs, the design rows
    "test_reproduce.py",      # ~140 s: the tiny reproduction and its rerun
    "test_regimes.py",        # ~95 s: the tiny study and its continuum reference
    "test_sweep.py",          # ~120 s: sweeps on worker processes, SIGINT/SIGKILL of sweeps
    "test_docs.py",           # ~70 s: the sphinx build
    "test_animation.py",      # ~75 s: a run with dense snapshots, GIF frames
    "test_checkpoint.py",     # ~70 s: interrupted runs resumed bit for bit
    "test_animation3d.py",    # ~50 s
    "test_highorder.py",      # ~45 s: the DOP853 ensemble against single runs
    "test_notebooks.py",      # ~45 s: three notebooks in kernels
    "test_peers_scripts.py",  # ~65 s: the peers' quick runs
    "test_caps_levels.py",
    "test_elastic_links.py",
    "test_checkpoint_dop853.py",
)


def pytest_collection_modifyitems(config, items):
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return  # one process: the files' own order
    rank = {name: i for i, name in enumerate(SLOWEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: the rest keep their order
