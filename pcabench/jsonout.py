"""Strict JSON for every ``--json``: what json.loads with a strict parser reads (NaN and infinities as null)."""

from __future__ import annotations

import json
import math
import os
import sys

import numpy as np

_json_fd = {"fd": None}  # the real stdout, kept for the one JSON object once stdout is the process's stderr


def stdout_to_stderr() -> None:
    """For a ``--json`` command, from here to the process's end: whatever anything prints on stdout (Python's
    sys.stdout and file descriptor 1, so a plug-in at import, compiled code, an atexit handler) goes to
    stderr; :func:`emit` writes to the real stdout, which so holds exactly one JSON object."""
    if _json_fd["fd"] is not None:
        return
    sys.stdout.flush()
    _json_fd["fd"] = os.dup(1)
    os.dup2(2, 1)


def emit(text: str) -> None:
    """``text`` and a newline on the real stdout (after :func:`stdout_to_stderr`), else printed."""
    fd = _json_fd["fd"]
    if fd is None:
        print(text, flush=True)
        return
    data = (text + "\n").encode()
    while data:
        data = data[os.write(fd, data) :]


def plain(value):
    """``value`` with numpy scalars and arrays as Python ones, and every non-finite float as None."""
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [plain(v) for v in value]
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if value is None or isinstance(value, str):
        return value
    return str(value)


def significant(value, digits: int = 3):
    """``value`` (a float, or a dict or list of them) to ``digits`` significant digits, as the text prints it
    (``f"{x:.3g}"``); other values as they are."""
    if isinstance(value, dict):
        return {k: significant(v, digits) for k, v in value.items()}
    if isinstance(value, list):
        return [significant(v, digits) for v in value]
    if isinstance(value, (float, np.floating)) and math.isfinite(value):
        return float(f"{value:.{digits}g}")
    return value


def dumps(value, **kw) -> str:
    """``value`` as strict JSON (``allow_nan=False`` holds: NaN and +-inf are null)."""
    return json.dumps(plain(value), allow_nan=False, **kw)
