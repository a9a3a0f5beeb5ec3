"""``amsa-phys``: parse, dispatch, and turn an AmsaError into one line and an exit code.

Only this module catches AmsaError. Any other exception keeps its traceback: it is a bug.
Exit codes: 0 done, 1 an expectation failed, 2 bad input or usage, 3 a run fault,
130 interrupted.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import NoReturn

from .. import __version__
from ..errors import AmsaError
from . import describe, export, graph, imports, plot, run, sweep, templates, validate
from . import test as test_cmd

COMMANDS = {
    "run": run,
    "validate": validate,
    "describe": describe,
    "templates": templates,
    "plot": plot,
    "test": test_cmd,
    "sweep": sweep,
    "graph": graph,
    "export": export,
    "import": imports,
}


class _Parser(argparse.ArgumentParser):
    """argparse with usage errors as one line (exit 2), pointing at ``--help``."""

    def error(self, message: str) -> NoReturn:
        """Print ``error: <prog>: <message>`` and exit 2."""
        self.exit(2, f"error: {self.prog}: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser."""
    parser = _Parser(
        prog="amsa-phys",
        description="Physics-backed 2D rover testbed implementing the AMSA framework.",
    )
    parser.add_argument("--version", action="version", version=f"amsa-phys {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module in COMMANDS.items():
        doc = (module.__doc__ or "").strip().splitlines()[0]
        p = sub.add_parser(name, help=doc, description=doc)
        module.add_args(p)
        p.set_defaults(func=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code (tests call this in-process)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except AmsaError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt as exc:  # Interrupted says where; a bare one during loading
        print(f"error: {exc}" if str(exc) else "interrupted", file=sys.stderr)
        return 130
