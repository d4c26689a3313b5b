"""The device payload: what a lent GPU machine gets fits the 64 MiB a run carries, and the device side reports
instead of raising."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from pcabench.gpu import asv_stage
from tools import device_payload as dp

ROOT = Path(__file__).resolve().parent.parent

ASV_METADATA = """Metadata-Version: 2.1
Name: asv
Requires-Dist: asv-runner>=0.2.5
Requires-Dist: tomli; python_version < "3.11"
Requires-Dist: colorama; platform_system == "Windows"
Requires-Dist: pyyaml; platform_python_implementation != "PyPy"
Requires-Dist: pytest; extra == "test"
"""


def test_requirements_are_those_of_the_lent_machine():
    assert [r.name for r in dp.requirements(ASV_METADATA)] == ["asv-runner", "pyyaml"]
    assert "tomli" in [r.name for r in dp.requirements(ASV_METADATA, {**dp.TARGET_ENV, "python_version": "3.10"})]


def test_working_tree_fits():
    assert dp.payload_bytes(ROOT, carry=()) < dp.LIMIT_BYTES


def test_payload_with_wheels_and_history_fits(tmp_path):
    """The prepared .whl and .gl when present, else a fresh prepare into tmp_path (skipped offline)."""
    if (ROOT / ".whl").is_dir() and (ROOT / ".gl" / "repo.bundle").is_file():
        size = dp.payload_bytes(ROOT)
    else:
        try:
            size = dp.prepare(ROOT, dest=tmp_path)["payload"]
        except subprocess.CalledProcessError as exc:
            pytest.skip(f"no package index here ({exc})")
    assert size <= dp.LIMIT_BYTES, f"{size / 2**20:.1f} MiB to carry, over {dp.LIMIT_BYTES / 2**20:.0f} MiB"


def test_run_asv_gpu_reports_instead_of_raising(tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path))  # pcabench profile --asv writes ~/.asv-machine.json
    spent = asv_stage.run_asv_gpu(tmp_path / "out", budget_s=0, root=ROOT)
    assert [r["commit"] for r in spent] == list(asv_stage.COMMITS)
    assert all(r["message"].startswith("not run: budget spent") for r in spent)
    (tmp_path / "bare").mkdir()
    bare = asv_stage.run_asv_gpu(tmp_path / "out", commits=("HEAD",), budget_s=60, root=tmp_path / "bare")
    assert len(bare) == 1 and bare[0]["message"].startswith("not run") and bare[0]["returncode"] is None
