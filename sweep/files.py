"""Durable file writes shared by the chunk store, the netCDF output and the figures: free
space, temporaries made exclusively and fsynced, renames made durable."""

from __future__ import annotations

import contextlib
import os
import tempfile


def mib(n_bytes: float) -> str:
    """`n_bytes` (bytes) as text in MiB, e.g. '12.3 MiB'."""
    return f"{n_bytes / 2**20:,.1f} MiB"


def free_bytes(directory: str | os.PathLike) -> int | None:
    """Bytes an unprivileged writer can still use on the file system of `directory`, or None."""
    try:
        st = os.statvfs(directory)
    except OSError:
        return None
    return st.f_bavail * st.f_frsize


def fsync_directory(directory: str | os.PathLike) -> None:
    """Make a rename in `directory` durable (where the file system allows it)."""
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def new_file_mode() -> int:
    """The mode a new file gets from this process's umask (0o666 less it), as any tool's.

    Read from /proc/self/status where the kernel reports it (Linux 4.7 and later): setting the
    umask to read it back would change it for every thread of the process for an instant (a
    file another thread creates then would get the wrong mode). Elsewhere it is read that way.
    """
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status", encoding="ascii", errors="replace") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return 0o666 & ~int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return 0o666 & ~mask


def write_temporary(directory: str | os.PathLike, prefix: str, data: bytes,
                    mode: int | None = None) -> str:
    """`data` in a new temporary file of `directory` (created with O_EXCL under an
    unpredictable name starting with `prefix`, ending in .tmp), fsynced; its permission bits
    `mode` when given (mkstemp makes it 0o600). Returns its path, for the caller to rename into
    place; on failure nothing is left and the error is raised."""
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=prefix, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            if mode is not None:
                os.fchmod(fh.fileno(), mode)
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return tmp
