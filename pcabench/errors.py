"""The harness's errors that end a command: raised by library code, mapped to exit codes in cli.py only.

Bad input is :class:`~pcabench.spec.OptionError` (a harness option) or
:class:`~solvers.scene.SceneError` (a scene or solver parameter); a store that
cannot be read or written is :class:`StoreError` (raised by the store and by what checks names that become
store paths), one whose disk is full :class:`StoreFull` (an exit code of its own).
"""

from __future__ import annotations


class NoResults(Exception):
    """There are no stored runs to work from (an empty or missing results folder)."""


class StoreError(OSError):
    """The store cannot be written (one line naming the path)."""


class StoreFull(StoreError):
    """The store's disk (or quota, or file size limit) is full: the machine's state, not bad input."""
