"""Regime study files: load one (:func:`load_study`), or one shipped with the package
(:func:`bundled_study`, :data:`BUNDLED`). Re-exported by :mod:`snapping.regimes`, where the studies are run."""

from __future__ import annotations

import os

import xarray as xr

from . import _validate as V

__all__ = ["load_study", "bundled_study", "BUNDLED"]


def load_study(path) -> xr.Dataset:
    """A regime study's file (:func:`regimes`), loaded into memory."""
    p = V.file_path("path", path)
    if not os.path.isfile(p):
        raise V.SnappingInputError(f"path={p!r} does not exist")
    try:
        with xr.open_dataset(p) as ds:
            ds = ds.load()
    except (OSError, ValueError) as exc:
        raise V.SnappingInputError(f"path={p!r} is not a readable netCDF file ({exc})") from None
    if "regimes_study" not in ds.attrs:
        raise V.SnappingInputError(f"path={p!r} is not a regime study (snapping regimes)")
    return ds


#: the studies shipped with the package (``snapping/data/regimes/<mechanism>.nc``, made by
#: ``benchmarks/bench_regimes.py --study``): 4 chi x 8 numbers each
BUNDLED = ("bending", "drag", "end-mass", "stretching")


def bundled_study(mechanism: str) -> xr.Dataset:
    """The regime study of ``mechanism`` shipped with the package (see the guide page
    "What caps the snap" for how it was computed: its attributes say the levels, tolerance
    and grid damping), loaded into memory.

    >>> ds = bundled_study("end-mass")  # doctest: +SKIP
    >>> ds.v_peak_ratio.sel(chi=0.2)  # doctest: +SKIP
    """
    from importlib import resources

    if not isinstance(mechanism, str) or mechanism not in BUNDLED:
        raise V.SnappingInputError(f"mechanism={mechanism!r} is not one of the shipped studies {BUNDLED}")
    path = resources.files("snapping") / "data" / "regimes" / f"{mechanism}.nc"
    if not path.is_file():
        raise V.SnappingInputError(f"the {mechanism} study is not shipped in this installation ({path})")
    with resources.as_file(path) as p:
        return load_study(str(p))
