"""Reports: paper-style tables and figures from the results store, per hardware profile.

``write_reports(results_dir, reports_dir)`` writes, for every profile with
stored runs, ``reports/<profile>/report.md`` and its PNG figures, with the
paper's published numbers (hardware_profiles/paper-system-1.json) beside ours,
and ``reports/README.md`` as the index.
"""

from __future__ import annotations

from pcabench.reports.build import summary, write_reports

__all__ = ["summary", "write_reports"]
