"""Batched sweeps of runs that start within reach: the paper's Fig. 5 grid.

Run: ``python benchmarks/bench_batch_start.py [--seeds 2] [--rounds 2]``.

The Fig. 5 scenarios start the follower 1 m behind the leader, so every run of a batch is
within reach (``physics/columns.py``) before its first step. Such runs used to be computed in
the batch and then again alone; now they go alone at once (``runs/batched.py``). Timed here
in one process (``-j 1``, so "before" can switch the check off by patching it): the batched
sweep now, the batched sweep with the check off (before), and the process pool
(``--executor local``), alternating, on 8 Kv x ``--seeds`` runs of 300 s. The three
``results.csv`` must be the same file.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENARIO = ROOT / "scenarios" / "paper_fig5_kv035.yaml"
GRID = "MyFollowerController.Kv=0.05,0.1,0.15,0.2,0.25,0.3,0.35,0.4"


def sweep(out: Path, seeds: int, executor: str, check: bool) -> float:
    """Seconds for one sweep into ``out``; ``check`` False switches the t = 0 check off."""
    from amsa_phys.cli.main import main
    from amsa_phys.physics.columns import ColumnPhysics

    original = ColumnPhysics.within_reach_at_start
    if not check:
        ColumnPhysics.within_reach_at_start = lambda self: set()  # type: ignore[method-assign]
    try:
        argv = ["sweep", str(SCENARIO), "--grid", GRID, "--seeds", str(seeds), "-j", "1"]
        t0 = time.perf_counter()
        assert main([*argv, "--executor", executor, "--out", str(out)]) == 0
        return time.perf_counter() - t0
    finally:
        ColumnPhysics.within_reach_at_start = original  # type: ignore[method-assign]


def main() -> None:
    """Time the three sweeps ``--rounds`` times, alternating, and compare their results."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    cases = {"batch, now": ("batch", True), "batch, before": ("batch", False)}
    cases["process pool"] = ("local", True)
    runs = 8 * args.seeds
    with tempfile.TemporaryDirectory() as tmp:
        times: dict[str, list[float]] = {name: [] for name in cases}
        for r in range(args.rounds):
            for name, (executor, check) in cases.items():
                out = Path(tmp) / f"{r}-{executor}-{check}"
                times[name].append(sweep(out, args.seeds, executor, check))
                if r:
                    shutil.rmtree(out)
        first = [(Path(tmp) / f"0-{e}-{c}" / "results.csv").read_bytes() for e, c in cases.values()]
        same = all(f == first[0] for f in first)
    for name, ts in times.items():
        best = min(ts)
        print(f"{name:14s} {runs} runs: {', '.join(f'{t:.2f}' for t in ts)} s (best {best:.2f} s)")
    print(f"results.csv identical across the three: {same}")


if __name__ == "__main__":
    main()
