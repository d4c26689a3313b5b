"""Hardware profiles: capture this machine, read stored ones (one JSON file per machine).

Stored profiles live beside this file as ``<id>.json``. The paper's three
systems (``paper-system-1..3``) carry its published timings as reference
data, marked ``"source": "published"``; captured profiles are ``"measured"``.
"""
from __future__ import annotations

import json
from pathlib import Path

from .capture import capture, profile_id

PROFILE_DIR = Path(__file__).resolve().parent


def load(pid: str) -> dict:
    """The stored profile ``pid``."""
    path = PROFILE_DIR / f"{pid}.json"
    if not path.exists():
        known = ", ".join(sorted(p.stem for p in PROFILE_DIR.glob("*.json")))
        raise KeyError(f"no hardware profile {pid!r}; stored: {known}")
    return json.loads(path.read_text())


def stored() -> dict:
    """Every stored profile by id."""
    return {p.stem: json.loads(p.read_text()) for p in sorted(PROFILE_DIR.glob("*.json"))}


def save(profile: dict, directory: Path | None = None) -> Path:
    """Write ``profile`` as ``<id>.json`` (into this folder unless told otherwise)."""
    directory = Path(directory) if directory else PROFILE_DIR
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / f"{profile['id']}.json"
    path.write_text(json.dumps(profile, indent=2, sort_keys=True) + "\n")
    return path


__all__ = ["capture", "profile_id", "load", "stored", "save", "PROFILE_DIR"]
