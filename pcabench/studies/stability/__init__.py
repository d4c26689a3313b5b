"""Where methods fail (``pcabench study --stability short|long``): the stability map and each model's
long-run limit (long_runs.py)."""
