"""What ``--bag`` costs: a run with and without its MCAP bag, in one sitting.

``amsa_phys.run`` on a scenario (default scenario1, 500 s) without a bag and with
``bag=...``; CPU seconds of this process (``time.process_time``: the machine is shared, wall
time swings with the other users) and wall seconds, median of N repetitions; then the bag's
size, message count and the CPU cost per message. Compare ratios, not absolute numbers.
Run: ``python benchmarks/bench_bag.py [--reps 3] [--duration 500] [SCENARIO]``.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from mcap.reader import make_reader

import amsa_phys as ap

ROOT = Path(__file__).resolve().parent.parent


def measure(scenario: str, duration: float, bag: Path | None) -> tuple[float, float]:
    """(CPU s, wall s) of one run."""
    if bag is not None:
        bag.unlink(missing_ok=True)
    c0, w0 = time.process_time(), time.perf_counter()
    ap.run(scenario, duration=duration, bag=bag)
    return time.process_time() - c0, time.perf_counter() - w0


def main() -> None:
    """Print the table."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("scenario", nargs="?", default=str(ROOT / "scenarios/scenario1.yaml"))
    parser.add_argument("--reps", type=int, default=3)
    parser.add_argument("--duration", type=float, default=500.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / "run.mcap"
        rows = {}
        for label, target in (("no bag", None), ("--bag", bag)):
            runs = [measure(args.scenario, args.duration, target) for _ in range(args.reps)]
            rows[label] = (
                statistics.median(r[0] for r in runs),
                statistics.median(r[1] for r in runs),
            )
        with bag.open("rb") as fh:
            summary = make_reader(fh).get_summary()
        count = summary.statistics.message_count if summary and summary.statistics else 0
        size = bag.stat().st_size
    base = rows["no bag"][0]
    for label, (cpu, wall) in rows.items():
        print(f"{label:8s} cpu {cpu:6.2f} s  wall {wall:6.2f} s  x{cpu / base:5.1f} cpu")
    extra = rows["--bag"][0] - base
    print(f"bag: {size / 1e6:.1f} MB, {count:,} messages, {extra / count * 1e6:.1f} µs cpu each")


if __name__ == "__main__":
    main()
