"""The chunk store behind --resume: the finished chunks of one run, on disk next to the output.

`<output>.chunks/` holds `run.json` (the run's fingerprint and chunk size), a `lock` file and
one `chunk-LO-HI.npz` per finished range of points (solve order, LO..HI-1), and a
`progress-LO-HI.npz` for a chunk of stepped-sweep lines left part-way (each line's finished
dwells and what its next dwell starts from; replaced as the lines move on, removed when the
chunk is stored whole). Each chunk file
carries what proves it belongs: its range, the run's fingerprint and a SHA-256 checksum of its
arrays (names, dtypes, shapes and bytes). On resume a chunk that is damaged (empty, truncated,
a flipped byte) or foreign (another range's, another run's, a link) is left out and its points
are computed again, with one line saying so; it is never trusted.

Writes are atomic and durable: a temporary file made with O_EXCL (tempfile.mkstemp, an
unpredictable name) in the store, fsync, rename, fsync of the directory. A store that is a
symbolic link is refused, and no file in it is opened through a link.

Only one run uses a store at a time: the run holds an fcntl lock on `lock` (which holds its
pid) while the store is open; the kernel drops the lock when the process dies, so a lock left
by a killed run is taken over, and a second live run is refused ("in use by a running sweep
(pid N)").
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import hashlib
import json
import os
import re
import shutil
import stat
import sys
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from .errors import UserError
from .files import free_bytes, fsync_directory, mib, write_temporary

STORE_SUFFIX = ".chunks"
_META = "__chunk__"                      # the array in each chunk file that says what it is
_CHUNK = re.compile(r"chunk-(\d{12})-(\d{12})\.npz")
_PROGRESS = re.compile(r"progress-(\d{12})-(\d{12})\.npz")
_FULL = (errno.ENOSPC, errno.EDQUOT)

# Stores this process holds the lock of: directory -> the open lock file's descriptor.
_HELD: dict[Path, int] = {}


def store_path(output: str | os.PathLike) -> Path:
    """The chunk store directory of output file `output`: `<output>.chunks`."""
    out = Path(output)
    return out.with_name(out.name + STORE_SUFFIX)


def checksum(arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 of arrays by name: their names, dtypes, shapes and bytes, in name order."""
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(json.dumps([name, a.dtype.str, list(a.shape)]).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _is_link(path: Path) -> bool:
    try:
        return stat.S_ISLNK(os.lstat(path).st_mode)
    except OSError:
        return False


class ChunkStore:
    """Finished chunks of one run, as .npz files in `<output>.chunks/`, written atomically.

    `fingerprint` identifies the run (resolved scene, kernel, chunking); a store made by another
    run is refused rather than mixed in, and a chunk made by another run is recomputed.
    """

    def __init__(self, output: str | os.PathLike, fingerprint: str) -> None:
        self.directory = store_path(output)
        self.fingerprint = fingerprint
        self.points = 0                  # the run's number of points (space estimates)
        self.stored = 0                  # points held by chunk files
        self.bytes_per_point = 0.0       # of a chunk file (bytes), once one is written
        self._key = Path(os.path.abspath(self.directory))

    def exists(self) -> bool:
        return os.path.lexists(self.directory)

    # --- opening, locking ------------------------------------------------------------------

    def open(self, resume: bool, overwrite: bool, chunk_size: int,
             points: int = 0) -> tuple[dict[tuple[int, int], dict], int]:
        """Lock the store and prepare it; return the chunks already finished (only when
        resuming) and the chunk size to use (a resumed run keeps the interrupted run's).
        `points`: the run's number of points (for the space it needs on disk)."""
        self.points = points
        if _is_link(self.directory):
            raise UserError(f"chunk store '{self.directory}': is a symbolic link, refused (a "
                            "sweep writes only a store it made: remove the link)")
        if self.exists() and not self.directory.is_dir():
            raise UserError(f"chunk store '{self.directory}': is not a directory (remove it, "
                            "or choose another -o path)")
        existed = self.exists()
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            self._lock()
            return self._prepare(existed, resume, overwrite, chunk_size)
        except OSError as exc:
            self.release(discard_empty=not existed)     # leave no store this run made
            if exc.errno in _FULL:
                need = self.space_needed()
                amount = f"the run needs about {mib(need)} there; " if need > 0.0 else ""
                raise UserError(f"chunk store '{self.directory}': no space left on the device "
                                f"({amount}free space and run again)") from exc
            raise UserError(f"chunk store '{self.directory}': cannot be used "
                            f"({exc.strerror or exc})") from exc

    def _lock(self) -> None:
        """Take the store's lock, or refuse: another live run holds it."""
        if self._key in _HELD:
            return
        path = self.directory / "lock"
        while True:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                text = os.pread(fd, 32, 0).decode(errors="replace").strip()
                os.close(fd)
                pid = f"pid {text}" if text.isdigit() else "pid unknown"
                raise UserError(f"{self.directory}/ is in use by a running sweep ({pid}); wait "
                                "for it to finish, or choose another -o path") from None
            # The holder before us may have removed the store once done: lock the live file.
            try:
                same = os.stat(path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
            self.directory.mkdir(parents=True, exist_ok=True)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        _HELD[self._key] = fd

    def _prepare(self, existed: bool, resume: bool, overwrite: bool,
                 chunk_size: int) -> tuple[dict[tuple[int, int], dict], int]:
        meta = self.directory / "run.json"
        if existed and not resume:
            if not overwrite and self._holds_work():
                self.release()
                raise UserError(f"chunk store '{self.directory}': left by an interrupted run "
                                "(use --resume to finish it, or --overwrite to start again)")
            self._clear()
        self._remove_temporaries()
        stored = None
        with contextlib.suppress(OSError, ValueError, TypeError):
            stored = json.loads(self._read(meta))
            stored = stored if isinstance(stored, dict) else None
        if stored is not None and stored.get("fingerprint") != self.fingerprint:
            self.release()
            raise UserError(f"chunk store '{self.directory}': made by a different scene or "
                            "another version of cable-sweep (remove it, or use --overwrite to "
                            "start again)")
        try:
            chunk_size = int(stored["chunk_size"]) if stored is not None else chunk_size
        except (KeyError, TypeError, ValueError):
            stored = None
        if stored is None or chunk_size < 1:
            chunk_size = max(chunk_size, 1)
            self._write_atomic(meta, json.dumps({"fingerprint": self.fingerprint,
                                                 "chunk_size": chunk_size}).encode())
        done = self._load_chunks()
        self.stored = sum(hi - lo for lo, hi in done)
        return done, chunk_size

    def _holds_work(self) -> bool:
        """Whether the store holds a chunk file or a progress file."""
        return any(_CHUNK.fullmatch(e.name) or _PROGRESS.fullmatch(e.name)
                   for e in os.scandir(self.directory))

    def _clear(self) -> None:
        """Everything in the store but its lock (which this run holds)."""
        for entry in os.scandir(self.directory):
            if entry.name == "lock":
                continue
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(entry.path, ignore_errors=True)
            else:
                os.unlink(entry.path)

    def _remove_temporaries(self) -> None:
        """Temporary chunk files of a run that was killed while writing (the lock says no other
        run is writing)."""
        for entry in os.scandir(self.directory):
            if entry.name.startswith(".") and entry.name.endswith(".tmp"):
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)

    # --- reading -----------------------------------------------------------------------------

    @staticmethod
    def _read(path: Path) -> bytes:
        """The bytes of a regular file `path`, never through a link (OSError otherwise)."""
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                raise OSError(errno.EINVAL, "not a regular file")
            return fh.read()

    def _load_chunks(self, pattern: re.Pattern = _CHUNK,
                     done: dict | None = None) -> dict[tuple[int, int], dict]:
        """The chunks (files named by `pattern`) that prove they belong and overlap none of
        `done`; the others are removed and said so in one line."""
        found: dict[tuple[int, int], dict] = {}
        bad: list[str] = []
        for entry in sorted(os.scandir(self.directory), key=lambda e: e.name):
            match = pattern.fullmatch(entry.name)
            if not match:
                continue
            lo, hi = int(match[1]), int(match[2])
            reason = None
            try:
                arrays = self._load(Path(entry.path), lo, hi)
            except _Bad as exc:
                reason = str(exc)
            else:
                if any(a < hi and lo < b for a, b in list(found) + list(done or {})):
                    reason = "overlaps another chunk"
                elif self.points and hi > self.points:
                    reason = f"lies outside the {self.points:,} points"
                else:
                    found[(lo, hi)] = arrays
            if reason is not None:
                bad.append(f"{entry.name} {reason}")
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)
        if bad:
            shown = "; ".join(bad[:3]) + (f"; and {len(bad) - 3} more" if len(bad) > 3 else "")
            sys.stderr.write(f"sweep: warning: chunk store '{self.directory}': {len(bad)} "
                             f"chunk file{'s' if len(bad) > 1 else ''} not used ({shown}); "
                             "their points are computed again\n")
            sys.stderr.flush()
        return found

    def progress(self, done: dict[tuple[int, int], dict]) -> dict[tuple[int, int], dict]:
        """The progress files (chunks of lines left part-way) that prove they belong and
        overlap no finished chunk of `done`, by range; the others are removed (one line)."""
        return self._load_chunks(_PROGRESS, done)

    def _load(self, path: Path, lo: int, hi: int) -> dict[str, np.ndarray]:
        """The arrays of chunk file `path` named for points lo..hi-1, or _Bad saying why not."""
        import io
        if _is_link(path):
            raise _Bad("is a symbolic link")
        try:
            raw = self._read(path)
            if not raw:
                raise _Bad("is empty")
            with np.load(io.BytesIO(raw), allow_pickle=False) as data:
                arrays = {k: data[k] for k in data.files}
        except _Bad:
            raise
        except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, RuntimeError,
                MemoryError) as exc:
            raise _Bad(f"is damaged ({type(exc).__name__})") from exc
        try:
            meta = json.loads(str(arrays.pop(_META)))
            own = (int(meta["lo"]), int(meta["hi"]), str(meta["fingerprint"]),
                   str(meta["checksum"]))
        except (KeyError, ValueError, TypeError) as exc:
            raise _Bad("says nothing of what it holds (damaged, or made by an older version)") \
                from exc
        if own[2] != self.fingerprint:
            raise _Bad("was made by another run")
        if own[:2] != (lo, hi):
            raise _Bad(f"holds points {own[0]}-{own[1]}, not {lo}-{hi}")
        if checksum(arrays) != own[3]:
            raise _Bad("is damaged (checksum)")
        if not arrays or any(a.ndim == 0 or len(a) != hi - lo for a in arrays.values()):
            raise _Bad("holds the wrong number of points")
        return arrays

    # --- writing -----------------------------------------------------------------------------

    def save(self, lo: int, hi: int, arrays: dict[str, np.ndarray]) -> None:
        """Write points lo..hi-1's arrays as one chunk file, atomically and durably. A full
        disk raises UserError naming the store and the space the run still needs."""
        data = self._encode(lo, hi, arrays)
        self.bytes_per_point = max(self.bytes_per_point, len(data) / max(hi - lo, 1))
        self._write(self.directory / f"chunk-{lo:012d}-{hi:012d}.npz", data)
        self.stored += hi - lo
        for entry in os.scandir(self.directory):     # the chunk's progress, now superseded
            match = _PROGRESS.fullmatch(entry.name)
            if match and lo <= int(match[1]) and int(match[2]) <= hi:
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)

    def _encode(self, lo: int, hi: int, arrays: dict[str, np.ndarray]) -> bytes:
        """lo..hi-1's arrays as the bytes of a chunk file: the arrays and what proves them."""
        import io
        meta = json.dumps({"lo": lo, "hi": hi, "fingerprint": self.fingerprint,
                           "checksum": checksum(arrays)})
        buffer = io.BytesIO()
        np.savez(buffer, **arrays, **{_META: np.array(meta)})
        return buffer.getvalue()

    def _write(self, path: Path, data: bytes) -> None:
        """`data` as file `path`, atomically; a full disk or another failure is one line."""
        try:
            self._write_atomic(path, data)
        except OSError as exc:
            if exc.errno in _FULL:
                raise UserError(
                    f"chunk store '{self.directory}': no space left on the device (the run "
                    f"needs about {mib(self.space_needed())} more there, "
                    f"{mib(free_bytes(self.directory) or 0)} free; the {self.stored:,} points "
                    "already stored are kept: free space and run again with --resume)") from exc
            raise UserError(f"chunk store '{self.directory}': a chunk could not be written "
                            f"({exc.strerror or exc}; the points already stored are kept, "
                            "run again with --resume)") from exc

    def save_progress(self, lo: int, hi: int, arrays: dict[str, np.ndarray]) -> None:
        """Write the progress of the part-way chunk of lines lo..hi-1 (replacing the last)."""
        self._write(self.directory / f"progress-{lo:012d}-{hi:012d}.npz",
                    self._encode(lo, hi, arrays))

    def space_needed(self) -> float:
        """Bytes the chunks not yet stored need (an estimate from the chunks written so far;
        0 before the first)."""
        return self.bytes_per_point * max(self.points - self.stored, 0)

    def _write_atomic(self, path: Path, data: bytes) -> None:
        """`data` as file `path`: a new temporary (O_EXCL), fsync, rename, fsync of the store."""
        tmp = write_temporary(self.directory, ".chunk-", data)
        try:
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
        fsync_directory(self.directory)

    # --- ending --------------------------------------------------------------------------------

    def release(self, discard_empty: bool = False) -> None:
        """Drop this process's lock on the store; with `discard_empty`, first remove the store
        when it holds no finished chunk (a run that failed before finishing any)."""
        fd = _HELD.get(self._key)
        if fd is None:
            return
        if discard_empty and not self._holds_work():
            shutil.rmtree(self.directory, ignore_errors=True)
        _HELD.pop(self._key, None)
        os.close(fd)

    def remove(self) -> None:
        """Remove the store (its work is in the output file) and drop the lock."""
        if not _is_link(self.directory):
            shutil.rmtree(self.directory, ignore_errors=True)
        fd = _HELD.pop(self._key, None)
        if fd is not None:
            os.close(fd)


class _Bad(Exception):
    """A chunk file that does not prove it belongs (the message says why)."""


def fingerprint(*parts: Any) -> str:
    """A hash of everything that decides a run's chunks and their contents."""
    text = json.dumps([str(p) for p in parts])
    return hashlib.sha256(text.encode()).hexdigest()
