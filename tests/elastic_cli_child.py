"""A ``snapping`` command line run in a subprocess by the extensible line's CLI checkpoint tests
(tests/test_elastic_cli_checkpoint.py, test_elastic_cli_lock.py): ``python elastic_cli_child.py
MARKER GO K ARGS...`` runs ``snapping ARGS...`` and, at the K-th return of the checkpointed
run's compiled loop (elastic_checkpoint._chunk_hook), creates MARKER and waits (at most 60 s)
for GO to exist: the test then signals it, or holds it there while it tries the same files.
Not a test file (no ``test_`` prefix)."""

import os
import sys
import time

from snapping.cli import main
from snapping.simulate import elastic_checkpoint

marker, go, k = sys.argv[1], sys.argv[2], int(sys.argv[3])
calls = [0]


def hook(run):
    calls[0] += 1
    if calls[0] == k:
        open(marker, "w").close()
        t0 = time.monotonic()
        while not os.path.exists(go) and time.monotonic() - t0 < 60.0:
            time.sleep(0.01)
    return None


elastic_checkpoint._chunk_hook = hook
sys.exit(main(sys.argv[4:]))
