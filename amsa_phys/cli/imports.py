"""Import an original AMSA model (.amsacore + .amsatemplate) as a world file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..atomic import AtomicFile
from ..errors import ConfigError
from ..interop.importer import import_model
from ..model.world import load_world
from ..runs.outfile import check_output_file, refuse_input_file
from ..runs.rundir import check_output


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys import``."""
    p.add_argument("model", help="the AMSA model (.amsacore, XMI)")
    p.add_argument(
        "--templates",
        metavar="FILE",
        help="the AMSA template file (.amsatemplate; default: the one the model names)",
    )
    p.add_argument(
        "--template-module",
        action="append",
        default=[],
        metavar="MODULE",
        help="a Python module the model names as a template's implementation (mypkg.rovers): "
        "import it (import never imports code a file names unless told to); repeatable",
    )
    p.add_argument("-o", "--out", required=True, metavar="WORLD.yaml", help="the world to write")
    p.add_argument("--force", action="store_true", help="replace an existing WORLD.yaml")


def run(args: argparse.Namespace) -> int:
    """Read, convert, check by loading, then rename into place; warnings one line each."""
    model = Path(args.model)
    templates = Path(args.templates) if args.templates else None
    out = Path(args.out)
    if not out.parent.exists():  # ``-o new/dir/w.yaml``: made, as for any output directory
        check_output(out, "-o", make_parent=True)
    inputs = [p for p in (model, templates) if p is not None]
    out = check_output_file(out, "-o", args.force, inputs)
    imported = import_model(model, templates, args.template_module)
    if imported.templates is not None:  # the sibling the model names, read too
        refuse_input_file(out, [imported.templates], "-o")
    # the outfile rule's writer: an exclusive temporary name that never follows a link
    # planted there (a guessable ``.NAME.tmp-PID`` was written through to the link's target)
    written = AtomicFile(out)
    try:
        written.write(imported.text.encode("utf-8"))
        try:
            world = load_world(written.tmp)  # the world must validate before it gets its name
        except ConfigError as exc:  # name the model, not the temporary file (removed below)
            where = f"line {exc.line} of " if exc.line else ""
            key = f"{exc.key}: " if exc.key else ""
            raise ConfigError(
                f"the world it imports to does not load ({where}the world {out.name}: "
                f"{key}{exc.message})",
                file=model,
            ) from None
    except BaseException:
        written.discard()
        raise
    written.commit()
    for warning in imported.warnings:
        print(f"warning: {warning}", file=sys.stderr)
    print(
        f"wrote {out} (world {world.name}: {len(world.leaves)} components, "
        f"{len(imported.warnings)} warnings)"
    )
    return 0
