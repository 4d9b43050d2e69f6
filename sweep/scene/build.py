"""The scene pipeline: read, parse, override, check every key and axis against the schema,
apply the rules of the scene's model kind (sweep/models/rules.py, found through the registry,
`sweep.models.rules_for`), resolve the defaults, and return the Scene.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import models, schema
from ..errors import SceneError
from ..models import cable, rules
from ..models.swept import Swept
from .axes import _check_axes, _flatten_axes
from .document import Scene
from .messages import _fail
from .overrides import _apply_overrides, _parse_overrides
from .points import _check_points
from .reading import _parse_toml, _read_scene
from .units import convert_document
from .values import _check_description, _check_name, _check_sections, _check_top_level


def load_scene(scene: str | os.PathLike, overrides: Mapping[str, Any] | None = None) -> Scene:
    """Load a built-in scene by name, or a scene file by path, and validate it.

    overrides: dotted key -> value, applied to the document before validation. Values may be
    Python values or strings; strings are parsed as TOML values (see `parse_override`).
    """
    if not isinstance(scene, (str, os.PathLike)):
        raise SceneError(f"load_scene: scene {scene!r:.60}: not a scene name or a path (give a "
                         "built-in name such as 'paper-fig5', or the path of a .toml file)")
    _check_overrides(overrides, "load_scene")
    source, text, default_name = _read_scene(scene)
    return _build(text, source, default_name, overrides)


def load_scene_text(text: str, source: str = "<string>",
                    overrides: Mapping[str, Any] | None = None) -> Scene:
    """Like `load_scene`, from TOML text; ``source`` is used in error messages."""
    if not isinstance(text, str):
        raise SceneError(f"load_scene_text: text {type(text).__name__}: not TOML text (give "
                         "the scene as a str; a file's path goes to load_scene)")
    if not isinstance(source, str):
        raise SceneError(f"load_scene_text: source {type(source).__name__}: the second "
                         "argument names the text in messages; give overrides by keyword, "
                         "load_scene_text(text, overrides={...})")
    _check_overrides(overrides, "load_scene_text")
    return _build(text, source, "unnamed", overrides)


def _check_overrides(overrides: Any, where: str) -> None:
    """Overrides are a mapping of dotted keys (or None): refuse anything else in one line."""
    if overrides is not None and not isinstance(overrides, Mapping):
        raise SceneError(f"{where}: overrides {overrides!r:.60}: not a mapping of dotted keys "
                         "(give e.g. overrides={'model.modes': 3})")


def _build(text: str, source: str, default_name: str,
           overrides: Mapping[str, Any] | None) -> Scene:
    """Parse, override, validate and resolve a scene."""
    doc = _parse_toml(text, source)
    for section in schema.SWEPT_SECTIONS:
        if isinstance(doc.get(section), dict):
            doc[section] = _flatten_axes(doc[section])
    file_has_base = "base" in doc
    _flatten_tables(doc)
    applied = _parse_overrides(overrides)
    _apply_overrides(doc, applied)
    _flatten_tables(doc)
    _check_top_level(doc)
    convert_document(doc)               # unit strings -> SI numbers, once
    name = _check_name(doc.get("name", default_name))
    description = _check_description(doc.get("description", ""))
    given = _check_sections(doc)
    axes = _check_axes(doc.get("axes", {}))
    points = _check_points(doc.get("points", {}), axes)
    swept = Swept(axes, points)         # what the rules see: every key that varies
    rules.check_base(given, swept, "base" in doc, file_has_base)
    kind = models.rules_for(rules.model_kind(given))
    _check_continued(given, points)
    rules.check_pairs(given, swept)     # two spellings of one quantity first: the rules
    kind.check(given, swept)            # below read one of them
    cable.check(given, swept)           # one description of the cable (material or sheet)
    _check_run(given)
    values = _resolve(given, swept, kind)
    kind.check_resolved(values, swept, given)
    return Scene(name=name, description=description, values=values, axes=axes,
                 text=text, source=source, overrides=applied, points=points)


def _check_continued(given: dict[str, Any], points: dict[str, np.ndarray]) -> None:
    """A stepped sweep steps along an axis: its points are ordered values, [points] are not."""
    axis = given.get("continuation.axis")
    if axis in points:
        _fail("scene key 'continuation.axis'", f"'{axis}' is a [points] entry; a stepped sweep "
              "steps along an ordered axis", f"move {axis} from [points] to [axes]")


def _flatten_tables(doc: dict[str, Any]) -> None:
    """Write a section's inline tables of keys (``[base] sweep = {start, stop, rate}``) as the
    schema's dotted names (``sweep.start``), in place; a table replaces the dotted keys it
    had. A plain value where such a table belongs is refused in one line."""
    for section, table in doc.items():
        if not isinstance(table, dict) or section in schema.SWEPT_SECTIONS:
            continue
        for name in [n for n in table if f"{section}.{n}" in schema.TABLES]:
            value = table.pop(name)
            dotted = f"{section}.{name}"
            if not isinstance(value, dict):
                _fail(f"scene key '{dotted}'", f"must be a table, got {value!r}",
                      f"write e.g. {schema.TABLES[dotted]}")
            for old in [n for n in table if n.startswith(f"{name}.")]:
                del table[old]
            for sub, item in value.items():
                table[f"{name}.{sub}"] = item


def _check_run(given: dict[str, Any]) -> None:
    """run.workers sizes the LocalCluster of the dask backend; with threads it would be
    ignored (run.threads is the threads backend's count)."""
    if given.get("run.workers", 0) and given.get("run.backend", "threads") != "dask":
        _fail("scene key 'run.workers'", "only for run.backend = 'dask' (the LocalCluster's "
              "worker processes); the threads backend would ignore it",
              "use run.threads for the threads backend, or set run.backend = 'dask'")
    cores = os.cpu_count() or 1          # run.threads is capped at the cores (threads.py)
    if given.get("run.workers", 0) > cores:
        _fail("scene key 'run.workers'", f"{given['run.workers']} worker processes on a "
              f"machine of {cores} core{'s' if cores != 1 else ''}: more would only compete "
              "for them", f"give at most {cores}, or 0 for one per core")


def _resolve(given: dict[str, Any], axes: dict[str, np.ndarray],
             kind: rules.Rules) -> dict[str, Any]:
    """Every dotted key -> value: given, else the default (the schema's, then those of the
    model kind's rules); None for swept keys (axes and [points])."""
    swept = {schema.BY_AXIS[a].dotted for a in axes}
    values = {k.dotted: None if k.dotted in swept else given.get(k.dotted, k.default)
              for k in schema.KEYS}
    kind.defaults(values, given, set(given) | swept, Swept.of(axes))
    return values
