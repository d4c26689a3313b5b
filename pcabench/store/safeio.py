"""Writing the harness's files without following links and without leaving partial files.

Every file pcabench writes outside the store (profiles, reports and their
figures, the GPU check's files) is written to a temporary file in the same
folder and renamed over its name (``os.replace``): a link at that name is
replaced, never followed, and a write that fails (a full disk) leaves no
partial file and says which path it was writing (:class:`~pcabench.store.StoreError`).
A folder pcabench writes into, or deletes in, that is itself a link is
refused (:func:`own_folder`).
"""

from __future__ import annotations

import errno
import os
import tempfile
from pathlib import Path

FULL = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


def _error(path, exc: OSError):
    from pcabench.store import StoreError

    if exc.errno in FULL:
        return StoreError(f"{path}: {exc.strerror or exc} (the disk is full); nothing was written there")
    return StoreError(f"{path} could not be written: {exc.strerror or exc}")


def _write_all(fd: int, data: bytes) -> None:
    while data:
        data = data[os.write(fd, data) :]


def own_folder(path, what: str = "folder", within=None) -> Path:
    """``path`` made if needed; StoreError naming it if it, or a folder between it and ``within`` (a folder
    pcabench made or was given, itself checked too), is a symbolic link: pcabench writes and deletes only in
    folders of its own, never where a link points."""
    from pcabench.store import StoreError

    path = Path(path)
    levels = [path]
    if within is not None:
        within = Path(within)
        here = path
        while here != within and here != here.parent and within in here.parents:
            here = here.parent
            levels.append(here)
    for level in levels:
        if level.is_symlink():
            raise StoreError(f"{what} {level} is a symbolic link; pcabench writes only into real folders")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _error(path, exc) from None
    return path


def fresh(path) -> Path:
    """``path`` with a symbolic link at that name removed (for a file a library opens by name, such as a
    log, a tarball or an .npz): what is then written there is a new file, never the link's target."""
    path = Path(path)
    if path.is_symlink():
        path.unlink()
    return path


def _temp(path: Path) -> tuple[int, str]:
    try:
        return tempfile.mkstemp(dir=path.parent, prefix=f".{path.name[:60]}.", suffix=".tmp")
    except OSError as exc:
        raise _error(path, exc) from None


def _finish(tmp: str, path: Path) -> None:
    try:
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)  # the name is replaced: a link there is not followed
    except OSError as exc:
        _discard(tmp)
        raise _error(path, exc) from None


def _discard(tmp: str) -> None:
    try:
        os.unlink(tmp)
    except OSError:
        pass


def write_file(path, data: str | bytes) -> Path:
    """Write ``data`` to ``path`` whole or not at all (a temporary file in its folder, then renamed); a link
    at ``path`` is replaced, not followed. StoreError naming ``path`` if it fails (nothing left behind)."""
    path = Path(path)
    if isinstance(data, str):
        data = data.encode("utf-8")
    fd, tmp = _temp(path)
    try:
        try:
            _write_all(fd, data)
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError as exc:
        _discard(tmp)
        raise _error(path, exc) from None
    _finish(tmp, path)
    return path


def save_figure(fig, path, **kwargs) -> Path:
    """``fig.savefig`` to ``path`` as :func:`write_file` writes: whole or not at all, no link followed."""
    path = Path(path)
    fd, tmp = _temp(path)
    os.close(fd)
    try:
        fig.savefig(tmp, format=path.suffix.lstrip(".") or None, **kwargs)
    except OSError as exc:
        _discard(tmp)
        raise _error(path, exc) from None
    except BaseException:
        _discard(tmp)
        raise
    _finish(tmp, path)
    return path
