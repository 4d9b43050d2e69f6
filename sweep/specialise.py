"""Kernel entry points specialised to their switches, so that Numba compiles only the code a
scene uses.

The kernels take their optional terms and choices as switches: None (off) or True (on), one
compiled specialisation each (kernels/oscillator.py, kernels/lanes.py). Numba removes a branch
on `switch is None` before it types a function only where it can tell the switch's value from
its type: None has a type of its own, but Python's True arrives as the type `bool`, which
might be either, so both branches are typed and compiled, the dead one included (the other
right-hand side's stage chain, the other controller ...), in every function the switch
reaches. Typed as the literal True instead (`numba.types.literal(True)`), the switch prunes
its branches everywhere it goes, and the cold start compiles less.

`entry_point(kernel, *args)` gives the kernel's compiled entry point for these arguments, each
True typed as that literal and every other argument as the dispatcher types it; compiled or
loaded from Numba's on-disk cache on first use, then kept. Call it with the same arguments.
"""

from __future__ import annotations

import threading
from typing import Any, Callable

_ENTRIES: dict[tuple, Callable] = {}
_LOCK = threading.Lock()


def entry_point(kernel: Any, *args: Any) -> Callable:
    """The compiled entry point of Numba dispatcher `kernel` for `args` with every True
    argument typed as the literal True (module docstring)."""
    from numba.core import types
    signature = tuple(types.literal(True) if a is True else kernel.typeof_pyval(a)
                      for a in args)
    key = (kernel, signature)
    found = _ENTRIES.get(key)
    if found is None:
        with _LOCK:
            found = _ENTRIES.get(key)
            if found is None:
                found = _ENTRIES[key] = kernel.compile(signature)
    return found


def call(kernel: Any, *args: Any) -> Any:
    """kernel(*args) through `entry_point`."""
    return entry_point(kernel, *args)(*args)
