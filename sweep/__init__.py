"""cable-sweep: JIT-accelerated parameter sweeps of nonlinear spacecraft-cable vibration.

    import sweep
    scene = sweep.load_scene("paper-fig5")          # built-in name or path to a .toml file
    ds = sweep.run(scene, output="fig5.nc")         # xarray.Dataset, also written as netCDF

SI units throughout; see the README and docs/model.md for the equations.
"""

import os as _os
import sys as _sys
import types as _types

if not _os.path.isdir(_os.path.join(_os.path.dirname(__file__), "kernels")):
    # Imported from a source checkout (not installed): kernels/ sits beside sweep/ there, and is
    # found as sweep.kernels through the package's search path.
    __path__.append(_os.path.dirname(_os.path.dirname(_os.path.abspath(__file__))))

from .jitcache import drop_stale_cache as _drop_stale_cache  # noqa: E402

_drop_stale_cache(__name__ + ".kernels")   # before any kernel is imported: see sweep/jitcache.py

from .errors import CableSweepWarning, SceneError, UserError  # noqa: E402  (no numpy)

__all__ = ["CableSweepWarning", "Scene", "SceneError", "UserError", "builtin_scenes", "load_scene",
           "load_scene_text", "plot", "run"]

# Imported on first use (PEP 562), so that `import sweep` and the commands that need neither
# NumPy, xarray nor Numba (`sweep --help`, `sweep scenes`, `sweep keys`) start in a fraction of
# a second: name -> the module that defines it.
_LAZY = {"run": "sweep.run", "Scene": "sweep.scene.document",
         "builtin_scenes": "sweep.scene.reading", "load_scene": "sweep.scene.build",
         "load_scene_text": "sweep.scene.build"}
_LAZY_SUBMODULES = ("plot",)   # matplotlib is slow to import


class _Package(_types.ModuleType):
    """The package module: `import sweep.run` (the submodule) leaves ``sweep.run`` the
    function, as ``from .run import run`` used to make it."""

    def __setattr__(self, name: str, value: object) -> None:
        if name == "run" and isinstance(value, _types.ModuleType):
            value = value.run                     # type: ignore[attr-defined]
        super().__setattr__(name, value)


_sys.modules[__name__].__class__ = _Package


def __getattr__(name: str):
    import importlib
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name in _LAZY_SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
