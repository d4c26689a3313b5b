"""Provenance of a result: git commit, package versions, a short machine id."""

from __future__ import annotations

import functools
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

PACKAGES = ("pcabench", "numpy", "numba", "numba-cuda", "cupy-cuda12x", "cupy-cuda13x", "pandas", "matplotlib")


# The paths whose changes change a run's numbers (git pathspecs from the repository root).
CODE = (":(top)solvers", ":(top)pcabench", ":(top)pyproject.toml")


def checked_env(variable: str, field: str) -> str:
    """The environment variable ``variable``, checked like the record field ``field`` it becomes
    (pcabench/store/schema.py); StoreError naming the variable if it would not read back."""
    from pcabench.errors import StoreError
    from pcabench.store import schema

    value = os.environ[variable]
    why = schema.check_value(field, schema.FIELDS[field], value)
    if why:
        raise StoreError(f"{variable}={value!r:.120}: {why}")
    return value


@functools.lru_cache(maxsize=None)
def git_commit() -> str:
    """The commit of the source tree (with '+dirty' if its code has local changes), or 'unknown'.

    Only the code that makes a run counts (``CODE``): results, reports, stored
    profiles and documents are not, so a sweep that appends to a tracked
    results file, or an edited README, does not make later runs dirty.
    """
    if os.environ.get("PCABENCH_COMMIT"):  # a copy without git history (e.g. a GPU machine)
        return checked_env("PCABENCH_COMMIT", "commit")
    here = Path(__file__).resolve().parent
    try:
        proc = subprocess.run(
            ["git", "rev-parse", "--verify", "HEAD"], cwd=here, capture_output=True, text=True, timeout=10
        )
        sha = proc.stdout.strip()
        if proc.returncode != 0 or len(sha) != 40:
            return "unknown"
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no", "--", *CODE],
            cwd=here,
            capture_output=True,
            text=True,
            timeout=10,
        ).stdout.strip()
        return sha + ("+dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


@functools.lru_cache(maxsize=None)
def host_id() -> str:
    """A short hash of this computer's network name: tells two machines of one hardware profile apart
    (a sweep resumes only the runs this host made) without publishing the name."""
    import hashlib
    import platform

    return hashlib.sha1(platform.node().encode()).hexdigest()[:10]


@functools.lru_cache(maxsize=None)
def package_versions() -> dict:
    out = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            pass
    return out
