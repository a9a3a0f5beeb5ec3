"""What ``--bag`` costs: a run with and without its MCAP bag, in one sitting.

``amsa_phys.run`` on a scenario (default scenario1, 500 s) without a bag and with
``bag=...``, interleaved so the machine's load hits both alike; CPU seconds of this process
(``time.process_time``: the machine is shared, wall time swings with the other users), median
of N repetitions; then the bag's size against the run's ``trace.csv``, its message count and
the CPU cost per message. Compare ratios, not absolute numbers.
Run: ``python benchmarks/bench_bag.py [--reps 3] [--duration 500] [SCENARIO]`` or through
``python -m benchmarks.perf --only bag``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

from mcap.reader import make_reader

import amsa_phys as ap

ROOT = Path(__file__).resolve().parent.parent
SCENARIO1 = str(ROOT / "scenarios" / "scenario1.yaml")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import results  # noqa: E402


def measure(scenario: str, duration: float, bag: Path | None) -> tuple[float, float]:
    """(CPU s, wall s) of one run."""
    if bag is not None:
        bag.unlink(missing_ok=True)
    c0, w0 = time.process_time(), time.perf_counter()
    ap.run(scenario, duration=duration, bag=bag)
    return time.process_time() - c0, time.perf_counter() - w0


def _med(xs: list[float]) -> str:
    return f"{statistics.median(xs):.4g} (min {min(xs):.4g}, max {max(xs):.4g})"


def perf(
    reps: int,
    report: results.Report = results.print_report,
    scenario: str = SCENARIO1,
    duration: float = 500.0,
) -> None:
    """The bag's cost as ratios to the same run without it, interleaved rep by rep."""
    plain, bagged = [], []
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / "run.mcap"
        measure(scenario, 10.0, None)  # warm: imports, the compiled step
        for _ in range(reps):
            plain.append(measure(scenario, duration, None)[0])
            bagged.append(measure(scenario, duration, bag)[0])
        with bag.open("rb") as fh:
            summary = make_reader(fh).get_summary()
        count = summary.statistics.message_count if summary and summary.statistics else 0
        size = bag.stat().st_size
        run = ap.run(scenario, duration=duration)
        run.save(Path(tmp) / "run")
        trace = (Path(tmp) / "run" / "trace.csv").stat().st_size
    ratio = [b / p for p, b in zip(plain, bagged, strict=True)]
    name = Path(scenario).stem
    report(
        f"run with --bag CPU / without, {name} {duration:g} s",
        f"{_med(ratio)}; without {statistics.median(plain):.3f} s CPU",
        "",
        None,
    )
    per = [(b - p) / count * 1e6 for p, b in zip(plain, bagged, strict=True)] if count else [0.0]
    report(f"bag: CPU a message, µs ({count:,} messages)", _med(per), "", None)
    report("bag size / trace.csv size", f"{size / trace:.3g}; bag {size / 2**20:.1f} MiB", "", None)


def main() -> None:
    """Print the figures."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("scenario", nargs="?", default=SCENARIO1)
    parser.add_argument("--reps", type=int, default=3)
    parser.add_argument("--duration", type=float, default=500.0)
    args = parser.parse_args()
    perf(args.reps, results.print_report, args.scenario, args.duration)


if __name__ == "__main__":
    main()
