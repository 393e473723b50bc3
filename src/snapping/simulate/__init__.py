"""The compiled N-link chain simulator, writing self-describing xarray Datasets.

The discrete chain is the N-pendulum of the paper's appendix (N equal masses of
total mass 1, N rigid links of length 1/N, the node N+1 pinned at the origin,
gravity along +e2), integrated with the paper's Euler-Richardson adaptive
scheme. Kernels are compiled with numba (``cache=True``); the result of a run
is an :class:`xarray.Dataset` with the names of :mod:`snapping.schema`.

Example
-------
>>> from snapping.simulate import run, load_run
>>> r = run(0.5, 10, t_end=0.1)                     # a short run
>>> r.dataset.attrs["status"], int(r.dataset.attrs["N"])
('completed', 10)
"""

from .chain import ChainState, curvature_profile, evaluate, initial_state, link_arclength, node_arclength
from .dataset import build_dataset, initial_from_dataset, inputs_from_attrs, load_run, save
from .ensemble import run_ensemble
from .problem import Links, PinMotion, Problem
from .stepper import (
    METHODS,
    DriftError,
    EnergyDriftError,
    NonFiniteError,
    RejectionError,
    Run,
    RunInterrupted,
    SimulationError,
    StepSizeError,
    integrate_fixed,
    is_resumable,
    memory_need,
    rerun,
    resume,
    run,
    summary,
)

__all__ = [
    "run",
    "Problem",
    "Links",
    "PinMotion",
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
