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
