"""The ``pcabench`` console script: :func:`pcabench.cli.main`, with a Ctrl-C or SIGTERM while the harness, numpy
and numba are still being imported (the first fraction of a second) ending in one line, never a traceback, and
with the exit code of each (130 interrupted, 143 terminated). It lives
outside pcabench/cli/, whose import is the one it guards."""

from __future__ import annotations

import signal
import sys


class _Terminated(BaseException):
    """SIGTERM while the harness is being imported (cli's own handler is not installed yet)."""


def _terminated(signum, frame):
    raise _Terminated


def main() -> int:
    before = signal.signal(signal.SIGTERM, _terminated)  # kept until cli.main installs its own
    try:
        from pcabench.cli import main as cli_main
    except KeyboardInterrupt:
        sys.stderr.write("pcabench: interrupted\n")
        return 130  # cli.exits.EXIT_INTERRUPTED (not imported: the import is what was interrupted)
    except _Terminated:
        sys.stderr.write("pcabench: terminated\n")
        return 143  # cli.exits.EXIT_TERMINATED: a SIGTERM is not a Ctrl-C, from the first instant
    try:
        return cli_main()
    except _Terminated:  # in the instant before cli.main's handler
        sys.stderr.write("pcabench: terminated\n")
        return 143
    finally:
        signal.signal(signal.SIGTERM, before)


if __name__ == "__main__":
    sys.exit(main())
