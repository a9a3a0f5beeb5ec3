"""The replay (``amsa-phys view``): loading a run, and the cost of one frame against 60 fps.

* load: trace, metrics and resolved scenario read and every history precomputed (trails,
  GPS fixes, lost fixes, running metrics);
* frame: ``ReplayScene.frame(row)`` and the renderer drawing it, at random rows (scrubbing),
  with and without the plot pane showing one signal; the live window's ``Scene.frame`` and
  renderer on the same run for comparison.

Runs scenario 2 (200 s, lost fixes) and the 11-rover platoon (60 s) headless first. Median of
N repetitions. Compare ratios: the machine is shared. The frame is set against a 60 fps
frame's time, and the plot pane (pygame lines) against matplotlib redrawing the same signal
on an Agg canvas of the same size, measured alongside: the reason the pane is not matplotlib.
Run: ``SDL_VIDEODRIVER=dummy python benchmarks/bench_view.py [--reps 200]`` or through
``python -m benchmarks.perf --only view``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import statistics
import sys
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
from amsa_phys.view.plotpane import SPAN_S, draw_pane

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

import results  # noqa: E402

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


#: A frame's time at 60 frames a second, ms
FRAME_MS = 1000 / 60


def perf(reps: int, report: results.Report = results.print_report) -> None:
    """Per run: loading it, and a frame's costs against 60 fps and matplotlib's redraw.

    ``reps`` rounds of 40 random frames each (the medians of each round are the samples)."""
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
            loads, build, draw, pane, mpl = [], [], [], [], []
            load_run(out)  # warm: the first load imports the replay's modules
            for _ in range(reps):
                t0 = time.perf_counter()
                scene = load_run(out)
                loads.append(1000 * (time.perf_counter() - t0))
                costs = _frame_costs(scene, screen, renderer, rng.integers(0, scene.rows, 40))
                build.append(costs[0])
                draw.append(costs[1])
                pane.append(costs[2])
                mpl.append(_matplotlib_ms(scene, rng.integers(0, scene.rows, 5)))
            report(f"view {label}: load the run, ms", _med(loads), "", None)
            report(f"view {label}: build a frame, ms", _med(build), "", None)
            ok = statistics.median(draw) <= FRAME_MS
            report(f"view {label}: build and draw a frame, ms", _med(draw), "<= 16.7", ok)
            ratio = [m / p for p, m in zip(pane, mpl, strict=True)]
            report(
                f"view {label}: matplotlib redraw / plot pane",
                f"{_med(ratio)}; pane {statistics.median(pane):.3g} ms, "
                f"matplotlib {statistics.median(mpl):.3g} ms",
                "",
                None,
            )


def _med(xs: list[float]) -> str:
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


def _matplotlib_ms(scene, rows) -> float:  # type: ignore[no-untyped-def]
    """Median ms of matplotlib redrawing the pane's signal up to a row, on an Agg canvas
    the pane's size (the figure made once, as a live pane would keep it)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    signal = scene.quality.signal if scene.quality else scene.columns[1]
    fig = Figure(figsize=(5.6, 3.0), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    (line,) = ax.plot([], [])
    it = iter(rows.tolist())

    def redraw() -> None:
        t, v = scene.series(signal, next(it), SPAN_S)
        line.set_data(t, v)
        ax.relim()
        ax.autoscale_view()
        fig.canvas.draw()

    redraw()  # the first draw lays the figure out
    return _median_ms(redraw, len(rows) - 1)


def main_bench() -> None:
    """Print load time and per-frame costs for each run."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--reps", type=int, default=5)
    args = parser.parse_args()
    perf(args.reps)


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
