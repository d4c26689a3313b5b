"""The ``pcabench`` console script: :func:`pcabench.cli.main`, with a Ctrl-C or SIGTERM while the harness, numpy
and numba are still being imported (the first fraction of a second) ending in one line, never a traceback, and
with the exit code of each (130 interrupted, 143 terminated). It lives
outside pcabench/cli/, whose import is the one it guards."""

from __future__ import annotations

import signal
import sys


class _Terminated(BaseException):
    """SIGTERM while the harness is being imported (cli's own handler is not installed yet)."""


_got = {"signal": None}  # the signal that arrived during the import (a C extension's import turns the
# exception its handler raises into an ImportError: the flag says what it was)


def _terminated(signum, frame):
    _got["signal"] = signal.SIGTERM
    raise _Terminated


def _interrupted(signum, frame):
    _got["signal"] = signal.SIGINT
    raise KeyboardInterrupt


def _said(signum) -> int:
    if signum == signal.SIGTERM:
        sys.stderr.write("pcabench: terminated\n")
        return 143  # cli.exits.EXIT_TERMINATED: a SIGTERM is not a Ctrl-C, from the first instant
    sys.stderr.write("pcabench: interrupted\n")
    return 130  # cli.exits.EXIT_INTERRUPTED (not imported: the import is what was interrupted)


def main() -> int:
    before = signal.signal(signal.SIGTERM, _terminated)  # kept until cli.main installs its own
    before_int = signal.signal(signal.SIGINT, _interrupted)
    try:
        if "--json" in sys.argv[1:]:  # one JSON object on stdout, whatever a plug-in the import loads prints
            from pcabench import jsonout

            jsonout.stdout_to_stderr()
        from pcabench.cli import main as cli_main
    except BaseException:  # noqa: BLE001 - a signal during the import, whatever the import made of it
        if _got["signal"] is None:
            raise
        return _said(_got["signal"])
    finally:
        signal.signal(signal.SIGINT, before_int)
    try:
        return cli_main()
    except _Terminated:  # in the instant before cli.main's handler
        return _said(signal.SIGTERM)
    finally:
        signal.signal(signal.SIGTERM, before)


if __name__ == "__main__":
    sys.exit(main())
