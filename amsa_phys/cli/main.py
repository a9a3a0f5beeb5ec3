"""``amsa-phys``: parse, dispatch, and turn an AmsaError into one line and an exit code.

Only this module catches AmsaError. Any other exception keeps its traceback: it is a bug.
Exit codes: 0 done, 1 an expectation failed, 2 bad input or usage, 3 a run fault,
130 interrupted.
"""

from __future__ import annotations

import argparse
import os
import sys
import sysconfig
import threading
import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from .. import __version__
from ..errors import AmsaError, one_line
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
        self.exit(2, one_line(f"error: {self.prog}: {message} (see {self.prog} --help)") + "\n")


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser."""
    parser = _Parser(
        prog="amsa-phys",
        description="Physics-backed 2D rover testbed implementing the AMSA framework.",
    )
    parser.add_argument("--version", action="version", version=f"amsa-phys {__version__}")
    debug_help = (
        "on an error caused by code (a user template's exception), print its traceback "
        "before the one-line message"
    )
    parser.add_argument("--debug", action="store_true", help=debug_help)
    # also accepted after the command (`amsa-phys run x.yaml --debug`); SUPPRESS keeps the
    # subcommand from resetting a --debug given before it
    shared = argparse.ArgumentParser(add_help=False)
    shared.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=debug_help)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name, module in COMMANDS.items():
        doc = (module.__doc__ or "").strip().splitlines()[0]
        p = sub.add_parser(name, help=doc, description=doc, parents=[shared])
        module.add_args(p)
        p.set_defaults(func=module.run)
    return parser


#: Exit code when the reader of our output went away (``amsa-phys templates | head -1``):
#: 128 + SIGPIPE, what a program killed by the signal returns, as ``yes | head`` does.
EXIT_BROKEN_PIPE = 141


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code (tests call this in-process)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        code = int(args.func(args))
        sys.stdout.flush()  # here, where a reader that went away is caught (not at exit)
        return code
    except AmsaError as exc:
        if args.debug:
            cause = _root_cause(exc, hidden=True)
            traceback.print_exception(cause or exc, chain=False, file=sys.stderr)
        cause = _root_cause(exc)  # raised *from* code: a component's exception, not a message
        user = cause is not None and _in_user_code(cause)
        hint = " (amsa-phys --debug shows its traceback)" if user and not args.debug else ""
        print(f"error: {one_line(str(exc))}{hint}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt as exc:  # Interrupted says where; a bare one during loading
        if argv is None:  # the program itself (tests call main(argv) in their own process)
            _deaf_to_more_signals()
        print(f"error: {one_line(str(exc))}" if str(exc) else "interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE


def _deaf_to_more_signals() -> None:
    """Once the command has stopped for an interrupt, more Ctrl-C or SIGTERM are ignored.

    A user pressing Ctrl-C again while the process exits (a pool shutting down, files
    flushed, the interpreter tearing down: seconds on a loaded machine) would otherwise
    kill it by the signal's default action: exit -2 instead of 130, after the message that
    said what was kept.
    """
    import signal

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)


def _root_cause(exc: BaseException, hidden: bool = False) -> BaseException | None:
    """The exception in code (not an AmsaError) that ``exc`` was raised from, if any.

    A component's own exception reaches the user as one line (``do_step raised
    NameError(...)``); its traceback is kept on the chain (``raise ... from exc``). With
    ``hidden``, the context a ``raise ... from None`` hides counts too (``--debug`` shows
    everything it can find: a rejected change, a module that failed to import).
    """
    seen: list[BaseException] = []
    e: BaseException | None = exc
    while e is not None and e not in seen:
        seen.append(e)
        e = e.__cause__ or (e.__context__ if hidden else None)
    code = [e for e in seen if not isinstance(e, AmsaError | LookupError)]
    return code[-1] if code else None


def _in_user_code(exc: BaseException) -> bool:
    """Whether ``exc`` went through code outside amsa-phys (a user template's module)."""
    ours = (
        str(Path(__file__).resolve().parent.parent),  # amsa_phys
        sysconfig.get_paths()["stdlib"],  # importlib, when a module cannot be found
        "<frozen",
    )
    return any(
        not frame.filename.startswith(ours) for frame in traceback.extract_tb(exc.__traceback__)
    )


def _silence_stdout() -> None:
    """Point stdout at /dev/null: its reader is gone, and Python's final flush of what is
    still buffered would print a second BrokenPipeError at exit."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # no real stdout (tests capture it)
        pass
