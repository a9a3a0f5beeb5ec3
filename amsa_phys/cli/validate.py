"""Check worlds and scenarios without running them."""

from __future__ import annotations

import argparse
import sys

from ..errors import AmsaError, one_line
from ..model.adaptrules import describe_rules
from ..model.wording import plural
from .loading import load_any


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys validate``."""
    p.add_argument("files", nargs="+", help="world or scenario YAML files")


def run(args: argparse.Namespace) -> int:
    """One line per file: ``ok: ...`` or the error. Exit 2 if any file is bad."""
    bad = 0
    for path in args.files:
        try:
            kind, obj = load_any(path)
        except AmsaError as exc:
            print(f"error: {one_line(str(exc))}", file=sys.stderr)
            bad += 1
            continue
        if kind == "scenario":
            print(
                one_line(
                    f"ok: {path} (scenario: {plural(len(obj.world.leaves), 'component')}, "
                    f"{plural(len(obj.timeline.phases), 'phase')}, {float(obj.duration):g} s)"
                )
            )
            for line in describe_rules(obj.adapt):  # what each rule reads and sets, checked
                print(one_line(f"  adapt {line}"))
        else:
            print(one_line(f"ok: {path} (world: {plural(len(obj.leaves), 'component')})"))
    return 2 if bad else 0
