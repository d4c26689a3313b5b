"""What a held store holds: the bytes its sweep has seen, so that a row written behind the sweep's back is found.

A sweep holds its store's lock for its whole life (:class:`pcabench.store.SweepLock`), and a pcabench process
never writes a store another holds; but a lock is advisory, and a run's own process (a plug-in, running as the
user) can append to the file all the same. So the holder keeps the store's size and the SHA-256 of its bytes as
it last saw them (when it took the store, after each of its own appends), and before each append and on release
compares: a store that grew is cut back to what the sweep saw and the bytes added behind its back are moved to
``<store>.foreign`` (never read: only ``*.jsonl`` is a store); a store whose earlier bytes changed, or that was
replaced by another file, cannot be mended. Either way :meth:`StoreWatch.check` returns one line naming the file,
which the holder gives as a warning.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

CHUNK = 1 << 20
TAIL = 1 << 16  # bytes at the store's end compared at every check


class StoreWatch:
    """The bytes of one held store (open as ``fd``, at ``path``) as its holder last saw them."""

    def __init__(self, fd: int, path: Path):
        self.fd, self.path = fd, Path(path)
        self.size, self.digest = 0, hashlib.sha256()
        self._read_to(os.fstat(fd).st_size)
        self.stamp, self.tail = self._stamp(), self._tail()

    def _stamp(self) -> tuple:
        st = os.fstat(self.fd)
        return st.st_ino, st.st_size, st.st_mtime_ns

    def _tail(self) -> bytes:
        """The SHA-256 of the store's last TAIL bytes (a rewrite in place within the time stamp's tick changes no
        stamp: it is found where it reaches them)."""
        size = os.fstat(self.fd).st_size
        return hashlib.sha256(os.pread(self.fd, min(TAIL, size), max(size - TAIL, 0))).digest()

    def _read_to(self, end: int) -> None:
        """Hash the store's bytes from what is seen up to ``end``."""
        while self.size < end:
            data = os.pread(self.fd, min(CHUNK, end - self.size), self.size)
            if not data:
                break
            self.digest.update(data)
            self.size += len(data)

    def _prefix_digest(self, end: int) -> bytes:
        h, pos = hashlib.sha256(), 0
        while pos < end:
            data = os.pread(self.fd, min(CHUNK, end - pos), pos)
            if not data:
                break
            h.update(data)
            pos += len(data)
        return h.digest()

    def check(self) -> str:
        """Compare the store with what its holder last saw: '' where it is unchanged; else, after moving what was
        appended behind the holder's back aside (or finding a change that cannot be mended), one line saying
        so (the holder warns with it)."""
        try:
            on_disk = os.stat(self.path).st_ino
        except OSError:
            on_disk = None
        if on_disk != os.fstat(self.fd).st_ino:
            return (
                f"{self.path} was removed or replaced by another file while the sweep held it (a run's process "
                "wrote it): the runs this sweep stores from here go to the file it holds, which no longer has that "
                "name; rerun the sweep"
            )
        if self._stamp() == self.stamp and self._tail() == self.tail:  # (a write in the stamp's own tick: the tail)
            return ""
        size = os.fstat(self.fd).st_size
        if size < self.size or self._prefix_digest(self.size) != self.digest.digest():
            message = (
                f"{self.path} was changed behind the sweep's back (its first {self.size:,} bytes are not what the "
                "sweep last saw): a run's process rewrote it; its rows are as that process left them"
            )
            self.size, self.digest = 0, hashlib.sha256()
            self._read_to(size)
            self.stamp, self.tail = self._stamp(), self._tail()
            return message
        if size == self.size:  # touched, not changed
            self.stamp, self.tail = self._stamp(), self._tail()
            return ""
        extra = os.pread(self.fd, size - self.size, self.size)
        foreign = Path(f"{self.path}.foreign")
        out = os.open(foreign, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_NOFOLLOW, 0o644)
        try:
            while extra:
                extra = extra[os.write(out, extra) :]
            os.fsync(out)
        finally:
            os.close(out)
        os.ftruncate(self.fd, self.size)
        os.fsync(self.fd)
        self.stamp, self.tail = self._stamp(), self._tail()
        return (
            f"{self.path}: {size - self.size:,} bytes written into the store behind the sweep's back (a run's "
            f"process, while the sweep held it) were moved to {foreign}: they are not read"
        )

    def saw_append(self) -> None:
        """The holder appended: what it wrote is seen (the store checked just before by :meth:`check`)."""
        self._read_to(os.fstat(self.fd).st_size)
        self.stamp, self.tail = self._stamp(), self._tail()
