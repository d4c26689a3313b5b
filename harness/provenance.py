"""Provenance of a result: git commit, package versions, a short machine id."""
from __future__ import annotations

import functools
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

PACKAGES = ("pcabench", "numpy", "numba", "numba-cuda", "cupy-cuda12x", "cupy-cuda13x", "pandas",
            "matplotlib")


@functools.lru_cache(maxsize=None)
def git_commit() -> str:
    """The commit of the source tree (with '+dirty' if it has local changes), or 'unknown'."""
    here = Path(__file__).resolve().parent
    try:
        sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=here, capture_output=True,
                             text=True, timeout=10).stdout.strip()
        if not sha:
            return os.environ.get("PCABENCH_COMMIT", "unknown")
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=here,
                               capture_output=True, text=True, timeout=10).stdout.strip()
        return sha + ("+dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return os.environ.get("PCABENCH_COMMIT", "unknown")


@functools.lru_cache(maxsize=None)
def package_versions() -> dict:
    out = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            pass
    return out
