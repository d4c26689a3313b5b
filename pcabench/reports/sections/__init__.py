"""The report's sections, one module each (see base.py), found by the section registry :data:`SECTIONS`."""

from __future__ import annotations

from pcabench.reports.sections.base import ENTRY_POINT_GROUP, SECTIONS, Context, Section, in_order
from pcabench.reports.sections.table6 import table6_md

__all__ = ["ENTRY_POINT_GROUP", "SECTIONS", "Context", "Section", "in_order", "table6_md"]
