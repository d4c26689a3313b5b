"""Provenance of a result: the code that made it (:func:`code_key`, a content hash) beside its git commit,
package versions, a short machine id."""

from __future__ import annotations

import functools
import hashlib
import inspect
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


RUN_PACKAGES = ("solvers", "pcabench")  # the first-party code a run is made of, file by file
NOT_RUN_CODE = ("pcabench/reports",)  # under those: what only reads the store (a report's edit reruns nothing)


def run_registries() -> tuple:
    """The registries whose entries make a run's numbers (solvers, kernels, scenes, absorbers, boundary methods,
    corrections): a plug-in of any of them is part of :func:`code_key`. Presets only name runs and report
    sections only read them."""
    from solvers.boundaries.absorbers.registry import ABSORBERS
    from solvers.boundaries.bodies.registry import BOUNDARY_METHODS
    from solvers.corrections.registry import CORRECTIONS
    from solvers.kernels.registry import KERNELS
    from solvers.registry import SOLVERS
    from solvers.scenes.registry import SCENES

    return (SOLVERS, KERNELS, SCENES, ABSORBERS, BOUNDARY_METHODS, CORRECTIONS)


def _package_root(name: str) -> Path:
    import importlib

    return Path(importlib.import_module(name).__file__).resolve().parent


def run_sources() -> dict[str, Path | None]:
    """{name: file} of every source that makes a run: each ``*.py`` of :data:`RUN_PACKAGES` (but
    :data:`NOT_RUN_CODE`), named by its path from the packages' folder; and each plug-in of
    :func:`run_registries` (an entry whose class, or a class it inherits from, lives outside them): every file
    its code can come from (:func:`solvers.sources.code_sources`: its distribution's, its package's, the modules
    it imports that are neither the interpreter's nor the environment's), named by the content alone, so the
    same plug-in installed at two places is one code. A plug-in class with no source file: None (its code is
    unknown, so no two processes share its key and nothing resumes on it)."""
    from solvers.sources import code_sources

    out, roots = {}, [_package_root(p) for p in RUN_PACKAGES]
    for root in roots:
        for path in sorted(root.rglob("*.py")):
            name = path.relative_to(root.parent).as_posix()
            if "__pycache__" not in path.parts and not name.startswith(NOT_RUN_CODE):
                out[name] = path
    for registry in run_registries():
        for entry in registry.all().values():
            cls = entry if inspect.isclass(entry) else type(entry)
            try:
                sources = code_sources(cls)
            except ValueError:  # a class with no file (made in a notebook's cell): its code cannot be known
                out[f"unknown:{cls.__module__}.{cls.__qualname__}"] = None
                continue
            for path in sources:
                if not any(path.is_relative_to(root) for root in roots):
                    out[f"plug-in:{hashlib.sha256(path.read_bytes()).hexdigest()}"] = path
    return out


@functools.lru_cache(maxsize=None)
def code_key() -> str:
    """The code that makes this process's runs, by content: the SHA-256 (16 hex digits) of
    :func:`run_sources`, names and bytes. Two trees with the same code have one key whatever their commits
    (a commit of documents or results changes nothing); any edit, committed or not, and any plug-in's
    source change it. The store's resume key and every record carry it (``code``, beside ``commit``).
    Computed once per process (a sweep's children inherit the forkserver's, which loaded their code)."""
    h = hashlib.sha256()
    for name, path in sorted(run_sources().items()):
        content = path.read_bytes() if path is not None else os.urandom(32)  # unknown code: a key of its own
        h.update(name.encode() + b"\0" + hashlib.sha256(content).digest() + b"\0")
    return h.hexdigest()[:16]


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
