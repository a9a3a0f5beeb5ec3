"""Draw the architecture of a world or scenario, components coloured by kind."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import ConfigError, one_line
from ..runs.outfile import check_output_file, drawn_by_us
from .loading import load_any


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys graph``."""
    p.add_argument("file", help="world or scenario YAML file")
    p.add_argument(
        "-o",
        "--output",
        required=True,
        help="OUT.png, OUT.svg or OUT.dot; an existing file is replaced only if amsa-phys drew it",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="replace an existing -o file that amsa-phys did not draw (a link: the link)",
    )
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
    check_output_file(out, "--output", args.force, [Path(args.file)], ours=drawn_by_us)
    kind, obj = load_any(args.file)
    world = obj.world if kind == "scenario" else obj
    from ..plots.graph import MAX_BOXES, SLOW_BOXES, draw, structure  # matplotlib: here

    if out.suffix.lower() != ".dot":
        st = structure(world, collapse=not args.expand)
        boxes, links = len(st.nodes), len({(a, b) for a, b, _ in st.links})
        if boxes > MAX_BOXES:
            hint = "drop --expand (copies drawn once), or " if args.expand else ""
            raise ConfigError(
                f"{boxes} components are too many to draw (at most {MAX_BOXES}): {hint}"
                "write a .dot file for Graphviz",
                key="--expand" if args.expand else "--output",
            )
        if boxes >= SLOW_BOXES:  # the label layout takes a while: say so before it starts
            print(
                one_line(f"laying out {boxes} components and {links} links (seconds per 100)..."),
                file=sys.stderr,
                flush=True,
            )
    draw(world, out, collapse=not args.expand)
    print(one_line(f"wrote {out}"))
    return 0
