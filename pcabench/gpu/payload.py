"""asv on a lent GPU machine that has no package index and gets the working tree without history.

Here, with an index, :func:`prepare` puts asv and the dependencies that machine
lacks into ``.whl/`` (cp312 manylinux wheels) and the history into
``.gl/repo.bundle``; both are git-ignored, so they travel as carried paths, and
:func:`payload_bytes` says whether everything fits the 64 MiB a run carries.
There, after :data:`DEVICE_PREFIX`, :func:`run_asv_gpu` rebuilds ``.git`` from
the bundle and runs asv's GPU benchmarks at each commit (``--python=same``):
the tree itself is HEAD's code, an older commit's tree is extracted from the
history and put first on the benchmarks' path (asv passes them ``ASV_PYTHONPATH``,
not ``PYTHONPATH``), where ``benchmarks/common.py`` finds its solver package.
"""

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
import zipfile
from pathlib import Path

LIMIT_BYTES = 64 * 2**20  # what one device run carries: working tree plus carried paths
COMMITS = ("HEAD", "bf587a5")  # bf587a5: the commit the H100 was measured at
TOP = ("asv==0.6.6",)
# Already on the lent machine's image; asv's own dependencies are not among them, so all of those travel.
DEVICE_HAS = frozenset(
    {
        "numpy",
        "scipy",
        "pandas",
        "matplotlib",
        "pytest",
        "pytest-benchmark",
        "numba",
        "numba-cuda",
        "psutil",
        "py-cpuinfo",
    }
)
PLATFORMS = (
    "manylinux_2_28_x86_64",
    "manylinux_2_27_x86_64",
    "manylinux_2_17_x86_64",
    "manylinux2014_x86_64",
    "manylinux1_x86_64",
)
# The lent machine's Python, for the wheels' environment markers.
TARGET_ENV = {
    "python_version": "3.12",
    "python_full_version": "3.12.0",
    "implementation_name": "cpython",
    "platform_python_implementation": "CPython",
    "sys_platform": "linux",
    "os_name": "posix",
    "platform_system": "Linux",
    "platform_machine": "x86_64",
    "extra": "",
}
# The device command's start: asv from the wheels, the tree as the import path.
DEVICE_PREFIX = (
    "python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade "
    "--target /tmp/site .whl/*.whl && export PYTHONPATH=/tmp/site:$PWD"
)


def _say(msg: str) -> None:
    print(f"[asv-gpu] {msg}", flush=True)


def _git(root: Path, *args: str, **kw) -> subprocess.CompletedProcess:
    return subprocess.run(["git", *args], cwd=root, capture_output=True, check=True, **kw)


def _tree_size(path: Path) -> int:
    return sum(p.lstat().st_size for p in Path(path).rglob("*") if p.is_file() and not p.is_symlink())


# -- here ---------------------------------------------------------------------------------------------


def requirements(metadata: str, env: dict = TARGET_ENV) -> list:
    """The ``Requires-Dist`` of a wheel's METADATA that apply on the lent machine, as packaging Requirements."""
    from packaging.requirements import Requirement

    reqs = [
        Requirement(line.split(":", 1)[1].strip())
        for line in metadata.splitlines()
        if line.startswith("Requires-Dist:")
    ]
    return [r for r in reqs if r.marker is None or r.marker.evaluate(env)]


def _pinned(req) -> str:
    """``name==version`` of this environment's copy when it satisfies ``req`` (the versions tested here)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        v = version(req.name)
    except PackageNotFoundError:
        return f"{req.name}{req.specifier}"
    return f"{req.name}=={v}" if req.specifier.contains(v, prereleases=True) else f"{req.name}{req.specifier}"


def download_wheels(dest: Path, top=TOP, skip=DEVICE_HAS, python: str = "3.12") -> dict:
    """``top`` and, recursively, its dependencies not in ``skip``, as CPython ``python`` manylinux x86_64 wheels
    in ``dest`` (emptied first). Returns {wheel file name: bytes}."""
    from packaging.utils import canonicalize_name

    dest = Path(dest)
    shutil.rmtree(dest, ignore_errors=True)
    dest.mkdir(parents=True)
    platforms = [a for p in PLATFORMS for a in ("--platform", p)]
    env = {**TARGET_ENV, "python_version": python, "python_full_version": f"{python}.0"}
    seen, read, batch = set(skip), set(), list(top)
    while batch:
        subprocess.run(
            [
                sys.executable,
                "-m",
                "pip",
                "download",
                "-q",
                "--no-deps",
                "--only-binary=:all:",
                "--python-version",
                python,
                "--implementation",
                "cp",
                *platforms,
                "-d",
                str(dest),
                *batch,
            ],
            check=True,
        )
        batch = []
        for wheel in sorted(set(dest.glob("*.whl")) - read):
            read.add(wheel)
            seen.add(canonicalize_name(wheel.name.split("-")[0]))
            with zipfile.ZipFile(wheel) as z:
                meta = next(n for n in z.namelist() if n.endswith(".dist-info/METADATA"))
                for r in requirements(z.read(meta).decode(), env):
                    if canonicalize_name(r.name) not in seen:
                        seen.add(canonicalize_name(r.name))
                        batch.append(_pinned(r))
    return {w.name: w.stat().st_size for w in sorted(dest.glob("*.whl"))}


def prepare(root: Path, commits=COMMITS, dest: Path | None = None) -> dict:
    """Wheels into ``dest/.whl`` and a bundle of HEAD's history (which must hold every commit) into
    ``dest/.gl/repo.bundle``; ``dest`` is the checkout ``root`` unless given. Returns {"wheels": {name: bytes},
    "bundle": bytes, "payload": bytes of the working tree plus both}."""
    root = Path(root)
    dest = Path(dest or root)
    for c in commits:
        sha = _git(root, "rev-parse", "--verify", f"{c}^{{commit}}", text=True).stdout.strip()
        if subprocess.run(["git", "merge-base", "--is-ancestor", sha, "HEAD"], cwd=root).returncode:
            raise ValueError(f"{c} is not in HEAD's history: the bundle would not hold it")
    wheels = download_wheels(dest / ".whl")
    bundle = dest / ".gl" / "repo.bundle"
    bundle.parent.mkdir(parents=True, exist_ok=True)
    _git(root, "bundle", "create", "-q", str(bundle.resolve()), "HEAD")
    return {
        "wheels": wheels,
        "bundle": bundle.stat().st_size,
        "payload": payload_bytes(root, carry=(dest / ".whl", dest / ".gl")),
    }


def payload_bytes(root: Path, carry=(".whl", ".gl")) -> int:
    """Bytes a device run would carry: tracked and untracked-not-ignored files, plus the ``carry`` paths
    (relative to ``root``, or absolute)."""
    root = Path(root)
    names = _git(root, "ls-files", "-co", "--exclude-standard", "-z").stdout.decode().split("\0")
    tree = sum((root / n).lstat().st_size for n in names if n and (root / n).is_file())
    return tree + sum(
        _tree_size(root / c) if (root / c).is_dir() else (root / c).stat().st_size for c in carry if (root / c).exists()
    )


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
        _git(root, "-c", "init.defaultBranch=main", "init", "-q", env=env)
        _git(root, "fetch", "-q", str(bundle), "HEAD", env=env)
        _git(root, "reset", "-q", "FETCH_HEAD", env=env)
    return _git(root, "rev-parse", "HEAD", text=True, env=env).stdout.strip()


def _extract(root: Path, sha: str, dest: Path) -> None:
    """The tree of commit ``sha`` into ``dest``."""
    data = _git(root, "archive", "--format=tar", sha, env=_git_env()).stdout
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
    from pcabench.bench.asv_smoke import scratch_config

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
            sha = _git(root, "rev-parse", "--verify", f"{commit}^{{commit}}", text=True, env=env).stdout.strip()
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


# -- the one command --------------------------------------------------------------------------------------


def device_command(commit: str, budget_s: float = 450.0) -> str:
    """The whole device call: asv from the wheels, then ``pcabench gpu-check`` within ``budget_s`` seconds;
    what to bring back (the check's tarball, its tables and the log) lands in ``$OUT``."""
    install, path = DEVICE_PREFIX.split(" && ")
    return (
        f"set -o pipefail; {install} || echo 'gpu-check: the wheels did not install: no asv'; {path}; "
        f"export PCABENCH_HOME=/tmp/pcabench PCABENCH_COMMIT={commit} PYTHONUNBUFFERED=1; "
        "nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,memory.total --format=csv; "
        f"python3 -m pcabench.cli gpu-check --out /tmp/check --budget {budget_s:.0f} "
        "2>&1 | tee $OUT/gpu_check.log; "
        "rc=$?; cp /tmp/check/gpu_check.tar.gz /tmp/check/gpu_check.md $OUT/; exit $rc"
    )


def main(argv=None) -> int:
    """``python -m pcabench.gpu.payload [BUDGET_S]``: prepare the payload here and print the device call."""
    argv = sys.argv[1:] if argv is None else argv
    root = Path(__file__).resolve().parents[2]
    if _git(root, "status", "--porcelain", "--untracked-files=no", text=True).stdout.strip():
        print("commit first: the bundle and the results carry HEAD's commit", file=sys.stderr)
        return 2
    sizes = prepare(root)
    commit = _git(root, "rev-parse", "HEAD", text=True).stdout.strip()
    print(
        f"payload {sizes['payload'] / 2**20:.1f} MiB of {LIMIT_BYTES / 2**20:.0f} (carry .whl and .gl)", file=sys.stderr
    )
    print(device_command(commit, float(argv[0]) if argv else 450.0))
    return 0 if sizes["payload"] <= LIMIT_BYTES else 1


if __name__ == "__main__":
    sys.exit(main())
