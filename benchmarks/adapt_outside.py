"""The shipped adaptation rules on contexts outside the sweep's box (the leader's speed too).

``python benchmarks/adapt_outside.py`` runs two 600 s sequences the sweep behind
``scenarios/rules/adaptive_rules.yaml`` never spanned, seeds 1-3, three ways: the rules
(starting from the robust gain), the robust fixed gain alone, and every fixed gain of the
sweep's grid (the best of them is the gain a user would pick in hindsight). It prints the
Markdown table of docs/adaptation.md's "Outside the box", writes it to
``benchmarks/results/adapt_outside.json`` and rewrites the page's ``<!-- results:
adapt-outside -->`` block from it. Deterministic: the same table at any load.
"""

from __future__ import annotations

import json
import statistics
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run as a script: `benchmarks` is the repository's package

from benchmarks import results  # noqa: E402

OUT = results.OWN_TABLES["adapt-outside"]
SWEEP = ROOT / "scenarios" / "adaptive_sweep.yaml"
RULES = "rules/adaptive_rules.yaml"
SEEDS = (1, 2, 3)
ROBUST = 0.2
GRID = (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.6, 0.7, 0.8)
#: Leader.cruisePower 4 drives at 0.06 m/s, 7 at the MDE speed (0.22 m/s), 12 at 0.5 m/s
SEQUENCES: dict[str, tuple[dict[str, Any], list[dict[str, Any]]]] = {
    "slow straight leader (0.06 m/s); at 250 s a fast random one (0.5 m/s) and motors at 70 %": (
        {"Leader.behavior": 1, "Leader.cruisePower": 4.0},
        [
            {
                "at": 250,
                "set": {
                    "Leader.behavior": 4,
                    "Leader.cruisePower": 12.0,
                    "MyNormalizePower.motorCoef": 70,
                },
            }
        ],
    ),
    "slow straight; motors at 70 % at 250 s; random at the MDE speed at 400 s": (
        {"Leader.behavior": 1, "Leader.cruisePower": 4.0},
        [
            {"at": 250, "set": {"MyNormalizePower.motorCoef": 70}},
            {"at": 400, "set": {"Leader.behavior": 4, "Leader.cruisePower": 7.0}},
        ],
    ),
}


def _rms(sets: dict[str, Any], timeline: list, seed: int, kv: float | None) -> float:
    import amsa_phys as ap

    scenario: dict[str, Any] = {
        "world": str(ROOT / "worlds" / "mde_adaptive.yaml"),
        "duration": 600,
        "seed": seed,
        "quality": {"signal": "MyDistanceMonitor.distanceFollowerToLeader", "reference": 15},
        "trace_columns": ["MyDistanceMonitor.*"],
        "set": dict(sets),
        "timeline": timeline,
    }
    if kv is None:
        scenario["adapt"] = str(ROOT / "scenarios" / RULES)
        kv = ROBUST
    scenario["set"]["MyFollowerController.Kv"] = kv
    run = ap.run(scenario)
    return float(run.metrics["overall"]["rms_error"])


def main() -> None:
    rows = []
    for name, (sets, timeline) in SEQUENCES.items():
        rules = statistics.fmean(_rms(sets, timeline, s, None) for s in SEEDS)
        fixed = {kv: statistics.fmean(_rms(sets, timeline, s, kv) for s in SEEDS) for kv in GRID}
        best = min(fixed, key=fixed.__getitem__)
        change = 100 * (rules / fixed[ROBUST] - 1)
        rows.append(
            [
                name,
                f"{rules:.3f}",
                f"{fixed[ROBUST]:.3f}",
                f"{change:+.1f} %".replace("-", "−"),
                f"{fixed[best]:.3f} (Kv {best:g})",
            ]
        )
        print(" | ".join(rows[-1]), flush=True)
    doc = results.table_doc(
        [
            "sequence",
            "rules",
            f"robust Kv {ROBUST:g}",
            "rules vs robust",
            "best fixed in hindsight",
        ],
        rows,
        f"seeds {SEEDS[0]}–{SEEDS[-1]}, 600 s, rms error in m; the best fixed gain of the "
        f"sweep's grid ({', '.join(f'{kv:g}' for kv in GRID)}) picked for each sequence after "
        "the fact",
        "python -m benchmarks.adapt_outside",
    )
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    for page in results.write_pages():
        print(f"rewrote {page.relative_to(ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
