"""asv's machine description, taken from the hardware profile (GPU included, which asv does not record).

asv reads ``~/.asv-machine.json``; every key of a machine's entry lands in the
``machine.json`` of its results. ``write`` adds or replaces this profile's
entry: the machine name is the profile id, ``cpu`` and ``ram`` come from the
profile, and ``gpu`` and ``pcabench_profile`` are extra keys.
"""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path


def entry(profile: dict) -> dict:
    """asv's fields (machine, os, arch, cpu, num_cpu, ram) plus the GPU, from ``profile``."""
    cpu, gpu = profile.get("cpu") or {}, profile.get("gpu") or {}
    gpu_text = "none"
    if gpu:
        gpu_text = (
            f"{gpu.get('name')}, {gpu.get('memory_bytes', 0) / 2**30:.0f} GiB, "
            f"compute capability {gpu.get('compute_capability')}, driver {gpu.get('driver')}"
        )
    return {
        "machine": profile["id"],
        "os": profile.get("os") or platform.platform(),
        "arch": cpu.get("machine") or platform.machine(),
        "cpu": f"{cpu.get('model', 'unknown CPU')} ({cpu.get('cores_usable', '?')} cores usable)",
        "num_cpu": str(cpu.get("logical_cores", os.cpu_count())),
        "ram": str(profile.get("memory_bytes", "")),
        "gpu": gpu_text,
        "pcabench_profile": profile["id"],
    }


def write(profile: dict, path: Path | None = None) -> str:
    """Add this profile's entry to asv's machine file; returns the machine name for ``asv run --machine``."""
    path = Path(path) if path else Path.home() / ".asv-machine.json"
    data = json.loads(path.read_text()) if path.exists() else {}
    data.setdefault("version", 1)
    e = entry(profile)
    data[e["machine"]] = e
    path.write_text(json.dumps(data, indent=4, sort_keys=True) + "\n")
    return e["machine"]
