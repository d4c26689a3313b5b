"""Reports: paper-style tables and figures from the results store, per hardware profile.

``pcabench.reports.build.write_reports(results_dir, reports_dir)`` writes, for every profile with stored runs,
``reports/<profile>/report.md`` with each study's sections and their PNG figures (the paper's published numbers,
hardware_profiles/paper-system-1.json, beside ours), ``reports/cards.md`` and ``reports/README.md``, the index.

This face imports nothing: a study's modules import the report's toolkits (``pcabench.reports.figures``, ``md``,
``paper``) and the build imports every study's sections, so a face that imported the build would close a circle
(a study -> this package -> build -> the study).
"""
