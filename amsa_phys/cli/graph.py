"""Draw the architecture of a world or scenario, components coloured by kind."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import ConfigError, one_line
from ..runs.rundir import check_output
from .loading import load_any


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys graph``."""
    p.add_argument("file", help="world or scenario YAML file")
    p.add_argument("-o", "--output", required=True, help="OUT.png, OUT.svg or OUT.dot")
    p.add_argument(
        "--expand",
        action="store_true",
        help="draw every copy of a repeated Composite (default: Car{i}.Robot once, ×N)",
    )


def run(args: argparse.Namespace) -> int:
    """Load and draw."""
    out = Path(args.output)
    if out.suffix.lower() not in (".png", ".svg", ".dot"):
        raise ConfigError("expected a .png, .svg or .dot file name", key="--output", file=out)
    check_output(out, "--output")
    kind, obj = load_any(args.file)
    world = obj.world if kind == "scenario" else obj
    from ..plots.graph import draw  # matplotlib: imported by the commands that draw

    draw(world, out, collapse=not args.expand)
    print(one_line(f"wrote {out}"))
    return 0
