"""asv's view of this machine: its machine description, from the hardware profile (GPU included, which asv does
not record), and a scratch copy of the config for runs that must leave the committed results alone.

asv reads ``~/.asv-machine.json``; every key of a machine's entry lands in the
``machine.json`` of its results. ``write`` adds or replaces this profile's
entry: the machine name is the profile id, ``cpu`` and ``ram`` come from the
profile, and ``gpu`` and ``pcabench_profile`` are extra keys (``pcabench profile --asv``).

asv writes ``machine.json`` and ``benchmarks.json`` into its results folder
even on a dry run, and the committed ``reports/asv/results`` hold real
measurements. :func:`scratch_config` writes a copy of ``asv.conf.json`` (an
ignored ``.asv-*.conf.json`` at the root, so the config's relative paths still
hold) whose results folder is a scratch one; the smoke run
(benchmarks/ci/asv_smoke.py) and the GPU check's asv stage run asv through it.
"""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path

RESULTS_LINE = '"results_dir": "reports/asv/results"'
SCRATCH = Path(".asv") / "smoke" / "results"  # under the ignored .asv/


def scratch_config(results: Path, root: Path, name: str = "smoke") -> Path:
    """``root/.asv-<name>.conf.json``: ``root``'s asv.conf.json with its results in ``results`` (made absolute)."""
    text = (root / "asv.conf.json").read_text()
    if RESULTS_LINE not in text:
        raise RuntimeError(f"{root / 'asv.conf.json'} has no line {RESULTS_LINE}: update pcabench/machine/asv.py")
    config = root / f".asv-{name}.conf.json"
    config.write_text(text.replace(RESULTS_LINE, json.dumps({"results_dir": str(Path(root, results).resolve())})[1:-1]))
    return config


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
