"""Plots never slow the run: a wide run's whole process with plots against ``--no-plot``.

The run is scenarios/platoon.yaml with the world's ``count:`` raised to 199 cars (200 rovers)
for 30 simulated seconds, run as ``amsa-phys run --headless`` processes, with and without
plots, interleaved so drifting machine load hits both alike. The target: the run
with plots takes at most 1.3x the run without.
Run: ``python benchmarks/bench_plots.py [--reps 3] [--cars 199]``.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent


def wide_platoon(cars: int, tmp: Path, duration: float = 30.0) -> Path:
    """scenarios/platoon.yaml around a copy of its world with ``count: cars``."""
    scen = yaml.safe_load((ROOT / "scenarios" / "platoon.yaml").read_text())
    world_path = (ROOT / "scenarios" / scen["world"]).resolve()
    world = yaml.safe_load(world_path.read_text())
    world["components"]["Car"]["count"] = cars
    (tmp / f"platoon{cars}.yaml").write_text(yaml.safe_dump(world, sort_keys=False))
    scen["world"] = f"platoon{cars}.yaml"
    scen["duration"] = duration
    scen.pop("expect", None)  # checks of the 10-car column; not what is measured here
    out = tmp / f"platoon{cars}_scenario.yaml"
    out.write_text(yaml.safe_dump(scen, sort_keys=False))
    return out


def run_process(scen: Path, out: Path, plot: bool) -> float:
    """Wall seconds of one ``amsa-phys run --headless`` process."""
    argv = [sys.executable, "-m", "amsa_phys", "run", str(scen), "--headless", "-q"]
    argv += ["--out", str(out)] + ([] if plot else ["--no-plot"])
    t0 = time.perf_counter()
    subprocess.run(argv, check=True, capture_output=True)
    return time.perf_counter() - t0


def measure(reps: int, cars: int = 199) -> dict[str, list[float]]:
    """{"plots": [...], "no plots": [...]} wall seconds, ``reps`` of each, interleaved."""
    walls: dict[str, list[float]] = {"plots": [], "no plots": []}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        scen = wide_platoon(cars, tmp)
        for i in range(reps):
            walls["no plots"].append(run_process(scen, tmp / f"n{i}", plot=False))
            walls["plots"].append(run_process(scen, tmp / f"p{i}", plot=True))
    return walls


def verdict(reps: int) -> tuple[str, bool]:
    """perf.py's line: (what was measured, whether the 1.3x target is met)."""
    walls = measure(reps)
    ratio = statistics.median(walls["plots"]) / statistics.median(walls["no plots"])
    spread = ", ".join(
        f"{name} {statistics.median(xs):.2f} s (min {min(xs):.2f}, max {max(xs):.2f})"
        for name, xs in walls.items()
    )
    return f"{ratio:.2f}; {spread}", ratio <= 1.3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--cars", type=int, default=199)
    args = ap.parse_args()
    walls = measure(args.reps, args.cars)
    for name, xs in walls.items():
        print(f"{name:9s} {statistics.median(xs):.2f} s (min {min(xs):.2f}, max {max(xs):.2f})")
    print(f"ratio {statistics.median(walls['plots']) / statistics.median(walls['no plots']):.2f}")


if __name__ == "__main__":
    main()
