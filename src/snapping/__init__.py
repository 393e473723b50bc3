"""snapping: the physics of snapping in flexible bodies.

Modules
-------
ideal      the perfectly folded falling string (chi = 0): kink ODE, t*, exponents
estimates  design rules from the initial geometry alone (catenary, P, delta, peaks)
simulate   the compiled N-link chain simulator writing xarray Datasets
scaling    snapping times, exponent fits, reports and figures from runs
schema     the names of the run Dataset (the public contract)
"""

from ._validate import SnappingInputError


def __getattr__(name: str):
    """``__version__``, read from the installed metadata on first use (importlib.metadata costs
    ~50 ms of every command's start-up otherwise)."""
    if name != "__version__":
        raise AttributeError(f"module 'snapping' has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, version

    try:
        value = version("snapping")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        value = "0.0.0+unknown"
    globals()["__version__"] = value
    return value

__all__ = ["SnappingInputError", "__version__"]
