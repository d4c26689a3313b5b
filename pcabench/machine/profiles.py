"""Hardware profiles: capture this machine's (CPU, memory, GPU where one exists), read stored ones.

Stored profiles are data, one JSON file per machine, ``<id>.json``: the
checkout's ``hardware_profiles/`` (the paper's three systems, marked
``"source": "published"``, carry its published timings) and the user's own
(``paths.user_profiles()``), where ``save`` writes. Captured profiles are
``"source": "measured"``.

GPU details come from CuPy's runtime API when CuPy and a device are present
(name, memory, compute capability, SM count, clocks, driver and runtime
versions) and from the datasheet table below for peak rates, which are
marked as datasheet values, not measurements.

A machine has one id, :func:`machine_id` (GPU name and CPU model): the name
of its store and profile and the ``profile_id`` of every record it makes,
CPU runs included. Two environment variables bear on it:

- ``PCABENCH_MACHINE_ID``: the id to use, set by a sweep for its children so
  that no child computes another one;
- ``PCABENCH_FAKE_GPU``: a test hook; a card name that :func:`gpu_info`
  reports as this machine's GPU.
"""

from __future__ import annotations

import functools
import json
import os
import platform
import re
import warnings
from pathlib import Path

from pcabench import paths

PROFILE_BYTES = 1 << 24  # a stored profile larger than this is not read
MACHINE_ID_ENV = "PCABENCH_MACHINE_ID"  # the id a sweep gives its children
FAKE_GPU_ENV = "PCABENCH_FAKE_GPU"  # test hook: a card name gpu_info() reports


class ProfileWarning(UserWarning):
    """A stored hardware profile was skipped (not JSON, or not an object)."""


# Datasheet peaks for cards we know (FP32/FP64 TFLOP/s without tensor cores, TB/s).
DATASHEET = {
    "H100 80GB HBM3": {"fp32_tflops": 66.9, "fp64_tflops": 33.5, "bandwidth_tbs": 3.35},
    "H100 PCIe": {"fp32_tflops": 51.2, "fp64_tflops": 25.6, "bandwidth_tbs": 2.0},
    "H200": {"fp32_tflops": 66.9, "fp64_tflops": 33.5, "bandwidth_tbs": 4.8},
    "A100-SXM4-80GB": {"fp32_tflops": 19.5, "fp64_tflops": 9.7, "bandwidth_tbs": 2.04},
}


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _memory_bytes() -> int:
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 0


def _slug(text: str) -> str:
    text = re.sub(r"\(R\)|\(TM\)|CPU|Processor|@.*$|NVIDIA|GeForce", "", text, flags=re.I)
    return re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")[:40] or "unknown"


def gpu_info() -> dict | None:
    """The first CUDA device as seen by CuPy, or None without CuPy or a device.

    Test hook: with ``PCABENCH_FAKE_GPU`` set to a card name, that card (its
    name only) is the GPU here, in this process and its children. It changes
    the machine's id and profile, never the solvers: linkedlist-gpu asks
    ``solvers/gpu/device.py`` for a device, not this function.
    """
    fake = os.environ.get(FAKE_GPU_ENV)
    if fake:
        return {"name": fake, "note": f"faked by {FAKE_GPU_ENV} (a test hook), not a device"}
    return _cuda_gpu_info()


@functools.lru_cache(maxsize=None)
def _cuda_gpu_info() -> dict | None:
    if os.environ.get("NUMBA_ENABLE_CUDASIM") == "1":
        return None
    try:
        import cupy

        if cupy.cuda.runtime.getDeviceCount() < 1:
            return None
        props = cupy.cuda.runtime.getDeviceProperties(0)
        name = props["name"].decode() if isinstance(props["name"], bytes) else str(props["name"])
        free, total = cupy.cuda.runtime.memGetInfo()
        info = {
            "name": name,
            "memory_bytes": int(total),
            "compute_capability": f"{props['major']}.{props['minor']}",
            "multiprocessors": int(props["multiProcessorCount"]),
            "clock_mhz": int(props.get("clockRate", 0)) // 1000,
            "memory_clock_mhz": int(props.get("memoryClockRate", 0)) // 1000,
            "memory_bus_bits": int(props.get("memoryBusWidth", 0)),
            "l2_bytes": int(props.get("l2CacheSize", 0)),
            "driver_version": cupy.cuda.runtime.driverGetVersion(),
            "runtime_version": cupy.cuda.runtime.runtimeGetVersion(),
            "cupy_version": cupy.__version__,
        }
        if info["memory_clock_mhz"] and info["memory_bus_bits"]:
            info["peak_bandwidth_tbs_from_clocks"] = round(
                2 * info["memory_clock_mhz"] * 1e6 * info["memory_bus_bits"] / 8 / 1e12, 3
            )
        for key, peaks in DATASHEET.items():
            if key.lower() in name.lower():
                info["datasheet"] = dict(peaks, note="datasheet value, not measured")
                break
        try:
            import subprocess

            smi = subprocess.run(
                ["nvidia-smi", "--query-gpu=driver_version", "--format=csv,noheader"],
                capture_output=True,
                text=True,
                timeout=20,
            ).stdout.strip()
            if smi:
                info["driver"] = smi.splitlines()[0]
        except (OSError, Exception):  # noqa: BLE001 - nvidia-smi is optional
            pass
        return info
    except Exception:  # noqa: BLE001 - no CuPy, no driver, no device: no GPU
        return None


def profile_id(cpu: str, gpu: dict | None = None) -> str:
    """A short stable id from a CPU model and a GPU (``gpu_info()``'s dict, or None): ``gpu__cpu`` or ``cpu``."""
    parts = [_slug(gpu["name"])] if gpu else []
    parts.append(_slug(cpu))
    return "__".join(parts)


@functools.lru_cache(maxsize=None)
def machine_id() -> str:
    """This machine's id, computed once per process: ``PCABENCH_MACHINE_ID`` if set (a sweep's child is
    given its parent's), else the GPU (when one is visible) and the CPU model, as in :func:`capture`."""
    if os.environ.get(MACHINE_ID_ENV):
        from pcabench.store.provenance import checked_env

        return checked_env(MACHINE_ID_ENV, "profile_id")  # checked like a store row's: it names files
    return profile_id(_cpu_model(), gpu_info())


def capture(with_gpu: bool = True) -> dict:
    """This machine's profile as a dict (source: measured); its id is :func:`machine_id` (the CPU's alone
    without the GPU)."""
    import numba

    cpu = _cpu_model()
    gpu = gpu_info() if with_gpu else None
    profile = {
        "id": machine_id() if with_gpu else profile_id(cpu),
        "source": "measured",
        "cpu": {
            "model": cpu,
            "logical_cores": os.cpu_count(),
            "cores_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count(),
            "numba_threads": numba.config.NUMBA_NUM_THREADS,
            "machine": platform.machine(),
        },
        "memory_bytes": _memory_bytes(),
        "os": platform.platform(),
        "gpu": gpu,
    }
    return profile


def _folders() -> list[Path]:
    """Where stored profiles are read from, in order (a later folder's profile wins)."""
    return [p for p in (paths.reference_profiles(), paths.user_profiles()) if p is not None and p.is_dir()]


def stored() -> dict:
    """Every stored profile by id; a file that is not a JSON object is skipped with one warning naming it."""
    from pcabench.store import read_regular

    out = {}
    for folder in _folders():
        for p in sorted(folder.glob("*.json")):
            try:  # a regular file of bounded size: a link, a FIFO or a device is skipped
                profile = json.loads(read_regular(p, limit=PROFILE_BYTES).decode("utf-8"))
            except (OSError, ValueError, RecursionError) as exc:  # unreadable, not UTF-8, not JSON
                profile = f"{type(exc).__name__}: {exc}"
            if isinstance(profile, dict):
                out[p.stem] = profile
            else:
                warnings.warn(
                    f"{p}: not a hardware profile (a JSON object), skipped ({str(profile)[:80]})",
                    ProfileWarning,
                    stacklevel=2,
                )
    return out


def load(pid: str) -> dict:
    """The stored profile ``pid``; KeyError naming the stored ones if there is none."""
    profiles = stored()
    if pid not in profiles:
        raise KeyError(f"no hardware profile {pid!r}; stored: {', '.join(sorted(profiles)) or 'none'}")
    return profiles[pid]


def save(profile: dict, directory: Path | None = None) -> Path:
    """Write ``profile`` as ``<id>.json`` into ``directory`` (default: the user's profiles folder): its id
    checked as a store row's ``profile_id`` (StoreError), the file written whole, a link at its name replaced,
    never followed."""
    from pcabench.store import check_name
    from pcabench.store.safeio import write_file

    directory = Path(directory) if directory else paths.user_profiles()
    name = check_name(profile.get("id"), "profile id")
    directory.mkdir(parents=True, exist_ok=True)
    return write_file(directory / f"{name}.json", json.dumps(profile, indent=2, sort_keys=True) + "\n")
