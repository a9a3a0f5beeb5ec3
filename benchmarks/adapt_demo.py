"""The adaptation demonstration's table: ``scenarios/adaptive.yaml`` adaptive and at fixed gains.

``python benchmarks/adapt_demo.py`` runs the shipped adaptive scenario (600 s, Kv 0.15 at the
start) for seeds 1-5 with its rules, and with the rules off at each fixed gain of the sweep's
grid, and prints the Markdown table of docs/adaptation.md's "The demonstration" (whole-run
rms error). Deterministic: the same table at any load.
"""

from __future__ import annotations

import statistics
from pathlib import Path

import amsa_phys as ap

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "adaptive.yaml"
SEEDS = (1, 2, 3, 4, 5)
GAINS = (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35)


def rms(seed: int, kv: float | None) -> float:
    """Whole-run rms error of one run: with the rules (``kv`` None) or at a fixed gain."""
    if kv is None:
        run = ap.run(SCENARIO, seed=seed)
    else:
        run = ap.run(SCENARIO, seed=seed, adapt=False, set={"MyFollowerController.Kv": kv})
    return float(run.metrics["overall"]["rms_error"])


def main() -> None:
    rows = {"adaptive": [rms(s, None) for s in SEEDS]}
    for kv in GAINS:
        rows[f"Kv = {kv:g}"] = [rms(s, kv) for s in SEEDS]
    print("| run | seed 1 | 2 | 3 | 4 | 5 | mean |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for name, values in rows.items():
        cells = " | ".join(f"{v:.3f}" for v in values)
        print(f"| {name} | {cells} | {statistics.fmean(values):.3f} |")


if __name__ == "__main__":
    main()
