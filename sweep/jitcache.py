"""Keep Numba's on-disk cache of the kernels honest when a kernel source changes.

Numba keys each cached function on its own source file only. A kernel that calls a function of
another module (the lanes driver calls `transverse.classify`, every driver calls the tableau's
step) keeps running the old compiled code after that other module changes, until its own file
changes too. For an installed package every file is replaced at once, so this only bites a
source checkout or an editable install; there it silently runs stale code. So, before the
kernels are first imported: hash every kernels/*.py, and when the hash differs from the one the
cache was built with, delete the cached kernels (they recompile on first use).

Only Numba's default cache location (kernels/__pycache__) is handled; a cache elsewhere
(NUMBA_CACHE_DIR) is left alone.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
from pathlib import Path

STAMP = "cable_sweep_sources.sha256"


def sources_digest(kernels_dir: Path) -> str:
    """SHA-256 of the names and contents of every .py file in `kernels_dir`."""
    h = hashlib.sha256()
    for path in sorted(kernels_dir.glob("*.py")):
        h.update(path.name.encode())
        h.update(b"\0")
        h.update(path.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def package_sources_digest(package: str = "sweep.kernels") -> str:
    """`sources_digest` of `package`'s directory, found without importing it (so without
    Numba); "" where it cannot be found or read."""
    try:
        spec = importlib.util.find_spec(package)
    except (ImportError, ValueError):
        return ""
    if spec is None or not spec.submodule_search_locations:
        return ""
    try:
        return sources_digest(Path(list(spec.submodule_search_locations)[0]))
    except OSError:
        return ""


def drop_stale_cache(package: str) -> bool:
    """Delete the cached kernels of `package` (e.g. "sweep.kernels", found without importing
    it) in its __pycache__ when any of its sources changed since they were written. Returns
    True when stale entries were removed. Never raises: a read-only or missing cache directory
    is left alone (Numba then uses another location or none)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return False
    try:
        spec = importlib.util.find_spec(package)
    except (ImportError, ValueError):
        return False
    if spec is None or not spec.submodule_search_locations:
        return False
    kernels_dir = Path(list(spec.submodule_search_locations)[0])
    cache = kernels_dir / "__pycache__"
    try:
        digest = sources_digest(kernels_dir)
        stamp = cache / STAMP
        if stamp.is_file() and stamp.read_text().strip() == digest:
            return False
        removed = False
        if cache.is_dir():
            for entry in cache.iterdir():
                if entry.suffix in (".nbi", ".nbc"):
                    entry.unlink(missing_ok=True)
                    removed = True
            stamp.write_text(digest + "\n")
        return removed
    except OSError:
        return False
