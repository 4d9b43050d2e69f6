"""The Scene (a validated, fully resolved scene) and its TOML writer, `Scene.to_toml`."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import schema
from ..models.rules import has_base
from ..models.swept import Swept

_VALUE_SECTIONS: tuple[str, ...] = tuple(s for s in schema.SECTIONS
                                         if s not in schema.SWEPT_SECTIONS)
"""The sections that hold keys with values: every section but [axes] and [points], in schema
order."""
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


class ReadOnly(dict):
    """A Scene's values, axes or points: a dict that refuses changes, so that a scene is run as
    it was validated (an edited value would skip every check: a negative damping ran as a
    divergence, a string one failed deep in the model). Pickles as a dict (dask workers)."""

    def _refuse(self, *args: Any, **kwargs: Any) -> None:
        raise TypeError("a Scene is read-only once validated: load it again with the change "
                        "as an override, e.g. sweep.load_scene(NAME, overrides={KEY: VALUE})")

    __setitem__ = __delitem__ = _refuse
    clear = pop = popitem = setdefault = update = _refuse
    __ior__ = _refuse

    def __reduce__(self) -> tuple:
        return (ReadOnly, (dict(self),))


@dataclass(frozen=True, eq=False)
class Scene:
    """A validated, fully resolved scene.

    values: every dotted key of `schema.KEYS` -> its value (defaults applied); None for an
        optional key that is absent and for a key that is swept (see ``axes``). A "floats"
        key (``outputs.snapshot_times``) holds a tuple of floats, or None.
    axes: axis name -> 1-D read-only float64 array, in scene order ([axes] table order,
        then axes added by overrides).
    points: axis name -> 1-D read-only float64 array, one common length: the [points]
        entries (zipped parameter sets, the result's ``point`` dimension); empty without.
    text: the TOML text as read; source: the built-in name or the path given;
    overrides: the overrides applied, with parsed values.

    Two scenes are equal when their name, description, values, axes and points are equal
    (text, source and overrides are not compared).
    """

    name: str
    description: str
    values: dict[str, Any]
    axes: dict[str, np.ndarray]
    text: str = field(repr=False)
    source: str
    overrides: dict[str, Any] = field(default_factory=dict)
    points: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("values", "axes", "points", "overrides"):
            object.__setattr__(self, name, ReadOnly(getattr(self, name)))

    @property
    def swept(self) -> Swept:
        """Every key that varies over the run -> its values: the axes and the [points]."""
        return Swept(self.axes, self.points)

    @property
    def has_base(self) -> bool:
        """Whether the scene has base excitation of the clamps (a [base] level and frequency)."""
        return has_base(self.values, self.swept)

    def get(self, dotted: str) -> Any:
        """The resolved value of a dotted key, e.g. ``scene.get("solver.rtol")``.

        A "floats" key gives a tuple of floats (possibly empty) or None.
        """
        return self.values[dotted]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Scene):
            return NotImplemented
        return (self.name == other.name
                and self.description == other.description
                and self.values == other.values
                and list(self.axes) == list(other.axes)
                and all(np.array_equal(self.axes[a], other.axes[a]) for a in self.axes)
                and list(self.points) == list(other.points)
                and all(np.array_equal(self.points[a], other.points[a]) for a in self.points))

    __hash__ = None  # type: ignore[assignment]

    def to_toml(self) -> str:
        """The resolved scene as TOML: every section, defaults included, axes and points as
        lists.

        None-valued keys are left out; a "floats" value is written as a list. `load_scene_text`
        of the result gives an equal Scene.
        """
        lines = [f"# Resolved scene from {_comment_text(self.source)}: "
                 "defaults written out, axes as explicit lists."]
        if self.overrides:
            lines.append(f"# Overrides applied: {_comment_text(', '.join(self.overrides))}.")
        lines.append(f"name = {_toml_value(self.name)}")
        lines.append(f"description = {_toml_value(self.description)}")
        for section in _VALUE_SECTIONS:
            lines.extend(self._section_lines(section))
        if self.axes:
            lines.extend(["", "[axes]"])
            lines.extend(f"{_toml_key(a)} = {_toml_array(v)}" for a, v in self.axes.items())
        if self.points:
            lines.extend(["", "[points]"])
            lines.extend(f"{_toml_key(a)} = {_toml_array(v)}" for a, v in self.points.items())
        return "\n".join(lines) + "\n"

    def _section_lines(self, section: str) -> list[str]:
        """``[section]`` and its non-None keys, in schema order; empty if none."""
        body = [f"{key.name} = {_toml_value(self.values[key.dotted])}"
                for key in schema.KEYS
                if key.section == section and self.values[key.dotted] is not None]
        return ["", f"[{section}]", *body] if body else []


def _comment_text(text: str) -> str:
    """Text safe inside a TOML comment (no control characters)."""
    return "".join(c if c.isprintable() else "?" for c in repr(text))


def _toml_value(value: Any) -> str:
    """TOML for a str, bool, int, float, or list of numbers."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        return _toml_array(value)
    raise TypeError(f"cannot write {type(value).__name__} as a TOML value")


def _toml_array(values: Any, per_line: int = 8) -> str:
    """A TOML array of numbers, wrapped every ``per_line`` items."""
    items = [_toml_value(v) for v in (values.tolist() if isinstance(values, np.ndarray) else values)]
    if len(items) <= per_line:
        return "[" + ", ".join(items) + "]"
    rows = [", ".join(items[i:i + per_line]) for i in range(0, len(items), per_line)]
    return "[\n    " + ",\n    ".join(rows) + ",\n]"


def _toml_string(text: str) -> str:
    """A TOML basic string with the escapes TOML requires."""
    escapes = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n",
               "\f": "\\f", "\r": "\\r"}
    out = []
    for char in text:
        if char in escapes:
            out.append(escapes[char])
        elif ord(char) < 0x20 or ord(char) == 0x7F:
            out.append(f"\\u{ord(char):04X}")
        else:
            out.append(char)
    return '"' + "".join(out) + '"'


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.fullmatch(key) else _toml_string(key)
