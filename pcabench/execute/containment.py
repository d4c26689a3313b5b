"""Every process a run starts ends with it, even one that leaves the run's process group.

A run's child has a process group of its own, and the sweep kills that group when the run ends; a
descendant that calls ``setsid`` (a daemon's double fork) is in no group of the run's and outlives it, holding
the run's pipes open (the sweep would wait for their end) and running as the user. So the process that
supervises runs is a *child subreaper* (Linux ``PR_SET_CHILD_SUBREAPER``): a descendant whose parent dies is
adopted by it instead of by init. What it adopted during a run, it ends after the run: every child of its own
that it did not start itself (:func:`children` before the run, and the run's child), its process group with
it, again until none is left (each end can orphan more), each reaped; then it stops adopting (so only what
a run orphans is ever adopted). Elsewhere than Linux: nothing (the group kill stays).
"""

from __future__ import annotations

import ctypes
import os
import signal
import time

PR_SET_CHILD_SUBREAPER = 36
_subreaper = {"pid": None}  # the process that became one (a fork's child is not one: it asks again)


def become_subreaper() -> bool:
    """Make this process adopt its orphaned descendants (once per process); whether it could."""
    if _subreaper["pid"] == os.getpid():
        return True
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        ok = libc.prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0
    except (OSError, AttributeError):  # not Linux
        return False
    if ok:
        _subreaper["pid"] = os.getpid()
    return ok


def stop_subreaper() -> None:
    """This process adopts no more orphans (after a run: a process that runs runs among other work, a notebook
    or a test session, adopts only what its runs orphan)."""
    if _subreaper["pid"] != os.getpid():
        return
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 0, 0, 0, 0)
    except (OSError, AttributeError):
        pass
    _subreaper["pid"] = None


def children(pid: int | None = None) -> set[int]:
    """The processes whose parent is ``pid`` (this process by default), from /proc; empty where there is none."""
    pid = os.getpid() if pid is None else pid
    out = set()
    try:
        entries = os.listdir("/proc")
    except OSError:
        return out
    for entry in entries:
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as f:
                stat = f.read()
        except OSError:  # gone meanwhile
            continue
        fields = stat[stat.rfind(b")") + 2 :].split()  # after "pid (comm) ": state, ppid, pgrp, ...
        if len(fields) > 1 and int(fields[1]) == pid:
            out.add(int(entry))
    return out


def end_adopted(known: set[int], deadline_s: float = 5.0) -> int:
    """Kill, with their process groups, this process's children that are not ``known`` (those it started, and
    its children from before the run): descendants of a run it adopted. Repeated until none is left or
    ``deadline_s`` passes; each is reaped. How many were ended."""
    if _subreaper["pid"] != os.getpid():
        return 0
    ended, until, me = 0, time.monotonic() + deadline_s, os.getpgrp()
    while time.monotonic() < until:
        adopted = children() - known
        if not adopted:
            break
        for pid in adopted:
            try:
                group = os.getpgid(pid)
                if group != me:
                    os.killpg(group, signal.SIGKILL)
                os.kill(pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
            try:
                os.waitpid(pid, 0)  # ours now: reaped, so it leaves /proc
            except ChildProcessError:
                pass
            ended += 1
    return ended
