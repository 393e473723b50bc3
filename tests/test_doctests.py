"""Every example in the public docstrings runs and prints what it says."""

import doctest
import importlib
import pkgutil

import pytest

MODULES = ["snapping.schema", "snapping.estimates", "snapping.estimates.catenary", "snapping.estimates.rules",
           "snapping.table", "snapping.design", "snapping.shape_estimates", "snapping.ideal", "snapping._validate",
           "snapping._files", "snapping.units", "snapping.unit_scales", "snapping.cli", "snapping.lines",
           "snapping.dimensionless", "snapping.simulate.compression", "snapping.spatial", "snapping.regimes_analysis",
           "snapping.caps", "snapping.caps_inputs", "snapping.reproduce_verdicts"]


def _with_submodules(module):
    """The module and, for a package, every module in it (doctest.testmod skips the functions a
    package only re-exports from its modules: each module's own examples are run there)."""
    if not hasattr(module, "__path__"):
        return [module]
    return [module] + [importlib.import_module(m.name) for m in pkgutil.walk_packages(module.__path__, module.__name__ + ".")
                       if not m.name.endswith(".__main__")]  # (runs the command line)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    failed = attempted = 0
    for module in _with_submodules(importlib.import_module(name)):
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
        failed, attempted = failed + result.failed, attempted + result.attempted
    # a module without examples would pass by construction: require that some ran
    assert failed == 0 and attempted > 0, (name, failed, attempted)
