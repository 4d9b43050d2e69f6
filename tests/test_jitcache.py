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


_RECORD_RUNS = """
import sys, sweep
def rms(overrides):
    overrides = {"run.threads": 1, "axes.length": [0.1], "base.realisations": 2,
                 "base.duration": 1.0, "outputs.response_asd": False,
                 "axes.base_asd_scale": [0.0], **overrides}
    ds = sweep.run(sweep.load_scene("launch-random-gevs", overrides), progress=False)
    return repr(float(ds.rms_deflection.values.ravel()[0]))
print(" ".join(rms(eval(overrides)) for overrides in sys.argv[1:]))
"""


@pytest.mark.slow
def test_a_record_s_result_does_not_depend_on_what_was_compiled_before(tmp_path):
    """A one-mode and a 3-mode record scene compiled in both orders, each order in a process of
    its own on an empty Numba cache (the two at once): the same bits. Before, the one-mode
    scene's read of its record (excitation.record_acceleration, a call shared with the
    several-mode System) was compiled by whichever came first, and the one-mode rms_deflection
    came out 3.78e-4 instead of 4.45e-4 when the 3-mode scene came first, the 3-mode one
    1.1909872e-4 instead of 1.1909800e-4 when it came second. (Two cold compiles of both
    scenes: the fewest that put each scene first and second.)"""
    import os
    import subprocess
    import sys

    from conftest import sweep_env

    def start(cache, *overrides):
        env = sweep_env({**os.environ, "NUMBA_CACHE_DIR": str(cache)})
        return subprocess.Popen([sys.executable, "-c", _RECORD_RUNS, *overrides], env=env,
                                cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)

    one, three = '{"base.ramp": 0.2}', '{"model.modes": 3}'
    runs = [start(tmp_path / "a", one, three), start(tmp_path / "b", three, one)]
    done = [run.communicate(timeout=900) for run in runs]        # both finish, pass or fail
    for run, (_, err) in zip(runs, done):
        assert run.returncode == 0, err[-2000:]
    one_then_three, three_then_one = ([float(x) for x in out.split()] for out, _ in done)
    assert len(one_then_three) == 2 and one_then_three == three_then_one[::-1]
