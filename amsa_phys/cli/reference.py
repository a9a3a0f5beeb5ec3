"""The command-line reference as Markdown, generated from the argparse parsers themselves.

The manual's CLI page is this module's output (``python -m amsa_phys.cli.reference
docs/reference/cli.md``), committed, and a test regenerates it and fails when the two differ:
an option added to a command without rebuilding the page is caught, and the page can never
describe flags the parser does not have. Rendering reads argparse's action list (the same data
``--help`` prints from) at a fixed width, so the page does not depend on the terminal.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from pathlib import Path

from ..atomic import write_atomic
from .main import COMMANDS, build_parser

#: Width the usage lines are wrapped at (argparse reads $COLUMNS otherwise).
WIDTH = 96

HEADER = """# Command-line reference

*Generated from the argparse parsers by `python -m amsa_phys.cli.reference
docs/reference/cli.md`; a test fails when this page is out of date. Exit codes of every
command: 0 done, 1 an expectation failed (or a falsification found a violation), 2 bad input
or usage (one line naming the file, line and key), 3 a fault during a run, 130 interrupted
(outputs finalised).*
"""


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")


def _flags(action: argparse.Action) -> str:
    if not action.option_strings:
        return f"`{action.metavar or action.dest}`"
    shown = []
    for flag in action.option_strings:
        if action.nargs == 0:
            shown.append(f"`{flag}`")
        else:
            metavar = action.metavar or (
                "{" + ",".join(map(str, action.choices)) + "}"
                if action.choices
                else action.dest.upper()  # as argparse spells it in the usage line
            )
            shown.append(f"`{flag} {metavar}`")
    return ", ".join(shown)


def _options(parser: argparse.ArgumentParser, skip: frozenset[str]) -> Iterator[str]:
    rows = []
    for action in parser._actions:  # argparse keeps no public list of its actions
        if isinstance(action, argparse._SubParsersAction | argparse._HelpAction):
            continue
        if action.help == argparse.SUPPRESS or action.dest in skip:
            continue
        # as --help prints it: argparse expands %(default)s and friends, and %% is a %
        help_text = action.help or ""
        if "%" in help_text:
            try:
                help_text = help_text % {**vars(action), "prog": parser.prog}
            except (KeyError, TypeError, ValueError):
                help_text = help_text.replace("%%", "%")
        if action.choices and action.option_strings and "{" not in _flags(action):
            help_text += f" (one of {', '.join(map(str, action.choices))})"
        rows.append(f"| {_flags(action)} | {_cell(help_text)} |")
    if rows:
        yield "| argument | meaning |"
        yield "| --- | --- |"
        yield from rows
        yield ""


def _usage(parser: argparse.ArgumentParser) -> str:
    formatter = argparse.HelpFormatter(parser.prog, width=WIDTH)
    formatter.add_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups)
    return formatter.format_help().strip()


def _section(
    parser: argparse.ArgumentParser, level: int, skip: frozenset[str] = frozenset()
) -> Iterator[str]:
    yield f"{'#' * level} `{parser.prog}`"
    yield ""
    if parser.description:
        yield _cell(parser.description)
        yield ""
    yield "```text"
    yield _usage(parser)
    yield "```"
    yield ""
    yield from _options(parser, skip)
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) and level > 2:
            for sub in dict.fromkeys(action.choices.values()):  # aliases once
                yield from _section(sub, level + 1, skip)


def render() -> str:
    """The whole reference page."""
    lines = [HEADER]
    top = build_parser(only=None)
    lines.extend(_section(top, 2))
    lines.append("| command | does |")
    lines.append("| --- | --- |")
    lines.extend(
        f"| [`{name}`](#amsa-phys-{name}) | {doc} |" for name, (_, doc) in COMMANDS.items()
    )
    lines.append("")
    for name in COMMANDS:
        parser = build_parser(only=name)
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        # --debug is every command's (documented once above)
        lines.extend(_section(sub.choices[name], 3, skip=frozenset({"debug"})))
    return "\n".join(lines).rstrip() + "\n"


def main(argv: list[str] | None = None) -> int:
    """Write the page to the file named (or print it)."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) > 1 or (args and args[0].startswith("-")):
        sys.stderr.write("usage: python -m amsa_phys.cli.reference [PAGE.md]\n")
        return 0 if args[0] in ("-h", "--help") else 2
    text = render()
    if args:
        write_atomic(Path(args[0]), text.encode())
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
