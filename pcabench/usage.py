"""The command lines' argument parser: a usage error is one line naming the option, and exit code 2.

Shared by ``pcabench`` (cli.py) and the smaller entry points (asv_smoke.py) without either importing the
other."""

from __future__ import annotations

import argparse

EXIT_BAD_INPUT = 2  # bad input: one line naming the parameter and its allowed range, before any work


class Parser(argparse.ArgumentParser):
    """argparse, but a usage error is one line naming the option, and exit code 2."""

    subcommands: dict = {}  # name -> its parser (set by the command line that has them)

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")

    def parse_args(self, args=None, namespace=None):
        """As argparse's, but an option no parser knows is the subcommand's error (its name, its --help)."""
        namespace, extras = self.parse_known_args(args, namespace)
        if extras:
            sub = self.subcommands.get(getattr(namespace, "command", None), self)
            sub.error(f"unrecognized arguments: {' '.join(extras)}")
        return namespace
