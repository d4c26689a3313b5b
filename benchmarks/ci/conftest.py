"""pytest-benchmark: this machine's hardware profile goes into every saved run's machine info."""

from __future__ import annotations


def pytest_benchmark_update_machine_info(config, machine_info):
    from pcabench.machine.profiles import capture

    machine_info["pcabench_profile"] = capture()


def pytest_configure(config):
    """Create the folder of --benchmark-json, so reports/pytest-benchmark/run.json works on a fresh checkout."""
    from pathlib import Path

    path = config.getoption("benchmark_json", None)
    if path:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
