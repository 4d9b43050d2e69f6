"""Longitudinal coefficients: cable data -> the central-difference kernel's span parameters and
the closed-form references (docs/model.md sec. 4). Element-wise on floats, arrays or
DataArrays, like sweep/models/modal.py; no other sweep module is imported, so the scene
layer can check coefficients without loading a runner.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def wave_parameters(p: dict[str, Any], t_end: float | None, transits: float | None) -> dict:
    """Per-span kernel parameters and closed-form references (float, array or DataArray).

    p: youngs_modulus (Pa), density (kg/m^3), area (m^2), length (m), load_amplitude (N),
    divergence_bound (m or None). The end time is t_end (s) or `transits` x l/a.
    """
    a = np.sqrt(p["youngs_modulus"] / p["density"])
    ea = p["youngs_modulus"] * p["area"]
    transit = p["length"] / a
    return {
        "length": p["length"],
        "wave_speed": a,
        "axial_stiffness": ea,
        "load": p["load_amplitude"],
        "t_end": transits * transit if transits is not None else t_end,
        "bound": p["divergence_bound"] if p.get("divergence_bound") is not None
        else p["length"],
        "transit_time": transit,
        "static_end_displacement": p["load_amplitude"] * p["length"] / ea,
        "impedance": p["density"] * p["area"] * a,
    }
