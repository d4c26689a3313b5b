"""A sweep's child process: run one spec and send its record on a channel of its own.

    python -m pcabench.execute.child --record-fd FD --fields PATH '<RunSpec JSON>'

The record goes, as one JSON object, to the file descriptor FD (a pipe the
sweep passes in), never to stdout: what a solver prints on stdout or stderr
cannot be taken for a record (the sweep keeps it, cut, in the record's
message). Without ``--record-fd`` the record is printed on stdout (by hand).
With ``--fields`` the run's final fields go to the .npz PATH (a folder of the
sweep's own) unscored: the sweep takes from the record only what was measured
(times, steps, status) and computes the errors from the fields itself
(:func:`pcabench.execute.sweep.accept`).

The child never writes the store: the sweep (its parent) is the only writer,
so a progress line always reports the record this child made. Its record
carries the sweep's machine id and commit (``PCABENCH_MACHINE_ID``
and ``PCABENCH_COMMIT``, set by the parent).
"""

from __future__ import annotations

import json
import os
import sys
import warnings

from pcabench.execute.progress import Progress
from pcabench.execute.run import run
from pcabench.machine.profiles import machine_id
from pcabench.spec import RunSpec
from pcabench.store import to_row
from solvers.plugins import PluginWarning


def run_spec(spec: RunSpec, fields_path=None) -> dict:
    """Run one resolved spec with step progress on stderr; its record as a store row (unscored, its fields
    at ``fields_path``, if that is given)."""
    progress = Progress(f"    {spec.solver} N={spec.scene.n_particles:,}", every=5.0)
    record = run(spec, machine_id(), fields_path=fields_path, progress=progress, scored=fields_path is None)
    return to_row(record)


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    warnings.filterwarnings("ignore", category=PluginWarning)  # the sweep (the parent) said it once
    fd = None
    if argv[:1] == ["--record-fd"]:
        fd, argv = int(argv[1]), argv[2:]
        os.set_inheritable(fd, False)  # the solver's own subprocesses do not get it
    fields = None
    if argv[:1] == ["--fields"]:
        fields, argv = argv[1], argv[2:]
    data = (json.dumps(run_spec(RunSpec.from_json(argv[0]), fields), sort_keys=True) + "\n").encode("utf-8")
    if fd is None:
        sys.stdout.buffer.write(data)
        sys.stdout.flush()
        return 0
    with os.fdopen(fd, "wb") as f:  # closed here: the record is whole before anything at exit can print
        f.write(data)
    return 0


if __name__ == "__main__":
    sys.exit(main())
