"""amsa-phys against IR-SIM, in one sitting.

IR-SIM (``pip install ir-sim``, https://github.com/hanruihua/ir-sim) is a kinematic 2D robot
simulator in Python that robotics users compare with: its differential-drive robots move by
the unicycle model, with no forces, tyres or motors. The comparison: simulated seconds per
CPU second of two differential-drive robots, one behind the other, without drawing: IR-SIM
stepping its world at 10 Hz and at 100 Hz (its ``step_time``), and amsa-phys running
scenario1 through the Python API (``amsa_phys.run``: rigid bodies in pymunk at 100 Hz,
slipping tyres, motors, the sensors, controller and monitors of the MDE world, the trace kept
in memory). The ratio says how much faster amsa-phys runs a rover second while it computes
far more; both are measured alternately, medians of ``--reps`` rounds, so the machine's load
hits both alike.

Run: ``pip install ir-sim`` (not a dependency of amsa-phys), then
``python benchmarks/bench_irsim.py [--reps 5] [--seconds 300]`` or through
``python -m benchmarks.perf --only irsim`` (which records a row saying so when IR-SIM is not
installed).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")

ROOT = Path(__file__).resolve().parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"
sys.path.insert(0, str(Path(__file__).resolve().parent))

import results  # noqa: E402

#: two diff-drive robots 15 m apart driving the same way (IR-SIM's own world format)
WORLD = """world:
  height: 20000
  width: 20000
  step_time: {dt}
  sample_time: {dt}
  offset: [-100, -10000]
robot:
  - number: 2
    distribution: {{name: 'manual'}}
    kinematics: {{name: 'diff'}}
    shape: {{name: 'circle', radius: 0.3}}
    state: [[0, 0, 0], [15, 0, 0]]
    goal: [[19000, 0, 0], [19015, 0, 0]]
    vel_max: [1, 1]
    behavior: {{name: 'dash'}}
"""


def irsim_rate(dt: float, seconds: float, tmp: Path) -> float:
    """IR-SIM's simulated seconds per CPU second at step ``dt``, without display."""
    import irsim

    world = tmp / f"two_{round(1 / dt)}hz.yaml"
    world.write_text(WORLD.format(dt=dt))
    env = irsim.make(str(world), display=False)
    steps = round(seconds / dt)
    t0 = time.process_time()
    for _ in range(steps):
        env.step()
    cpu = time.process_time() - t0
    return seconds / cpu


def amsa_rate(seconds: float) -> float:
    """amsa-phys's simulated seconds per CPU second: scenario1 through ``amsa_phys.run``."""
    import amsa_phys as ap

    t0 = time.process_time()
    ap.run(str(SCENARIO1), duration=seconds)
    return seconds / (time.process_time() - t0)


def _med(xs: list[float]) -> str:
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


def perf(reps: int, report: results.Report = results.print_report, seconds: float = 300.0) -> None:
    """amsa-phys's real-time factor (CPU) over IR-SIM's at 10 and 100 Hz, interleaved."""
    name = "amsa-phys (scenario1) / IR-SIM {} Hz, x real time (CPU)"
    if importlib.util.find_spec("irsim") is None:
        for hz in (10, 100):
            why = "not measured: IR-SIM is not installed here (pip install ir-sim)"
            report(name.format(hz), why, "", None, skipped=True)
        return
    import logging

    logging.disable(logging.WARNING)
    rates: dict[str, list[float]] = {"irsim 10 Hz": [], "irsim 100 Hz": [], "amsa-phys": []}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        amsa_rate(10.0)  # warm: imports, the compiled step
        irsim_rate(0.1, 10.0, tmp)
        for _ in range(reps):
            rates["amsa-phys"].append(amsa_rate(seconds))
            rates["irsim 10 Hz"].append(irsim_rate(0.1, seconds, tmp))
            rates["irsim 100 Hz"].append(irsim_rate(0.01, seconds, tmp))
    amsa = rates["amsa-phys"]
    for hz in (10, 100):
        theirs = rates[f"irsim {hz} Hz"]
        ratio = [a / b for a, b in zip(amsa, theirs, strict=True)]
        report(
            name.format(hz),
            f"{_med(ratio)}; amsa-phys {statistics.median(amsa):,.0f}x, "
            f"IR-SIM {statistics.median(theirs):,.0f}x real time",
            "",
            None,
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--seconds", type=float, default=300.0)
    args = parser.parse_args()
    perf(args.reps, results.print_report, args.seconds)


if __name__ == "__main__":
    main()
