"""Local worker processes that do not outlive their parent (sweeps, convergence studies).

:func:`local_pool` gives a ``ProcessPoolExecutor`` of spawned workers, each started by
:func:`worker_init`: a shared "stop" flag that makes them start no further task and stops
a run in progress at its next step boundary (saved with its checkpoint), set by the sweep
when it is interrupted and by a worker that receives SIGINT itself (Ctrl-C reaches the whole
process group); a worker whose run has not made its first steps yet (it is still starting:
importing, compiling) has nothing to save and ends at once; and a watchdog thread that ends
the worker when its parent is gone.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor

__all__ = ["local_pool", "stop_pool", "run_all", "worker_init", "stopped", "until_first_step", "nothing_to_save", "StopFlag",
           "WORKER_PID_FILE_ENV", "EXIT_ABANDONED"]

#: test hook: a path to which each local worker process appends its pid when it starts
WORKER_PID_FILE_ENV = "SNAPPING_SWEEP_WORKER_PID_FILE"


#: set in a local worker process: the sweep's "stop" flag (set when the sweep is interrupted)
_STOP = None
#: in a local worker process: "idle" between tasks, "starting" in a run (:func:`until_first_step`)
#: that has not made its first steps yet, "running" once it has (the driver's first chunk)
_PHASE = "idle"
_PHASE_LOCK = None
#: exit status of a worker that ended a run still starting because the sweep was interrupted
EXIT_ABANDONED = 3


class StopFlag:
    """A flag shared by a sweep and its local workers: one byte of shared memory, no lock
    (set from a signal handler, read at every step chunk; a process killed at any moment
    cannot leave it locked)."""

    def __init__(self, ctx):
        self._value = ctx.RawValue("b", 0)

    def set(self) -> None:
        self._value.value = 1

    def is_set(self) -> bool:
        return bool(self._value.value)


def worker_init(parent_pid: int, stop=None, interval: float = 0.1, grace: float = 3.0) -> None:
    """Initializer of the local worker processes.

    * SIGINT between runs sets ``stop`` (no ``KeyboardInterrupt`` traceback): a Ctrl-C
      reaches the whole process group, and a worker must not start a queued run before
      the sweep's own process has acted on it. A run in progress stops at a step boundary
      and saves its checkpoint (the driver installs its own handler while it runs), and
      then sets ``stop`` too (:func:`_call`).
    * ``stop`` (the :class:`StopFlag` the sweep sets when interrupted) makes the worker
      skip the tasks still queued for it, and stops a run in progress at its next step
      boundary, saved with its checkpoint, as SIGINT would (through the driver's chunk
      hook), so that an interrupted sweep ends promptly whenever the signal reached the
      worker. A run still starting (:func:`until_first_step`: importing, compiling, before
      its first steps; nothing of it to save, and a compilation may take a minute) is not
      waited for: the worker exits at once (status :data:`EXIT_ABANDONED`).
    * A daemon thread checks both every ``interval`` seconds; it also notices when the
      sweep's process is gone (the worker has been re-parented: ``os.getppid()`` changed,
      e.g. after a SIGKILL of the sweep) and ends this worker: it first sends itself
      SIGTERM, so that a run in progress stops at a step boundary and saves its
      checkpoint (a rerun of the sweep resumes it), and exits for good after ``grace``
      seconds.
    """
    import signal
    import threading
    import time

    global _STOP, _PHASE_LOCK
    _STOP = stop
    _PHASE_LOCK = threading.Lock()
    if stop is None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    else:
        signal.signal(signal.SIGINT, lambda signum, frame: stop.set())
    pid_file = os.environ.get(WORKER_PID_FILE_ENV)
    if pid_file:
        with open(pid_file, "a") as fh:
            fh.write(f"{os.getpid()}\n")

    def watch():
        while os.getppid() == parent_pid:
            if _PHASE == "starting" and stopped():
                with _PHASE_LOCK:  # (not while the run's first chunk hook marks it running)
                    if _PHASE == "starting":
                        os._exit(EXIT_ABANDONED)
            time.sleep(interval)
        try:
            os.kill(os.getpid(), signal.SIGTERM)
        finally:
            time.sleep(grace)
            os._exit(1)

    threading.Thread(target=watch, name="snapping-sweep-parent-watchdog", daemon=True).start()
    if stop is not None:
        from .simulate import driver

        driver._chunk_hook = _chunk_hook


def _chunk_hook(eng):
    """The driver's hook in a local worker: the run is under way; SIGINT when the sweep stops."""
    global _PHASE
    if _PHASE == "starting":
        with _PHASE_LOCK:
            _PHASE = "running"
    import signal

    return signal.SIGINT if stopped() else None


def stopped() -> bool:
    """True in a worker whose pool was told to stop (:func:`stop_pool`), or that got SIGINT."""
    return _STOP is not None and _STOP.is_set()


def until_first_step():
    """Context of one run in a local worker task: until the driver's first chunk of steps
    the run has nothing to save, and a stopped sweep ends the worker at once
    (:func:`worker_init`) instead of waiting for the run to import, compile and start.
    (Nothing outside a local worker.)"""
    import contextlib

    @contextlib.contextmanager
    def phase():
        global _PHASE
        if _STOP is None:
            yield
            return
        _PHASE = "starting"
        try:
            yield
        finally:
            with _PHASE_LOCK:
                _PHASE = "idle"

    return phase()


def nothing_to_save():
    """Context of a run that keeps no checkpoint (an extensible line's run: :mod:`snapping.simulate.elastic`)
    in a local worker task: it has nothing to save at any step (an interrupted one is run again), so a
    stopped sweep ends the worker at once (:func:`worker_init`) instead of waiting for the run to end.
    Such a run never reaches the driver's chunk hook, so it stays "starting" (:func:`until_first_step`)
    to its end. Around the run only, not its file's write. (Nothing outside a local worker.)"""
    return until_first_step()


def _call(fn, *args):
    """``fn(*args)`` in a local worker. An interrupted run (SIGINT or SIGTERM reached this
    worker: a ``KeyboardInterrupt``, its checkpoint saved) stops the sweep (no queued run
    starts, here or in the other workers) and goes back to the sweep without its Dataset:
    a small message (the pool's result pipe holds 64 KiB; the run is in its file)."""
    try:
        return fn(*args)
    except KeyboardInterrupt as exc:
        if _STOP is not None:
            _STOP.set()
        from .simulate.errors import RunInterrupted

        if isinstance(exc, RunInterrupted):
            raise RunInterrupted(str(exc), exc.signum, None, exc.path) from None
        raise KeyboardInterrupt(str(exc)) from None


def local_pool(n: int):
    """``n`` local worker processes (spawned) that end themselves if this process dies,
    and the :class:`StopFlag` that tells them to start no further task (:func:`worker_init`)."""
    import multiprocessing as mp

    ctx = mp.get_context("spawn")
    stop = StopFlag(ctx)
    return ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=worker_init,
                               initargs=(os.getpid(), stop)), stop


def stop_pool(stop, futures) -> None:
    """The sweep was interrupted: no queued task starts, every run in progress stops at
    a step boundary and saves its checkpoint, and a run still starting is dropped
    (:func:`worker_init`), whether the SIGINT reached the workers too (Ctrl-C) or this
    process alone."""
    stop.set()
    for fut in futures:
        fut.cancel()


def run_all(n: int, fn, calls, collect) -> None:
    """Call ``fn(*args)`` for every ``args`` of ``calls`` in ``n`` local workers
    (:func:`local_pool`); ``collect(args, result)`` is called in this process as each
    finishes (``result()`` returns its value or raises its exception). An interruption
    (SIGINT) or an exception in ``collect`` stops the pool (:func:`stop_pool`: nothing
    queued starts, runs in progress save their checkpoints) and propagates."""
    import sys
    import tempfile

    pool, stop = local_pool(n)
    futures = {}
    # the workers' stderr goes to a file: a worker that cannot start (e.g. cannot import snapping)
    # prints a multiprocessing traceback there, and its last line becomes the failure's reason
    err = tempfile.TemporaryFile()
    try:
        with _stderr_to(err):  # (the workers are spawned by the first submit, and inherit it)
            futures = {pool.submit(_call, fn, *args): args for args in calls}
        for fut in _as_completed(futures):
            collect(futures[fut], lambda fut=fut: _result(fut, err))
    except BaseException:
        stop_pool(stop, futures)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        text = _read(err)
        err.close()
        if text and "Traceback" not in text:  # what a working worker printed (warnings): passed on
            sys.stderr.write(text)


def _as_completed(futures):
    """The futures as they complete, waiting at most 0.5 s at a time: a SIGINT that the
    kernel delivers to another thread of this process (the pool's) is acted on by the
    main thread within 0.5 s, not only when the next run ends."""
    from concurrent.futures import FIRST_COMPLETED, wait

    pending = set(futures)
    while pending:
        done, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
        yield from done


def _stderr_to(fh):
    import contextlib
    import sys

    @contextlib.contextmanager
    def redirect():
        sys.stderr.flush()
        saved = os.dup(2)
        try:
            os.dup2(fh.fileno(), 2)
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)

    return redirect()


def _read(err) -> str:
    """What the workers wrote so far (pread: the offset they share with us is not moved)."""
    return os.pread(err.fileno(), 1 << 20, 0).decode(errors="replace")


def _result(fut, err):
    """``fut.result()``; a dead pool's error says why its worker died, when the worker said it."""
    from concurrent.futures.process import BrokenProcessPool

    try:
        return fut.result()
    except BrokenProcessPool as exc:
        lines = [ln.strip() for ln in _read(err).splitlines() if ln.strip()]
        if lines and "Traceback" in "".join(lines):
            raise BrokenProcessPool(f"a worker process could not run: {lines[-1][:200]}") from exc
        raise
