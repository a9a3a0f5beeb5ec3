"""``amsa-phys``: parse, dispatch, and turn an AmsaError into one line and an exit code.

Only this module catches AmsaError. Any other exception keeps its traceback: it is a bug.
Exit codes: 0 done, 1 an expectation failed, 2 bad input or usage, 3 a run fault,
130 interrupted.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
import sysconfig
import threading
import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal, NoReturn

from .._version import __version__
from ..errors import AmsaError, one_line

# One BLAS thread unless the user chose otherwise, set before any command imports numpy.
# numpy's OpenBLAS starts a thread per core at import, and they spin for a while: ~45 ms
# CPU of an ``amsa-phys run`` (a sixth of it), for no use, since nothing in a run is a
# large matrix product. Sweep and plot workers inherit it: N processes never contend with
# N more BLAS threads each.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

#: command -> (its module in this package, its one-line help: the module docstring's first
#: line, which a test keeps equal). Modules are imported only for the command that runs:
#: ``amsa-phys --help`` must not pay for numpy, jsonschema, pymunk or matplotlib.
COMMANDS = {
    "run": ("run", "Run one scenario and write its run directory."),
    "validate": ("validate", "Check worlds and scenarios without running them."),
    "describe": (
        "describe",
        "Components, kinds, parameters with ranges, links and execution order of a file.",
    ),
    "templates": (
        "templates",
        "List the template library: kind, ports and parameters of every built-in and plugin "
        "template.",
    ),
    "plot": (
        "plot",
        "Redraw a run's plots from its trace and metrics, or a sweep's summary from results.csv.",
    ),
    "test": ("test", "Run every scenario with expectations; print pass/fail against the bounds."),
    "sweep": (
        "sweep",
        "Exhaustive exploration: a parameter grid × seeds in parallel, on this machine or Dask.",
    ),
    "falsify": (
        "falsify",
        "Falsification: search a box of context parameters for the worst case with CMA-ES.",
    ),
    "monitor": ("monitor", "Evaluate an STL formula's robustness on a finished run's trace."),
    "graph": (
        "graph",
        "Draw the architecture of a world or scenario, components coloured by kind.",
    ),
    "export": (
        "export",
        "Export a scenario as a ROS package, or a world as the original AMSA files.",
    ),
    "ros2": (
        "ros2",
        "ROS 2: run an exported package's nodes against the simulator (lockstep), or on a robot.",
    ),
    "import": (
        "imports",
        "Import an original AMSA model (.amsacore + .amsatemplate) as a world file.",
    ),
    "adapt": (
        "adapt",
        "Derive adapt: rules from a context sweep: best parameters per context, on estimators.",
    ),
    "tune": (
        "tune",
        "Robust tuning: the controller parameters best in the worst case over a context set.",
    ),
    "view": ("view", "Open the window on a finished run: play, pause, scrub, jump to events."),
}


def command_module(name: str) -> Any:
    """The module implementing command ``name`` (imported now)."""
    return importlib.import_module(f".{COMMANDS[name][0]}", __package__)


def chosen_command(argv: Sequence[str]) -> str | None:
    """The command ``argv`` names: its first word that is not an option (the top-level
    options take no value), if it is a command."""
    for word in argv:
        if not word.startswith("-"):
            return word if word in COMMANDS else None
    return None


class _Version(argparse.Action):
    """``--version``: the version and which physics step runs (said once, here)."""

    def __init__(self, option_strings: Sequence[str], dest: str, **kwargs: Any) -> None:
        super().__init__(option_strings, dest, nargs=0, help="show the version and exit")

    def __call__(self, parser: argparse.ArgumentParser, *args: Any) -> NoReturn:
        from ..physics.step_path import describe as step_path

        print(f"amsa-phys {__version__} (physics step: {step_path()[1]})")  # stdout, as argparse
        parser.exit(0)


class _Parser(argparse.ArgumentParser):
    """argparse with usage errors as one line (exit 2), pointing at ``--help``.

    No abbreviated options: ``--hea`` taken for ``--headless`` hides a typo, and an option
    added later would change what an old abbreviation means in users' scripts.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)
        self._words: list[str] = []

    def parse_known_args(self, args: Any = None, namespace: Any = None) -> Any:
        """argparse's, remembering the words: an unknown option is reported by the top
        parser, which needs them to find the command whose options to suggest."""
        self._words = [str(w) for w in (sys.argv[1:] if args is None else args)]
        return super().parse_known_args(args, namespace)

    def _options(self) -> list[str]:
        """Every option this command line could have meant: the top parser's and those of
        the command given (``run``'s ``--headless``), in declaration order."""
        parsers: list[argparse.ArgumentParser] = [self]
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                chosen = next((w for w in self._words if w in action.choices), None)
                if chosen is not None:
                    parsers.append(action.choices[chosen])
        return [o for p in parsers for a in p._actions for o in a.option_strings]

    def _option_hint(self, word: str) -> str:
        """`` (did you mean --headless?)`` for a mistyped option: the only option it
        begins (``--hea``, which Python 3.11's argparse does not suggest and an
        abbreviation must not silently take), else the nearest by spelling."""
        if not word.startswith("-"):
            return ""
        name = word.split("=", 1)[0]
        options = self._options()
        begun = [o for o in options if o.startswith("--") and o.startswith(name) and o != name]
        if len(begun) == 1 and len(name) > 2:
            return f" (did you mean {begun[0]}?)"
        from ..model.suggest import did_you_mean

        return did_you_mean(name, [o for o in options if o.startswith("--")])

    def error(self, message: str) -> NoReturn:
        """Print ``error: <prog>: <message>`` and exit 2 (a mistyped command gets a
        "did you mean", as every other name does)."""
        bad = re.match(r"argument COMMAND: invalid choice: '([^']*)'", message)
        if bad is not None:
            from ..model.suggest import did_you_mean

            hint = did_you_mean(bad.group(1), list(COMMANDS))
            if hint:
                message = f"unknown command {bad.group(1)!r}{hint}"
        extra = re.match(r"unrecognized arguments: (.*)", message)
        if extra is not None:
            words = extra.group(1).split(" ")
            message = "unrecognized arguments: " + " ".join(w + self._option_hint(w) for w in words)
        # argparse quotes the value it refused whole ("invalid int value: '999...'"): a value
        # of thousands of characters is said by its ends, so the line stays one to read
        message = re.sub(
            r"'([^']{81,})'", lambda m: f"'{m.group(1)[:40]}...{m.group(1)[-20:]}'", message
        )
        self.exit(2, one_line(f"error: {self.prog}: {message} (see {self.prog} --help)") + "\n")


def build_parser(only: str | Literal[False] | None = False) -> argparse.ArgumentParser:
    """The argument parser: every command's options, or (``only``) just that command's.

    ``only=None``: no command's options (enough for ``--help`` and usage errors); other
    commands are listed with their help either way.
    """
    parser = _Parser(
        prog="amsa-phys",
        description="Physics-backed 2D rover testbed implementing the AMSA framework.",
    )
    parser.add_argument("--version", action=_Version)
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
    for name, (_, doc) in COMMANDS.items():
        p = sub.add_parser(name, help=doc, description=doc, parents=[shared])
        if only is False or only == name:
            module = command_module(name)
            module.add_args(p)
            p.set_defaults(func=module.run)
            _debug_in_nested(p, debug_help)
    return parser


def _debug_in_nested(parser: argparse.ArgumentParser, debug_help: str) -> None:
    """``--debug`` accepted after a command's own subcommand too (``amsa-phys export ros2 ...
    --debug``), as after the command: each nested parser gets it, defaulting to SUPPRESS
    so that a ``--debug`` given earlier stands."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for nested in dict.fromkeys(action.choices.values()):
                if "--debug" not in nested._option_string_actions:
                    nested.add_argument(
                        "--debug", action="store_true", default=argparse.SUPPRESS, help=debug_help
                    )
                _debug_in_nested(nested, debug_help)


#: Exit code when the reader of our output went away (``amsa-phys templates | head -1``):
#: 128 + SIGPIPE, what a program killed by the signal returns, as ``yes | head`` does.
EXIT_BROKEN_PIPE = 141


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code (tests call this in-process)."""
    words = sys.argv[1:] if argv is None else argv
    parser = build_parser(only=chosen_command(words))
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
    finally:
        if argv is None:  # the program itself: its modules' bytecode for the next one
            from .. import bytecode

            bytecode.warm()


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
