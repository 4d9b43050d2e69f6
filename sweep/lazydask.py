"""Keep dask out of runs that do not use it: xarray, where dask is installed, imports
dask.array (about 0.7 s with the SciPy modules it pulls in) at its first DataArray, only to ask
whether an array is a dask array, and dask.distributed (0.25 s) at its first netCDF write, only
to ask which dask scheduler is running, and dask itself whenever it asks whether an object is
a dask collection. Before dask is imported none can be so: no dask array or collection exists
until dask is imported, and no dask scheduler runs until dask is.

`defer` makes xarray ask that way: its cached "dask" duck-array module answers from
``sys.modules`` (the real dask.array.Array once dask.array is imported, by anyone, else no
type), its collection test answers False and its scheduler lookup None while dask has not
been imported. Every answer is the one xarray would give; only the imports are saved. It
touches three private names of xarray (``xarray.namedarray.pycompat._cached_duck_array_modules``,
``xarray.namedarray.utils.is_dask_collection`` and ``get_dask_scheduler`` where xarray's
writers call it) and leaves any that is not there alone, and does nothing where dask is
already imported. Called by the entry points that are about to build xarray objects
(`sweep.run`, the plot and design commands); measured in benchmarks/startup.py.

pint the same way: xarray, where pint is installed (a dependency of ours, for unit strings in
scenes), imports pint at its first `.values` (0.6 s: pint imports dask where dask is
installed) only to ask whether an array is a pint Quantity, which none can be before pint is
imported. Its cached "pint" duck-array module answers from ``sys.modules`` too (the real
Quantity once pint is imported, by anyone).
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from typing import Any

_DONE = False


class _OnceImported:
    """xarray's DuckArrayModule for package `name`, answering from what is imported: its
    array type (`_kind`) only once the package is, and the package itself on demand."""

    name = ""

    def _kind(self) -> Any:
        raise NotImplementedError

    @property
    def type(self) -> tuple[type, ...]:
        kind = self._kind()
        return (kind,) if isinstance(kind, type) else ()

    @property
    def available(self) -> bool:
        return self.name in sys.modules or importlib.util.find_spec(self.name) is not None

    @property
    def module(self) -> Any:
        return importlib.import_module(self.name) if self.available else None

    @property
    def version(self) -> Any:
        from packaging.version import Version
        module = self.module
        return Version(module.__version__) if module is not None else Version("0.0.0")


class _DaskOnceImported(_OnceImported):
    """xarray's DuckArrayModule for "dask": dask.array.Array once dask.array is imported."""

    name = "dask"

    def _kind(self) -> Any:
        return getattr(sys.modules.get("dask.array"), "Array", None)


class _PintOnceImported(_OnceImported):
    """xarray's DuckArrayModule for "pint": pint.Quantity once pint is imported."""

    name = "pint"

    def _kind(self) -> Any:
        return getattr(sys.modules.get("pint"), "Quantity", None)


def _defer_pint() -> None:
    """xarray's "pint" duck-array module answers from sys.modules (module docstring)."""
    if "pint" in sys.modules:
        return
    try:
        from xarray.namedarray import pycompat
    except ImportError:
        return
    cache = getattr(pycompat, "_cached_duck_array_modules", None)
    if isinstance(cache, dict) and "pint" not in cache:
        cache["pint"] = _PintOnceImported()


def defer() -> None:
    """Install the deferrals (once per process; see the module docstring)."""
    global _DONE
    if _DONE:
        return
    _DONE = True
    _defer_pint()
    if "dask" in sys.modules:
        return
    try:
        from xarray.backends import locks, writers
        from xarray.namedarray import pycompat
        from xarray.namedarray import utils as named_utils
    except ImportError:
        return
    collection = getattr(named_utils, "is_dask_collection", None)
    if collection is not None and not getattr(collection, "_sweep_deferred", False):
        def is_dask_collection(x: object) -> bool:
            return "dask" in sys.modules and collection(x)   # none exists before dask does
        is_dask_collection._sweep_deferred = True          # type: ignore[attr-defined]
        named_utils.is_dask_collection = is_dask_collection
    cache = getattr(pycompat, "_cached_duck_array_modules", None)
    if isinstance(cache, dict) and "dask" not in cache:
        cache["dask"] = _DaskOnceImported()
    original = getattr(locks, "get_dask_scheduler", None)
    if original is None or getattr(original, "_sweep_deferred", False):
        return

    def get_dask_scheduler(get: Any = None, collection: Any = None) -> str | None:
        if "dask" not in sys.modules and get is None and collection is None:
            return None                    # no dask imported: no dask scheduler is running
        return original(get, collection)
    get_dask_scheduler._sweep_deferred = True      # type: ignore[attr-defined]
    get_dask_scheduler.__doc__ = original.__doc__
    for module in (locks, writers):
        if getattr(module, "get_dask_scheduler", None) is original:
            module.get_dask_scheduler = get_dask_scheduler
