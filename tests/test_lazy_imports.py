"""What a command imports: `sweep --help`, `sweep scenes` and `sweep keys` need neither NumPy,
xarray nor Numba; a threads run and a plot need no dask (xarray would import dask.array and
dask.distributed only to ask questions whose answer is no while dask is not imported:
sweep/lazydask.py); and once dask is imported, xarray sees dask arrays as before. Each case
runs in a fresh interpreter, the only way to see what an import costs."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import pytest

# the sweep this process imports (and its Numba cache), found without importing it
ROOT = Path(importlib.util.find_spec("sweep").origin).resolve().parents[1]
HEAVY = ("numpy", "xarray", "numba", "pandas", "dask", "distributed", "scipy", "matplotlib",
         "pint")


def _loaded_after(code: str) -> dict:
    """Run `code` in a fresh interpreter; the HEAVY modules it left imported, and its output."""
    probe = (code + "\nimport json, sys\n"
             f"print('@@' + json.dumps([m for m in {HEAVY!r} if m in sys.modules]))\n")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    line = next(l for l in done.stdout.splitlines() if l.startswith("@@"))
    return {"loaded": json.loads(line[2:]), "stdout": done.stdout}


@pytest.mark.parametrize("argv", [["--help"], ["scenes"], ["keys", "points"], ["--version"]])
def test_light_commands_import_no_numpy_xarray_or_numba(argv):
    code = ("import sys\nfrom sweep.cli import main\n"
            f"try:\n    main({argv!r})\nexcept SystemExit:\n    pass\n")
    assert _loaded_after(code)["loaded"] == []


def test_import_sweep_is_light_and_the_api_is_whole():
    assert _loaded_after("import sweep\n")["loaded"] == []
    code = ("import sweep\nnames = [sweep.run, sweep.load_scene, sweep.Scene, "
            "sweep.builtin_scenes, sweep.load_scene_text, sweep.SceneError]\n"
            "scene = sweep.load_scene('paper-fig5')\n")
    assert _loaded_after(code)["loaded"] == ["numpy"]      # a scene's axes are arrays


def test_pint_is_imported_only_for_a_scene_with_a_unit_string():
    """A scene of plain numbers loads without pint (about 0.9 s to import and build its
    registry); one with "1.27 mm" loads it."""
    plain = "import sweep\nsweep.load_scene_text('[cable]\\nlength = 0.3\\n')\n"
    assert "pint" not in _loaded_after(plain)["loaded"]
    with_unit = "import sweep\nsweep.load_scene_text('[cable]\\nlength = \"300 mm\"\\n')\n"
    assert "pint" in _loaded_after(with_unit)["loaded"]


def test_sweep_run_stays_the_function_after_importing_the_submodule():
    import sweep
    import sweep.run as module_or_function    # noqa: F401  (binds the submodule)
    from sweep.run import solve_points        # noqa: F401  (a re-exported kernel entry point)
    assert callable(sweep.run) and sweep.run.__name__ == "run"
    assert sweep.run.__module__ == "sweep.run"


@pytest.mark.slow
def test_a_threads_run_and_a_plot_import_no_dask(tmp_path):
    out = tmp_path / "f5.nc"
    code = ("import sweep\n"
            "s = sweep.load_scene('paper-fig5', overrides={'solver.t_end': 0.2})\n"
            f"sweep.run(s, output={str(out)!r})\n"
            "import matplotlib\nmatplotlib.use('Agg')\n"
            f"from sweep.plot import load_result, plot\nplot(load_result({str(out)!r}))\n")
    loaded = _loaded_after(code)["loaded"]
    assert "dask" not in loaded and "distributed" not in loaded
    assert "pint" not in loaded               # xarray would import it at the first .values
    assert {"numpy", "xarray", "numba"} <= set(loaded)


@pytest.mark.slow
def test_xarray_still_sees_dask_arrays_once_dask_is_imported(tmp_path):
    out = tmp_path / "f5.nc"
    code = ("import sweep\n"
            "s = sweep.load_scene('paper-fig5', overrides={'solver.t_end': 0.2})\n"
            f"ds = sweep.run(s, output={str(out)!r})\n"
            "import dask.array as da, xarray as xr\n"
            "from xarray.namedarray.utils import is_duck_dask_array\n"
            "a = xr.DataArray(da.ones(4, chunks=2), dims='x')\n"
            "assert a.chunks == ((2, 2),) and is_duck_dask_array(a.data)\n"
            f"b = xr.open_dataset({str(out)!r}, chunks={{}})\n"
            "assert is_duck_dask_array(b.amplitude.data)\n"
            f"b.to_netcdf({str(tmp_path / 'again.nc')!r})\n"
            "assert float(abs(b.amplitude - ds.amplitude).max()) == 0.0\n")
    assert "dask" in _loaded_after(code)["loaded"]


@pytest.mark.slow
def test_a_cli_run_imports_no_scipy_linalg_and_numba_keeps_its_linear_algebra(tmp_path):
    """The command line loads Numba's registries without the SciPy import its BLAS probe
    makes (sweep/numba_start.py); afterwards SciPy, np.dot and np.convolve in compiled code
    work and give the right answers."""
    out = tmp_path / "f5.nc"
    code = ("import sys\nfrom sweep.cli import main\n"
            f"main(['run', 'paper-fig5', '-o', {str(out)!r}, '--set', 'solver.t_end=0.2', "
            "'-q'])\n"
            "linalg_after_run = 'scipy.linalg' in sys.modules\n"
            "import numpy as np, numba, scipy.linalg\n"
            "@numba.njit\n"
            "def f(a, b):\n"
            "    return np.dot(a, b), np.convolve(a, b)\n"
            "a, b = np.arange(3.0), np.array([2.0, -1.0, 0.5])\n"
            "d, c = f(a, b)\n"
            "assert d == np.dot(a, b) and np.allclose(c, np.convolve(a, b))\n"
            "assert np.allclose(scipy.linalg.solve(np.eye(2) * 2.0, np.ones(2)), 0.5)\n"
            "print('linalg after run:', linalg_after_run)\n")
    result = _loaded_after(code)
    assert "linalg after run: False" in result["stdout"]
    assert out.exists()


def test_the_numba_start_leaves_a_process_with_numba_started_alone():
    code = ("import numba\n@numba.njit\ndef g(x):\n    return x + 1\ng(1)\n"
            "from sweep.numba_start import start_without_scipy\n"
            "print('started:', start_without_scipy())\n")
    assert "started: False" in _loaded_after(code)["stdout"]


def test_the_numba_start_gives_way_to_a_numba_it_does_not_know():
    code = ("import sys\nfrom numba.core import registry\n"
            "class Broken:\n    target_context = property(lambda self: 1 / 0)\n"
            "registry.cpu_target = Broken()\n"
            "from sweep.numba_start import start_without_scipy\n"
            "print('started:', start_without_scipy())\n"
            "print('probe left:', 'scipy.linalg.cython_blas' in sys.modules)\n")
    out = _loaded_after(code)["stdout"]
    assert "started: False" in out and "probe left: False" in out
