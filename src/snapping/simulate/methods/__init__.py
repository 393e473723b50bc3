"""How a problem is stepped: the table of methods.

A method is a module with an ``Engine`` (the compiled step loop and its state, driven by
:func:`snapping.simulate.driver._drive` through the interface every engine shares), a
``setup(chi, N, method, opts, *, chords, initial, problem)`` returning the run's input
attributes and its engine, ``complete(opts, method)`` filling in the method's defaults
of the shared :class:`snapping.simulate.options.RunOptions`, its ``NAMES`` and its
``CHECKPOINT_VARS``. A new method is one module here and one line in :data:`METHODS`.

>>> from snapping.simulate import methods
>>> methods.resolve("fast"), methods.method("fast").__name__
('dop853', 'snapping.simulate.methods.dop853')
"""

from __future__ import annotations

from types import ModuleType

from ... import _validate as V
from . import dop853, euler_richardson, rodas4

__all__ = ["METHODS", "NAMES", "ALIASES", "method", "resolve"]

#: method name -> module. ``euler-richardson``: the paper's adaptive scheme (reference);
#: ``euler-richardson-fixed``: the same step at a fixed dt = dt0 (order studies);
#: ``dop853``: the chain in link angles (links exact to round-off), compiled Dormand-Prince
#: 8(5,3) with dense output, every :class:`snapping.simulate.problem.Problem`; ``rodas4``: the
#: stiff method (linearly implicit, L-stable, banded O(N) stage solves) for problems with a body.
METHODS: dict[str, ModuleType] = {
    "euler-richardson": euler_richardson,
    "euler-richardson-fixed": euler_richardson,
    "dop853": dop853,
    "rodas4": rodas4,
}
#: names that stand for another: ``fast`` is always the project's best exact method (the
#: default of :func:`snapping.simulate.run`, ``snapping simulate`` and ``snapping sweep``)
#: ``stiff`` names the stiff method
ALIASES = {"fast": "dop853", "stiff": "rodas4"}
#: every name :func:`snapping.simulate.run` takes
NAMES = (*METHODS, *ALIASES)


def resolve(name: str) -> str:
    """The method a name stands for."""
    return ALIASES.get(name, name)


def method(name: str) -> ModuleType:
    """The module of method ``name`` (an alias resolved), or SnappingInputError."""
    if not isinstance(name, str) or resolve(name) not in METHODS:
        raise V.SnappingInputError(f"method={name!r} is not one of {NAMES}")
    return METHODS[resolve(name)]
