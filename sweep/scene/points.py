"""``[points]``: zipped parameter sets. Each entry is a list of one sweepable key's values
(named as under [axes]: the axis name or the dotted key); all lists have one length, and
entry i of every list is parameter set i, the result's ``point`` dimension. Points combine
with the [axes] as a product: every point is solved at every axis combination.

Values need not be ordered or distinct (two segments may share a length); each is checked
against its key's bounds. A key that is also an axis is refused, as is a key that only some
points could give (a list of unequal length).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import schema
from .axes import MAX_AXIS_POINTS, _axis_list, _axis_name
from .messages import _fail, _show
from .values import _check_bounds

POINT_DIM = "point"
"""The dimension (and integer coordinate, 0, 1, ...) of the [points] entries."""


def _check_points(table: dict[str, Any], axes: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Validate ``[points]``: axis name -> read-only float64 array, one common length, in
    table order; no name that is also under [axes]."""
    points: dict[str, np.ndarray] = {}
    for entry, raw in table.items():
        where = f"[points] entry '{entry}'"
        name = _axis_name(entry, where)
        if name in points:
            _fail(where, f"'{name}' is given twice", "keep one of the entries")
        if name in axes:
            _fail(where, f"'{name}' is also an axis under [axes]; a key varies one way",
                  f"remove it from [axes] (every point then takes its own {name}) or from "
                  "[points] (every point is then solved at every value of the axis)")
        if not isinstance(raw, list):
            _fail(where, f"must be a list with one value per point, got {_show(raw)}",
                  f"write e.g. {name} = [0.3, 0.5] ([points] takes lists, not range tables)")
        values = _axis_list(where, raw)
        _check_bounds(where, schema.BY_AXIS[name], values)
        values.flags.writeable = False
        points[name] = values
    lengths = {name: len(v) for name, v in points.items()}
    if len(set(lengths.values())) > 1:
        listed = ", ".join(f"{name} has {n}" for name, n in lengths.items())
        _fail("[points]", f"every list needs one value per point, but {listed}",
              "give every [points] entry the same number of values")
    count = next(iter(lengths.values()), 0)
    if count > MAX_AXIS_POINTS:
        _fail("[points]", f"{count} points; at most {MAX_AXIS_POINTS}", "give fewer points")
    return points
