"""Numba's one-time start in a process the command line owns, without SciPy.

The first compiled function a process loads (from the on-disk cache or by compiling it) makes
Numba load its typing and lowering registries. One of them, `numba.np.arraymath`, asks at its
import whether a BLAS is at hand by importing `scipy.linalg.cython_blas`, which imports all of
`scipy.linalg`: about 0.15 s of a warm `sweep run` (0.1-0.2 s on the development machines,
RESULTS.md "Start-up"), for a kernel that calls no linear algebra. The answer is used only to
choose how np.correlate and np.convolve compute their inner products inside compiled code
(BLAS or a plain loop); np.dot and np.linalg ask again when they are compiled.

`start_without_scipy()` loads the registries with that one import refused, so the answer is
"no BLAS" (np.correlate and np.convolve in compiled code use the plain loop) and SciPy is not
imported; then the import is allowed again, so SciPy, np.dot and np.linalg work as ever. Only
the command line calls it: a Python program that imports `sweep` keeps Numba as it is.
"""

from __future__ import annotations

import sys

_BLAS_PROBE = "scipy.linalg.cython_blas"


def start_without_scipy() -> bool:
    """Load Numba's registries now, without importing SciPy, unless they (or SciPy's BLAS
    module) are already loaded. Returns True when it did; False, and nothing changed, where
    it cannot (a Numba whose internals differ: it then loads them at its first compile)."""
    if "numba.np.arraymath" in sys.modules or _BLAS_PROBE in sys.modules:
        return False
    sys.modules[_BLAS_PROBE] = None            # `import` of it raises ImportError
    try:
        from numba.core.registry import cpu_target
        cpu_target.target_context.refresh()
    except Exception:           # another Numba's internals: it loads them itself, as ever
        return False
    finally:
        if sys.modules.get(_BLAS_PROBE, 0) is None:
            del sys.modules[_BLAS_PROBE]
    return True
