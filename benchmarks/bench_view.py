"""The replay (``amsa-phys view``): loading a run, and the cost of one frame against 60 fps.

* load: trace, metrics and resolved scenario read and every history precomputed (trails,
  GPS fixes, lost fixes, running metrics);
* frame: ``ReplayScene.frame(row)`` and the renderer drawing it, at random rows (scrubbing),
  with and without the plot pane showing one signal; the live window's ``Scene.frame`` and
  renderer on the same run for comparison.

Runs scenario 2 (200 s, lost fixes) and the 11-rover platoon (60 s) headless first. Median of
N repetitions. Compare ratios: the machine is shared.
Run: ``SDL_VIDEODRIVER=dummy python benchmarks/bench_view.py [--reps 200]``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

from amsa_phys.cli.main import main
from amsa_phys.cli.view import load_run
from amsa_phys.view.camera import Camera
from amsa_phys.view.draw import Renderer
from amsa_phys.view.pg import pygame
from amsa_phys.view.plotpane import draw_pane

ROOT = Path(__file__).resolve().parent.parent
RUNS = {
    "scenario2 (200 s)": ("scenario2.yaml", []),
    "platoon (11 rovers, 60 s)": ("platoon.yaml", ["--duration", "60"]),
}
SIZE = (1280, 720)


def _median_ms(fn, reps: int) -> float:  # type: ignore[no-untyped-def]
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1000 * statistics.median(times)


def main_bench() -> None:
    """Print load time and per-frame costs for each run."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--reps", type=int, default=200)
    args = parser.parse_args()
    pygame.display.init()
    screen = pygame.display.set_mode(SIZE)
    renderer = Renderer(SIZE)
    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as tmp:
        for label, (name, extra) in RUNS.items():
            out = Path(tmp) / name
            argv = ["run", str(ROOT / "scenarios" / name), "--headless", "--no-plot", "-q"]
            with contextlib.redirect_stdout(io.StringIO()):
                main([*argv, *extra, "--out", str(out)])
            t0 = time.perf_counter()
            scene = load_run(out)
            load_ms = 1000 * (time.perf_counter() - t0)
            costs = _frame_costs(scene, screen, renderer, rng.integers(0, scene.rows, args.reps))
            print(
                f"{label}: {scene.rows} rows, load {load_ms:.0f} ms; per frame: "
                f"build {costs[0]:.2f} ms, build+draw {costs[1]:.2f} ms, "
                f"plot pane {costs[2]:.2f} ms (60 fps: 16.7 ms)"
            )


def _frame_costs(scene, screen, renderer, rows) -> tuple[float, float, float]:  # type: ignore[no-untyped-def]
    """Median ms of building a frame, building and drawing it, and drawing the plot pane."""
    camera = Camera(SIZE)
    it = iter(rows.tolist() * 3)
    reps = len(rows)

    def frame_only() -> None:
        scene.frame(next(it))

    def frame_and_draw() -> None:
        f = scene.frame(next(it))
        camera.update([(r.x, r.y, r.name) for r in f.rovers], 1e9)
        renderer.draw(screen, f, camera, ["replay"])

    signal = scene.quality.signal if scene.quality else scene.columns[1]

    def pane() -> None:
        row = next(it)
        rect = pygame.Rect(700, 400, 560, 300)
        draw_pane(screen, rect, [signal], lambda c, s: scene.series(c, row, s), 14)

    return (_median_ms(frame_only, reps), _median_ms(frame_and_draw, reps), _median_ms(pane, reps))


if __name__ == "__main__":
    main_bench()
