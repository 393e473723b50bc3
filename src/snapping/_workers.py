"""Local worker processes that do not outlive their parent (sweeps, convergence studies).

:func:`local_pool` gives a ``ProcessPoolExecutor`` of spawned workers, each started by
:func:`worker_init`: SIGINT ignored between tasks, a shared "stop" event that makes them
start no further task and stops a run in progress at its next step boundary (saved with
its checkpoint), and a watchdog thread that ends the worker when its parent is gone.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor, as_completed

__all__ = ["local_pool", "stop_pool", "run_all", "worker_init", "stopped", "WORKER_PID_FILE_ENV"]

#: test hook: a path to which each local worker process appends its pid when it starts
WORKER_PID_FILE_ENV = "SNAPPING_SWEEP_WORKER_PID_FILE"


#: set in a local worker process: the sweep's "stop" event (set when the sweep is interrupted)
_STOP = None


def worker_init(parent_pid: int, stop=None, interval: float = 0.2, grace: float = 3.0) -> None:
    """Initializer of the local worker processes.

    * SIGINT is ignored between runs: a Ctrl-C reaches the whole process group, and a
      worker waiting for its next task must not print a ``KeyboardInterrupt``
      traceback; a run in progress still stops at a step boundary and saves its
      checkpoint (the driver installs its own handler while it runs).
    * ``stop`` (an event the sweep sets when interrupted) makes the worker skip the
      tasks still queued for it, and stops a run in progress at its next step boundary,
      saved with its checkpoint, as SIGINT would (through the driver's chunk hook), so
      that an interrupted sweep ends promptly whenever the signal reached the worker.
    * A daemon thread notices when the sweep's process is gone (the worker has been
      re-parented: ``os.getppid()`` changed, e.g. after a SIGKILL of the sweep) and
      ends this worker: it first sends itself SIGTERM, so that a run in progress stops
      at a step boundary and saves its checkpoint (a rerun of the sweep resumes it),
      and exits for good after ``grace`` seconds.
    """
    import signal
    import threading
    import time

    global _STOP
    _STOP = stop
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    pid_file = os.environ.get(WORKER_PID_FILE_ENV)
    if pid_file:
        with open(pid_file, "a") as fh:
            fh.write(f"{os.getpid()}\n")

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(interval)
        try:
            os.kill(os.getpid(), signal.SIGTERM)
        finally:
            time.sleep(grace)
            os._exit(1)

    threading.Thread(target=watch, name="snapping-sweep-parent-watchdog", daemon=True).start()
    if stop is not None:
        from .simulate import driver

        driver._chunk_hook = lambda eng: signal.SIGINT if stop.is_set() else None


def stopped() -> bool:
    """True in a worker whose pool was told to stop (:func:`stop_pool`)."""
    return _STOP is not None and _STOP.is_set()


def local_pool(n: int):
    """``n`` local worker processes (spawned) that end themselves if this process dies,
    and the event that tells them to start no further task (:func:`worker_init`)."""
    import multiprocessing as mp

    ctx = mp.get_context("spawn")
    stop = ctx.Event()
    return ProcessPoolExecutor(max_workers=n, mp_context=ctx, initializer=worker_init,
                               initargs=(os.getpid(), stop)), stop


def stop_pool(stop, futures) -> None:
    """The sweep was interrupted: no queued task starts, and every run in progress
    stops at a step boundary and saves its checkpoint (:func:`worker_init`), whether
    the SIGINT reached the workers too (Ctrl-C) or this process alone."""
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
            futures = {pool.submit(fn, *args): args for args in calls}
        for fut in as_completed(futures):
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
