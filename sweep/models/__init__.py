"""The physics models, one per scene `model.kind`, and the registry that finds them.

A model is a module with:
    KIND      its model.kind
    run(scene, options) -> xarray.Dataset   (options: sweep.runner.RunOptions)
              every grid point of the scene solved (through sweep/runner.py) and assembled
and beside it whatever its physics needs: coefficients from cable data, the kernel settings,
the output variables with units and long names. Today's models:
    transverse    sweep/models/transverse.py (coefficients: sweep/models/modal.py)
    longitudinal  sweep/models/longitudinal.py
The scene rules of each kind (which keys and axes its scenes take, their defaults, the checks
of the resolved scene) are in sweep/models/rules.py, found with `rules_for`.
docs/architecture.md ("How to add a new physics") says how to add one.

The modal coefficient functions (`oscillator`, `consistent`, `paper`, ...) are re-exported
here: `from sweep import models; models.oscillator(...)`.
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import TYPE_CHECKING

from .modal import (MAX_SLOPE, PAPER_COS_CUBIC, PAPER_COS_LINEAR, PAPER_LOAD,  # noqa: F401
                    PAPER_OMEGA0, base_excitation, base_response, consistent, escape_barrier,
                    oscillator, paper, state_scale, PARTICIPATION)

if TYPE_CHECKING:
    from .rules import Rules

# model.kind -> the module of its model (imported on first use: each pulls in its own layers)
MODELS: dict[str, str] = {"transverse": "sweep.models.transverse",
                          "longitudinal": "sweep.models.longitudinal"}


def model_for(kind: str) -> ModuleType:
    """The model module of scene kind `kind` (a key of MODELS; the scene layer has already
    refused any other)."""
    module = importlib.import_module(MODELS[kind])
    assert module.KIND == kind
    return module


def rules_for(kind: str) -> Rules:
    """The scene rules of kind `kind` (sweep/models/rules.py), for the scene pipeline. Imported
    on first use, so this registry imports no part of sweep.scene; no model is imported."""
    from .rules import RULES
    return RULES[kind]
