"""Progress of a run on stderr: its steps, and an ETA from the steps so far."""

from __future__ import annotations

import sys
import time

OPEN = {"line": False}  # whether a progress line is on the terminal without its newline yet


def end_line(stream=sys.stderr) -> None:
    """End a progress line left open (a Ctrl-C mid-run): what is printed next starts on a line of its own."""
    if OPEN["line"]:
        stream.write("\n")
        stream.flush()
        OPEN["line"] = False


class Progress:
    """Step progress on stderr, at most every ``every`` seconds, with an ETA."""

    def __init__(self, label: str, every: float = 2.0, stream=sys.stderr):
        self.label, self.every, self.stream = label, every, stream
        self.t0 = self.last = time.perf_counter()

    def __call__(self, done: int, total: int) -> None:
        now = time.perf_counter()
        if done <= 1:  # the clock starts with the first step, after compilation
            self.t0 = self.last = now
            return
        if now - self.last < self.every and done < total:
            return
        self.last = now
        eta = (now - self.t0) / max(done, 1) * (total - done)
        self.stream.write(f"\r{self.label}: step {done}/{total} ({100 * done / total:5.1f} %), eta {eta:6.1f} s ")
        OPEN["line"] = self.stream is sys.stderr
        if done == total:
            self.stream.write("\n")
            OPEN["line"] = False
        self.stream.flush()


class Heartbeat:
    """Within: a line on stderr every ``every`` seconds once the work has taken that long ("label: 4 s ..."), for
    work that has no steps to count (a prediction); the line is ended on leaving."""

    def __init__(self, label: str, every: float = 2.0, stream=sys.stderr):
        import threading

        self.label, self.every, self.stream = label, every, stream
        self.done, self.said = threading.Event(), False
        self.thread = threading.Thread(target=self._beat, daemon=True)

    def _beat(self) -> None:
        t0 = time.perf_counter()
        while not self.done.wait(self.every):
            self.stream.write(f"\r{self.label}: {time.perf_counter() - t0:.0f} s ")
            self.stream.flush()
            OPEN["line"], self.said = self.stream is sys.stderr, True

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.done.set()
        self.thread.join()
        if self.said:
            self.stream.write("\n")
            self.stream.flush()
            OPEN["line"] = False
