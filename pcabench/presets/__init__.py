"""Study matrices: the presets (one file each in this package, found by the registry :data:`PRESETS`) and the
matrix built from command-line options (:func:`matrix`)."""

from __future__ import annotations

from pcabench.presets.base import (
    DEFAULT_PRESET,
    ENTRY_POINT_GROUP,
    MATRIX_BUDGET,
    PRESETS,
    Preset,
    budget,
    flags,
    matrix,
    named_by,
    preset,
    size_text,
    spec_of,
)
from pcabench.presets.front import (
    FRONT,
    FRONT_2D,
    FRONT_T_END,
    PAPER_SCENE_DX,
    fast_methods,
    front,
    front_axes,
    model_needs,
)
from pcabench.presets.stability import (
    INACCURATE_ABOVE,
    LONG_MODELS,
    LONG_SCENES,
    LONG_T_END,
    STABILITY_CFL,
    STABILITY_DX,
)
from pcabench.presets.walls import (
    FREE_COUNTERPART,
    WALL_COST_DX,
    WALL_COST_ROUNDS,
    WALL_COST_TAG,
    WALL_STRIP,
    WALLS,
    cost_round,
)

__all__ = [
    "DEFAULT_PRESET",
    "ENTRY_POINT_GROUP",
    "MATRIX_BUDGET",
    "PRESETS",
    "Preset",
    "budget",
    "flags",
    "matrix",
    "named_by",
    "preset",
    "size_text",
    "spec_of",
    "FRONT",
    "FRONT_2D",
    "FRONT_T_END",
    "PAPER_SCENE_DX",
    "fast_methods",
    "front",
    "front_axes",
    "model_needs",
    "INACCURATE_ABOVE",
    "LONG_MODELS",
    "LONG_SCENES",
    "LONG_T_END",
    "STABILITY_CFL",
    "STABILITY_DX",
    "FREE_COUNTERPART",
    "WALL_COST_DX",
    "WALL_COST_ROUNDS",
    "WALL_COST_TAG",
    "WALL_STRIP",
    "WALLS",
    "cost_round",
]
