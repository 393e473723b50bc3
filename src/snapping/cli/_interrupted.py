"""What the command line says when SIGINT or SIGTERM arrives outside a run's step loop (parsing,
compiling, setting up, or after the run, while it writes or prints): the run's loops say it
themselves (they save a checkpoint and print the command that continues it); here, where no
checkpoint is taken, the words say what happened to each file the command names (-o, the
--resume file, the extensible line's --checkpoint) and what to do next.

A file's state is taken when the command starts (:func:`file_states`: its identity, inode,
size and modification time) and compared when it is interrupted: files are replaced whole
(written to a temporary, then renamed), so a file is either as it was ("unchanged"), absent
("nothing was written") or the one this command wrote ("holds what this command wrote")."""

from __future__ import annotations

import os

#: the dests of simulate's file options
_FILE_DESTS = ("output", "resume", "checkpoint")


def _identity(path: str):
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)


def file_states(args) -> dict:
    """{path: identity or None} of the files the command names, as the command starts."""
    out = {}
    for dest in _FILE_DESTS:
        v = getattr(args, dest, None)
        if isinstance(v, str) and v:
            out[os.path.realpath(v)] = _identity(v)
    return out


def _changed(args, path: str) -> bool:
    """True if ``path`` exists and is not the file it was when the command started."""
    now = _identity(path)
    return now is not None and now != getattr(args, "_files_before", {}).get(os.path.realpath(path))


def _kept(path: str, args) -> str:
    if _identity(path) is None:
        return f"nothing was written ({path} does not exist)"
    if _changed(args, path):
        return f"{path} holds what this command wrote before the interruption (written whole)"
    return f"{path} is unchanged"


def outside_run(args) -> str:
    """The words after "interrupted by SIGINT " (or "terminated by SIGTERM ") when the signal
    arrived outside a run's loop."""
    generic = "while starting up or finishing (outside a run's loop, where no checkpoint is taken)"
    if args.command != "simulate":
        return generic
    from ._elastic import is_elastic

    out = getattr(args, "output", None)
    res = args.resume if isinstance(getattr(args, "resume", None), str) else None
    if is_elastic(args):
        return _elastic_words(args, out, res)
    if out and _changed(args, out) or res and not out and _changed(args, res):
        where = out or res
        return f"after the run: {where} holds the run this command wrote before the interruption (written whole)"
    if res is not None:
        also = f"; -o: {_kept(out, args)}" if out else ""
        return (f"before the resumed run's first step: its checkpoint {res} is unchanged{also}; run the same "
                f"command again to continue it")
    if out:
        return f"before the run's first step: {_kept(out, args)}; run the command again"
    return generic + " (no -o RUN.nc: nothing is written)"


def _elastic_words(args, out, res) -> str:
    """The extensible line's: its -o is written when the run ends, its --checkpoint (if any) by its loop."""
    if out and _changed(args, out):
        return f"after the extensible line's run: {out} holds the finished run (written whole before the interruption)"
    kept = _kept(out, args) if out else "nothing was written (no -o)"
    running = getattr(args, "_elastic_running", False)
    ck = getattr(args, "checkpoint", None) or res
    if ck is None:
        if running:
            return (f"during the extensible line's run, which keeps no checkpoint (no --checkpoint FILE) and cannot "
                    f"be resumed: {kept}; run the command again")
        return f"before the run's first step: {kept}; run the command again"
    where = ("during the extensible line's run, outside its step loop (where its checkpoint is saved)" if running
             else "before the extensible line's run started")
    if _identity(ck) is None:
        return f"{where}: {kept}; no checkpoint was saved ({ck} does not exist): run the command again"
    from ._elastic import resume_command

    return (f"{where}: {kept}; its checkpoint {ck} is kept as last saved: continue with: "
            f"{resume_command(args, ck)}")
