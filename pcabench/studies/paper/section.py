"""The paper study's report sections, one module each, in report order (the registry finds them here)."""

from __future__ import annotations

from pcabench.studies.paper.failed import SECTION as FAILED
from pcabench.studies.paper.fig8 import SECTION as FIG8
from pcabench.studies.paper.fig9 import SECTION as FIG9
from pcabench.studies.paper.fig10 import SECTION as FIG10
from pcabench.studies.paper.float32 import SECTION as FLOAT32
from pcabench.studies.paper.simplifications import SECTION as SIMPLIFICATIONS
from pcabench.studies.paper.speed import SECTION as SPEED
from pcabench.studies.paper.table4 import SECTION as TABLE4
from pcabench.studies.paper.table5 import SECTION as TABLE5
from pcabench.studies.paper.table6 import SECTION as TABLE6

__all__ = ["TABLE4", "TABLE5", "TABLE6", "SPEED", "FIG8", "FIG9", "FIG10", "SIMPLIFICATIONS", "FLOAT32", "FAILED"]
