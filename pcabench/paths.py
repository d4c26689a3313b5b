"""Where pcabench reads reference data and writes a user's output: one setting.

Two kinds of place:

- the *reference* data of a checkout, committed and never written by a
  user's run: ``reports/results/*.jsonl`` (the authors' results store),
  ``reports/`` (the reports built from it) and ``hardware_profiles/*.json``
  (stored profiles, the paper's three systems among them);
- the user's *home*, where their runs, captured profiles and reports go:
  ``$PCABENCH_HOME`` if set; else ``results/`` at the top of a checkout
  (ignored by git, so a user's runs never change tracked files); else, for a
  wheel install, ``$XDG_DATA_HOME/pcabench`` (``~/.local/share/pcabench``).

Nothing is ever written into the installed package.
"""

from __future__ import annotations

import os
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent


def checkout() -> Path | None:
    """The repository root when pcabench runs from a source checkout, else None (a wheel install)."""
    root = PACKAGE_DIR.parent
    if (root / "pyproject.toml").is_file() and (root / "hardware_profiles").is_dir():
        return root
    return None


def home() -> Path:
    """The user's output folder (see the module docstring for the order of choice)."""
    if os.environ.get("PCABENCH_HOME"):
        return Path(os.environ["PCABENCH_HOME"]).expanduser()
    root = checkout()
    if root is not None:
        return root / "results"
    base = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
    return base / "pcabench"


def user_results() -> Path:
    """Folder of the user's results stores (``<machine>.jsonl``)."""
    return home() / "store"


def user_reports() -> Path:
    """Folder of the reports built from the user's results."""
    return home() / "reports"


def user_profiles() -> Path:
    """Folder of the hardware profiles captured on the user's machines."""
    return home() / "hardware_profiles"


def reference_results() -> Path | None:
    """The committed results store of a checkout (reference data), or None."""
    root = checkout()
    return root / "reports" / "results" if root else None


def reference_reports() -> Path | None:
    """The committed reports of a checkout, or None."""
    root = checkout()
    return root / "reports" if root else None


def reference_profiles() -> Path | None:
    """The stored hardware profiles of a checkout (the paper's systems among them), or None."""
    root = checkout()
    return root / "hardware_profiles" if root else None
