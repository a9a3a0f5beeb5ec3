"""Derive adapt: rules from a context sweep: best parameters per context, on estimators."""

from __future__ import annotations

import argparse
import json
import math
import shlex
import sys
from pathlib import Path

import yaml

from ..adapt.damping import STEPS
from ..adapt.derive import CELL_GAIN, DAMP, MARGIN, MIN_GAIN, NEAR, SWING, Derivation, derive
from ..adapt.sweepdir import read_sweep_scenario
from ..atomic import write_atomic
from ..errors import ConfigError, one_line
from ..model import schema
from ..model.adaptrules import FILE, parse_rules
from ..model.scenario import Scenario, load_scenario
from ..model.wording import plural
from ..model.yamlio import parse_yaml
from ..runs.outfile import check_output_file
from ..runs.suite import input_files
from ..tune.objective import ROBUSTNESS


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys adapt``."""
    p.add_argument("sweepdir", help="a sweep's output directory (its results.csv)")
    p.add_argument(
        "--scenario",
        help="the scenario the sweep ran (default: the one the sweep directory records)",
    )
    p.add_argument("-o", "--output", required=True, metavar="RULES.yaml", help="rules file")
    p.add_argument(
        "--metric",
        default="rms_error",
        help="the metric to minimise (default rms_error), or robustness.NAME to maximise",
    )
    p.add_argument(
        "--hold",
        type=float,
        default=10.0,
        metavar="S",
        help="each rule's hold time in seconds, and the least time between switches (default 10)",
    )
    p.add_argument(
        "--fallback-hold",
        type=float,
        default=None,
        metavar="S",
        help="seconds an estimator must stay unsure before the robust choice is set "
        "(default: --hold)",
    )
    p.add_argument(
        "--fallback-dwell",
        type=float,
        default=None,
        metavar="S",
        help="seconds after a switch before the robust choice may be set for an unsure "
        "estimator (default: the estimator's window)",
    )
    p.add_argument(
        "--margin",
        type=float,
        default=MARGIN,
        metavar="M",
        help="a chosen point's grid neighbours may be at most M worse (default 0.5: 50 %%; "
        "inf: no margin)",
    )
    p.add_argument(
        "--near",
        type=float,
        default=NEAR,
        metavar="T",
        help="safe points at most T worse than a cell's lowest count as level with it, and "
        "the one fewest grid steps from the robust choice is the cell's best (default "
        f"{NEAR:g}: {100 * NEAR:g} %%)",
    )
    p.add_argument(
        "--cell-gain",
        type=float,
        default=CELL_GAIN,
        metavar="G",
        help="a cell keeps the robust choice unless its best is at least G better there "
        f"(default {CELL_GAIN:g}: {100 * CELL_GAIN:g} %%)",
    )
    p.add_argument(
        "--min-gain",
        type=float,
        default=MIN_GAIN,
        metavar="G",
        help="least gain of switching over the robust fixed choice worth rules (default 0.05)",
    )
    p.add_argument(
        "--robust",
        action="append",
        default=[],
        metavar="Comp.param=V",
        help="the fixed choice to fall back on and compare with (`amsa-phys tune`'s answer, "
        "on the sweep's grid; default: the sweep's least worst-case point)",
    )
    p.add_argument(
        "--damp",
        type=float,
        default=DAMP,
        metavar="F",
        help="when the sweep measured the follower's path speed (a requirement "
        "always(M.pathSpeed <= C)), set a lower gain while it is above F times the fastest "
        f"seen under a chosen point and M is unsure (default {DAMP:g}; 0: no damping rule)",
    )
    p.add_argument(
        "--damp-steps",
        type=int,
        default=STEPS,
        metavar="N",
        help=f"the damping rule's point: N grid steps below the robust one (default {STEPS})",
    )
    p.add_argument(
        "--swing",
        type=float,
        default=SWING,
        metavar="F",
        help="when the sweep measured the distance's swings (a requirement "
        "always[a:b](S.amplitude <= C)), set the robust choice while S's amplitude is above F "
        "times the largest seen under a chosen point, and hold higher choices back until it "
        f"falls below (default {SWING:g}; 0: no swing rule)",
    )
    p.add_argument(
        "--no-guard",
        action="store_true",
        help="leave out the guarded motor fallback (the robust choice once the damped "
        "estimator is unsure with its held value above the switched band, swing or not): the "
        "rules without it, for comparison",
    )
    p.add_argument("--force", action="store_true", help="replace an existing -o or --results")
    p.add_argument(
        "--validate",
        action="store_true",
        help="score the rules on held-out context sequences against the robust fixed choice "
        "and the oracle schedule; exit 1 if they lose",
    )
    p.add_argument(
        "--sequences", type=int, default=5, metavar="N", help="held-out sequences (default 5)"
    )
    p.add_argument(
        "--seeds",
        type=int,
        default=3,
        metavar="N",
        help="seeds per sequence (default 3); the verdict is on their mean, and with few "
        "seeds one unlucky seed can decide it",
    )
    p.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="S",
        help="with --validate: length of a held-out sequence in seconds (default 600)",
    )
    p.add_argument(
        "--results",
        metavar="FILE.json",
        help="with --validate: also write the table, per seed, as a results file (JSON)",
    )
    p.add_argument(
        "--tolerance",
        type=float,
        default=0.02,
        metavar="T",
        help="the rules lose on a sequence when their mean is more than T above the robust "
        "choice's (default 0.02: 2 %%)",
    )


def run(args: argparse.Namespace) -> int:
    """Read the sweep, derive, write the rules file (or say why not), print the table."""
    sweepdir = Path(args.sweepdir)
    results = sweepdir / "results.csv"
    if not results.is_file():
        raise ConfigError(
            f"no results.csv in {one_line(str(sweepdir))} (is it a sweep's --out?)", key="adapt"
        )
    if args.duration is not None and not args.validate:
        raise ConfigError(
            "sets the length of --validate's held-out sequences: give --validate (the rules "
            "are derived from the sweep's runs as they are)",
            key="--duration",
        )
    if args.duration is None:
        args.duration = 600.0
    if not (args.hold >= 0 and math.isfinite(args.hold)):
        raise ConfigError(f"must be a number of seconds >= 0, got {args.hold}", key="--hold")
    if args.fallback_hold is not None and not (
        args.fallback_hold >= 0 and math.isfinite(args.fallback_hold)
    ):
        raise ConfigError(
            f"must be a number of seconds >= 0, got {args.fallback_hold}", key="--fallback-hold"
        )
    if args.fallback_dwell is not None and not (
        args.fallback_dwell >= 0 and math.isfinite(args.fallback_dwell)
    ):
        raise ConfigError(
            f"must be a number of seconds >= 0, got {args.fallback_dwell}", key="--fallback-dwell"
        )
    if not args.margin >= 0:
        raise ConfigError(f"must be >= 0 (or inf), got {args.margin}", key="--margin")
    for key, value, top in (
        ("--near", args.near, 1),
        ("--cell-gain", args.cell_gain, 1),
        ("--damp", args.damp, 100),
        ("--swing", args.swing, 100),
        ("--min-gain", args.min_gain, 1),
    ):
        if not (0 <= value < top):
            raise ConfigError(f"must be in [0, {top}), got {value}", key=key)
    if not 1 <= args.damp_steps <= 1000:
        raise ConfigError(f"must be 1..1000, got {args.damp_steps}", key="--damp-steps")
    if args.validate:
        _check_validate_args(args)
    # what it reads (the sweep's files, --scenario's and its world) is never replaced
    given = load_scenario(args.scenario) if args.scenario else None
    inputs = [results, sweepdir / "scenario.yaml", *(input_files(given) if given else [])]
    out = check_output_file(Path(args.output), "-o", args.force, inputs)
    if args.results is not None:
        if not args.validate:
            raise ConfigError("needs --validate (it holds the validation's table)", key="--results")
        if Path(args.results).resolve() == out.resolve():
            raise ConfigError("names the rules file (-o) too; choose another", key="--results")
        check_output_file(Path(args.results), "--results", args.force, inputs)
    scenario = given if given is not None else read_sweep_scenario(sweepdir)
    robust = _robust_option(args.robust, scenario)
    found = derive(
        results,
        scenario,
        args.metric,
        args.hold,
        args.margin,
        args.min_gain,
        robust,
        args.fallback_hold,
        args.fallback_dwell,
        args.near,
        args.cell_gain,
        args.damp,
        args.damp_steps,
        guard=not args.no_guard,
        swing_factor=args.swing,
    )
    for line in table(found):
        print(one_line(line))
    if found.refused:
        print(one_line(f"no rules written: {found.refused}"))
        return 0
    text = rules_text(found, str(sweepdir))
    _check_loads(text, out, scenario)
    write_atomic(out, text)
    for problem in found.unplaced:
        print(one_line(f"warning: no rule for {problem}"), file=sys.stderr)
    print(one_line(f"{len(found.rules)} rules written to {out}"))
    if args.validate:
        return _validate(args, scenario, found)
    return 0


def _robust_option(texts: list[str], scenario: Scenario) -> dict[str, object] | None:
    """``--robust Comp.param=V`` values, judged as the parameter's own values."""
    if not texts:
        return None
    from ..model.changes import resolve_change
    from ..model.yamlio import parse_value

    out: dict[str, object] = {}
    for text in texts:
        key, sep, raw = text.partition("=")
        if not sep:
            raise ConfigError(f"expected Comp.param=V, got {one_line(text)!r}", key="--robust")
        try:
            value = parse_value(raw, "--robust")
            out[key.strip()] = resolve_change(key.strip(), value, scenario.world).value
        except ValueError as exc:
            raise ConfigError(str(exc), key=f"--robust {one_line(key.strip())}") from None
    return out


def _check_validate_args(args: argparse.Namespace) -> None:
    """--validate's numbers, refused before any work."""
    if not 1 <= args.sequences <= 1000:
        raise ConfigError(f"must be 1..1000, got {args.sequences}", key="--sequences")
    if not 1 <= args.seeds <= 1000:
        raise ConfigError(f"must be 1..1000, got {args.seeds}", key="--seeds")
    if not (60 <= args.duration <= 100_000 and math.isfinite(args.duration)):
        raise ConfigError(f"must be 60..100000 seconds, got {args.duration}", key="--duration")
    if not (0 <= args.tolerance < 1):
        raise ConfigError(f"must be in [0, 1), got {args.tolerance}", key="--tolerance")


def _validate(args: argparse.Namespace, scenario: Scenario, found: Derivation) -> int:
    """Run the held-out sequences, print the table; 1 if the rules lose to the robust one."""
    from ..adapt.validate import HEADER, loses, results, short_of_oracle, validate

    contexts = dict(scenario.data.get("sweep", {}).get("contexts", {}))
    if not contexts:
        raise ConfigError(
            "--validate draws held-out contexts from the sweep's contexts; this sweep has none",
            key="--validate",
        )
    from ..tune.contexts import MIN_SEGMENT_S

    if args.duration < 2 * MIN_SEGMENT_S:
        print(
            one_line(
                f"warning: held-out sequences of {args.duration:g} s hold one context each (a "
                f"context lasts at least {MIN_SEGMENT_S:g} s): no switch between contexts is "
                f"scored; give --duration {2 * MIN_SEGMENT_S:g} or more"
            ),
            file=sys.stderr,
        )
    print(
        one_line(
            f"validating on {plural(args.sequences, 'held-out sequence')} x "
            f"{plural(args.seeds, 'seed')} "
            f"({found.metric}, seed means, lower is better):"
        )
    )
    print(HEADER)
    rows = validate(
        scenario,
        found,
        contexts,
        args.sequences,
        args.seeds,
        args.duration,
        report=lambda text: print(one_line(text), flush=True),
    )
    if args.results is not None:
        settings = {
            "sequences": args.sequences,
            "seeds": args.seeds,
            "duration": args.duration,
            "tolerance": args.tolerance,
            "command": _command(args),
        }
        doc = results(rows, found, settings)
        write_atomic(Path(args.results), json.dumps(doc, indent=1) + "\n")
    worth, short = short_of_oracle(rows)
    if worth:
        print(
            one_line(
                f"where the oracle gains 10 % or more ({len(worth)} of {len(rows)} sequences), "
                f"the rules do on {len(worth) - len(short)}"
            )
        )
    lost = loses(rows, args.tolerance)
    if lost:
        print(
            one_line(
                f"warning: the rules lose to the robust fixed choice on {len(lost)} of "
                f"{plural(len(rows), 'held-out sequence')} (by more than "
                f"{100 * args.tolerance:g} % in the mean over {plural(args.seeds, 'seed')})"
            ),
            file=sys.stderr,
        )
        return 1
    print(
        one_line(
            f"the rules hold: never more than {100 * args.tolerance:g} % worse than the "
            f"robust fixed choice on {plural(len(rows), 'held-out sequence')}, in the mean "
            f"over {plural(args.seeds, 'seed')}"
        )
    )
    return 0


def _command(args: argparse.Namespace) -> str:
    """The ``adapt --validate`` command line that regenerates a results file."""
    # DIR: the sweep's output directory (a temporary one, as a rule: not worth naming)
    words = ["amsa-phys", "adapt", "DIR", "-o", args.output, "--force", "--validate"]
    words += ["--sequences", str(args.sequences), "--seeds", str(args.seeds)]
    if args.duration != 600.0:
        words += ["--duration", f"{args.duration:g}"]
    for flag, value in (("--hold", args.hold), ("--fallback-hold", args.fallback_hold)):
        if value is not None and not (flag == "--hold" and value == 10.0):
            words += [flag, f"{value:g}"]
    if args.fallback_dwell is not None:
        words += ["--fallback-dwell", f"{args.fallback_dwell:g}"]
    for flag, value, default in (
        ("--near", args.near, NEAR),
        ("--cell-gain", args.cell_gain, CELL_GAIN),
    ):
        if value != default:
            words += [flag, f"{value:g}"]
    if getattr(args, "swing", SWING) != SWING:
        words += ["--swing", f"{args.swing:g}"]
    if args.no_guard:
        words.append("--no-guard")
    words += ["--results", args.results]
    return shlex.join(one_line(w) for w in words)


def table(found: Derivation) -> list[str]:
    """The cells: context, estimator levels, best values and their metric; then the gain."""
    lines = [
        f"cell | estimator levels | best {', '.join(found.tuned)} | mean {found.metric} | robust's"
    ]
    for c in found.cells:
        levels = ", ".join(f"{k}={v:g}" for k, v in c.levels.items()) or "-"
        best = ", ".join(f"{v}" for v in c.best.values()) or "-"
        note = ""
        if c.unsafe is not None:
            lowest = ", ".join(f"{v}" for v in c.unsafe[0].values())
            at = _shown(found, c.unsafe[1])
            note = f" (not {lowest} at {at:.4g}: {c.why})"
        score, robust = _shown(found, c.score), _shown(found, c.robust_score)
        lines.append(f"{c.name} | {levels} | {best} | {score:.4g} | {robust:.4g}{note}")
    if found.robust:
        robust = ", ".join(f"{k}={v}" for k, v in found.robust.items())
        lines.append(
            f"robust fixed choice (least worst-case mean): {robust}, "
            f"mean {_shown(found, found.robust_mean):.4g}; switching per context (oracle): "
            f"{_shown(found, found.oracle_mean):.4g} ({100 * found.gain:.1f} % better)"
        )
    d = found.damping
    if d is not None:
        point = ", ".join(f"{k}={v}" for k, v in d.point.items())
        lines.append(
            f"damping: {point} while {d.leaf} is unsure and its pathSpeed is above {d.speed:g} "
            f"(the fastest under a chosen point: {d.fastest:g}); its fallback waits for "
            f"pathSpeed below {d.release:g}"
        )
    s = found.swing
    if s is not None:
        point = ", ".join(f"{k}={v}" for k, v in s.rule["set"].items())
        lines.append(
            f"swing: {point} while {s.leaf}'s amplitude is above {s.level:g} (the largest "
            f"swing under a chosen point: {s.largest:g}); higher choices wait for it to fall "
            "below"
        )
    r = found.recovery
    if r is not None:
        point = ", ".join(f"{k}={v}" for k, v in r["set"].items())
        when = " and ".join(
            f"{k} {'above' if 'above' in b else 'below'} {b.get('above', b.get('below')):g}"
            for k, b in r["when"].items()
        )
        lines.append(
            f"recovery: {point} when {when} for {r['hold']:g} s (motors a high gain was set "
            "for recover)"
        )
    return lines


def _shown(found: Derivation, value: float) -> float:
    """A mean as the user's metric reads it (a robustness objective is kept negated)."""
    return -value if found.metric.startswith(ROBUSTNESS) else value


def rules_text(found: Derivation, sweepdir: str) -> str:
    """The rules file: the table as comments, then ``adapt:`` (written by the YAML emitter)."""
    head = [
        f"adapt: rules derived by `amsa-phys adapt {sweepdir}` ({found.metric}, "
        + ("highest wins)" if found.metric.startswith(ROBUSTNESS) else "lowest wins)"),
        "estimator -> context parameter:",
    ]
    head += [f"  {w.signal} ~ {w.key}" for w in found.watches]
    head += table(found)
    head += [f"not placed: {p}" for p in found.unplaced]
    # a comment is one line whatever a name holds: newlines and control characters escaped
    comments = "".join(f"# {one_line(line)}\n" for line in head)
    body = yaml.dump(
        {"adapt": found.rules},
        Dumper=_PlainDumper,
        sort_keys=False,
        default_flow_style=None,
        width=100,
    )
    return comments + body


class _PlainDumper(yaml.SafeDumper):
    """``yaml.safe_dump`` without anchors and aliases: rules share their ``set:`` and
    ``when:`` objects, which the dumper would write once as ``&id001`` and then as
    ``*id001``; a rules file is read and edited by people, so every rule says its own."""

    def ignore_aliases(self, data: object) -> bool:
        return True


def _check_loads(text: str, out: Path, scenario: Scenario) -> None:
    """Refuse to write rules that would not load (the loader's own checks, on the text)."""
    try:
        doc = parse_yaml(text, out)
        schema.validate(doc.data, FILE, doc)
        parse_rules(doc, doc.data["adapt"], scenario.world)
    except ConfigError as exc:
        raise ConfigError(
            f"the derived rules would not load ({exc.message}); nothing written", file=out
        ) from None
