"""Derive adapt: rules from a context sweep: best parameters per context, on estimators."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import yaml

from ..adapt.derive import Derivation, derive
from ..atomic import write_atomic
from ..errors import ConfigError
from ..model.scenario import load_scenario


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys adapt``."""
    p.add_argument("sweepdir", help="a sweep's output directory (its results.csv)")
    p.add_argument(
        "--scenario",
        required=True,
        help="the scenario the sweep ran (its sweep.contexts and the world's estimators)",
    )
    p.add_argument("-o", "--output", required=True, metavar="RULES.yaml", help="rules file")
    p.add_argument(
        "--metric", default="rms_error", help="the metric to minimise (default rms_error)"
    )
    p.add_argument(
        "--hold",
        type=float,
        default=10.0,
        metavar="S",
        help="each rule's hold time in seconds (default 10)",
    )
    p.add_argument("--force", action="store_true", help="replace an existing rules file")


def run(args: argparse.Namespace) -> int:
    """Read the sweep, derive, write the rules file, print the table."""
    results = Path(args.sweepdir) / "results.csv"
    if not results.is_file():
        raise ConfigError(
            f"no results.csv in {args.sweepdir} (is it a sweep's --out?)", key="adapt"
        )
    if not (args.hold >= 0 and math.isfinite(args.hold)):
        raise ConfigError(f"must be a number of seconds >= 0, got {args.hold}", key="--hold")
    out = Path(args.output)
    if out.exists() and not args.force:
        raise ConfigError(f"{out} exists; use --force to replace it", key="-o")
    scenario = load_scenario(args.scenario)
    found = derive(results, scenario, args.metric, args.hold)
    write_atomic(out, rules_text(found, args.sweepdir))
    for line in table(found):
        print(line)
    for problem in found.unplaced:
        print(f"warning: no rule for {problem}", file=sys.stderr)
    print(f"{len(found.rules)} rules written to {out}")
    return 0


def table(found: Derivation) -> list[str]:
    """The cells: context, estimator levels, best values and their metric."""
    lines = [f"cell | estimator levels | best {', '.join(found.tuned)} | mean {found.metric}"]
    for c in found.cells:
        levels = ", ".join(f"{k}={v:g}" for k, v in c.levels.items()) or "-"
        best = ", ".join(f"{v}" for v in c.best.values()) or "-"
        lines.append(f"{c.name} | {levels} | {best} | {c.score:.4g}")
    return lines


def rules_text(found: Derivation, sweepdir: str) -> str:
    """The rules file: the table as comments, then ``adapt:``."""
    head = [f"# adapt: rules derived by `amsa-phys adapt {sweepdir}` ({found.metric}, lowest wins)"]
    head += ["# estimator -> context parameter:"]
    head += [f"#   {w.signal} ~ {w.key}" for w in found.watches]
    head += [f"# {line}" for line in table(found)]
    head += [f"# not placed: {p}" for p in found.unplaced]
    body = yaml.safe_dump(
        {"adapt": found.rules}, sort_keys=False, default_flow_style=None, width=100
    )
    return "\n".join(head) + "\n" + body
