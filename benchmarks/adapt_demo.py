"""The adaptation demonstration's table: ``scenarios/adaptive.yaml`` adaptive and at fixed gains.

``python benchmarks/adapt_demo.py`` runs the shipped adaptive scenario (600 s, Kv 0.15 at the
start) for seeds 1-5 with its rules, and with the rules off at each fixed gain of the sweep's
grid, prints the Markdown table of docs/adaptation.md's "The demonstration" (whole-run rms
error), writes it to ``benchmarks/results/adapt_demo.json`` and rewrites the page's
``<!-- results: adapt-demo -->`` block from it. Deterministic: the same table at any load.
"""

from __future__ import annotations

import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run as a script: `benchmarks` is the repository's package

import amsa_phys as ap  # noqa: E402
from benchmarks import results  # noqa: E402

SCENARIO = ROOT / "scenarios" / "adaptive.yaml"
SEEDS = (1, 2, 3, 4, 5)
GAINS = (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.45, 0.6)
ROBUST = 0.2
OUT = results.OWN_TABLES["adapt-demo"]


def rms(seed: int, kv: float | None) -> float:
    """Whole-run rms error of one run: with the rules (``kv`` None) or at a fixed gain."""
    if kv is None:
        run = ap.run(SCENARIO, seed=seed)
    else:
        run = ap.run(SCENARIO, seed=seed, adapt=False, set={"MyFollowerController.Kv": kv})
    return float(run.metrics["overall"]["rms_error"])


def main() -> None:
    adaptive = [rms(s, None) for s in SEEDS]
    fixed = {kv: [rms(s, kv) for s in SEEDS] for kv in GAINS}
    best = min(fixed, key=lambda kv: statistics.fmean(fixed[kv]))
    rows = [["adaptive", *(f"{v:.3f}" for v in adaptive), f"**{statistics.fmean(adaptive):.3f}**"]]
    for kv, values in fixed.items():
        name = f"Kv = {kv:g}" + (
            " (best fixed)" if kv == best else " (the robust gain)" if kv == ROBUST else ""
        )
        rows.append([name, *(f"{v:.3f}" for v in values), f"{statistics.fmean(values):.3f}"])
    wins = sum(a < min(fixed[kv][i] for kv in GAINS) for i, a in enumerate(adaptive))
    doc = results.table_doc(
        ["run", *(f"seed {s}" for s in SEEDS), "mean"],
        rows,
        f"`scenarios/adaptive.yaml`, 600 s, whole-run rms error in m; fixed gains with the "
        f"rules off (`--no-adapt --set MyFollowerController.Kv=K`); the adaptive run beats "
        f"every fixed gain in {wins} of {len(SEEDS)} seeds",
        "python benchmarks/adapt_demo.py",
        adaptive=adaptive,
        fixed={f"{kv:g}": v for kv, v in fixed.items()},
    )
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(results.json.dumps(doc, indent=1) + "\n")
    print(results.table_markdown(doc), end="")
    for page in results.write_pages():
        print(f"rewrote {page.relative_to(ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
