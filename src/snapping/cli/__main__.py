"""``python -m snapping.cli``: the ``snapping`` command."""

import sys

from . import main

sys.exit(main())
