"""Recording throughput: frames per second rendered, rendered + encoded, and encoded alone.

Three measurements of scenario2 at ``--size`` (default 1280x720), 30 fps:

* **render**: simulate and draw every frame, no encoder (the drawing cost);
* **record**: simulate, draw and encode to H.264 (what ``--record out.mp4`` does);
* **encoder alone**: the same ffmpeg fed pre-rendered frames from memory (the floor).

Run: ``python benchmarks/bench_record.py [--reps 5] [--duration 60] [--size 1280x720]``.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import tempfile
import time
from fractions import Fraction
from pathlib import Path

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

from amsa_phys.cli.recording import parse_size
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.view.camera import Camera
from amsa_phys.view.draw import Renderer
from amsa_phys.view.drive import advance
from amsa_phys.view.encoder import VideoEncoder
from amsa_phys.view.scene import Scene
from amsa_phys.view.video import PIX_FMT, Recorder, RecordOptions, new_surface

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / "scenarios" / "scenario2.yaml"
FPS = 30


class RenderOnly:
    """A recorder without the encoder: the drawing cost alone."""

    def __init__(self, sim: Simulation, size: tuple[int, int], quality) -> None:
        self.sim = sim
        self.period = Fraction(1, FPS)
        self.total = math.ceil(sim.duration / self.period)
        self.index = 0
        self.scene = Scene(sim, quality)
        self.camera = Camera(size)
        self.renderer = Renderer(size)
        self.surface = new_surface(size)
        self.last_view = None

    def next_time(self) -> Fraction | None:
        return self.period * self.index if self.index < self.total else None

    def capture(self) -> None:
        frame = self.scene.frame(t=float(self.period * self.index))
        self.camera.update([(r.x, r.y, r.name) for r in frame.rovers], float(self.period))
        self.renderer.draw(self.surface, frame, self.camera)
        view = self.surface.get_view("0")  # what the recorder hands over, then drops
        del view
        self.index += 1


def simulate(duration: float, size: tuple[int, int], encode: bool, out: Path) -> tuple[float, int]:
    """Wall seconds and frames for one run rendered (and encoded)."""
    sc = load_scenario(SCENARIO, duration=duration)
    sim = Simulation.from_scenario(sc)
    sim.initialize()
    t0 = time.perf_counter()
    if encode:
        sink = Recorder(sim, RecordOptions(out, size, FPS), sc.quality)
        advance(sim, sim.grid.ticks(sim.duration), [sink])
        sink.close()
    else:
        sink = RenderOnly(sim, size, sc.quality)
        advance(sim, sim.grid.ticks(sim.duration), [sink])
    return time.perf_counter() - t0, sink.index


def encoder_alone(frames: int, size: tuple[int, int], out: Path) -> float:
    """Wall seconds to encode ``frames`` pre-rendered frames (30 distinct ones, cycled)."""
    sc = load_scenario(SCENARIO, duration=30)
    sim = Simulation.from_scenario(sc)
    sim.initialize()
    grab = RenderOnly(sim, size, sc.quality)
    pictures = []
    for k in range(30):
        sim.advance(sim.grid.ticks(Fraction(k)))
        grab.capture()
        pictures.append(bytes(grab.surface.get_view("0")))
    enc = VideoEncoder(out, size, FPS, PIX_FMT)
    t0 = time.perf_counter()
    for k in range(frames):
        enc.submit(pictures[k % 30])
    enc.close()
    return time.perf_counter() - t0


def measure(reps: int, duration: float, size: tuple[int, int]) -> dict[str, list[float]]:
    """Frames per second of each path, ``reps`` times."""
    fps: dict[str, list[float]] = {"render": [], "record": [], "encoder alone": []}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.mp4"
        for _ in range(reps):
            wall, n = simulate(duration, size, False, out)
            fps["render"].append(n / wall)
            wall, n = simulate(duration, size, True, out)
            fps["record"].append(n / wall)
            fps["encoder alone"].append(n / encoder_alone(n, size, out))
    return fps


def main() -> None:
    """Measure and print."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--size", default="1280x720")
    args = ap.parse_args()
    size = parse_size(args.size)
    fps = measure(args.reps, args.duration, size)
    for name, xs in fps.items():
        print(
            f"{name:14s} median {statistics.median(xs):6.0f} frames/s "
            f"(min {min(xs):.0f}, max {max(xs):.0f})"
        )
    rec, ren, enc = (statistics.median(fps[k]) for k in ("record", "render", "encoder alone"))
    print(
        f"record / render alone: {rec / ren:.2f}   encoder alone / record time: "
        f"{enc / rec:.2f}  ({size[0]}x{size[1]}, {args.duration:g} s at {FPS} fps, "
        f"{args.reps} repetitions)"
    )


if __name__ == "__main__":
    main()
