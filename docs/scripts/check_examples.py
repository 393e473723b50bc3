"""Run the examples of the documentation pages, as a reader would copy them.

Every ``$ command`` line of a ``console`` block and every ``python`` block of the given
Markdown pages is run, in page order, in one scratch directory (so a page's later
examples see the files its earlier ones wrote); a command or block that fails is
reported with its output. Lines matching ``--skip`` patterns are not run (long jobs,
cluster commands).

Usage::

    PYTHONPATH=src python docs/scripts/check_examples.py docs/index.md docs/guide/*.md \\
        --skip "reproduce --full" --skip "dask scheduler" --skip "dask worker"
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

FENCE = re.compile(r"^```(\w+)\s*$")


def examples(page: Path):
    """(kind, text) of each example of a page: kind 'console' (one command) or 'python'."""
    lines = page.read_text().splitlines()
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        kind, body = m.group(1), []
        i += 1
        while i < len(lines) and not lines[i].startswith("```"):
            body.append(lines[i])
            i += 1
        i += 1
        if kind == "console":
            for line in body:
                if line.startswith("$ "):
                    yield "console", line[2:]
        elif kind == "python":
            yield "python", "\n".join(body) + "\n"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("pages", nargs="+", type=Path)
    p.add_argument("--skip", action="append", default=[], help="do not run examples containing this text")
    p.add_argument("--dir", default=None, help="scratch directory (default: a new temporary one)")
    args = p.parse_args()
    work = Path(args.dir or tempfile.mkdtemp(prefix="snapping_docs_"))
    work.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, MPLBACKEND="Agg")
    if env.get("PYTHONPATH"):  # relative entries (PYTHONPATH=src) must still name this tree in the scratch directory
        env["PYTHONPATH"] = os.pathsep.join(os.path.abspath(p) for p in env["PYTHONPATH"].split(os.pathsep))
    env["PATH"] = os.path.dirname(sys.executable) + os.pathsep + env.get("PATH", "")
    failed = 0
    for page in args.pages:
        for kind, text in examples(page):
            if any(s in text for s in args.skip):
                print(f"skip  {page}: {text.strip().splitlines()[0]}")
                continue
            t0 = time.perf_counter()
            if kind == "console":
                proc = subprocess.run(["bash", "-c", text], cwd=work, env=env, capture_output=True, text=True)
            else:
                proc = subprocess.run([sys.executable, "-c", text], cwd=work, env=env, capture_output=True, text=True)
            ok = proc.returncode == 0
            failed += not ok
            head = text.strip().splitlines()[0]
            print(f"{'ok  ' if ok else 'FAIL'}  {page}: {head}  ({time.perf_counter() - t0:.1f} s)")
            if not ok or os.environ.get("SHOW"):  # SHOW=1: every example's output
                print("    " + (proc.stdout + proc.stderr).strip().replace("\n", "\n    "))
    print(f"{failed} failed; scratch directory {work}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
