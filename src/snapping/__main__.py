"""``python -m snapping``: the ``snapping`` command (the same as ``python -m snapping.cli``)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
