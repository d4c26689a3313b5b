"""A sweep's child process: run one spec and print its record as one JSON line on stdout.

    python -m pcabench.child '<RunSpec JSON>'

The child never writes the store: the sweep (its parent) is the only writer,
so a progress line always reports the record this child made. Its record
carries the sweep's machine id and commit (``PCABENCH_MACHINE_ID``
and ``PCABENCH_COMMIT``, set by the parent).
"""
from __future__ import annotations

import json
import sys
import warnings

from solvers.registry import PluginWarning

from .profiles import machine_id
from .progress import Progress
from .run import run
from .spec import RunSpec
from .store import to_row


def run_spec(spec: RunSpec) -> dict:
    """Run one resolved spec with step progress on stderr; its record as a store row."""
    progress = Progress(f"    {spec.solver} N={spec.scene.n_particles:,}", every=5.0)
    return to_row(run(spec, machine_id(), progress=progress))


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    warnings.filterwarnings("ignore", category=PluginWarning)  # the sweep (the parent) said it once
    print(json.dumps(run_spec(RunSpec.from_json(argv[0])), sort_keys=True), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
