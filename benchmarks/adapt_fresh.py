"""The shipped adaptation rules on a second, fresh draw of held-out context sequences.

``adapt --validate`` draws its held-out sequences from the sweep's box with one generator
seed, and the rules' settings were chosen while watching that table: it is no longer quite
held out. ``python -m benchmarks.adapt_fresh DIR`` (DIR: the output of ``amsa-phys sweep
scenarios/adaptive_sweep.yaml``) derives the rules from DIR exactly as the docs say, checks
that they are the committed ``scenarios/rules/adaptive_rules.yaml``, and scores them the
way ``--validate`` does (robust fixed gain, rules, oracle schedule; seeds 1-3, 600 s) on
``--sequences`` (30) sequences drawn with another generator seed (``--draw``, 2000). It
prints the table and the two counts ``--validate`` prints, writes
``benchmarks/results/adapt_fresh.json`` (``--validate``'s results format) and rewrites the
page's ``<!-- results: adapt-fresh -->`` block from it. ``--no-save`` prints the table and
the counts only, so another draw (the docs' third, ``--draw 3000``) can be scored without
replacing the committed one. A variant is scored without saving: ``--sweep FILE`` for DIR
swept from another scenario (``scenarios/adaptive_sweep_braking.yaml``: the rules with the
braking rule it derives), ``--rules FILE`` for a rules file instead of the derived rules (the
committed rules on a draw, say), ``--no-guard`` for the rules derived without the guarded
motor fallback (``adapt --no-guard``). ``--draw 1000 --sequences 20`` is ``adapt
--validate``'s twenty. Deterministic: the same table at any load.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run as a script: `benchmarks` is the repository's package
SWEEP = ROOT / "scenarios" / "adaptive_sweep.yaml"
RULES = ROOT / "scenarios" / "rules" / "adaptive_rules.yaml"
OUT = ROOT / "benchmarks" / "results" / "adapt_fresh.json"


def main(argv: list[str] | None = None) -> int:
    """Derive, check against the committed rules, score on the fresh draw; 1 if they lose."""
    import yaml

    from amsa_phys.adapt.derive import derive
    from amsa_phys.adapt.validate import (
        loses,
        markdown,
        results,
        short_of_oracle,
        validate,
    )
    from amsa_phys.cli.adapt import load_scenario
    from benchmarks import results as bench_results

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sweepdir", type=Path, help="the sweep's output directory")
    ap.add_argument("--sequences", type=int, default=30)
    ap.add_argument("--draw", type=int, default=2000, help="the sequences' generator seed")
    ap.add_argument(
        "--no-save",
        action="store_true",
        help="print only: leave the results file and the page as they are",
    )
    ap.add_argument(
        "--sweep",
        type=Path,
        default=SWEEP,
        help="the swept scenario DIR ran (default: scenarios/adaptive_sweep.yaml)",
    )
    ap.add_argument(
        "--no-guard",
        action="store_true",
        help="derive without the guarded motor fallback (adapt --no-guard: the rules as they "
        "were before it shipped); implies --no-save",
    )
    ap.add_argument(
        "--rules",
        type=Path,
        help="score this rules file (adapt: list) instead of the derived rules; implies --no-save",
    )
    args = ap.parse_args(argv)
    scenario = load_scenario(str(args.sweep))
    found = derive(args.sweepdir / "results.csv", scenario, guard=not args.no_guard)
    committed = yaml.safe_load(RULES.read_text())["adapt"]
    if args.rules is not None:
        found.rules = yaml.safe_load(args.rules.read_text())["adapt"]
    if args.rules is not None or args.no_guard or args.sweep.resolve() != SWEEP.resolve():
        args.no_save = True  # a variant: the committed table stays the shipped rules'
    elif found.rules != committed:
        print(f"warning: the rules derived from {args.sweepdir} differ from {RULES.name}")
    contexts = dict(scenario.data["sweep"]["contexts"])
    rows = validate(
        scenario,
        found,
        contexts,
        args.sequences,
        3,
        600.0,
        seed=args.draw,
        report=lambda text: print(text, flush=True),
    )
    settings = {
        "sequences": args.sequences,
        "seeds": 3,
        "duration": 600.0,
        "tolerance": 0.02,
        "draw": args.draw,
        "command": f"python -m benchmarks.adapt_fresh DIR --sequences {args.sequences} "
        f"--draw {args.draw}",
    }
    doc = results(rows, found, settings)
    print(markdown(doc))
    if not args.no_save:
        OUT.parent.mkdir(parents=True, exist_ok=True)
        OUT.write_text(json.dumps(doc, indent=1) + "\n")
        for page in bench_results.write_pages():
            print(f"rewrote {page.relative_to(ROOT)}", file=sys.stderr)
    worth, short = short_of_oracle(rows)
    print(
        f"where the oracle gains 10 % or more ({len(worth)}), the rules do on "
        f"{len(worth) - len(short)}"
    )
    lost = loses(rows, 0.02)
    print(f"the rules lose (by more than 2 %) on {len(lost)} of {len(rows)}")
    changes = [r.change for r in rows]
    print(
        f"change against the robust choice: worst {100 * max(changes):+.1f} %, mean "
        f"{100 * sum(changes) / len(changes):+.1f} %"
    )
    return 1 if lost else 0


if __name__ == "__main__":
    sys.exit(main())
