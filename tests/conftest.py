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

#: the slowest files, slowest first: the sums of their tests' ``--durations`` in one cold run on one
#: process (numba caches empty, 2 cores shared, load 3-9, 2026-12-03; compiling numba kernels is much of it)
SLOWEST_FIRST = (
    "test_caps.py",             # ~245 s: the stretching levels' elastic runs (their compile), the design rows
    "test_sweep.py",            # ~200 s: sweeps on worker processes, SIGINT/SIGKILL of sweeps
    "test_reproduce.py",        # ~180 s: the tiny reproduction and its rerun
    "test_peers_scripts.py",    # ~115 s: the peers' quick runs
    "test_regimes.py",          # ~115 s: the tiny study and its continuum reference
    "test_docs.py",             # ~110 s: the sphinx build
    "test_highorder.py",        # ~110 s: the DOP853 ensemble kernel's compile
    "test_notebooks.py",        # ~105 s: three notebooks in kernels
    "test_regimes_stretch.py",  # ~75 s: the shipped stretching study's checks
    "test_animation3d.py",      # ~70 s
    "test_elastic.py",          # ~65 s
    "test_checkpoint.py",       # ~60 s: interrupted runs resumed bit for bit
    "test_elastic_damping.py",  # ~60 s
    "test_animation.py",        # ~55 s: a run with dense snapshots, GIF frames
    "test_checkpoint_dop853.py",
    "test_snap_window.py",
    "test_body_figures.py",
    "test_caps_levels.py",
    "test_elastic_links.py",
)


def pytest_collection_modifyitems(config, items):
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return  # one process: the files' own order
    rank = {name: i for i, name in enumerate(SLOWEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: the rest keep their order
