"""The GPU check's asv stage on a lent machine without history or index: ``.git`` rebuilt from the carried
bundle, asv's GPU benchmarks run at each commit (``--python=same``; an older commit's tree extracted and put first on
the benchmarks' path). What carries the bundle and the wheels there: tools/device_payload.py, in the checkout."""

from __future__ import annotations

import contextlib
import io
import os
import shutil
import signal
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

COMMITS = ("HEAD", "bf587a5")  # bf587a5: the commit the H100 was measured at


def _say(msg: str) -> None:
    print(f"[asv-gpu] {msg}", flush=True)


def git(root: Path, *args: str, **kw) -> subprocess.CompletedProcess:
    return subprocess.run(["git", *args], cwd=root, capture_output=True, check=True, **kw)


# -- there --------------------------------------------------------------------------------------------


def _git_env() -> dict:
    """The environment for git and asv: a copied tree owned by another user is still a safe directory."""
    return {**os.environ, "GIT_CONFIG_COUNT": "1", "GIT_CONFIG_KEY_0": "safe.directory", "GIT_CONFIG_VALUE_0": "*"}


def ensure_repo(root: Path) -> str:
    """Make ``root`` a git repository at the bundle's HEAD when it has no ``.git`` (the working tree is
    left as it is). Returns HEAD's sha."""
    root, env = Path(root), _git_env()
    if not (root / ".git").exists():
        bundle = root / ".gl" / "repo.bundle"
        if not bundle.is_file():
            raise FileNotFoundError(f"no .git and no {bundle}: run device_payload.prepare() with network first")
        git(root, "-c", "init.defaultBranch=main", "init", "-q", env=env)
        git(root, "fetch", "-q", str(bundle), "HEAD", env=env)
        git(root, "reset", "-q", "FETCH_HEAD", env=env)
    return git(root, "rev-parse", "HEAD", text=True, env=env).stdout.strip()


def _extract(root: Path, sha: str, dest: Path) -> None:
    """The tree of commit ``sha`` into ``dest``."""
    data = git(root, "archive", "--format=tar", sha, env=_git_env()).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(dest, filter="data")


def _run(cmd: list, cwd: Path, env: dict, timeout: float) -> int:
    """Run ``cmd`` in its own process group, output passed through; on timeout the whole group is ended.
    Returns the exit status, None on timeout."""
    proc = subprocess.Popen(cmd, cwd=cwd, env=env, start_new_session=True)
    try:
        return proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        for sig, wait in ((signal.SIGTERM, 10), (signal.SIGKILL, None)):
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, sig)
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(timeout=wait)
                break
        return None


def run_asv_gpu(
    out: Path, commits=COMMITS, budget_s: float = 600, bench: str = "GPU", root: Path | None = None, asv_args=()
) -> list:
    """asv's ``bench`` benchmarks at each commit in this tree (``--python=same --set-commit-hash``), within
    ``budget_s`` seconds: each commit gets an equal share of what is left (asv saves a commit's results
    when its run ends, so a commit cut short has none). The result files go to ``out/<machine>/``.
    ``asv_args``: more ``asv run`` arguments (``("--quick",)``); ``root``: the tree, this checkout by default.
    Returns one row per commit: commit, sha, seconds, returncode, result (file or None), message.
    Never raises."""
    start, rows = time.monotonic(), []
    root = Path(root or Path(__file__).resolve().parents[2])
    out = Path(out)

    def row(commit, sha=None, seconds=0.0, returncode=None, result=None, message=""):
        rows.append(
            {
                "commit": commit,
                "sha": sha,
                "seconds": round(seconds, 1),
                "returncode": returncode,
                "result": result,
                "message": message,
            }
        )
        _say(f"{commit}: {message or 'done'} ({seconds:.0f} s, rc {returncode})")

    try:
        if shutil.which("git") is None:
            raise RuntimeError("no git on this machine: asv needs the history")
        head = ensure_repo(root)
        env = _git_env()
        machine = subprocess.run(
            [sys.executable, "-m", "pcabench.cli", "profile", "--asv"],
            cwd=root,
            env=env,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()[-1]
        _say(f"machine {machine}, HEAD {head[:8]}, budget {budget_s:.0f} s, benchmarks {bench!r}")
    except Exception as exc:  # noqa: BLE001 - a device run reports, never stops
        detail = exc.stderr.strip()[-300:] if getattr(exc, "stderr", None) else ""
        for c in commits:
            row(c, message=f"not run: {exc} {detail}".strip())
        return rows
    # asv writes machine.json and benchmarks.json into its results folder: a scratch copy of the config points
    # it under ``out``, so the committed reports/asv/results stay as they are (as in the smoke run)
    from pcabench.machine.asv import scratch_config

    scratch = Path(out).resolve() / "asv-results"
    config = scratch_config(scratch, root, "gpu-check")
    results = scratch / machine
    path = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    for i, commit in enumerate(commits):
        t0, wall, sha, tmp = time.monotonic(), time.time(), None, None  # wall: results written by this run
        try:
            left = budget_s - (t0 - start)
            if left < 30:
                row(commit, message=f"not run: budget spent ({left:.0f} s left)")
                continue
            sha = git(root, "rev-parse", "--verify", f"{commit}^{{commit}}", text=True, env=env).stdout.strip()
            code = [] if sha == head else [tmp := tempfile.mkdtemp(prefix=f"asv-{sha[:8]}-")]
            if tmp:
                _extract(root, sha, Path(tmp))
            asv_path = code + path + ([] if str(root) in path else [str(root)])
            timeout = left / (len(commits) - i)
            _say(f"{commit} = {sha[:8]}: asv run, at most {timeout:.0f} s, code from {code[0] if code else root}")
            rc = _run(
                [
                    sys.executable,
                    "-m",
                    "asv",
                    "--config",
                    str(config),
                    "run",
                    "--python=same",
                    "--set-commit-hash",
                    sha,
                    "--machine",
                    machine,
                    "-b",
                    bench,
                    "--show-stderr",
                    *asv_args,
                ],
                root,
                {**env, "ASV_PYTHONPATH": os.pathsep.join(asv_path)},
                timeout,
            )
            found = sorted(f for f in results.glob(f"{sha[:8]}-*.json") if f.stat().st_mtime >= wall)
            copied = None
            if found:
                (out / machine).mkdir(parents=True, exist_ok=True)
                for f in [results / "machine.json", *found]:
                    if f.exists():
                        shutil.copy2(f, out / machine / f.name)
                copied = str(out / machine / found[-1].name)
            msg = "timed out: no results for this commit" if rc is None else "" if copied else "no result file"
            row(commit, sha, time.monotonic() - t0, rc, copied, msg)
        except Exception as exc:  # noqa: BLE001
            row(commit, sha, time.monotonic() - t0, message=f"failed: {type(exc).__name__}: {exc}")
        finally:
            if tmp:
                shutil.rmtree(tmp, ignore_errors=True)
    return rows
