"""sweep.jitcache: cached kernels are dropped when any kernel source changes (Numba itself
only watches each function's own file)."""

from __future__ import annotations

import pytest

from sweep.jitcache import STAMP, drop_stale_cache


@pytest.fixture
def package(tmp_path, monkeypatch):
    root = tmp_path / "pkg_jitcache_probe"
    kernels = root / "kernels"
    (kernels / "__pycache__").mkdir(parents=True)
    (root / "__init__.py").write_text("")
    (kernels / "__init__.py").write_text("")
    (kernels / "a.py").write_text("X = 1\n")
    (kernels / "b.py").write_text("Y = 2\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    return kernels


def _plant(kernels):
    for name in ("b.f-1.py311.nbi", "b.f-1.py311.1.nbc"):
        (kernels / "__pycache__" / name).write_bytes(b"cached")


def test_cache_is_kept_while_sources_are_unchanged_and_dropped_when_one_changes(package):
    _plant(package)
    assert drop_stale_cache("pkg_jitcache_probe.kernels")          # no stamp yet: dropped
    assert (package / "__pycache__" / STAMP).is_file()
    _plant(package)
    assert not drop_stale_cache("pkg_jitcache_probe.kernels")      # same sources: kept
    assert len(list((package / "__pycache__").glob("*.nb?"))) == 2
    (package / "a.py").write_text("X = 3\n")                     # another module changed
    assert drop_stale_cache("pkg_jitcache_probe.kernels")
    assert not list((package / "__pycache__").glob("*.nb?"))


def test_a_cache_elsewhere_is_left_alone(package, monkeypatch):
    _plant(package)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(package.parent))
    assert not drop_stale_cache("pkg_jitcache_probe.kernels")
    assert len(list((package / "__pycache__").glob("*.nb?"))) == 2


def test_a_missing_package_is_not_an_error():
    assert not drop_stale_cache("no_such_package_for_jitcache.kernels")


_RECORD_RUN = """
import sys, numpy as np, sweep
if sys.argv[1] == "python-first":      # as tests do: the small record reads called from Python
    import sweep.kernels.excitation as ex, sweep.kernels.modes as md
    p, records = np.ones(1000), np.ones((1, 16, 4))
    ex.record_acceleration(0.1, p, 0, 1, records)
    md.base_acceleration(0.1, p, 3, records)
overrides = {"run.threads": 1, "axes.length": [0.1], "base.realisations": 2,
             "base.duration": 1.0, "outputs.response_asd": False,
             "axes.base_asd_scale": [0.0], "model.modes": 3}
ds = sweep.run(sweep.load_scene("launch-random-gevs", overrides), progress=False)
print(" ".join(repr(float(ds[v].values.ravel()[0]))
               for v in ("rms_deflection", "rms_acceleration", "peak_deflection")))
"""


@pytest.mark.slow
def test_a_record_s_result_does_not_depend_on_what_was_compiled_before(tmp_path):
    """A 3-mode record scene on an empty Numba cache, in two processes at once: one runs it
    first thing, the other after calling the record reads it shares from Python (as tests do):
    the same bits. Numba compiles a kernel that states no `fastmath` with the flags of its
    first caller (kernels/flags.py has the rule); before the reads stated theirs, the second
    process's rms_deflection came out 3.6225e-4 instead of 3.8657e-4 (7304cfa). One scene, not
    two, to keep the two cold compiles short: tests/test_architecture.py checks the rule for
    every kernel from the source."""
    import os
    import subprocess
    import sys

    from conftest import sweep_env

    def start(first):
        env = sweep_env({**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / first)})
        return subprocess.Popen([sys.executable, "-c", _RECORD_RUN, first], env=env,
                                cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)

    runs = [start("scene-first"), start("python-first")]
    done = [run.communicate(timeout=900) for run in runs]        # both finish, pass or fail
    for run, (_, err) in zip(runs, done):
        assert run.returncode == 0, err[-2000:]
    scene_first, python_first = ([float(x) for x in out.split()] for out, _ in done)
    assert len(scene_first) == 3 and scene_first == python_first
