"""``python -m pcabench.cli``: the command line, as the console script runs it (pcabench/console.py)."""

import sys

from pcabench.console import main

sys.exit(main())
