"""What varies over a run: the scene's axes (a product grid) and its [points] (zipped
parameter sets on one `point` dimension), seen by the scene rules as one mapping.

`Swept` maps every varying key's axis name to its values, as a dict, so a rule that asks
"is this key swept?" or "what is its largest value?" reads axes and points alike. `zipped`
names the keys that vary together along the point dimension; `product` broadcasts any set of
keys over the run's real grid, so a rule that needs the combinations a run will solve
(a sweep's start and stop, the derived coefficients at the grid's corners) sees only those.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np


class Swept(dict):
    """Axis name -> values (1-D float64) of every key that varies over a run.

    zipped: the names given under [points]: their values have one common length and vary
    together (entry i of each is point i). Every other name is an axis of the product grid.
    """

    def __init__(self, axes: Mapping[str, np.ndarray] = (),
                 points: Mapping[str, np.ndarray] | None = None) -> None:
        super().__init__(axes)
        points = dict(points or {})
        self.update(points)
        self.zipped: frozenset[str] = frozenset(points)

    @classmethod
    def of(cls, axes: Mapping[str, np.ndarray]) -> "Swept":
        """`axes` itself when it is a Swept, else a Swept of axes alone (no [points])."""
        return axes if isinstance(axes, Swept) else cls(axes)

    def product(self, names: Iterable[str],
                fixed: Mapping[str, Any]) -> list[np.ndarray]:
        """The values of `names` broadcast over the grid the run solves: one dimension per
        axis among them and one shared dimension for the [points] among them, in that
        order; a name that does not vary takes ``fixed[name]`` (a scalar). The arrays
        broadcast together; corner-style checks may reduce them over all dimensions."""
        names = list(names)
        plain = [n for n in names if n in self and n not in self.zipped]
        has_points = any(n in self.zipped for n in names)
        ndim = len(plain) + has_points
        out = []
        for name in names:
            if name not in self:
                out.append(np.asarray(fixed[name], dtype=float).reshape((1,) * ndim))
                continue
            where = len(plain) if name in self.zipped else plain.index(name)
            shape = [1] * ndim
            shape[where] = len(self[name])
            out.append(np.asarray(self[name], dtype=float).reshape(shape))
        return out

    def corners(self, names: Iterable[str] | None = None) -> dict[str, np.ndarray]:
        """Rows that cover the extremes of any product of powers of the varying values: each
        axis at its first and last value, times every [points] entry; name -> column."""
        names = list(self if names is None else names)
        plain = [n for n in names if n not in self.zipped]
        zipped = [n for n in names if n in self.zipped]
        ends = [np.array([self[n][0], self[n][-1]], dtype=float) for n in plain]
        count = len(self[zipped[0]]) if zipped else 1
        grids = np.meshgrid(*ends, np.arange(count), indexing="ij") if (ends or zipped) else []
        if not grids:
            return {}
        columns = {n: g.ravel() for n, g in zip(plain, grids)}
        index = grids[-1].ravel().astype(np.intp)
        columns.update({n: np.asarray(self[n], dtype=float)[index] for n in zipped})
        return columns
