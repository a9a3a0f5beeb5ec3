"""One held-out sequence of a draw as a scenario file, to trace it with ``amsa-phys run``.

The docs trace the rules' losses on the draws sequence by sequence, seed by seed.
``python -m benchmarks.adapt_case DRAW INDEX -o CASE.yaml`` writes sequence INDEX (from 0)
of the draw with generator seed DRAW (``adapt --validate``'s are 1000; the docs' fresh,
third, fourth and fifth draws 2000-5000) exactly as ``--validate`` runs it: the swept
scenario's world, the sequence as its timeline, 600 s, the robust gain at the start and the
rules (the committed ``scenarios/rules/adaptive_rules.yaml``, ``--rules FILE`` for another,
``--robust`` for none). ``--set T:K`` adds ``MyFollowerController.Kv = K`` at T s (repeat it:
a spell of another gain). Then ``amsa-phys run CASE.yaml --headless --seed S --out DIR``
traces it; its rms error is the one ``--validate`` scores for seed S.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SWEEP = ROOT / "scenarios" / "adaptive_sweep.yaml"
RULES = ROOT / "scenarios" / "rules" / "adaptive_rules.yaml"
GAIN = "MyFollowerController.Kv"


def main(argv: list[str] | None = None) -> int:
    """Write the case's scenario file."""
    import yaml

    from amsa_phys.cli.adapt import load_scenario
    from amsa_phys.tune.contexts import box, sequences
    from amsa_phys.tune.evaluate import case_data

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("draw", type=int, help="the draw's generator seed")
    ap.add_argument("index", type=int, help="the sequence, from 0")
    ap.add_argument("-o", "--output", type=Path, required=True)
    ap.add_argument("--sweep", type=Path, default=SWEEP, help="the swept scenario")
    ap.add_argument("--rules", type=Path, default=RULES, help="a rules file (adapt: list)")
    ap.add_argument("--robust", action="store_true", help="no rules: the robust gain alone")
    ap.add_argument("--robust-gain", type=float, default=0.2)
    ap.add_argument("--set", action="append", default=[], metavar="T:K", help="Kv K at T s")
    args = ap.parse_args(argv)
    if not 0 <= args.index < 1000:
        print(f"adapt_case: index must be 0..999, got {args.index}", file=sys.stderr)
        return 2
    scenario = load_scenario(str(args.sweep))
    axes = box(scenario, dict(scenario.data["sweep"]["contexts"]))
    sequence = list(sequences(axes, args.index + 1, 600.0, args.draw))[args.index]
    rules = None if args.robust else yaml.safe_load(args.rules.read_text())["adapt"]
    data = case_data(scenario, sequence, {GAIN: args.robust_gain}, 600.0, rules)
    data["world"] = str((Path(scenario.path).parent / data["world"]).resolve())
    data.pop("trace_columns", None)
    for spec in args.set:
        at, _, gain = spec.partition(":")
        data.setdefault("timeline", []).append({"at": float(at), "set": {GAIN: float(gain)}})
    data.get("timeline", []).sort(key=lambda e: e["at"])
    args.output.write_text(yaml.safe_dump(data, sort_keys=False))
    print(sequence.describe())
    return 0


if __name__ == "__main__":
    sys.exit(main())
