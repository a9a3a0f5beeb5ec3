"""Open the window on a finished run: play, pause, scrub, jump to events."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..errors import ConfigError, one_line
from ..runs.rundata import read_run, refuse_sweep_dir

RUN_FILES = ("trace.csv", "metrics.json", "scenario.yaml")


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys view``."""
    p.add_argument(
        "rundir",
        help="a run directory (`amsa-phys run --out`, or a sweep's kept run: SWEEP/runs/NAME)",
    )
    p.add_argument(
        "--size",
        default="1280x720",
        help="window size in pixels, WIDTHxHEIGHT (default 1280x720)",
    )


def load_run(rundir: Path) -> Any:
    """The run in ``rundir`` as a :class:`~amsa_phys.view.replay.ReplayScene`.

    Refuses, with one line naming the file, anything that is not a whole run: a missing
    directory, a sweep's directory (it names its kept runs), a missing file, a truncated
    trace, metrics that are not a run's, a trace without a row.
    """
    from ..plots.distance import read_trace
    from ..view.replay import ReplayScene

    if not rundir.is_dir():
        raise ConfigError(
            "no such directory" if not rundir.exists() else "not a directory", file=rundir
        )
    refuse_sweep_dir(rundir, "view")
    run = read_run(rundir)  # data only: nothing the run directory names is imported
    columns, data = read_trace(run.trace)
    if len(data) == 0:
        raise ConfigError("the trace has no row: nothing to replay", file=run.trace)
    return ReplayScene(columns, data, run.metrics, run.world)


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise ConfigError(f"expected WIDTHxHEIGHT, got {text!r}", key="--size") from None
    if w < 320 or h < 240:
        raise ConfigError(f"at least 320x240, got {text!r}", key="--size")
    return w, h


def untraced_note(scene: Any, rundir: Path) -> str | None:
    """The line saying which of the world's rovers the window cannot draw, or None.

    A run made with ``--trace-columns`` (or ``trace_columns:``) may keep no rover's
    ``posX``/``posY``: the window then shows an empty world while the HUD and the plot pane
    replay the run, and without a word a user takes it for a broken replay."""
    from ..palette import rover_names

    missing = [r for r in rover_names(list(scene.world.buffers)) if r not in scene.rover_names]
    if not missing:
        return None
    names = ", ".join(missing)
    if not scene.rover_names:
        what = "no rover is"
    else:
        what = f"{names} {'is' if len(missing) == 1 else 'are'} not"
    return (
        f"note: {rundir / 'trace.csv'}: no posX, posY columns for {names} (the run traced "
        f"only some buffers: trace_columns), so {what} drawn; the HUD and the plot pane (g) "
        "replay the columns it has"
    )


def run(args: argparse.Namespace) -> int:
    """Replay the run until the window is closed."""
    size = _size(args.size)
    scene = load_run(Path(args.rundir))
    note = untraced_note(scene, Path(args.rundir))
    if note is not None:
        print(one_line(note), file=sys.stderr)
    from ..view.player import Player
    from ..view.window import open_display

    try:
        open_display(interactive=True)
    except RuntimeError as exc:
        raise ConfigError(
            f"{exc}; `amsa-phys plot` draws the run's pictures without one", key="view"
        ) from None
    name = one_line(str(scene.metrics.get("scenario") or Path(args.rundir).name))
    Player(scene, title=name, size=size).run()
    return 0
