"""``python tools/device_payload.py [BUDGET_S]``: what a lent GPU machine that has no package index and gets the
working tree without history needs for asv, prepared here (a checkout's tool, not part of the installed package).

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

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

from pcabench.gpu.asv_stage import COMMITS, git

LIMIT_BYTES = 64 * 2**20  # what one device run carries: working tree plus carried paths
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
        sha = git(root, "rev-parse", "--verify", f"{c}^{{commit}}", text=True).stdout.strip()
        if subprocess.run(["git", "merge-base", "--is-ancestor", sha, "HEAD"], cwd=root).returncode:
            raise ValueError(f"{c} is not in HEAD's history: the bundle would not hold it")
    wheels = download_wheels(dest / ".whl")
    bundle = dest / ".gl" / "repo.bundle"
    bundle.parent.mkdir(parents=True, exist_ok=True)
    git(root, "bundle", "create", "-q", str(bundle.resolve()), "HEAD")
    return {
        "wheels": wheels,
        "bundle": bundle.stat().st_size,
        "payload": payload_bytes(root, carry=(dest / ".whl", dest / ".gl")),
    }


def payload_bytes(root: Path, carry=(".whl", ".gl")) -> int:
    """Bytes a device run would carry: tracked and untracked-not-ignored files, plus the ``carry`` paths
    (relative to ``root``, or absolute)."""
    root = Path(root)
    names = git(root, "ls-files", "-co", "--exclude-standard", "-z").stdout.decode().split("\0")
    tree = sum((root / n).lstat().st_size for n in names if n and (root / n).is_file())
    return tree + sum(
        _tree_size(root / c) if (root / c).is_dir() else (root / c).stat().st_size for c in carry if (root / c).exists()
    )


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
    """``python tools/device_payload.py [BUDGET_S]``: prepare the payload here and print the device call."""
    argv = sys.argv[1:] if argv is None else argv
    root = Path(__file__).resolve().parents[1]  # the checkout: tools/ is one folder down
    if git(root, "status", "--porcelain", "--untracked-files=no", text=True).stdout.strip():
        print("commit first: the bundle and the results carry HEAD's commit", file=sys.stderr)
        return 2
    sizes = prepare(root)
    commit = git(root, "rev-parse", "HEAD", text=True).stdout.strip()
    print(
        f"payload {sizes['payload'] / 2**20:.1f} MiB of {LIMIT_BYTES / 2**20:.0f} (carry .whl and .gl)", file=sys.stderr
    )
    print(device_command(commit, float(argv[0]) if argv else 450.0))
    return 0 if sizes["payload"] <= LIMIT_BYTES else 1


if __name__ == "__main__":
    sys.exit(main())
