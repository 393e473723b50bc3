#!/usr/bin/env python3
"""Mutation testing of snapping: does the test suite catch small plausible bugs?

Each mutation in ``tools/mutations.toml`` replaces one exact piece of text (which must occur
exactly once in its file: the runner refuses otherwise) by another. The runner applies one
mutation at a time to a private copy of the tree (``src/``, ``tests/``, ``tools/``, ``pyproject.toml``
copied to a temporary directory; the working tree is never edited), runs the mutation's
covering tests there with ``python -m pytest -x -q -p no:cacheprovider`` (PYTHONPATH at the
copy's ``src``; a fresh NUMBA_CACHE_DIR when the mutated file holds numba-compiled code, else a
numba cache shared by the run's unmutated files), and says per mutation:

* ``caught``   the tests failed (the mutation was detected)
* ``survived`` the tests passed (the tests cannot tell the mutation from the code)
* ``timeout``  the tests ran past ``--timeout`` (counted as caught: a hang is visible)
* ``error``    pytest could not run (exit status 2-5: collection error, no tests, ...;
  counted as not caught, so a rotten list shows up in the score)

and the total ``caught X of Y (Z%)``; the exit status is 1 when the score is below
``--min-score`` (percent), 2 when the list is invalid.

Usage (from the repository root; stdlib only)::

    python tools/mutate.py --list                       # the mutations, by class
    python tools/mutate.py --check                      # every original occurs once (fast)
    python tools/mutate.py --min-score 90               # run them all
    python tools/mutate.py --only design-interval-le table-tip-scale
    python tools/mutate.py --class design --jobs 2 --timeout 300
    python tools/mutate.py --control --jobs 2        # first: the covering tests pass unmutated

A mutation (one ``[[mutation]]`` table)::

    [[mutation]]
    id = "design-interval-le"
    class = "design"                    # the class of bug (boundaries, off-by-one, units, ...)
    file = "src/snapping/design.py"
    original = "ok = g <= 0.0"           # exact text, once in the file
    replacement = "ok = g < 0.0"
    tests = ["tests/test_mutation_guards.py", "tests/test_table.py"]   # pytest arguments
    k = "design"                        # optional: a -k expression

A covering test file that does not exist is left out (so a list can be scored against an
older test suite); a mutation none of whose test files exists is an ``error``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIST = Path(__file__).resolve().parent / "mutations.toml"
COPY = ("src", "tests", "tools", "benchmarks", "pyproject.toml", "conftest.py", "docs", "README.md", "notebooks", "examples")
FIELDS = {"id", "class", "file", "original", "replacement", "tests"}


def load(path: Path = LIST) -> list[dict]:
    """The mutations of ``path``, checked: the fields are there, ids unique, every original
    occurs exactly once in its file and differs from its replacement. Raises ValueError."""
    with open(path, "rb") as fh:
        muts = tomllib.load(fh).get("mutation", [])
    problems, seen = [], set()
    for i, m in enumerate(muts):
        name = m.get("id", f"#{i}")
        missing = FIELDS - set(m)
        if missing:
            problems.append(f"{name}: missing {sorted(missing)}")
            continue
        if name in seen:
            problems.append(f"{name}: duplicate id")
        seen.add(name)
        f = ROOT / m["file"]
        if not f.is_file():
            problems.append(f"{name}: no file {m['file']}")
            continue
        n = f.read_text().count(m["original"])
        if n != 1:
            problems.append(f"{name}: the original occurs {n} times in {m['file']} (must be once)")
        if m["original"] == m["replacement"]:
            problems.append(f"{name}: the replacement is the original")
        if not m["tests"] or not all(isinstance(t, str) for t in m["tests"]):
            problems.append(f"{name}: tests must be a non-empty list of pytest arguments")
    if problems:
        raise ValueError("invalid mutation list " + str(path) + ":\n  " + "\n  ".join(problems))
    return muts


def _compiled(text: str) -> bool:
    return "@njit" in text or "numba.njit" in text or "@jit" in text or "@nb.njit" in text


def _copy_tree(dest: Path) -> None:
    for name in COPY:
        src = ROOT / name
        if src.is_dir():
            shutil.copytree(src, dest / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", ".pytest_cache"))
        elif src.is_file():
            shutil.copy2(src, dest / name)


def run_one(m: dict, slot: Path, shared_cache: Path, timeout: float, python: str,
            control: bool = False) -> tuple[str, float, str]:
    """Apply ``m`` in the slot's copy, run its tests, restore the file: (verdict, seconds, last output).
    ``control``: run the tests on the unmutated copy instead (they must pass: 'survived')."""
    rel = m["file"]
    target = slot / rel
    original_text = target.read_text()  # the copy's (the tree as it was when the run began)
    if original_text.count(m["original"]) != 1:
        return "error", 0.0, f"the original occurs {original_text.count(m['original'])} times in {rel}"
    st = target.stat()
    mutated = original_text if control else original_text.replace(m["original"], m["replacement"], 1)
    env = dict(os.environ)
    env["PYTHONPATH"] = str(slot / "src")
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    env.pop("PYTEST_ADDOPTS", None)
    env["SNAPPING_MUTATION"] = m["id"]  # (the list's own validity test skips: a mutated copy fails it)
    fresh = None
    if _compiled(original_text) and not control:
        fresh = tempfile.mkdtemp(prefix="numba-", dir=slot.parent)
        env["NUMBA_CACHE_DIR"] = fresh
    else:
        env["NUMBA_CACHE_DIR"] = str(shared_cache)
    tests = [t for t in m["tests"] if t.startswith("-") or (slot / t.split("::")[0]).exists()]
    if not tests:
        return "error", 0.0, f"none of the covering tests {m['tests']} exists"
    cmd = [python, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *tests]
    if m.get("k"):
        cmd += ["-k", m["k"]]
    t0 = time.monotonic()
    target.write_text(mutated)
    try:
        p = subprocess.Popen(cmd, cwd=slot, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                             start_new_session=True)
        try:
            out, _ = p.communicate(timeout=timeout)
            verdict = {0: "survived", 1: "caught"}.get(p.returncode, "error")
            tail = out.strip().splitlines()[-3:]
            if verdict == "caught":  # the test that caught it
                tail = [ln.split(" - ")[0] for ln in out.splitlines() if ln.startswith("FAILED ")][:1] or tail
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)  # pytest and whatever it started (its own session)
            p.communicate()
            verdict, tail = "timeout", [f"(ran past {timeout:g} s)"]
    finally:
        target.write_text(original_text)  # restore, with its mtime: the shared numba cache stays valid
        os.utime(target, ns=(st.st_atime_ns, st.st_mtime_ns))
        if fresh:
            shutil.rmtree(fresh, ignore_errors=True)
    return verdict, time.monotonic() - t0, " | ".join(tail)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--list", action="store_true", help="list the mutations and exit")
    ap.add_argument("--check", action="store_true", help="only check the list (every original once) and exit")
    ap.add_argument("--only", nargs="+", metavar="ID", help="run only these mutations")
    ap.add_argument("--class", dest="klass", metavar="NAME", help="run only the mutations of this class")
    ap.add_argument("--jobs", type=int, default=1, help="mutations run at once (default 1)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per mutation (default 600)")
    ap.add_argument("--min-score", type=float, default=0.0, help="exit 1 below this percentage caught")
    ap.add_argument("--mutations", type=Path, default=LIST, help="the mutation list (default tools/mutations.toml)")
    ap.add_argument("--python", default=sys.executable, help="the interpreter that runs pytest")
    ap.add_argument("--verbose", action="store_true", help="name the test that caught each mutation")
    ap.add_argument("--control", action="store_true",
                    help="first run each distinct set of covering tests on the unmutated copy: all must pass "
                         "(else a 'caught' could be a test that fails anyway); exit 2 if one does not")
    args = ap.parse_args(argv)
    try:
        muts = load(args.mutations)
    except (ValueError, tomllib.TOMLDecodeError, OSError) as e:
        print(f"mutate: {e}", file=sys.stderr)
        return 2
    if args.only:
        unknown = set(args.only) - {m["id"] for m in muts}
        if unknown:
            print(f"mutate: --only: no mutation {sorted(unknown)}", file=sys.stderr)
            return 2
        muts = [m for m in muts if m["id"] in args.only]
    if args.klass:
        muts = [m for m in muts if m["class"] == args.klass]
    if args.list:
        for m in muts:
            print(f"{m['id']:40s} {m['class']:12s} {m['file']}")
            print(f"    - {m['original']!r}\n    + {m['replacement']!r}")
        print(f"{len(muts)} mutations")
        return 0
    if args.check:
        print(f"mutate: {len(muts)} mutations, every original occurs once in its file")
        return 0
    if not muts:
        print("mutate: no mutation selected", file=sys.stderr)
        return 2
    jobs = max(1, args.jobs)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # (a terminated run removes its copies too)
    with tempfile.TemporaryDirectory(prefix="snapping-mutate-") as tmp:
        tmp = Path(tmp)
        shared_cache = tmp / "numba-shared"
        slots = []
        for j in range(jobs):
            slot = tmp / f"slot{j}" / "tree"
            slot.mkdir(parents=True)
            _copy_tree(slot)
            slots.append(slot)
        free = list(slots)
        results = {}
        t_all = time.monotonic()

        def task(m):
            slot = free.pop()
            try:
                res = run_one(m, slot, shared_cache, args.timeout, args.python)
            finally:
                free.append(slot)
            results[m["id"]] = res
            v, sec, tail = res
            print(f"{v:9s} {sec:7.1f} s  {m['id']:40s} {m['class']}" + (f"\n          {tail}"
                                                                         if v != "caught" or args.verbose else ""),
                  flush=True)

        if args.control:
            sets = {}
            for m in muts:
                sets.setdefault((tuple(m["tests"]), m.get("k")), m)
            failed = []

            def control(m):
                slot = free.pop()
                try:
                    v, sec, tail = run_one(m, slot, shared_cache, args.timeout, args.python, control=True)
                finally:
                    free.append(slot)
                print(f"control {'ok' if v == 'survived' else 'FAILED':6s} {sec:7.1f} s  {' '.join(m['tests'])}"
                      + (f" -k {m['k']!r}" if m.get("k") else "") + ("" if v == "survived" else f"\n          {tail}"),
                      flush=True)
                if v != "survived":
                    failed.append(m["id"])

            with ThreadPoolExecutor(max_workers=jobs) as pool:
                list(pool.map(control, sets.values()))
            if failed:
                print(f"mutate: the covering tests of {failed} fail without a mutation", file=sys.stderr)
                return 2
        with ThreadPoolExecutor(max_workers=jobs) as pool:
            list(pool.map(task, muts))
        counted = {"caught": 0, "timeout": 0, "survived": 0, "error": 0}
        for v, _, _ in results.values():
            counted[v] += 1
        caught = counted["caught"] + counted["timeout"]
        score = 100.0 * caught / len(muts)
        print()
        by_class = {}
        for m in muts:
            c = by_class.setdefault(m["class"], [0, 0])
            c[1] += 1
            c[0] += results[m["id"]][0] in ("caught", "timeout")
        for name, (a, b) in sorted(by_class.items()):
            print(f"  {name:14s} {a} of {b}")
        left = [m["id"] for m in muts if results[m["id"]][0] in ("survived", "error")]
        if left:
            print("not caught: " + " ".join(f"{i} ({results[i][0]})" for i in left))
        print(f"caught {caught} of {len(muts)} ({score:.1f}%) in {time.monotonic() - t_all:.0f} s "
              f"[{counted['caught']} caught, {counted['timeout']} timeout, {counted['survived']} survived, "
              f"{counted['error']} error]")
    return 1 if score < args.min_score else 0


if __name__ == "__main__":
    sys.exit(main())
