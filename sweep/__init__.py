"""cable-sweep: JIT-accelerated parameter sweeps of nonlinear spacecraft-cable vibration.

    import sweep
    scene = sweep.load_scene("paper-fig5")          # built-in name or path to a .toml file
    ds = sweep.run(scene, output="fig5.nc")         # xarray.Dataset, also written as netCDF

SI units throughout; see the README and docs/model.md for the equations.
"""

import os as _os

if not _os.path.isdir(_os.path.join(_os.path.dirname(__file__), "kernels")):
    # Imported from a source checkout (not installed): kernels/ sits beside sweep/ there, and is
    # found as sweep.kernels through the package's search path.
    __path__.append(_os.path.dirname(_os.path.dirname(_os.path.abspath(__file__))))

from .jitcache import drop_stale_cache as _drop_stale_cache  # noqa: E402

_drop_stale_cache(__name__ + ".kernels")   # before any kernel is imported: see sweep/jitcache.py

from .errors import CableSweepWarning, SceneError, UserError
from .run import run
from .scene import Scene, builtin_scenes, load_scene, load_scene_text

__all__ = ["CableSweepWarning", "Scene", "SceneError", "UserError", "builtin_scenes", "load_scene",
           "load_scene_text", "plot", "run"]

_LAZY_SUBMODULES = ("plot",)   # imported on first use: matplotlib is slow to import


def __getattr__(name: str):
    if name in _LAZY_SUBMODULES:
        import importlib
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
