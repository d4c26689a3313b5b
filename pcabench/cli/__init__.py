"""The ``pcabench`` command line: the only module that knows about argparse.

    pcabench run --solver linkedlist-cpu --dx 0.1 --t-end 10
    pcabench study --quick | --paper | --stability [short|long] | --front [quick|full] | --walls | --dx 1 0.5 ...
    pcabench report [--reference]
    pcabench profile [--save | --asv]
    pcabench gpu-check --out DIR

Library code raises exceptions; this module alone maps them to the exit
codes of :data:`EXIT_HELP` (bad input is one line naming the parameter and its
allowed range, never a traceback).
"""

from __future__ import annotations

import errno
import os
import signal
import sys
import warnings

from pcabench import jsonout
from pcabench.cli.exits import (  # noqa: F401 - the package's face
    EXIT_DISK_FULL,
    EXIT_HELP,
    EXIT_INTERRUPTED,
    EXIT_NO_RESULTS,
    EXIT_OK,
    EXIT_PIPE,
    EXIT_RUN_FAILED,
    EXIT_TERMINATED,
    EXIT_UNAVAILABLE,
)
from pcabench.cli.options import (
    option_words,
    scene_from_args,  # noqa: F401 - the package's face
)
from pcabench.cli.parsers import build_parser
from pcabench.cli.study import study_specs  # noqa: F401 - the package's face
from pcabench.errors import NoResults, StoreFull
from pcabench.execute.progress import end_line
from pcabench.spec import OptionError
from pcabench.store import StoreError
from pcabench.usage import EXIT_BAD_INPUT, Parser
from solvers import SceneError, SolverUnavailable


class Terminated(BaseException):
    """SIGTERM, raised in the main thread so that a sweep ends as an interrupt does (its lock and reserve
    released, every finished run kept)."""


def _terminated(signum, frame):
    raise Terminated()


def main(argv=None) -> int:
    shown = warnings.formatwarning
    warnings.formatwarning = lambda message, *_, **__: f"pcabench: warning: {message}\n"  # one line each
    prog = "pcabench"
    parser = Parser(prog=prog)  # until the whole one is built (a Ctrl-C while the plug-ins load)
    import threading

    on_term = None
    if threading.current_thread() is threading.main_thread():
        on_term = signal.signal(signal.SIGTERM, _terminated)
    if argv is None and "--json" in sys.argv[1:]:  # the process's own command: one JSON object on its stdout,
        jsonout.stdout_to_stderr()  # whatever a plug-in prints at import or at exit (in-process calls: the run's)
    try:
        parser = build_parser()  # finds the solvers: a plug-in left out is one warning line
        args = parser.parse_args(argv)
        prog = f"pcabench {args.command}"
        return args.func(args)
    except StoreFull as exc:  # the machine's state, not the input
        parser.exit(EXIT_DISK_FULL, f"{prog}: error: {exc}\n")
    except (SceneError, OptionError, StoreError) as exc:
        parser.exit(EXIT_BAD_INPUT, f"{prog}: error: {option_words(str(exc))} (see {prog} --help)\n")
    except BrokenPipeError:  # `pcabench ... | head`: the reader has what it wanted
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # so that the flush at exit does not complain either
        return EXIT_PIPE
    except OSError as exc:  # a path the checks before the work could not foresee: one line all the same
        where = f"{exc.filename}: " if exc.filename else ""
        full = exc.errno in (errno.ENOSPC, errno.EDQUOT)  # a report's figures on a full disk: not bad input
        parser.exit(EXIT_DISK_FULL if full else EXIT_BAD_INPUT, f"{prog}: error: {where}{exc.strerror or exc}\n")
    except SolverUnavailable as exc:
        parser.exit(EXIT_UNAVAILABLE, f"{prog}: {exc}\n")
    except NoResults as exc:
        parser.exit(EXIT_NO_RESULTS, f"{prog}: {exc}\n")
    except KeyboardInterrupt:
        end_line()  # not on the progress line
        parser.exit(EXIT_INTERRUPTED, f"{prog}: interrupted\n")
    except Terminated:
        end_line()
        parser.exit(EXIT_TERMINATED, f"{prog}: terminated\n")
    finally:
        warnings.formatwarning = shown
        if on_term is not None:
            signal.signal(signal.SIGTERM, on_term)
