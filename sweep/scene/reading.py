"""Finding and reading a scene: a built-in name (a file in ``sweep/scenes/``) or a path.

A scene argument that names no built-in scene and no file is reported as a missing file when it
looks like a path (holds a '/' or ends in .toml), else as an unknown name. A scene file is read
as bytes (only a regular file, at most MAX_SCENE_BYTES), decoded as UTF-8 and parsed as TOML
(a syntax error names the line and column): nothing in it is executed.
"""

from __future__ import annotations

import os
import re
import stat
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

from .messages import _close, _fail

MAX_SCENE_BYTES = 8 * 2**20
"""A scene file longer than this (bytes) is refused before it is read; 8 MiB holds an axis of
400 000 values written out (parsed in about 1 s, 70 MB)."""
_BUILTIN_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]*")
_TOML_POSITION = re.compile(r"\s*\(at line (\d+), column (\d+)\)\s*$")
_TOML_AT_END = re.compile(r"\s*\(at end of document\)\s*$")


def builtin_scenes() -> dict[str, str]:
    """Built-in scene name -> the first line of its description, sorted by name."""
    found: dict[str, str] = {}
    try:
        entries = list(_scenes_dir().iterdir())
    except OSError:
        return {}
    for entry in entries:
        if entry.name.endswith(".toml") and entry.is_file():
            found[entry.name[:-len(".toml")]] = _first_description_line(entry.read_text("utf-8"))
    return dict(sorted(found.items()))


def _scenes_dir() -> Any:
    """The package-data folder of built-in scenes (works from an installed wheel too)."""
    return resources.files("sweep") / "scenes"


def _builtin_file(name: str) -> Any | None:
    """The built-in scene file called ``name``, or None."""
    if not _BUILTIN_NAME.fullmatch(name):
        return None
    try:
        candidate = _scenes_dir() / f"{name}.toml"
        return candidate if candidate.is_file() else None
    except OSError:
        return None


def _read_scene(scene: str | os.PathLike) -> tuple[str, str, str]:
    """(source, text, default name) of a built-in name or a scene file path.

    Only a regular file of at most MAX_SCENE_BYTES is read (a FIFO would block, a device
    never ends); every OS error (permissions, a name too long, ...) is a one-line SceneError.
    """
    if isinstance(scene, str):
        builtin = _builtin_file(scene)
        if builtin is not None:
            return scene, builtin.read_text("utf-8"), scene
    source = os.fspath(scene)
    if isinstance(source, bytes):
        source = os.fsdecode(source)
    where = f"scene file '{source}'"
    info = _stat_scene(source, where)
    if info is None:
        if _looks_like_path(source):
            _fail(where, "no such file", "check the path; 'sweep scenes' lists the built-in names")
        guess = _close(source, builtin_scenes())
        _fail(f"scene '{source}'", "no built-in scene of that name and no such file",
              (f"did you mean '{guess}'? " if guess else "")
              + "run 'sweep scenes' for the built-in names")
    _check_text(where, source, "the file name", "give the file (and its folders) a UTF-8 name")
    if stat.S_ISDIR(info.st_mode):
        _fail(where, "is a directory, not a TOML file", "give the path of a .toml scene file")
    data = _read_regular(source, where)
    if data[:3] == b"CDF" or data[:8] == b"\x89HDF\r\n\x1a\n":
        _fail(where, "is a netCDF file (a result), not a TOML scene",
              "give the scene's .toml file or a built-in name; a result keeps the scene it was "
              "run from in its 'scene' attribute")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        _fail(where, f"is not UTF-8 text (bad byte at offset {exc.start})",
              "save the file as UTF-8")
    return source, text, Path(source).stem or "unnamed"


def _stat_scene(source: str, where: str) -> os.stat_result | None:
    """os.stat of a scene path (following links); None when nothing is there."""
    if not source:
        return None
    try:
        return os.stat(source)
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as exc:
        _fail(where, f"cannot be read: {exc.strerror or exc}", "check the path and its permissions")
    except ValueError as exc:                    # an embedded NUL character
        _fail(where, f"is not a valid path ({exc})", "check the path")


def _read_regular(source: str, where: str) -> bytes:
    """The bytes of a regular file of at most MAX_SCENE_BYTES (opened without blocking, so a
    FIFO put in its place is refused instead of waited on)."""
    fix = "give a TOML scene file; write long axes as range tables {start, stop, num}"
    too_large = f"is larger than {MAX_SCENE_BYTES // 2**20} MiB"
    try:
        fd = os.open(source, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        _fail(where, f"cannot be read: {exc.strerror or exc}", "check the path and its permissions")
    with os.fdopen(fd, "rb") as handle:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            _fail(where, f"is not a regular file (a {_file_kind(info.st_mode)})",
                  "give the path of a .toml scene file")
        if info.st_size > MAX_SCENE_BYTES:
            _fail(where, f"{too_large} ({info.st_size:,} bytes)", fix)
        try:
            data = handle.read(MAX_SCENE_BYTES + 1)
        except OSError as exc:
            _fail(where, f"cannot be read: {exc.strerror or exc}",
                  "check the path and its permissions")
    if len(data) > MAX_SCENE_BYTES:
        _fail(where, too_large, fix)
    return data


def _file_kind(mode: int) -> str:
    """'FIFO', 'character device', ... for a file mode that is not a regular file."""
    kinds = ((stat.S_ISFIFO, "FIFO (named pipe)"), (stat.S_ISCHR, "character device"),
             (stat.S_ISBLK, "block device"), (stat.S_ISSOCK, "socket"))
    return next((name for test, name in kinds if test(mode)), "special file")


def _check_text(where: str, text: str, what: str, fix: str) -> None:
    """Refuse text that cannot be stored as a netCDF attribute: not encodable as UTF-8 (lone
    surrogates, e.g. undecodable bytes of a command-line argument) or holding a NUL character
    (netCDF would drop it silently)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as exc:
        _fail(where, f"{what} is not valid UTF-8 text (character {exc.start + 1})", fix)
    if "\x00" in text:
        _fail(where, f"{what} holds a NUL character (character {text.index(chr(0)) + 1})", fix)


def _looks_like_path(source: str) -> bool:
    """Whether a scene argument that names nothing was meant as a file, not a built-in name."""
    return (os.sep in source or "/" in source or (os.altsep or "/") in source
            or source.lower().endswith(".toml"))


def _first_description_line(text: str) -> str:
    """The first line of a scene's ``description``, or "" if it has none."""
    try:
        description = tomllib.loads(text).get("description", "")
    except (ValueError, RecursionError):         # TOMLDecodeError is a ValueError
        return ""
    lines = description.strip().splitlines() if isinstance(description, str) else []
    return lines[0] if lines else ""


def _parse_toml(text: str, source: str) -> dict[str, Any]:
    """Parse scene text; a syntax error names the file, line and column."""
    try:
        return tomllib.loads(text)
    except RecursionError:
        _fail(f"scene file '{source}'", "arrays or tables are nested too deeply to parse",
              "write at most a few levels of nested [...] and {...}")
    except tomllib.TOMLDecodeError as exc:
        message = str(exc)
        position = _TOML_POSITION.search(message)
        if position:
            where = f"at line {position.group(1)}, column {position.group(2)}"
            message = message[:position.start()]
        elif _TOML_AT_END.search(message):
            where = "at the end of the file"
            message = _TOML_AT_END.sub("", message)
        else:
            where = "somewhere"
        _fail(f"scene file '{source}'", f"TOML syntax error {where}: {message}",
              "fix the line and run again")
    except ValueError as exc:                    # e.g. an integer of more than 4300 digits
        _fail(f"scene file '{source}'", f"cannot be parsed: {_value_error_text(exc)}",
              "fix the value and run again")


def _value_error_text(exc: ValueError) -> str:
    """What tomllib's plain ValueError (not a syntax error) means, in a few words."""
    message = str(exc)
    if "integer string conversion" in message:
        return "an integer has more than 4300 digits"
    return message
