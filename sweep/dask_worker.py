"""Preloaded into the worker processes of the LocalCluster that a dask run starts for itself
(never into the workers of a cluster given with --scheduler).

A worker that dies, and the one the nanny starts in its place while the run is being stopped,
print dask's and multiprocessing's tracebacks straight to the stderr they inherited, around the
run's one error line. The run itself says what happened (which chunk, how often its worker
died), so these workers write their stderr to os.devnull.
"""

from __future__ import annotations

import os
from typing import Any


def dask_setup(worker: Any) -> None:
    """dask's preload hook: point this worker process's stderr (fd 2) at os.devnull."""
    fd = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(fd, 2)
    finally:
        os.close(fd)
