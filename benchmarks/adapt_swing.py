"""The swing supervisor, measured: the rules with a swing rule on every held-out draw.

``python -m benchmarks.adapt_swing`` sweeps ``scenarios/adaptive_sweep_swing.yaml`` (the
shipped sweep on the world with a ``SwingMonitor``, each run's largest swing measured) into a
temporary directory (``--sweepdir DIR`` reuses one), derives the rules from it as ``amsa-phys
adapt`` does (the swing rule's level from the sweep: 1.5 times the largest swing under a
chosen point), checks that without the swing rule they are the shipped rules, and scores
each variant the way ``adapt --validate`` does (robust fixed gain, rules, oracle; seeds 1-3,
600 s) on the docs' draws: ``--validate``'s twenty (generator seed 1000) and the thirty of
2000, 3000, 4000 and 5000. It prints one row per variant (reached: sequences where the
oracle gains 10 % or more on which the rules do too; losses above 2 %; the worst and the
mean change against the robust gain), writes ``benchmarks/results/adapt_swing.json`` and
rewrites docs/adaptation.md's ``<!-- results: adapt-swing -->`` block from it. The levels
come from the sweep alone; no draw chose them. Deterministic: the same table at any load.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run as a script: `benchmarks` is the repository's package

from benchmarks import results as bench_results  # noqa: E402

SWEEP = ROOT / "scenarios" / "adaptive_sweep_swing.yaml"
RULES = ROOT / "scenarios" / "rules" / "adaptive_rules.yaml"
OUT = ROOT / "benchmarks" / "results" / "adapt_swing.json"
#: (generator seed, sequences): --validate's twenty, then the fresh, third, fourth, fifth draws
DRAWS = ((1000, 20), (2000, 30), (3000, 30), (4000, 30), (5000, 30))
NAMES = {1000: "twenty", 2000: "fresh (2000)", 3000: "third (3000)", 4000: "fourth (4000)"}
#: the variants: label -> derive()'s keyword arguments
VARIANTS = {
    "swing rule as derived (higher gains held back while the swing lasts)": {},
    "swing rule, higher gains not held back": {"swing_holds": False},
}


def _cell(rows) -> str:
    from amsa_phys.adapt.validate import loses, short_of_oracle

    worth, short = short_of_oracle(rows)
    changes = [r.change for r in rows]
    return (
        f"{len(worth) - len(short)} of {len(worth)}, {len(loses(rows, 0.02))}, "
        f"{100 * max(changes):+.1f} %, {100 * sum(changes) / len(changes):+.1f} %"
    ).replace("-", "−")


def main(argv: list[str] | None = None) -> int:
    """Sweep (or reuse), derive each variant, score it on every draw; write the table."""
    import yaml

    from amsa_phys.adapt.derive import derive
    from amsa_phys.adapt.validate import validate
    from amsa_phys.cli.adapt import load_scenario

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sweepdir", type=Path, help="a finished sweep of the swing scenario")
    ap.add_argument("--no-save", action="store_true", help="print only")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="adapt_swing_") as tmp:
        sweepdir = args.sweepdir
        if sweepdir is None:
            sweepdir = Path(tmp) / "sweep"
            command = [sys.executable, "-m", "amsa_phys", "sweep", str(SWEEP)]
            command += ["--out", str(sweepdir), "--executor", "batch", "--jobs", "1"]
            subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
        scenario = load_scenario(str(SWEEP))
        results = sweepdir / "results.csv"
        plain = derive(results, scenario, swing_factor=0.0)
        shipped = yaml.safe_load(RULES.read_text())["adapt"]
        if plain.rules != shipped:
            print("warning: without the swing rule the rules differ from the shipped ones")
        contexts = dict(scenario.data["sweep"]["contexts"])
        rows = []
        for label, kwargs in VARIANTS.items():
            found = derive(results, scenario, **kwargs)
            if found.swing is None:
                raise SystemExit("the sweep gave no swing rule: is SwingMonitor measured?")
            cells = [f"{label}: level {found.swing.level:g} m"]
            for draw, count in DRAWS:
                scored = validate(scenario, found, contexts, count, 3, 600.0, seed=draw)
                cells.append(_cell(scored))
                print(f"{label} | {NAMES.get(draw, f'fifth ({draw})')} | {cells[-1]}", flush=True)
            rows.append(cells)
    columns = ["rules", *(NAMES.get(d, f"fifth ({d})") for d, _ in DRAWS)]
    doc = bench_results.table_doc(
        columns,
        rows,
        "Rules with the swing rule vs the robust Kv 0.2, seeds 1–3, 600 s: reached, losses "
        "above 2 %, worst, mean change",
        "python -m benchmarks.adapt_swing",
    )
    print(bench_results.table_markdown(doc))
    if not args.no_save:
        OUT.parent.mkdir(parents=True, exist_ok=True)
        OUT.write_text(json.dumps(doc, indent=1, ensure_ascii=False) + "\n")
        for page in bench_results.write_pages():
            print(f"rewrote {page.relative_to(ROOT)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
