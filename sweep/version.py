"""cable-sweep's version: the installed package's metadata, else the checkout's constant."""

from __future__ import annotations

import functools

VERSION = "0.1.0"
"""The version a source checkout reports when cable-sweep is not installed (keep it equal to
pyproject.toml's; tests/test_keys.py checks)."""


@functools.cache
def package_version() -> str:
    """The installed cable-sweep's version (package metadata), else `VERSION`; looked up once a
    process (the lookup reads the installed packages' metadata: 3 ms, twice a run)."""
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("cable-sweep")
    except PackageNotFoundError:
        return VERSION
