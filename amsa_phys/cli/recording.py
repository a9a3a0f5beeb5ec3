"""``--record``, ``--fps``, ``--size``, ``--speedup``: parsed and checked before the run starts.

Everything that can be wrong with a recording request (extension, odd size, a directory that
does not exist, a file that would be overwritten) is refused here with exit 2, before any
simulated second is spent.
"""

from __future__ import annotations

import argparse
import os
import re
from fractions import Fraction
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import ConfigError
from ..runs.rundir import unwritable
from ..view.encoder import FORMATS

if TYPE_CHECKING:
    from ..view.video import RecordOptions, SnapshotOptions

MAX_SIDE = 7680


def add_recording(p: argparse.ArgumentParser) -> None:
    """The video options of ``run``."""
    p.add_argument("--record", metavar="FILE", help="write a video: FILE.mp4 (H.264) or FILE.gif")
    p.add_argument("--fps", type=int, help="video frames per second (default 30)")
    p.add_argument(
        "--size", metavar="WxH", help="video (and --snapshot) size in pixels (default 1280x720)"
    )
    p.add_argument(
        "--snapshot",
        metavar="FILE.png",
        help="also save one rendered frame (at --size) as a PNG picture",
    )
    p.add_argument(
        "--snapshot-at",
        type=float,
        metavar="S",
        help="simulated time of the --snapshot picture (default: the end of the run)",
    )
    p.add_argument(
        "--speedup",
        metavar="K",
        help="K simulated seconds per video second (default 1: video time = simulated time)",
    )


def parse_size(text: str) -> tuple[int, int]:
    """``1280x720`` -> (1280, 720): even (yuv420p needs it), 64..7680 a side."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m:
        raise ConfigError(f"expected WIDTHxHEIGHT like 1280x720, got {text!r}", key="--size")
    w, h = int(m.group(1)), int(m.group(2))
    if not (64 <= w <= MAX_SIDE and 64 <= h <= MAX_SIDE):
        raise ConfigError(f"{w}x{h}: each side must be 64..{MAX_SIDE} pixels", key="--size")
    if w % 2 or h % 2:
        raise ConfigError(f"{w}x{h}: width and height must be even (H.264 yuv420p)", key="--size")
    return w, h


DEFAULT_FPS = 30
DEFAULT_SIZE = "1280x720"


def recording_options(args: argparse.Namespace) -> RecordOptions | None:
    """The checked recording request, or None without ``--record``. A video option without
    ``--record`` (``--size`` without ``--snapshot`` either) is refused: it would do nothing,
    silently, as ``--snapshot-at`` without ``--snapshot`` would."""
    if args.record is None:
        given = [o for o, v in (("--fps", args.fps), ("--speedup", args.speedup)) if v is not None]
        if args.size is not None and args.snapshot is None:
            given.append("--size")
        if given:
            what = (
                "--record FILE or --snapshot FILE.png" if given[0] == "--size" else "--record FILE"
            )
            raise ConfigError(f"needs {what}: alone it would do nothing", key=given[0])
    size = parse_size(args.size or DEFAULT_SIZE)
    fps = DEFAULT_FPS if args.fps is None else args.fps
    if not 1 <= fps <= 240:
        raise ConfigError(f"{fps}: frames per second must be 1..240", key="--fps")
    text = "1" if args.speedup is None else args.speedup
    try:
        speedup = Fraction(str(text).strip())
    except (ValueError, ZeroDivisionError):
        raise ConfigError(f"expected a number, got {text!r}", key="--speedup") from None
    if not 0 < speedup <= 10_000:
        raise ConfigError(f"{text}: must be above 0 and at most 10000", key="--speedup")
    if args.record is None:
        return None
    path = recording_target(args.record, FORMATS, "--record", args.force)
    from ..view.video import RecordOptions

    return RecordOptions(path, size, fps, speedup)


def snapshot_options(args: argparse.Namespace) -> SnapshotOptions | None:
    """The checked ``--snapshot`` request, or None."""
    if args.snapshot is None:
        if args.snapshot_at is not None:
            raise ConfigError("needs --snapshot FILE.png", key="--snapshot-at")
        return None
    path = recording_target(args.snapshot, (".png",), "--snapshot", args.force)
    at = None
    if args.snapshot_at is not None:
        if not 0 <= args.snapshot_at < 1e9:
            raise ConfigError(f"{args.snapshot_at}: must be 0 or more", key="--snapshot-at")
        at = Fraction(str(args.snapshot_at))
    from ..view.video import SnapshotOptions

    return SnapshotOptions(path, parse_size(args.size or DEFAULT_SIZE), at)


def recording_target(name: str, formats: tuple[str, ...], flag: str, force: bool) -> Path:
    """An output file we may write: known extension, existing writable directory, no clobber."""
    if not str(name).strip():
        raise ConfigError("an empty file name", key=flag)
    path = Path(name)
    if path.suffix.lower() not in formats:
        hint = ""
        if path.suffix.lower() == ".bag" and ".mcap" in formats:
            hint = (
                " (for a ROS 1 .bag, write the .mcap and convert it: "
                "rosbags-convert --src run.mcap --dst run.bag)"
            )
        raise ConfigError(
            f"unknown format {path.suffix or '(none)'!r}; use " + " or ".join(formats) + hint,
            key=flag,
            file=path,
        )
    parent = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise ConfigError("is a directory; give a file name", key=flag, file=path)
    if not parent.is_dir():
        why = f"{parent} is not a directory" if parent.exists() else "directory does not exist"
        raise ConfigError(why, key=flag, file=path)
    if not os.access(parent, os.W_OK) or (why := unwritable(parent)) is not None:
        raise ConfigError(
            f"directory is not writable ({why})" if why else "directory is not writable",
            key=flag,
            file=path,
        )
    if path.exists() and not force:
        raise ConfigError("file exists (use --force to replace it)", key=flag, file=path)
    return path
