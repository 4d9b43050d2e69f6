"""netCDF output: checked before a run starts, written atomically after it ends."""

from __future__ import annotations

import contextlib
import errno
import os
import re
import stat
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .errors import UserError
from .files import free_bytes, fsync_directory, mib, new_file_mode
from .store import store_path

if TYPE_CHECKING:
    import xarray as xr


def check_output_path(path: str | os.PathLike, overwrite: bool = False,
                      resume: Any = None) -> Path:
    """Refuse, before any work is done, an output path that cannot be written.

    Raises UserError naming the file: missing or read-only directory, an existing file
    without `overwrite` (`resume`: the Scene being resumed; where the file holds that scene's
    finished run and no chunk store is left, the message says the run is complete), a
    directory in the way, or a name that is not .nc.
    """
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise UserError(f"output {path!r:.60}: not a file name (give a path ending in .nc, "
                        "e.g. 'out.nc')")
    raw = os.fspath(path)
    if isinstance(raw, bytes):
        raw = os.fsdecode(raw)
    try:
        raw.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise UserError(f"output {ascii(raw)}: the name is not valid UTF-8 text (character "
                        f"{exc.start + 1}), which netCDF cannot store (give a UTF-8 file name, "
                        "e.g. 'out.nc')") from None
    if "\0" in raw:
        raise UserError(f"output {ascii(raw)}: the name holds a NUL character (choose another name)")
    try:
        return _check_output_path(raw, overwrite, resume)
    except OSError as exc:
        raise UserError(f"output '{raw}': cannot be checked ({exc.strerror or exc}; choose "
                        "another -o path)") from None


def _check_output_path(raw: str, overwrite: bool, resume: Any = None) -> Path:
    """check_output_path's checks on a name already known to be UTF-8 (may raise OSError)."""
    if not raw.strip():
        raise UserError(f"output '{raw}': empty file name (give a file name ending in .nc, "
                        "e.g. 'out.nc')")
    out = Path(raw)
    if raw.endswith(("/", os.sep)) or out.name in ("", ".", ".."):
        raise UserError(f"output '{raw}': names a directory, not a file (give a file name "
                        "ending in .nc, e.g. 'results/out.nc')")
    if out.name == ".nc":
        raise UserError(f"output '{raw}': has nothing before .nc (give a name such as 'out.nc')")
    if out.suffix != ".nc":
        suggestion = out.with_name((out.stem.rstrip('.') or 'out') + '.nc')
        raise UserError(f"output '{raw}': the name must end in .nc (give e.g. '{suggestion}')")
    parent = out.parent if str(out.parent) else Path(".")
    if parent.exists() and not parent.is_dir():
        raise UserError(f"output '{out}': '{parent}' is a file, not a directory (choose another "
                        "-o path)")
    if not parent.is_dir():
        raise UserError(f"output '{out}': directory '{parent}' does not exist (create it first)")
    if not _can_create_in(parent):
        raise UserError(f"output '{out}': directory '{parent}' is not writable (choose another -o path)")
    if out.is_dir():
        raise UserError(f"output '{out}': is a directory (give a file name ending in .nc)")
    if out.exists() and not overwrite:
        if resume is not None and not os.path.lexists(store_path(out)) and _holds(out, resume):
            raise UserError(f"output '{out}': the run is already complete (the file holds it "
                            "and no chunk store is left to resume; use --overwrite to run it "
                            "again)")
        raise UserError(f"output '{out}': file exists (use --overwrite, or overwrite=True, to replace it)")
    return out


def _holds(path: Path, scene: Any) -> bool:
    """Whether the netCDF file `path` holds a finished run of `scene` (its `scene` attribute,
    the resolved scene, loads back equal to it); False for anything unreadable."""
    try:
        import netCDF4
        from .scene import load_scene_text
        with netCDF4.Dataset(path) as nc:
            text = nc.getncattr("scene")
        return load_scene_text(text) == scene
    except Exception:        # not netCDF, no scene, another scene's: not this run's file
        return False


def _can_create_in(directory: Path) -> bool:
    """Whether a file can really be created in `directory` (os.access says yes to root even on a
    read-only file system, so try it)."""
    try:
        with tempfile.NamedTemporaryFile(dir=directory, prefix=".cable-sweep-probe-"):
            return True
    except OSError:
        return False


def _temporary_pattern(out: Path) -> re.Pattern:
    """The names write_netcdf gives its temporaries of `out`: .NAME.PID.RANDOM.tmp (and the
    older .NAME.PID.tmp); the pid says which process made it."""
    return re.compile(re.escape(f".{out.name}.") + r"(\d+)\.(?:[A-Za-z0-9_]+\.)?tmp")


def remove_stale_temporaries(path: str | os.PathLike) -> list[Path]:
    """Remove the temporaries a killed write of `path` left: only regular files (not links)
    whose name is write_netcdf's, owned by this user, whose process is gone. Returns them."""
    out = Path(path)
    parent = out.parent if str(out.parent) else Path(".")
    pattern = _temporary_pattern(out)
    removed = []
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return removed
    for entry in entries:
        match = pattern.fullmatch(entry.name)
        if not match:
            continue
        with contextlib.suppress(OSError):
            st = entry.stat(follow_symlinks=False)
            if (stat.S_ISREG(st.st_mode) and st.st_uid == os.getuid()
                    and not _pid_alive(int(match[1]))):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
    return removed
    return True


def estimated_size(ds: xr.Dataset) -> int:
    """Bytes the netCDF file of `ds` needs at most (its arrays uncompressed, and 1 MiB)."""
    return int(sum(v.nbytes for v in ds.variables.values())) + 2**20


def write_netcdf(ds: xr.Dataset, path: str | os.PathLike, overwrite: bool = False) -> Path:
    """Write `ds` to `path` atomically: a new temporary file in the same directory (made with
    O_EXCL under an unpredictable name), fsync, then a rename over `path`.

    A failure leaves no partial file behind; an existing file is replaced only with `overwrite`.
    A symbolic link at `path` is replaced by the file (its target is never written). A full
    disk raises UserError naming the directory and the space the file needs.
    """
    out = check_output_path(path, overwrite)
    parent = out.parent if str(out.parent) else Path(".")
    encoding = {name: {"zlib": True, "complevel": 4}
                for name, var in ds.data_vars.items() if var.ndim >= 1 and var.dtype.kind == "f"}
    # CF: coordinates have no missing values, so no _FillValue (xarray adds NaN to floats).
    encoding.update({name: {"_FillValue": None} for name in ds.coords})
    # CF wants numeric coordinate variables: a label coordinate (a sweep's direction, "up" and
    # "down") is written as a char array, which xarray reads back as the same strings, so
    # .sel(direction="up") works as before and CF checkers read it as a string-valued label.
    for name, var in ds.coords.items():
        if var.dtype.kind in "OUS":
            encoding[name] = {"dtype": "S1"}
    try:
        fd, name = tempfile.mkstemp(dir=parent, prefix=f".{out.name}.{os.getpid()}.",
                                    suffix=".tmp")
    except OSError as exc:
        raise _write_error(out, parent, ds, exc) from exc
    tmp = Path(name)
    made = os.fstat(fd)
    try:
        ds.to_netcdf(tmp, engine="netcdf4", encoding=encoding)
        now = os.stat(tmp, follow_symlinks=False)
        if not stat.S_ISREG(now.st_mode) or (now.st_dev, now.st_ino) != (made.st_dev,
                                                                         made.st_ino):
            raise UserError(f"output '{out}': the temporary file '{tmp}' was replaced while "
                            "it was written (someone else writes in this directory; choose "
                            "another -o path)")
        os.fchmod(fd, new_file_mode())      # as any tool's new file, not mkstemp's 0600
        os.fsync(fd)
        os.replace(tmp, out)
        fsync_directory(parent)
    except (OSError, RuntimeError) as exc:
        _unlink_ours(tmp, made)
        raise _write_error(out, parent, ds, exc) from exc
    except BaseException:
        _unlink_ours(tmp, made)
        raise
    finally:
        os.close(fd)
    return out


def _unlink_ours(tmp: Path, made: os.stat_result) -> None:
    """Remove `tmp` if it is still the file this process made."""
    with contextlib.suppress(OSError):
        now = os.stat(tmp, follow_symlinks=False)
        if (now.st_dev, now.st_ino) == (made.st_dev, made.st_ino):
            os.unlink(tmp)


def _write_error(out: Path, parent: Path, ds: xr.Dataset, exc: BaseException) -> UserError:
    """The one line a failed write gives: a full disk says where and how much is needed."""
    free = free_bytes(parent)
    need = estimated_size(ds)
    # netCDF/HDF5 report a full disk as they like (RuntimeError, even EACCES): the space says
    full = (getattr(exc, "errno", None) in (errno.ENOSPC, errno.EDQUOT)
            or (free is not None and free < need))
    store = store_path(out)
    kept = (f"; the finished chunks are kept in '{store}/': free space and run again with "
            "--resume" if os.path.isdir(store) else "")
    if full:
        return UserError(f"output '{out}': no space left on the device in '{parent}' (the "
                         f"file needs up to {mib(need)}, {mib(free or 0)} free){kept}")
    reason = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
    return UserError(f"output '{out}': could not be written ({reason}){kept}")


def _pid_alive(pid: int) -> bool:
    """Whether process `pid` exists (a process of another user, or a pid beyond the OS's
    range, counts as alive: never take over what might be in use)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True
