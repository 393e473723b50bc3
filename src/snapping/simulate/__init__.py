"""The compiled N-link chain simulator, writing self-describing xarray Datasets.

The paper's chain is the N-pendulum of its appendix (N equal masses of total mass 1,
N rigid links of length 1/N, the node N+1 pinned at the origin, gravity along +e2);
:class:`Problem` holds any other (unequal links and masses, a tip mass, a taper, any
start shape, a moving held end, any gravity). Kernels are compiled with numba
(``cache=True``); the result of a run is an :class:`xarray.Dataset` with the names of
:mod:`snapping.schema`.

Layout (what is solved, how it is stepped, what is recorded, kept apart):

* ``problem``: :class:`Problem`, with ``links`` (:class:`Links`), ``pin``
  (:class:`PinMotion`) and ``shape_files`` (a start shape read from a file) (physics only);
  ``chain``: the paper's initial catenary and state; ``shapes``: start curves;
* ``kernels`` (position form: ``layout``, the array layouts; ``accelerations``, the
  tension solve; ``measures``; ``stepping``, the Euler-Richardson loop), ``angles``
  (link-angle form, the paper's chain), ``general`` (link-angle form, any chain and held
  end): the compiled equations;
* ``methods``: the table of methods, ``methods.euler_richardson`` and
  ``methods.dop853`` (with ``rk``, the compiled DOP853 loop): how a run is stepped;
* ``options``: :class:`RunOptions`, the validated options every method shares;
* ``driver``: the one loop for every method (:func:`run`, stop rules, progress, signals,
  checkpoints); ``resuming``: continuing a run from its checkpoint (:func:`resume`,
  :func:`is_resumable`); ``errors``: the failures;
* ``dataset``: building, saving and loading the run Dataset; ``ensemble``: several
  chains in one vectorised kernel.

Imports run one way, problem -> options -> methods -> driver -> dataset (the shared
readers and the memory guard sit apart, in ``_netcdf`` and ``_memory``);
``tests/test_structure.py`` fails on an import circle.

Example
-------
>>> from snapping.simulate import run, load_run
>>> r = run(0.5, 10, t_end=0.1)                     # a short run
>>> r.dataset.attrs["status"], int(r.dataset.attrs["N"])
('completed', 10)
"""

from .chain import ChainState, curvature_profile, evaluate, initial_state, link_arclength, node_arclength
from .dataset import Run, build_dataset, initial_from_dataset, inputs_from_attrs, load_run, save, summary
from .driver import METHODS, integrate_fixed, rerun, run
from .ensemble import run_ensemble
from .errors import (DriftError, EnergyDriftError, NonFiniteError, RejectionError, RunInterrupted, SimulationError,
                     StepSizeError)
from .options import RunOptions, memory_need
from .problem import Body, Links, PinMotion, Problem
from .resuming import is_resumable, resume

__all__ = [
    "run",
    "Problem",
    "Links",
    "PinMotion",
    "Body",
    "RunOptions",
    "run_ensemble",
    "rerun",
    "Run",
    "SimulationError",
    "NonFiniteError",
    "StepSizeError",
    "DriftError",
    "EnergyDriftError",
    "RejectionError",
    "RunInterrupted",
    "resume",
    "is_resumable",
    "memory_need",
    "METHODS",
    "ChainState",
    "initial_state",
    "evaluate",
    "integrate_fixed",
    "curvature_profile",
    "node_arclength",
    "link_arclength",
    "load_run",
    "save",
    "inputs_from_attrs",
    "initial_from_dataset",
    "build_dataset",
    "summary",
]
