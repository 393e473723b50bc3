"""The numerical failures of a run and its interruption by a signal.

A run that fails numerically raises one of the subclasses of :class:`SimulationError`
(what was computed is in ``exc.dataset``, and in the output file); SIGINT/SIGTERM stop
a run at a step boundary with :class:`RunInterrupted`. :data:`FAILURES` maps the return
codes of the compiled loops (``kernels.RET_FAIL_*``, shared by every method) to them.

Example
-------
>>> from snapping.simulate import run, StepSizeError
>>> try:
...     run(0.3, 50, method="fast", dt_min=0.01)
... except StepSizeError as exc:
...     print(exc.kind, exc.dataset.attrs["status"], exc.node >= 0)
step_size failed True
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import kernels as K

if TYPE_CHECKING:  # pragma: no cover
    import xarray as xr

__all__ = ["SimulationError", "NonFiniteError", "StepSizeError", "DriftError", "EnergyDriftError", "RejectionError",
           "RunInterrupted", "FAILURES", "RET_SIGNAL"]


class SimulationError(RuntimeError):
    """A run failed numerically (NaN, step-size underflow, link drift past the bound).

    The specific failures are the subclasses :class:`NonFiniteError`,
    :class:`StepSizeError`, :class:`DriftError` (link lengths),
    :class:`EnergyDriftError` and :class:`RejectionError`.

    Attributes
    ----------
    dataset : xarray.Dataset
        What was computed until the failure (``status = 'failed'``, ``stop_reason``,
        ``failure``, ``failure_node``).
    path : str or None
        Where it was saved, when the run had an output path.
    t : float
        Time of the last accepted step.
    step : int
        Number of accepted steps.
    node : int
        Index along the Dataset's ``node`` dimension of the worst node (0: free end), -1 if unknown.
    kind : str
        The ``failure`` attribute ('non_finite', 'step_size', 'link_drift', 'energy_drift', 'rejections').
    """

    kind = ""

    def __init__(self, message: str, dataset: xr.Dataset | None = None, path: str | None = None, *,
                 t: float = float("nan"), step: int = -1, node: int = -1):
        super().__init__(message)
        self.dataset = dataset
        self.path = path
        self.t = t
        self.step = step
        self.node = node


class NonFiniteError(SimulationError):
    """NaN or infinite values in the state, accelerations or error estimate."""

    kind = "non_finite"


class StepSizeError(SimulationError):
    """The adaptive time step fell below the floor ``dt_min``."""

    kind = "step_size"


class DriftError(SimulationError):
    """A link length drifted from 1/N past ``max_link_error`` (plus the initial chord error)."""

    kind = "link_drift"


class EnergyDriftError(DriftError):
    """The total energy drifted from its initial value past ``max_energy_drift``."""

    kind = "energy_drift"


class RejectionError(SimulationError):
    """More than ``max_rejections`` consecutive steps were rejected."""

    kind = "rejections"


def deliver_late(signum) -> None:
    """Raise now a SIGINT or SIGTERM that a run noted after its last check (in its last steps, or
    while it wrote its file, which is then whole): through the handler in place again once the
    run's own is put back (Python's SIGINT handler: ``KeyboardInterrupt``; the command line's
    SIGTERM handler: its exit 143), so a signal is acted on late, never dropped."""
    import signal

    signal.raise_signal(int(signum))


class RunInterrupted(KeyboardInterrupt):
    """A run stopped at a step boundary on SIGINT or SIGTERM (a ``KeyboardInterrupt``).

    Attributes
    ----------
    signum : int
        The signal (``signal.SIGINT`` or ``signal.SIGTERM``); exit status ``128 + signum``.
    dataset : xarray.Dataset
        The run so far (``status = 'interrupted'``), with its checkpoint.
    path : str or None
        Where it was saved (resume with :func:`resume` or ``snapping simulate --resume``).
    """

    def __init__(self, message: str, signum: int, dataset: xr.Dataset | None = None, path: str | None = None):
        super().__init__(message)
        self.signum = signum
        self.dataset = dataset
        self.path = path

    @property
    def exit_status(self) -> int:
        """128 + the signal number (130 for SIGINT, 143 for SIGTERM)."""
        return 128 + int(self.signum)

    def __reduce__(self):
        # (picklable, e.g. from a sweep's worker process: the default rebuilds it from the
        # message alone, which fails for want of ``signum``, and breaks the worker pool)
        return type(self), (str(self), self.signum, self.dataset, self.path), self.__dict__


#: the exception of each failure code of the compiled loops
FAILURES = {
    K.RET_FAIL_NAN: NonFiniteError,
    K.RET_FAIL_DT: StepSizeError,
    K.RET_FAIL_DRIFT: DriftError,
    K.RET_FAIL_ENERGY: EnergyDriftError,
    K.RET_FAIL_REJECT: RejectionError,
}

#: Python-side return code of an engine's ``loop``: stopped by a signal (or the test hook)
RET_SIGNAL = -1
