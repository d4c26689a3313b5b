"""``python -m pcabench.cli``: the command line, as the console script runs it (pcabench/launch.py)."""

import sys

from pcabench.launch import main

sys.exit(main())
