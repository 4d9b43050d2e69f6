"""netCDF output: checked before a run starts, written atomically after it ends."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import xarray as xr

from .errors import UserError


def check_output_path(path: str | os.PathLike, overwrite: bool = False) -> Path:
    """Refuse, before any work is done, an output path that cannot be written.

    Raises UserError naming the file: missing or read-only directory, an existing file
    without `overwrite`, a directory in the way, or a name that is not .nc.
    """
    raw = os.fspath(path)
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
    if not parent.is_dir():
        raise UserError(f"output '{out}': directory '{parent}' does not exist (create it first)")
    if not _can_create_in(parent):
        raise UserError(f"output '{out}': directory '{parent}' is not writable (choose another -o path)")
    if out.is_dir():
        raise UserError(f"output '{out}': is a directory (give a file name ending in .nc)")
    if out.exists() and not overwrite:
        raise UserError(f"output '{out}': file exists (use --overwrite, or overwrite=True, to replace it)")
    return out


def _can_create_in(directory: Path) -> bool:
    """Whether a file can really be created in `directory` (os.access says yes to root even on a
    read-only file system, so try it)."""
    try:
        with tempfile.NamedTemporaryFile(dir=directory, prefix=".cable-sweep-probe-"):
            return True
    except OSError:
        return False


def write_netcdf(ds: xr.Dataset, path: str | os.PathLike, overwrite: bool = False) -> Path:
    """Write `ds` to `path` atomically: a temporary file in the same directory, then a rename.

    A failure leaves no partial file behind; an existing file is replaced only with `overwrite`.
    """
    out = check_output_path(path, overwrite)
    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp")
    encoding = {name: {"zlib": True, "complevel": 4}
                for name, var in ds.data_vars.items() if var.ndim >= 1 and var.dtype.kind == "f"}
    # CF: coordinates have no missing values, so no _FillValue (xarray adds NaN to floats).
    encoding.update({name: {"_FillValue": None} for name in ds.coords})
    try:
        ds.to_netcdf(tmp, engine="netcdf4", encoding=encoding)
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, out)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise UserError(f"output '{out}': could not be written ({exc.strerror or exc})") from exc
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return out
