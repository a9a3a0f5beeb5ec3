"""The compiled physics step and what is around the loop, each against a baseline.

* headless scenario1 in-process with the compiled step vs the pure-Python step, interleaved
  in one process (``AMSA_PHYS_PURE`` switched between runs): >= 2.3x, and >= 2,400x real time;
* the whole ``amsa-phys run scenarios/scenario1.yaml --headless`` process <= 0.8 s (and the
  same with ``--no-plot``, to show the plot child's share);
* ``amsa-phys --help`` <= 0.15 s (against a bare ``python -c pass`` for the floor);
* a 1,000-rover platoon (worlds/platoon.yaml with ``count: 999``) >= 20x real time, with the
  collision index chosen by size (a spatial hash) and, for the ratio, the bounding-box tree.

Run: ``python benchmarks/bench_compiled.py [--reps 5]`` or through ``perf.py --only compiled``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"
Report = Callable[[str, str, str, bool], None]


def med(xs: list[float]) -> str:
    """``median (min..max)`` with sensible digits."""
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


def _print_report(name: str, measured: str, target: str, ok: bool) -> None:
    print(f"{'PASS' if ok else 'MISS'}  {name:34s} {measured}   target {target}", flush=True)


@contextmanager
def pure(on: bool) -> Iterator[None]:
    """Run the block with the pure-Python step (``AMSA_PHYS_PURE=1``) or the compiled one."""
    from amsa_phys.physics.step_path import PURE_ENV

    old = os.environ.get(PURE_ENV)
    os.environ[PURE_ENV] = "1" if on else "0"
    try:
        yield
    finally:
        if old is None:
            os.environ.pop(PURE_ENV, None)
        else:
            os.environ[PURE_ENV] = old


def scenario1_seconds(duration: float) -> float:
    """Wall seconds of scenario1 through the engine, trace written (bench_run's engine run)."""
    from amsa_phys.engine.runner import Simulation
    from amsa_phys.engine.tracefile import TraceWriter
    from amsa_phys.model.scenario import load_scenario

    sc = load_scenario(SCENARIO1, duration=duration)
    with tempfile.TemporaryDirectory() as tmp:
        trace = TraceWriter(Path(tmp) / "trace.csv", list(sc.world.buffers))
        t0 = time.perf_counter()
        Simulation.from_scenario(sc, trace=trace.write).run()
        trace.close()
        return time.perf_counter() - t0


def headless(reps: int, report: Report = _print_report) -> None:
    """Compiled vs pure step on headless scenario1, interleaved in this process."""
    from amsa_phys.physics.step_path import describe

    if not describe()[0]:
        report("compiled step built", describe()[1], "compiled (C)", False)
        return
    fast, slow = [], []
    for _ in range(reps):
        with pure(False):
            fast.append(300 / scenario1_seconds(300))
        with pure(True):
            slow.append(300 / scenario1_seconds(300))
    ratio = [f / s for f, s in zip(fast, slow, strict=True)]
    report(
        "compiled / pure step, scenario1",
        f"{med(ratio)}; pure {statistics.median(slow):.0f}x real time",
        ">= 2.3",
        statistics.median(ratio) >= 2.3,
    )
    report("headless compiled, x real time", med(fast), ">= 2400", statistics.median(fast) >= 2400)


def _wall(argv: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(argv, check=True, capture_output=True)
    return time.perf_counter() - t0


def process(reps: int, report: Report = _print_report) -> None:
    """The whole ``run --headless`` process, with plots and without; ``--help``."""
    env_cmd = [sys.executable, "-m", "amsa_phys"]
    floor, helps, plots, no_plots = [], [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(reps):
            floor.append(_wall([sys.executable, "-c", "pass"]))
            helps.append(_wall([*env_cmd, "--help"]))
            argv = [*env_cmd, "run", str(SCENARIO1), "--headless", "-q"]
            plots.append(_wall([*argv, "--out", f"{tmp}/p{i}"]))
            no_plots.append(_wall([*argv, "--no-plot", "--out", f"{tmp}/n{i}"]))
    report(
        "amsa-phys --help, s",
        f"{med(helps)}; bare python {statistics.median(floor):.3f}",
        "<= 0.15",
        statistics.median(helps) <= 0.15,
    )
    report(
        "run scenario1 --headless process, s",
        f"{med(plots)}; with --no-plot {statistics.median(no_plots):.3f}",
        "<= 0.8",
        statistics.median(plots) <= 0.8,
    )


def platoon_scenario(cars: int, tmp: Path, duration: float) -> Path:
    """worlds/platoon.yaml with ``count: cars`` and a scenario of ``duration`` around it."""
    world = yaml.safe_load((ROOT / "worlds" / "platoon.yaml").read_text())
    world["components"]["Car"]["count"] = cars
    (tmp / f"platoon{cars}.yaml").write_text(yaml.safe_dump(world))
    scen = tmp / f"platoon{cars}_scenario.yaml"
    scen.write_text(f"world: platoon{cars}.yaml\nduration: {duration}\nseed: 1\n")
    return scen


def platoon_rt(scen: Path, hash_min: int | None = None) -> float:
    """Real-time factor of a platoon run (loop only), ``SPATIAL_HASH_MIN`` set if given."""
    from amsa_phys.engine.runner import Simulation
    from amsa_phys.model.scenario import load_scenario
    from amsa_phys.physics import space

    saved = space.SPATIAL_HASH_MIN
    if hash_min is not None:
        space.SPATIAL_HASH_MIN = hash_min
    try:
        sc = load_scenario(scen)
        sim = Simulation.from_scenario(sc)
        sim.initialize()
        t0 = time.perf_counter()
        sim.run()
        return float(sc.duration) / (time.perf_counter() - t0)
    finally:
        space.SPATIAL_HASH_MIN = saved


def platoon(reps: int, report: Report = _print_report) -> None:
    """1,000 rovers: real-time factor with the index chosen by size, and with the tree."""
    chosen, tree = [], []
    with tempfile.TemporaryDirectory() as d:
        scen = platoon_scenario(999, Path(d), 10)
        for _ in range(reps):
            chosen.append(platoon_rt(scen))
            tree.append(platoon_rt(scen, hash_min=10**9))
    ratio = [c / t for c, t in zip(chosen, tree, strict=True)]
    report(
        "platoon 1,000 rovers, x real time",
        f"{med(chosen)}; {statistics.median(ratio):.2f}x the bounding-box tree's",
        ">= 20",
        statistics.median(chosen) >= 20,
    )


TARGETS: dict[str, Callable[[int, Report], None]] = {
    "headless": headless,
    "process": process,
    "platoon": platoon,
}


def run_all(reps: int, report: Report = _print_report) -> None:
    """Every target of this file (``perf.py`` calls this with its own report)."""
    for fn in TARGETS.values():
        fn(reps, report)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--only", nargs="*", choices=list(TARGETS), default=list(TARGETS))
    args = ap.parse_args()
    for name in args.only:
        TARGETS[name](args.reps, _print_report)


if __name__ == "__main__":
    main()
