"""Build the shipped table of computed snaps (:mod:`snapping.table`).

Every grid point (chi, N, tip-mass ratio) is one run of the fast exact method
(:func:`snapping.simulate.run`, its defaults: dop853, exact chords, tol 1e-6); only
its peaks are kept. The runs go to the sweep's local worker processes
(:mod:`snapping._workers`: they end with their parent) and each finished run is
appended at once to a ledger (``runs.jsonl``, one JSON object a line, flushed and
fsynced), so an interrupted build loses at most the runs in progress: run the same
command again and it does only what the ledger lacks. The full run files are not
kept: the table needs the peaks alone, and thousands of run files would weigh
gigabytes. :func:`assemble` turns a complete ledger into the table Dataset  and writes it atomically.

Command (what built the shipped file; its header repeats it with the CPU time)::

    python -m snapping.table.build --ledger build/table/runs.jsonl \
        -o src/snapping/data/snap_table.nc
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

from .. import _validate as V
from .. import _workers

__all__ = ["CHI", "N_LINKS", "TIP_MASS", "N_TIP_MAX", "points", "run_case", "peaks_of_run", "run_point", "build", "read_ledger", "assemble",
           "main"]

#: end separations (denser at small chi, where the peaks vary fastest, and towards chi = 1)
CHI = (0.05, 0.06, 0.07, 0.08, 0.09, 0.10, 0.115, 0.13, 0.15, 0.175, 0.20, 0.23, 0.27, 0.31, 0.36, 0.42, 0.50,
       0.55, 0.60, 0.65, 0.70, 0.75, 0.80, 0.85, 0.90)
#: numbers of links: every integer from 10 to 48 (few-link chains snap erratically: no interpolation in N
#: there), then a factor of about 2^(1/4) apart up to 1800 and sqrt(2) beyond; the paper's 229 among them
N_LINKS = (*range(10, 49), 57, 68, 80, 95, 113, 135, 160, 190, 229, 270, 320, 380, 450, 540, 640, 760, 900, 1070,
           1280, 1520, 1800, 2560, 3600, 5000, 7100, 10000)
#: tip-mass ratios (point mass at the free end / chain mass)
TIP_MASS = (0.0, 0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1.0)
#: the tip-mass axis is computed for N up to this (a tip mass above 0 with more links is outside the table)
N_TIP_MAX = 1800

#: run options of every table run (the rest are run()'s defaults)
RUN_OPTIONS = {"record_thin": 1e-3}


def points() -> list[tuple[float, int, float]]:
    """Every (chi, N, tip_mass) of the table, cheapest (fewest links) first."""
    pts = [(c, n, r) for n in N_LINKS for c in CHI for r in TIP_MASS if r == 0.0 or n <= N_TIP_MAX]
    return sorted(pts, key=lambda p: (p[1], p[2], p[0]))


def _key(chi, N, r) -> str:
    return f"{float(chi):.6g}/{int(N)}/{float(r):.6g}"


def run_case(chi: float, N: int, tip_mass: float = 0.0, *, progress: bool | None = False):
    """One run of the table's kind: the fast exact method from the catenary chi, N links,
    ``tip_mass`` at the free end (:func:`snapping.simulate.run`, :data:`RUN_OPTIONS`)."""
    from .. import simulate
    from ..simulate.problem import Links, Problem

    if tip_mass == 0.0:
        return simulate.run(chi, N, progress=progress, **RUN_OPTIONS)
    return simulate.run(problem=Problem.catenary(chi, links=Links.uniform(N, tip_mass=tip_mass)), progress=progress,
                        **RUN_OPTIONS)


def peaks_of_run(ds) -> dict:
    """The table's numbers of one run Dataset: its peaks, snapping times, drifts, cost and
    delta_kappa_m (NaN when the fold never nears the free end, e.g. under a heavy tip mass)."""
    from .. import estimates

    a = ds.attrs
    out = {k: float(a[k]) for k in ("v_peak", "a_peak", "sigma_peak", "kappa_peak", "t_snap_v", "t_snap_a",
                                    "t_snap_sigma", "energy_drift", "link_drift")}
    out.update(status=str(a["status"]), snap_reached=int(a["snap_reached"]), n_rhs=int(a["n_rhs"]),
               n_steps=int(a["n_steps"]), method=str(a["method"]), tol=float(a["tol"]))
    try:
        out["delta_kappa_m"] = estimates.delta_kappa_m(ds["t"].values, ds["kappa_max"].values,
                                                        ds["s_kappa_max"].values)
    except V.SnappingInputError:
        out["delta_kappa_m"] = float("nan")
    return out


def run_point(chi: float, N: int, tip_mass: float) -> dict:
    """One table run (:func:`run_case`) as a plain dict (:func:`peaks_of_run`, with its CPU
    and wall time; a failed run gives status 'failed' and its message)."""
    cpu0, wall0 = time.process_time(), time.perf_counter()
    out = {"chi": float(chi), "N": int(N), "tip_mass": float(tip_mass)}
    try:
        out.update(peaks_of_run(run_case(chi, N, tip_mass).dataset))
    except Exception as exc:  # a failed run is a hole in the table, reported by assemble
        out.update(status="failed", message=f"{type(exc).__name__}: {str(exc).splitlines()[0][:300]}")
    out["cpu_s"] = time.process_time() - cpu0
    out["wall_s"] = time.perf_counter() - wall0
    return out


def read_ledger(path) -> dict[str, dict]:
    """The runs of a ledger by key (a torn last line, from a killed build, is ignored)."""
    runs = {}
    path = Path(path)
    if not path.exists():
        return runs
    for line in path.read_text().splitlines():
        try:
            d = json.loads(line)
        except json.JSONDecodeError:
            continue
        runs[_key(d["chi"], d["N"], d["tip_mass"])] = d
    return runs


def build(ledger, *, workers: int | None = None, progress: bool = True, log=None) -> dict[str, dict]:
    """Run every table point the ledger lacks (in parallel), appending each result to it."""
    from tqdm.auto import tqdm

    from .._files import locked

    ledger = Path(ledger)
    ledger.parent.mkdir(parents=True, exist_ok=True)
    with locked(ledger, name="ledger"):
        done = read_ledger(ledger)
        todo = [p for p in points() if _key(*p) not in done]
        n = min(workers or os.cpu_count() or 1, max(len(todo), 1))
        bar = tqdm(total=len(points()), initial=len(points()) - len(todo), desc="table runs", unit="run",
                   disable=not progress)
        with open(ledger, "a") as fh:
            if fh.tell() and ledger.read_bytes()[-1:] != b"\n":  # a torn last line (killed build): end it
                fh.write("\n")

            def record(d):
                fh.write(json.dumps(d) + "\n")
                fh.flush()
                os.fsync(fh.fileno())
                done[_key(d["chi"], d["N"], d["tip_mass"])] = d
                bar.update(1)
                if log is not None:
                    log(f"chi={d['chi']:g} N={d['N']} tip={d['tip_mass']:g}: {d['status']} "
                        f"v={d.get('v_peak', float('nan')):.5g} ({d['wall_s']:.1f} s)")

            try:
                if n == 1:
                    for p in todo:
                        record(run_point(*p))
                else:
                    _workers.run_all(n, run_point, todo, lambda args, res: record(res()))
            finally:
                bar.close()
    return done


#: the quantities of the table: ledger key -> (variable name, long name)
QUANTITIES = {
    "v_peak": "peak speed (maximum over the chain)",
    "a_peak": "peak acceleration (maximum over the chain)",
    "sigma_peak": "peak tension (maximum over the chain)",
    "t_snap_v": "snapping time (peak of the maximum speed)",
    "delta_kappa_m": "regularising scale delta_kappa_m measured on the run",
}


def assemble(runs: dict[str, dict], *, command: str = "", wall_s: float | None = None):
    """The table Dataset from a ledger's runs (NaN where a point is missing or failed)."""
    import xarray as xr

    shape = (len(CHI), len(N_LINKS), len(TIP_MASS))
    data = {q: np.full(shape, np.nan) for q in QUANTITIES}
    cpu = np.full(shape, np.nan)
    failed = []
    for i, c in enumerate(CHI):
        for j, n in enumerate(N_LINKS):
            for k, r in enumerate(TIP_MASS):
                d = runs.get(_key(c, n, r))
                if d is None:
                    continue
                cpu[i, j, k] = d["cpu_s"]
                if d["status"] != "completed" or not d.get("snap_reached"):
                    failed.append(f"chi={c:g} N={n} tip={r:g}: {d.get('message', d['status'])}")
                    continue
                for q in QUANTITIES:
                    data[q][i, j, k] = d[q]
    dims = ("chi", "N", "tip_mass")
    ds = xr.Dataset(
        {q: (dims, data[q].astype(np.float32), {"long_name": QUANTITIES[q], "units": "1"}) for q in QUANTITIES},
        coords={"chi": ("chi", np.array(CHI), {"long_name": "end separation / length", "units": "1"}),
                "N": ("N", np.array(N_LINKS), {"long_name": "number of links", "units": "1"}),
                "tip_mass": ("tip_mass", np.array(TIP_MASS), {"long_name": "tip mass / chain mass", "units": "1"})},
    )
    ds["cpu_s"] = (dims, cpu.astype(np.float32), {"long_name": "CPU time of the run", "units": "s"})
    any_run = next(iter(runs.values()), {})
    ds.attrs.update(
        title="snapping: table of computed snaps (fast exact method), nondimensional (length L, mass M, g)",
        method=str(any_run.get("method", "dop853")), tol=float(any_run.get("tol", 1e-6)),
        run_options=json.dumps(RUN_OPTIONS), n_tip_max=N_TIP_MAX,
        command=command or "python -m snapping.table.build",
        cpu_seconds=float(np.nansum(cpu)), n_runs=int(np.isfinite(cpu).sum()),
        failed="; ".join(failed), built=time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        machine=f"{platform.machine()} {platform.processor() or ''} {os.cpu_count()} cores, "
                f"Python {platform.python_version()}".replace("  ", " "),
    )
    if wall_s is not None:
        ds.attrs["wall_seconds"] = float(wall_s)
    from .. import __version__

    ds.attrs["snapping_version"] = __version__
    return ds


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m snapping.table.build", description=__doc__.split("\n\n")[0])
    p.add_argument("--ledger", default="build/table/runs.jsonl", help="the ledger of finished runs (resumable)")
    p.add_argument("-o", "--output", default=None, help="write the assembled table here (netCDF: .nc, .nc4 or .netcdf)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--assemble-only", action="store_true", help="do not run: assemble the ledger as it is")
    args = p.parse_args(argv)
    if args.output:  # (refused before the runs: the table is netCDF)
        from .._files import netcdf_suffix
        from .._validate import SnappingInputError

        try:
            netcdf_suffix(args.output, name="--output")
        except SnappingInputError as exc:
            p.error(str(exc))
    t0 = time.perf_counter()
    runs = read_ledger(args.ledger) if args.assemble_only else build(
        args.ledger, workers=args.workers, log=lambda s: print(s, file=sys.stderr, flush=True))
    if args.output:
        from .._files import write_atomic

        ds = assemble(runs, command="python -m snapping.table.build " + " ".join(argv or sys.argv[1:]),
                      wall_s=None if args.assemble_only else time.perf_counter() - t0)
        enc = {v: {"zlib": True, "complevel": 9} for v in ds.data_vars}
        write_atomic(args.output, lambda tmp: ds.to_netcdf(tmp, engine="netcdf4", encoding=enc), name="output",
                     overwrite=True)
        print(f"wrote {args.output}: {ds.attrs['n_runs']} runs, {ds.attrs['cpu_seconds']:.0f} CPU s", file=sys.stderr)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
