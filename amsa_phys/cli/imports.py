"""Import an original AMSA model (.amsacore + .amsatemplate) as a world file."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from ..errors import ConfigError
from ..interop.importer import import_model
from ..model.world import load_world


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
    for given in (model, templates):
        if given is not None and given.exists() and out.exists() and out.samefile(given):
            raise ConfigError("is an input of the import; choose another file", key="-o", file=out)
    if out.is_dir():
        raise ConfigError("is a directory, expected a world file name", key="-o", file=out)
    if (out.exists() or out.is_symlink()) and not args.force:
        raise ConfigError("exists (use --force to replace it)", key="-o", file=out)
    imported = import_model(model, templates, args.template_module)
    tmp = out.with_name(f".{out.name}.tmp-{os.getpid()}")
    try:
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
            tmp.write_text(imported.text)
        except OSError as exc:
            raise ConfigError(f"cannot write: {exc.strerror}", key="-o", file=out) from None
        try:
            world = load_world(tmp)  # the world must validate before it gets its name
        except ConfigError as exc:  # name the model, not the temporary file (removed below)
            where = f"line {exc.line} of " if exc.line else ""
            key = f"{exc.key}: " if exc.key else ""
            raise ConfigError(
                f"the world it imports to does not load ({where}the world {out.name}: "
                f"{key}{exc.message})",
                file=model,
            ) from None
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)
    for warning in imported.warnings:
        print(f"warning: {warning}", file=sys.stderr)
    print(
        f"wrote {out} (world {world.name}: {len(world.leaves)} components, "
        f"{len(imported.warnings)} warnings)"
    )
    return 0
