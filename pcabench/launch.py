"""The ``pcabench`` console script: :func:`pcabench.cli.main`, with a Ctrl-C or SIGTERM while the harness, numpy
and numba are still being imported (the first fraction of a second) ending in one line, never a traceback. It lives
outside pcabench/cli/, whose import is the one it guards."""

from __future__ import annotations

import signal
import sys


def _terminated(signum, frame):
    raise KeyboardInterrupt


def main() -> int:
    before = signal.signal(signal.SIGTERM, _terminated)
    try:
        from pcabench.cli import main as cli_main
    except KeyboardInterrupt:
        sys.stderr.write("pcabench: interrupted\n")
        return 130
    finally:
        signal.signal(signal.SIGTERM, before)
    return cli_main()


if __name__ == "__main__":
    sys.exit(main())
