"""Every example in the public docstrings runs and prints what it says."""

import doctest
import importlib

import pytest

MODULES = ["snapping.schema", "snapping.estimates", "snapping.estimates.catenary", "snapping.estimates.rules",
           "snapping.table", "snapping.design", "snapping.shape_estimates", "snapping.ideal", "snapping._validate",
           "snapping._files", "snapping.units", "snapping.cli"]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    # a module without examples would pass by construction: require that some ran
    assert result.failed == 0 and result.attempted > 0, result
