"""Choosing and preparing a run's output directory.

An existing directory is never overwritten without ``force``; an unwritable location is
reported before the run starts, not after minutes of simulation.
"""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

from ..errors import ConfigError


def default_run_dir(scenario_name: str, root: Path = Path("runs")) -> Path:
    """``runs/<scenario>-<YYYYmmdd-HHMMSS>`` (a suffix is added if it exists already)."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    base = root / f"{scenario_name}-{stamp}"
    out = base
    n = 1
    while out.exists():
        n += 1
        out = base.with_name(f"{base.name}-{n}")
    return out


def prepare_run_dir(out: Path, force: bool) -> Path:
    """Create ``out`` (refusing to reuse a non-empty one unless ``force``)."""
    if out.exists():
        if not out.is_dir():
            raise ConfigError("exists and is not a directory", key="--out", file=out)
        if any(out.iterdir()):
            if not force:
                raise ConfigError(
                    "directory exists and is not empty (use --force to replace it)",
                    key="--out",
                    file=out,
                )
            shutil.rmtree(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(
            f"cannot create directory: {exc.strerror}", key="--out", file=out
        ) from None
    if not os.access(out, os.W_OK):
        raise ConfigError("directory is not writable", key="--out", file=out)
    return out
