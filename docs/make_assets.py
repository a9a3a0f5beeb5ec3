"""Regenerate the pictures of the README and the manual (``assets/``) with one command.

    python docs/make_assets.py              # every picture (minutes: two sweeps, a search)
    python docs/make_assets.py NAME ...     # only these (e.g. mde_architecture.png)
    python docs/make_assets.py --list       # each picture and the commands that make it
    python docs/make_assets.py --out DIR    # write them elsewhere (default: assets/)

Each picture is made by the project's own commands, the ones its caption names: a plot of the
paper's figures, a run's plots or snapshot, a sweep's summary, the architecture graph, the
falsification benchmark's figure, a bag drawn by ``tests/bag_plot.py``. They run from the
repository's root (the ``plot --paper`` defaults read ``scenarios/`` there), in a scratch
directory for the runs they need; a picture replaces the old one only once it is complete.
Run it after a change of the dynamics or of the drawing, and look at what moved
(``git diff --stat assets/``).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
AMSA = "amsa-phys"  # replaced by ``python -m amsa_phys`` of this interpreter when run

#: picture -> the steps that make it. ``{out}`` is the picture's path, ``{tmp}`` a scratch
#: directory shared by the steps of one picture; a step ``("copy", SRC)`` takes the picture
#: from a file a command wrote.
RECIPES: dict[str, list[tuple[str, ...]]] = {
    "paper_fig5.png": [(AMSA, "plot", "--paper", "fig5", "-o", "{out}")],
    "paper_fig6.png": [(AMSA, "plot", "--paper", "fig6", "-o", "{out}")],
    "paper_fig6_sensed.png": [(AMSA, "plot", "--paper", "fig6-sensed", "-o", "{out}")],
    "paper_fig5_start.png": [(AMSA, "plot", "--paper", "fig5-start", "-o", "{out}")],
    "paper_fig7.png": [(AMSA, "plot", "--paper", "fig7", "-o", "{out}")],
    "paper_fig6_urban_distance.png": [
        (AMSA, "run", "scenarios/paper_fig6_urban.yaml", "--headless", "-q", "--out", "{tmp}/run"),
        ("copy", "{tmp}/run/distance.png"),
    ],
    "scenario1_distance.png": [
        (AMSA, "run", "scenarios/scenario1.yaml", "--headless", "-q", "--out", "{tmp}/run"),
        ("copy", "{tmp}/run/distance.png"),
    ],
    "scenario2_distance.png": [
        (AMSA, "run", "scenarios/scenario2.yaml", "--headless", "-q", "--out", "{tmp}/run"),
        ("copy", "{tmp}/run/distance.png"),
    ],
    "scenario2_trajectory.png": [
        (AMSA, "run", "scenarios/scenario2.yaml", "--headless", "-q", "--out", "{tmp}/run"),
        ("copy", "{tmp}/run/trajectory.png"),
    ],
    "scenario2_frame.png": [
        (
            AMSA,
            "run",
            "scenarios/scenario2.yaml",
            "--headless",
            "-q",
            "--no-plot",
            "--out",
            "{tmp}/run",
            "--snapshot",
            "{out}",
            "--snapshot-at",
            "140",
        ),
    ],
    "mde_architecture.png": [(AMSA, "graph", "worlds/mde_challenge.yaml", "-o", "{out}")],
    "obstacle_course_frame.png": [
        (
            AMSA,
            "run",
            "scenarios/obstacle_course.yaml",
            "--headless",
            "-q",
            "--no-plot",
            "--out",
            "{tmp}/run",
            "--snapshot",
            "{out}",
            "--snapshot-at",
            "52",
        ),
    ],
    "obstacle_course_trajectory.png": [
        (AMSA, "run", "scenarios/obstacle_course.yaml", "--headless", "-q", "--out", "{tmp}/run"),
        ("copy", "{tmp}/run/trajectory.png"),
    ],
    "context_sweep.png": [
        (AMSA, "sweep", "scenarios/context_sweep.yaml", "--out", "{tmp}/sweep"),
        ("copy", "{tmp}/sweep/summary.png"),
    ],
    "context_sweep_large.png": [
        (AMSA, "sweep", "scenarios/context_sweep_large.yaml", "--out", "{tmp}/sweep"),
        ("copy", "{tmp}/sweep/summary.png"),
    ],
    "falsify_resonance.png": [
        ("python", "benchmarks/falsify_figure.py", "--seeds", "1"),
        ("copy", "assets/falsify_resonance.png"),
    ],
    "bag_plot.png": [
        (
            AMSA,
            "run",
            "scenarios/scenario1.yaml",
            "--headless",
            "-q",
            "--no-plot",
            "--out",
            "{tmp}/run",
            "--set",
            "Leader.behavior=2",
            "--duration",
            "300",
            "--bag",
            "{tmp}/run.mcap",
        ),
        ("python", "tests/bag_plot.py", "{tmp}/run.mcap", "{out}"),
    ],
}


def argv_of(step: tuple[str, ...], out: Path, tmp: Path) -> list[str]:
    """A step's command line, with this interpreter for ``amsa-phys`` and ``python``."""
    words = [w.format(out=out, tmp=tmp) for w in step]
    if words[0] == AMSA:
        return [sys.executable, "-m", "amsa_phys", *words[1:]]
    if words[0] == "python":
        return [sys.executable, *words[1:]]
    return words


def make(name: str, out_dir: Path) -> Path:
    """Make one picture into ``out_dir``; the old one stays until the new one is complete."""
    target = out_dir / name
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    with tempfile.TemporaryDirectory(prefix="amsa-assets-") as scratch:
        tmp = Path(scratch)
        made = tmp / f"new-{name}"
        for step in RECIPES[name]:
            if step[0] == "copy":
                shutil.copyfile(ROOT / step[1].format(tmp=tmp), made)
                continue
            subprocess.run(argv_of(step, made, tmp), cwd=ROOT, env=env, check=True)
        if not made.is_file():
            raise RuntimeError(f"{name}: the recipe wrote no picture")
        out_dir.mkdir(parents=True, exist_ok=True)
        staged = target.with_name(f".{name}.tmp")
        shutil.copyfile(made, staged)
        os.replace(staged, target)
    return target


def main(argv: list[str] | None = None) -> int:
    """Parse the arguments, then list or make the pictures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", metavar="NAME", help="pictures to make (default all)")
    parser.add_argument("--list", action="store_true", help="print each picture's commands")
    parser.add_argument("--out", type=Path, default=ROOT / "assets", help="where to write")
    args = parser.parse_args(argv)
    unknown = [n for n in args.names if n not in RECIPES]
    if unknown:
        parser.error(f"unknown picture {', '.join(unknown)}; known: {', '.join(RECIPES)}")
    names = args.names or list(RECIPES)
    if args.list:
        for name in names:
            steps = "; ".join(" ".join(s).replace("{out}", f"assets/{name}") for s in RECIPES[name])
            print(f"{name}: {steps}")
        return 0
    for name in names:
        print(f"making {name}", file=sys.stderr, flush=True)
        make(name, args.out.resolve())
    return 0


if __name__ == "__main__":
    sys.exit(main())
