"""The Python API and the Gymnasium environment against the CLI, in one process.

* ``amsa_phys.run`` (trace in memory) against ``amsa-phys run --headless --no-plot -q``
  called in-process (``cli.main``, trace streamed to a file) on scenario1;
* ``run.save(DIR, plot=False)``: writing the run directory afterwards;
* ``amsa_phys/Follow-v0``: agent steps per second with a constant action (each step is a
  4 Hz controller period, so steps/s / 4 is the real-time factor), against ``ap.run``'s.

Median of N repetitions, min and max shown. Compare ratios: the machine is shared.
Run: ``python benchmarks/bench_api.py [--reps 5] [--duration 300]``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

import amsa_phys as ap
from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = str(ROOT / "scenarios" / "scenario1.yaml")


def timed(fn: object, reps: int) -> list[float]:
    """Wall seconds of ``reps`` calls of ``fn()``."""
    out = []
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()  # type: ignore[operator]
        out.append(time.perf_counter() - t0)
    return out


def show(label: str, values: list[float], unit: str = "s") -> float:
    """Print median (min, max); return the median."""
    med = statistics.median(values)
    print(f"{label:44s} {med:.4g} {unit} (min {min(values):.4g}, max {max(values):.4g})")
    return med


def main_bench() -> None:
    """Measure and print."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--duration", type=float, default=300)
    args = parser.parse_args()
    dur = str(args.duration)
    ap.run(SCENARIO, duration=10)  # imports and first-call costs out of the way

    with tempfile.TemporaryDirectory() as tmp:
        n = iter(range(10**6))

        def cli() -> None:
            argv = ["run", SCENARIO, "--headless", "--no-plot", "-q", "--duration", dur]
            quiet = io.StringIO()
            with contextlib.redirect_stdout(quiet), contextlib.redirect_stderr(quiet):
                # 1: an expectation on a phase the duration cut short; the run itself is whole
                assert main([*argv, "--out", f"{tmp}/cli{next(n)}"]) in (0, 1)

        def api() -> None:
            ap.run(SCENARIO, duration=args.duration)

        run = ap.run(SCENARIO, duration=args.duration)

        def save() -> None:
            run.save(f"{tmp}/save{next(n)}", plot=False)

        t_cli = show("CLI in-process (main, --no-plot -q)", timed(cli, args.reps))
        t_api = show("ap.run (trace in memory)", timed(api, args.reps))
        t_save = show("run.save(DIR, plot=False)", timed(save, args.reps))
        print(f"{'ap.run / CLI in-process':44s} {t_api / t_cli:.3f}")
        print(f"{'(ap.run + save) / CLI in-process':44s} {(t_api + t_save) / t_cli:.3f}")

    import amsa_phys.gym

    env = amsa_phys.gym.FollowEnv(SCENARIO, duration=args.duration)
    action = np.array([0.3, 0.3])

    def episode() -> int:
        env.reset(seed=1)
        steps = 0
        while True:
            steps += 1
            if env.step(action)[3]:
                return steps

    steps = episode()
    rates = [steps / t for t in timed(episode, args.reps)]
    rate = show("env steps per second (4 Hz controller)", rates, "steps/s")
    env.close()
    api_rtf = args.duration / t_api
    print(f"{'env real-time factor / ap.run real-time factor':44s} {rate / 4 / api_rtf:.3f}")


if __name__ == "__main__":
    main_bench()
