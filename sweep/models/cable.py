"""The cable's data, one of two sets, and the one place the model's products come from it.

A scene describes its cable either by material (cable.youngs_modulus E, density rho, area A,
inertia I: the model uses EI, rho A, EA and E / rho) or as a harness engineer's data sheet has
it: cable.linear_mass m = rho A (kg/m), cable.bending_rigidity EI (N m^2), cable.axial_rigidity
EA (N) and, for the strain at clamps that hold rotation, cable.diameter d (m). EI may instead
come from a measured first natural frequency (cable.f1_measured, Hz, on a span of cable.f1_span,
m, between the scene's clamps; docs/model.md sec. 10) and m, EA, d and the EI bounds from the
wire table (cable.wire, cable.wires, cable.bending; sweep/wires.py).

`resolve` turns a data-sheet set into equivalent material parameters, so that every consumer
(sweep.models.modal, the clamp outputs, the design's natural frequency, the checks of
sweep.models.rules) gets its products unchanged: A = pi d^2 / 4 (1 m^2 without a diameter),
E = EA / A, rho = m / A, I = EI / E; then E I = EI, rho A = m, E A = EA and E / rho = EA / m,
each to round-off. `check` holds the rules of the two sets, `defaults` clears the material
defaults of a data-sheet scene.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from typing import Any

import numpy as np

from .. import schema, wires
from ..scene.messages import _fail

MATERIAL_KEYS: tuple[str, ...] = ("cable.youngs_modulus", "cable.density", "cable.area",
                                  "cable.inertia")
SHEET_KEYS: tuple[str, ...] = ("cable.linear_mass", "cable.bending_rigidity",
                               "cable.axial_rigidity", "cable.f1_measured", "cable.wire")
"""Keys any one of which makes the scene's cable a data-sheet one."""
WIRE_KEYS: tuple[str, ...] = ("cable.wires", "cable.bending")
_SHEET_TWIN = {"cable.youngs_modulus": "bending_rigidity = E I and axial_rigidity = E A",
               "cable.inertia": "bending_rigidity = E I", "cable.density": "linear_mass = rho A",
               "cable.area": "linear_mass = rho A and axial_rigidity = E A"}
"""What a material key is in the data-sheet set (for the message refusing both)."""
REFERENCE_AREA = 1.0
"""A (m^2) of the equivalent material of a data-sheet cable without a diameter: any area gives
the same products; this one is never shown."""


def _present(dotted: str, given: Mapping[str, Any], swept: Mapping[str, Any]) -> bool:
    axis = schema.BY_DOTTED[dotted].axis
    return dotted in given or (axis is not None and axis in swept)


def _where(dotted: str, swept: Mapping[str, Any]) -> str:
    axis = schema.BY_DOTTED[dotted].axis
    if axis is not None and axis in getattr(swept, "zipped", ()):
        return f"[points] '{axis}'"
    return f"axis '{axis}'" if axis is not None and axis in swept else f"scene key '{dotted}'"


def is_sheet(values: Mapping[str, Any], swept: Mapping[str, Any] = ()) -> bool:
    """Whether a scene (given keys or resolved values, and what it sweeps) describes its cable
    by the data-sheet keys."""
    return any(values.get(d) is not None or (schema.BY_DOTTED[d].axis or "") in swept
               for d in SHEET_KEYS)


def check(given: dict[str, Any], swept: Mapping[str, Any]) -> None:
    """Refuse, in one line each: both sets; a data-sheet set without its mass, EI or EA; f1
    without its span (and the other way round); the wire keys without a wire, or with what
    the table gives; two sources of EI; a data-sheet cable where the model needs E and rho
    apart (longitudinal) or the paper's Eq.32 (its cable is baked in)."""
    sheet = [d for d in SHEET_KEYS if _present(d, given, swept)]
    for dotted in ("cable.f1_span", *WIRE_KEYS):
        partner = "cable.f1_measured" if dotted == "cable.f1_span" else "cable.wire"
        if dotted in given and not _present(partner, given, swept):
            # not only without a data sheet: beside a sheet's mass and EI they were ignored
            # (wires = 7 ran one wire's cable)
            _fail(f"scene key '{dotted}'", f"is for a cable given by {partner}",
                  f"add {partner}, or remove {dotted}")
    if not sheet:
        return
    material = [d for d in MATERIAL_KEYS if _present(d, given, swept)]
    if material:
        _fail(f"{_where(material[0], swept)} and {_where(sheet[0], swept)}",
              "two descriptions of one cable: material (youngs_modulus, density, area, "
              "inertia) and data sheet (linear_mass, bending_rigidity, axial_rigidity, "
              "f1_measured, wire); give one set, not both",
              f"remove {material[0]}, or give it as the data sheet's "
              f"{_SHEET_TWIN[material[0]]}; or remove the data-sheet keys")
    if given.get("model.kind", "transverse") == "longitudinal":
        _fail(_where(sheet[0], swept), "the longitudinal wave model and its time-step checks "
              "take the material keys (wave speed sqrt(E / rho), E A)",
              "give cable.youngs_modulus, density and area (E = EA / A, rho = m / A)")
    if given.get("model.coefficients") == "paper":
        _fail(_where(sheet[0], swept), "model.coefficients = 'paper' bakes the Table 1 cable "
              "into Eq.32 and would ignore it", "use model.coefficients = 'consistent'")
    _check_f1(given, swept)
    if "cable.wire" in given:
        _check_wire(given, swept)
        return
    for dotted, what in (("cable.linear_mass", "'33.3 g/m'"),
                         ("cable.axial_rigidity", "'4.2e4 N' (E of the conductor x its area)")):
        if not _present(dotted, given, swept):
            _fail(f"scene key '{dotted}'", "missing: a cable given by its data sheet needs its "
                  "mass per length, bending stiffness and axial stiffness",
                  f"give {dotted} = {what}")
    _check_one_bending(given, swept)
    rotation = given.get("clamps.rotation", "pinned")
    if rotation != "pinned" and not _present("cable.diameter", given, swept):
        _fail("scene key 'cable.diameter'", f"missing: the bending strain at '{rotation}' "
              "clamps is (d / 2) x curvature, and a data-sheet cable has no area to take d from",
              "give cable.diameter = '1.27 mm' (the outer diameter)")


def _check_one_bending(given: dict[str, Any], swept: Mapping[str, Any]) -> None:
    """One source of EI: bending_rigidity or f1_measured, not both, not neither."""
    sources = [d for d in ("cable.bending_rigidity", "cable.f1_measured")
               if _present(d, given, swept)]
    if len(sources) == 2:
        _fail(f"{_where(sources[0], swept)} and scene key 'cable.f1_measured'", "two "
              "bending stiffnesses: EI given, and EI from a measured f1", "remove one of them")
    if not sources and "cable.wire" not in given:
        _fail("scene key 'cable.bending_rigidity'", "missing: a cable given by its data sheet "
              "needs its bending stiffness EI", "give cable.bending_rigidity = '2e-3 N m^2', "
              "or cable.f1_measured and cable.f1_span from a measured span")


def _check_f1(given: dict[str, Any], swept: Mapping[str, Any]) -> None:
    """f1_measured and f1_span together; with elastic clamps, EI depends on K = k_t l / EI
    and is solved once: neither the mass nor the clamps' stiffness may vary then."""
    has_f1, has_span = "cable.f1_measured" in given, "cable.f1_span" in given
    if has_f1 != has_span:
        missing = "cable.f1_span" if has_f1 else "cable.f1_measured"
        _fail(f"scene key '{missing}'", "missing: EI from a measured f1 needs the frequency "
              "and the length of the span it was measured on",
              "give cable.f1_measured = '12.5 Hz' and cable.f1_span = '0.3 m'")
    if has_f1 and given.get("clamps.rotation") == "elastic":
        for dotted in ("cable.linear_mass", "clamps.rotational_stiffness"):
            axis = schema.BY_DOTTED[dotted].axis
            if axis in swept:
                _fail(f"{_where(dotted, swept)} with cable.f1_measured", "with elastic clamps "
                      "the measured f1 gives EI through K = k_t l / EI, solved once for the "
                      "scene", f"give {dotted} as a single value")


def _check_wire(given: dict[str, Any], swept: Mapping[str, Any]) -> None:
    """A wire of the table gives m, EA and d; EI is a bound (cable.bending) or measured."""
    for dotted in ("cable.linear_mass", "cable.axial_rigidity", "cable.diameter"):
        if _present(dotted, given, swept):
            _fail(f"{_where(dotted, swept)} and scene key 'cable.wire'", "the wire table gives "
                  "the bundle's mass, axial stiffness and diameter", f"remove {dotted}, or "
                  "cable.wire (and give the data-sheet keys)")
    measured = [d for d in ("cable.bending_rigidity", "cable.f1_measured")
                if _present(d, given, swept)]
    _check_one_bending(given, swept)
    if measured and "cable.bending" in given:
        _fail(f"scene keys 'cable.bending' and '{measured[0]}'", "a bound of the bundle's EI "
              "and a given one", "remove cable.bending: a measured EI beats both bounds")
    if not measured and "cable.bending" not in given:
        _fail("scene key 'cable.bending'", "missing: a bundle's EI lies between two bounds, "
              "strands slipping (lower) and the solid section (upper)",
              "give cable.bending = 'lower' or 'upper', or a measured cable.f1_measured")


def defaults(values: dict[str, Any], mentioned: set[str]) -> None:
    """A data-sheet scene (`mentioned`: the dotted keys given or swept) has no material: its
    material keys (which have defaults) are None, so that the resolved scene shows the data
    sheet alone and loads back."""
    if any(d in mentioned for d in SHEET_KEYS):
        for dotted in MATERIAL_KEYS:
            values[dotted] = None


def resolve(p: dict[str, Any], values: Mapping[str, Any]) -> dict[str, Any]:
    """`p` (parameters by axis name: numbers, arrays or DataArrays) with the equivalent
    material of a data-sheet cable written in (youngs_modulus, density, area, inertia and the
    diameter; see the module's docstring); `p` itself for a material one. `values`: the
    resolved scene's values (the wire, the f1 measurement, the clamps)."""
    wire = values.get("cable.wire")
    if p.get("linear_mass") is None and wire is None:
        return p
    out = dict(p)
    mass, axial, bending, diameter = (p.get("linear_mass"), p.get("axial_rigidity"),
                                      p.get("bending_rigidity"), p.get("diameter"))
    if wire is not None:
        bundle = wires.bundle(wire, values.get("cable.wires") or 1)
        mass, axial, diameter = bundle.linear_mass, bundle.axial_rigidity, bundle.diameter
        if values.get("cable.bending") is not None:
            bending = bundle.bending(values["cable.bending"])
    if values.get("cable.f1_measured") is not None:
        bending = bending_from_f1(values["cable.f1_measured"], values["cable.f1_span"], mass,
                                  values.get("clamps.rotation") or "pinned",
                                  p.get("clamp_rotational_stiffness"))
    area = REFERENCE_AREA if diameter is None else np.pi * diameter * diameter / 4.0
    with np.errstate(all="ignore"):
        modulus = axial / area
        material = dict(youngs_modulus=modulus, density=mass / area, inertia=bending / modulus)
    for name, value in material.items():
        v = np.asarray(value, float)
        if not (np.all(np.isfinite(v)) and np.all(v > 0.0)):
            _fail("scene key 'cable.axial_rigidity', 'cable.bending_rigidity' or "
                  "'cable.linear_mass'", f"the cable they describe has no finite positive "
                  f"{name.replace('_', ' ')} (a value out of double precision's range)",
                  "give the data sheet's values in SI, e.g. axial_rigidity = \"660 kN\"")
    out.update(material, area=area, diameter=diameter)
    return out


CLAMPED_BETA = 4.730040744862704
"""beta_1 l of a span clamped at both ends (cosh b cos b = 1; sweep.models.basis gives the
same root)."""


def bending_from_f1(f1: float, span: float, mass: Any, rotation: str,
                    rotational_stiffness: Any = None) -> Any:
    """EI (N m^2) of a cable of `mass` per length (kg/m) whose span of `span` (m) between
    clamps of `rotation` has first natural frequency `f1` (Hz): from f1 = (beta_1 l)^2 /
    (2 pi l^2) sqrt(EI / m) (docs/model.md sec. 10.1, 10.3), beta_1 l = pi pinned, 4.7300
    clamped; elastic ends (rotational stiffness k_t, N m/rad) have beta_1 l of K = k_t l / EI,
    so EI is solved for by bisection (a scalar mass and k_t: `check` refuses axes there)."""
    scale = (2.0 * math.pi * f1 * span * span) ** 2        # EI = m scale / beta^4
    if rotation == "pinned":
        return mass * scale / math.pi ** 4
    if rotation == "clamped":
        return mass * scale / CLAMPED_BETA ** 4
    return _elastic_bending(float(f1), float(span), float(mass), float(rotational_stiffness))


@lru_cache(maxsize=64)
def _elastic_bending(f1: float, span: float, mass: float, stiffness: float) -> float:
    """EI of elastic ends: the root of beta(k_t l / EI)^4 EI = m (2 pi f1 l^2)^2, bracketed by
    the clamped (smallest EI) and the pinned (largest) spans, bisected in log EI."""
    from .basis import _eigenvalues
    target = mass * (2.0 * math.pi * f1 * span * span) ** 2
    low, high = target / CLAMPED_BETA ** 4, target / math.pi ** 4
    if stiffness == 0.0:
        return high
    for _ in range(60):
        middle = math.sqrt(low * high)
        beta = float(_eigenvalues(1, stiffness * span / middle)[0])
        if beta ** 4 * middle < target:
            low = middle
        else:
            high = middle
        if high / low - 1.0 < 1e-13:
            break
    return math.sqrt(low * high)


def bending_note(values: Mapping[str, Any]) -> str | None:
    """Where a data-sheet scene's EI came from, for the dataset's attributes; None for a
    material cable or a given EI."""
    wire = values.get("cable.wire")
    bundle = f"{values.get('cable.wires') or 1} x {wire}" if wire else None
    if values.get("cable.f1_measured") is not None:
        rotation = values.get("clamps.rotation") or "pinned"
        mass = (wires.bundle(wire, values.get("cable.wires") or 1).linear_mass if wire
                else values.get("cable.linear_mass"))
        stiffness = values.get("clamps.rotational_stiffness")
        ei = ""
        if mass is not None and not (rotation == "elastic" and stiffness is None):
            value = bending_from_f1(values["cable.f1_measured"], values["cable.f1_span"], mass,
                                    rotation, stiffness)
            ei = f" = {value:.6g} N m2"
        return (f"measured: EI{ei} from f1 = {values['cable.f1_measured']:g} Hz on a "
                f"{values['cable.f1_span']:g} m span with {rotation} ends (docs/model.md sec. 10)"
                + (f"; mass and EA of the bundle {bundle} (sweep/wires.py)" if bundle else ""))
    if bundle and values.get("cable.bending") is not None:
        return (f"bound: the {values['cable.bending']} bound of the EI of the bundle {bundle} "
                "(sweep/wires.py; a measured f1 beats both bounds)")
    if bundle:
        return (f"given: cable.bending_rigidity, with the mass and EA of the bundle {bundle} "
                "(sweep/wires.py)")
    return None
