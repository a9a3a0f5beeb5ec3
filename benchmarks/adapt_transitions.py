"""Adaptation rules on motors that recover: the cell transitions of docs/adaptation.md.

The held-out draws of ``adapt --validate`` hold few sequences where worn motors get better
again, and those are where a higher gain set for worn motors swings the follower. This set
is built, not drawn: motors at 25 %, 30 % or 50 % (the sweep's worn levels and one between
them) with a straight or random leader, for 150, 170, 190 or 210 s, then motors at 75 % or
100 % with either leader (from 50 %, to 100 % only: 64 sequences).
``python -m benchmarks.adapt_transitions`` scores ``--rules`` (default: the committed
``scenarios/rules/adaptive_rules.yaml``) against the robust fixed gain, seeds 1-3, 600 s,
on ``scenarios/adaptive_sweep.yaml`` with its ``--set`` settings
(``MotorMonitor.recentWindow=5`` for a rule that reads ``recent``), and prints every
sequence where the rules lose by more than 2 %, then the counts (``--level P``: a braking
rule's level moved to P %, to screen where between the right and the wrong braking it
sits; ``--derive DIR`` [``--sweep FILE``] [``--no-guard``]: the rules derived from a sweep's
output instead of a rules file, with the guarded motor fallback as ``adapt`` derives them,
or without it). It writes nothing: a
screening tool for a rule variant, on contexts of the sweep's own cells rather than on the
held-out draws. Deterministic: the same numbers at any load.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run as a script: `benchmarks` is the repository's package

SWEEP = ROOT / "scenarios" / "adaptive_sweep.yaml"
RULES = ROOT / "scenarios" / "rules" / "adaptive_rules.yaml"
SEEDS = (1, 2, 3)
ROBUST = {"MyFollowerController.Kv": 0.2}
BEFORE = ((25, 1), (30, 1), (25, 4), (50, 1), (50, 4))  # (motorCoef, Leader.behavior)
AFTER = ((100, 1), (75, 4), (100, 4), (75, 1))
INSTANTS = (150.0, 170.0, 190.0, 210.0)


def transitions() -> list[Any]:
    """The 64 sequences: worn motors, then stronger ones at one of ``INSTANTS``."""
    from amsa_phys.tune.contexts import Sequence

    out = []
    for worn, b0 in BEFORE:
        for at in INSTANTS:
            for strong, b1 in AFTER:
                if worn == 50 and strong == 75:
                    continue
                first = {"Leader.behavior": b0, "MyNormalizePower.motorCoef": worn}
                then = {"Leader.behavior": b1, "MyNormalizePower.motorCoef": strong}
                out.append(Sequence(((0.0, first), (at, then))))
    return out


def setting(text: str) -> tuple[str, float]:
    """``Comp.param=V`` as a key and a number (argparse type)."""
    key, sep, value = text.partition("=")
    if not sep or "." not in key:
        raise argparse.ArgumentTypeError(f"expected Comp.param=V, got {text!r}")
    try:
        return key, float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{key}: {value!r} is not a number") from None


def main(argv: list[str] | None = None) -> int:
    """Score the rules on the transitions; 1 when they lose on any by more than 2 %."""
    import yaml

    from amsa_phys.cli.adapt import load_scenario
    from amsa_phys.tune.evaluate import evaluate

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rules", type=Path, default=RULES, help="a rules file (adapt: list)")
    ap.add_argument("--set", type=setting, action="append", default=[], metavar="C.p=V")
    ap.add_argument(
        "--derive",
        type=Path,
        metavar="DIR",
        help="score the rules derived from the sweep output DIR instead of --rules",
    )
    ap.add_argument(
        "--sweep", type=Path, default=SWEEP, help="the scenario DIR was swept from (--derive)"
    )
    ap.add_argument(
        "--no-guard",
        action="store_true",
        help="derive without the guarded motor fallback, as adapt --no-guard (--derive)",
    )
    ap.add_argument(
        "--level",
        type=float,
        help="screen the braking rule (label 'damp, braking ...') at this level, %% of command",
    )
    args = ap.parse_args(argv)
    scenario = load_scenario(str(SWEEP))
    rules = yaml.safe_load(args.rules.read_text())["adapt"]
    if args.derive is not None:
        from amsa_phys.adapt.derive import derive

        found = derive(
            args.derive / "results.csv", load_scenario(str(args.sweep)), guard=not args.no_guard
        )
        rules = found.rules
    if args.level is not None:
        braking = [r for r in rules if str(r.get("label", "")).startswith("damp, braking")]
        if not braking:
            ap.error("--level: the rules have no braking rule")
        for key, bound in braking[0]["when"].items():
            if key.endswith("Power"):
                bound["below"] = -args.level
    extra = dict(args.set)
    changes = []
    for sequence in transitions():
        ways = []
        for r in (None, rules):
            values = [
                evaluate(scenario, sequence, {**ROBUST, **extra}, s, "rms_error", 600.0, r)
                for s in SEEDS
            ]
            ways.append(statistics.fmean(float("inf") if v is None else v for v in values))
        change = ways[1] / ways[0] - 1.0
        changes.append(change)
        if change > 0.02:
            print(f"{100 * change:+.1f} %  {sequence.describe()}", flush=True)
    lost = sum(c > 0.02 for c in changes)
    print(
        f"the rules lose (by more than 2 %) on {lost} of {len(changes)}; worst "
        f"{100 * max(changes):+.1f} %, mean {100 * statistics.fmean(changes):+.1f} %"
    )
    return 1 if lost else 0


if __name__ == "__main__":
    sys.exit(main())
