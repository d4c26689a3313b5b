"""The studies, one folder each: what a study runs, reports and checks, together.

A study is one sub-package of this package (a new study is one new folder here)::

    pcabench/studies/<study>/
        __init__.py   what it measures, in a sentence
        plan.py       its Preset(s): the runs, as ``pcabench study --<flag>`` makes them (registry PRESETS)
        section.py    its report Section(s) (registry pcabench.reports.section.SECTIONS), its other
                      modules the rows, text and figures those sections draw
        gpu.py        the scenes it checks on a GPU: its Stage of ``pcabench gpu-check`` (registry
                      pcabench.gpu.stage.STAGES), with a card's cases and the rehearsal's
        *.json        what it measured once and reads as data, each value with the command that measured it

The registries find ``plan.py``, ``section.py`` and ``gpu.py`` in every folder; a plug-in adds a preset or a section
through the entry-point groups ``pcabench.presets`` and ``pcabench.sections``. What a preset is, the preset
registry and the matrix of command-line options are in :mod:`pcabench.studies.preset`, re-exported here.
The paper's own tables and figures are the study ``paper``.
"""

from __future__ import annotations

from pcabench.studies.preset import (
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
]
