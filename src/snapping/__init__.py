"""snapping: the physics of snapping in flexible bodies.

Modules
-------
ideal      the perfectly folded falling string (chi = 0): kink ODE, t*, exponents
estimates  design rules from the initial geometry alone (catenary, P, delta, peaks)
simulate   the compiled N-link chain simulator writing xarray Datasets
scaling    snapping times, exponent fits, reports and figures from runs
schema     the names of the run Dataset (the public contract)
"""

from importlib.metadata import PackageNotFoundError, version as _version

from ._validate import SnappingInputError

try:
    __version__ = _version("snapping")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = ["SnappingInputError", "__version__"]
