"""What every model's result Dataset shares: CF conventions, global attributes (provenance and
the resolved scene), state flag attributes from the one state table, counters, history time
and derived quantities on their own axes. Each model (sweep/models/) assembles its variables
with these."""

from __future__ import annotations

import datetime as _dt
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import xarray as xr

from sweep.kernels import states as km

from .scene import Scene
from .version import package_version  # noqa: F401  (re-exported: the version written into results)


CONVENTIONS = "CF-1.11"

_INT32 = np.iinfo(np.int32)
TIME_DIM = "elapsed_time"       # the dimension (and coordinate) of stored histories


def counter(values: Any) -> Any:
    """A count as int32 (what every netCDF reader takes) when every value fits, else int64."""
    values = np.asarray(values)
    if values.size == 0 or (values.min() >= _INT32.min and values.max() <= _INT32.max):
        return values.astype(np.int32)
    return values.astype(np.int64)


def elapsed_time(values: np.ndarray) -> xr.DataArray:
    """The coordinate TIME_DIM of stored histories: times since the start of the run (s).

    Not CF's `time`: a CF time coordinate (standard_name time, and the name `time` to the IOOS
    compliance checker) needs units "s since <date>", and these are durations from the
    simulation's t = 0, which has no date. The times (k dt) are rounded to 15 significant
    digits of the largest, so that `.sel(elapsed_time=0.35)` finds the sample 7 x 0.05 s
    (0.35000000000000003 as computed), as the axes' values are found as typed.
    """
    values = np.asarray(values, dtype=np.float64)
    top = float(np.max(np.abs(values))) if values.size else 0.0
    if math.isfinite(top) and top > 0.0:
        digits = 15 - math.ceil(math.log10(top))
        rounded = np.round(values, digits) if digits <= 22 else values
        if values.size < 2 or np.all(np.diff(rounded) > 0.0):
            values = rounded
    return xr.DataArray(values, dims=TIME_DIM, attrs={
        "units": "s", "long_name": "simulated time since t = 0 (the initial state)"})


def derived(values: Any, coords: dict[str, xr.DataArray]) -> xr.DataArray:
    """A derived quantity as a DataArray over exactly the axes it depends on."""
    if isinstance(values, xr.DataArray):
        dims = [d for d in coords if d in values.dims]
        return values.transpose(*dims).drop_vars(list(values.coords), errors="ignore")
    return xr.DataArray(float(values))


@dataclass(frozen=True)
class Provenance:
    """What a result says about where it came from, resolved once from its scene
    (`provenance`): its name, description and source, the resolved scene text, the model kind
    and coefficient set; `bending_source`: where a data-sheet cable's EI came from (a measured
    f1, a bundle's bound; sweep.models.cable.bending_note), None otherwise."""
    title: str
    description: str
    source: str
    scene_text: str
    kind: str
    coefficients: str
    bending_source: str | None = None


def provenance(scene: Scene) -> Provenance:
    """The Provenance of a result of `scene`."""
    from .models.cable import bending_note
    return Provenance(scene.name, scene.description, scene.source, scene.to_toml(),
                      scene.get("model.kind"), scene.get("model.coefficients"),
                      bending_note(scene.values))


def global_attrs(origin: Provenance, shape: tuple[int, ...], elapsed: float,
                 method: str) -> dict[str, Any]:
    """The dataset's global attributes: CF conventions, provenance and the resolved scene."""
    version = package_version()
    now = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    return {
        "title": origin.title,
        "description": origin.description,
        "Conventions": CONVENTIONS,
        "source": f"cable-sweep {version}: {method}",
        "history": f"{now} created by cable-sweep {version} from scene '{origin.source}'",
        "cable_sweep_version": version,
        "scene": origin.scene_text,
        "model_kind": origin.kind,
        "coefficients": origin.coefficients,
        "run_seconds": float(elapsed),
        "n_points": counter(np.prod(shape, dtype=np.int64))[()],
        **({"bending_rigidity_source": origin.bending_source} if origin.bending_source else {}),
    }


def flag_attrs(flags: tuple[int, ...]) -> dict[str, Any]:
    """CF flag attributes of an int8 `state` variable that can hold the given flags.

    Every kind draws its flags from the one table of kernels/metrics.py (STATE_MEANINGS), so
    the same integer has the same meaning in every dataset.
    """
    return {
        "long_name": "state of the point",
        "units": "1",
        "flag_values": np.array(flags, dtype=np.int8),
        "flag_meanings": " ".join(km.STATE_MEANINGS[f] for f in flags),
    }


LABEL_LENGTH = 100
"""The longest `long_name` a result keeps (xarray's plots make their axis labels of it); a
longer one is cut to its longest leading clause within this length, the whole text kept as
`comment` (`short_long_names`)."""

_CLAUSE_ENDS = (": ", " (", "; ", ", ")


def short_long_names(ds: xr.Dataset) -> xr.Dataset:
    """`ds` with every variable's and coordinate's long_name of more than LABEL_LENGTH
    characters cut to its longest leading clause within LABEL_LENGTH (up to a ': ', ' (',
    '; ' or ', ' outside parentheses, not leaving a formula or a colon open), or to its
    words within it and '...'; the whole explanation moved to `comment` (before any comment
    it had). In place; returns `ds`."""
    for name in list(ds.variables):
        attrs = ds[name].attrs
        text = attrs.get("long_name")
        if not isinstance(text, str) or len(text) <= LABEL_LENGTH:
            continue
        ends = [i for mark in _CLAUSE_ENDS for i in _positions(text, mark)
                if 20 <= i <= LABEL_LENGTH and _closes_a_clause(text[:i])]
        if ends:
            short = text[:max(ends)]
        else:
            short = text[:LABEL_LENGTH - 3].rsplit(" ", 1)[0] + "..."
        comment = attrs.get("comment")
        attrs["comment"] = text + (f". {comment}" if comment else "")
        attrs["long_name"] = short
    return ds


def _closes_a_clause(head: str) -> bool:
    """Whether `head` may stand as a label: its parentheses closed, and not ending in the
    middle of a formula or on a colon."""
    return (head.count("(") == head.count(")") and head.count("[") == head.count("]")
            and not head.rstrip().endswith(tuple(":=+-*/,(")))


def _positions(text: str, mark: str) -> list[int]:
    """Where `mark` starts in `text`, every place."""
    found, i = [], text.find(mark)
    while i >= 0:
        found.append(i)
        i = text.find(mark, i + 1)
    return found
