"""cable-sweep: JIT-accelerated parameter sweeps of nonlinear spacecraft-cable vibration.

    import sweep
    scene = sweep.load_scene("paper-fig5")          # built-in name or path to a .toml file
    ds = sweep.run(scene, output="fig5.nc")         # xarray.Dataset, also written as netCDF

SI units throughout; see the README and MODEL.md for the equations.
"""

from .errors import CableSweepWarning, SceneError, UserError
from .run import run
from .scene import Scene, builtin_scenes, load_scene, load_scene_text

__all__ = ["CableSweepWarning", "Scene", "SceneError", "UserError", "builtin_scenes", "load_scene", "load_scene_text", "run"]
