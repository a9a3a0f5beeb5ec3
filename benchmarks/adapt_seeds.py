"""The shipped rules on every held-out draw with more seeds, and the robust gain's stalls.

A held-out sequence is lost when the rules' seed mean is more than 2 % above the robust fixed
gain's; with three seeds of chaotic 600 s runs that mean rests on one unlucky seed as often
as not. ``python -m benchmarks.adapt_seeds DIR`` (DIR: the output of ``amsa-phys sweep
scenarios/adaptive_sweep.yaml``) derives the rules from DIR as the docs say, checks that
they are the committed ``scenarios/rules/adaptive_rules.yaml``, and runs every sequence of
the docs' draws (``--validate``'s twenty, generator seed 1000, and the thirty of 2000, 3000,
4000 and 5000) the way ``--validate`` does (robust fixed gain, rules, oracle schedule;
600 s), for ``--seeds`` seeds (``10``: seeds 1-10; or a list, ``1-3`` or ``1,4,7``). Per
draw it reports, for seeds 1-3 and for all the seeds: reached (sequences where the oracle
gains 10 % or more on which the rules do too), losses above 2 %, the worst and the mean
change against the robust gain; over all the seeds, the gains and losses beyond the noise
(a mean change more than two standard errors below zero, or above the 2 % bound) and the
median standard error; for every sequence lost on either, each seed's values and the
standard error of the mean change (paired by seed).

It also counts *stalls*: a spell of 20 s or more in which the follower's speed stays below
0.05 m/s while it is more than 20 m from the leader (5 m behind its 15 m reference), read
from each run's trace; per way (robust alone, rules, oracle), the runs with one; the robust
gain's stalled runs whose rules run (same seed) stalls too; what a stall costs (the stalled
seeds' rms against the other seeds' of the same sequences); and the leader and motors in
force where each stall began.

It writes ``benchmarks/results/adapt_seeds.json`` after each draw (``--resume`` keeps the
draws already there that were run with the same seeds) and rewrites docs/adaptation.md's
``<!-- results: adapt-seeds -->`` block from it; ``--no-save`` prints only. ``--draws``
scores some draws only (``4000:30,5000:30``; implies ``--no-save`` unless all five).
It ends with the verdict ``--validate`` would give over these seeds, and how many of the
losses are within the seed noise; exit 1 if the rules lose on any sequence. Deterministic:
the same numbers at any load.

``--set KEY=VALUE`` (repeatable; ``MyFollowerController.Kw=0.1``) fixes a setting for every
way, the robust gain's, the rules' and the oracle's runs alike: the rules are derived from a
sweep run with it too (DIR's ``scenario.yaml`` must set the same value: the sweep's scenario
with a ``set:`` line), are not checked against the committed ones, and the results go to
``benchmarks/results/adapt_seeds_set.json`` and its own ``adapt-seeds-set`` block.

``--sweep FILE`` scores the rules derived from another swept scenario (DIR its output):
``scenarios/adaptive_sweep_fine.yaml``, the shipped sweep with a level between each two whose
best gains are more than a grid step apart. The held-out draws are the same (the box is the
same), the rules are not checked against the committed ones, and the results go to
``benchmarks/results/adapt_seeds_fine.json`` (``adapt_seeds_NAME.json`` for
``adaptive_sweep_NAME.yaml``) and its own ``adapt-seeds-fine`` block.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import statistics
import sys
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run as a script: `benchmarks` is the repository's package

SWEEP = ROOT / "scenarios" / "adaptive_sweep.yaml"
RULES = ROOT / "scenarios" / "rules" / "adaptive_rules.yaml"
OUT = ROOT / "benchmarks" / "results" / "adapt_seeds.json"
#: ``--set``'s results: rules derived and scored with a fixed setting (a sweep run with it)
OUT_SET = ROOT / "benchmarks" / "results" / "adapt_seeds_set.json"
#: (generator seed, sequences): the docs' draws (--validate's twenty is 1000), scored in this
#: order: the two the three-seed runs lost on first, so an interrupted run (``--resume``) has them
DRAWS = ((4000, 30), (5000, 30), (1000, 20), (2000, 30), (3000, 30))
NAMES = {
    1000: "twenty",
    2000: "fresh (2000)",
    3000: "third (3000)",
    4000: "fourth (4000)",
    5000: "fifth (5000)",
}
WAYS = ("robust", "rules", "oracle")
SPEED = "Follower.speed"
#: a stall: slower than SLOW m/s for LEAST s or more, all of it farther than FAR m
SLOW, FAR, LEAST = 0.05, 20.0, 20.0
TOLERANCE = 0.02


class SpecError(ValueError):
    """A command-line value that cannot be read (the message names the option)."""


def parse_seeds(text: str) -> list[int]:
    """``--seeds``: ``N`` (seeds 1..N), a range ``A-B`` or a comma list of either.

    Seeds are run seeds (1 or more), each once, in increasing order: the means do not
    depend on the order they are given in, and a repeated seed would weigh twice.
    """
    text = text.strip()
    if not text:
        raise SpecError("--seeds: empty (give N, A-B or a comma list)")
    if text.isdigit():
        n = int(text)
        if not 1 <= n <= 1000:
            raise SpecError(f"--seeds: {n} seeds: give 1 to 1000")
        return list(range(1, n + 1))
    seeds: set[int] = set()
    for part in text.split(","):
        part = part.strip()
        lo, dash, hi = part.partition("-")
        if not (lo.isdigit() and (not dash or hi.isdigit())):
            raise SpecError(f"--seeds: {part!r} is not a seed or a range A-B")
        a, b = int(lo), int(hi) if dash else int(lo)
        if a < 1 or b < a or b - a >= 1000:
            raise SpecError(f"--seeds: {part!r}: seeds from 1, A-B with A <= B")
        found = set(range(a, b + 1))
        if found & seeds:
            raise SpecError(f"--seeds: seed {min(found & seeds)} given twice")
        seeds |= found
    return sorted(seeds)


def parse_draws(text: str) -> list[tuple[int, int]]:
    """``--draws``: ``DRAW:COUNT`` pairs, comma separated (``4000:30,5000:30``)."""
    draws = []
    for part in text.split(","):
        draw, colon, count = part.strip().partition(":")
        if not (colon and draw.isdigit() and count.isdigit() and 1 <= int(count) <= 1000):
            raise SpecError(f"--draws: {part.strip()!r} is not DRAW:COUNT (COUNT 1 to 1000)")
        draws.append((int(draw), int(count)))
    if len({d for d, _ in draws}) != len(draws):
        raise SpecError("--draws: a draw given twice")
    return draws


def parse_set(texts: list[str]) -> dict[str, float]:
    """``--set KEY=VALUE`` (repeatable): a fixed setting every way runs with (a number).

    Only ``Component.param`` keys: the sweep's scenario sets them for every run, and a key
    the world does not have fails there, before any run.
    """
    found: dict[str, float] = {}
    for text in texts:
        key, eq, value = text.partition("=")
        key = key.strip()
        if not (eq and re.fullmatch(r"[A-Za-z_]\w*\.[A-Za-z_]\w*", key)):
            raise SpecError(f"--set: {text!r} is not Component.param=VALUE")
        try:
            number = float(value)
        except ValueError:
            raise SpecError(f"--set: {key}: {value.strip()!r} is not a number") from None
        if not math.isfinite(number):
            raise SpecError(f"--set: {key}: {value.strip()!r} is not a finite number")
        if key in found:
            raise SpecError(f"--set: {key} given twice")
        found[key] = number
    return found


def check_sweep_set(sweepdir: Path, fixed: dict[str, float]) -> None:
    """The sweep's output must have been run with the same fixed settings: rules derived at
    one setting and scored at another measure neither. Raises SpecError naming the key."""
    import yaml

    path = sweepdir / "scenario.yaml"
    if not path.is_file():
        raise SpecError(f"{path}: no such file (DIR: a sweep's output)")
    data = yaml.safe_load(path.read_text()) or {}
    swept = data.get("set") or {} if isinstance(data, dict) else {}
    for key, value in fixed.items():
        if key not in swept:
            raise SpecError(f"{path}: set: no {key} (sweep with {key}: {value:g} set)")
        if not isinstance(swept[key], int | float) or float(swept[key]) != value:
            raise SpecError(f"{path}: set: {key} is {swept[key]!r}, not {value:g}")


def sweep_key(path: Path) -> str:
    """``fine`` for ``adaptive_sweep_fine.yaml``: the name of its results file and block.
    Raises SpecError for a file that is not one of the repository's adaptive sweeps."""
    stem = path.name.removesuffix(".yaml")
    key = stem.removeprefix("adaptive_sweep_")
    if not path.name.endswith(".yaml") or key == stem or not re.fullmatch(r"[a-z0-9]+", key):
        raise SpecError(f"--sweep: {path.name}: expected scenarios/adaptive_sweep_NAME.yaml")
    if not path.is_file():
        raise SpecError(f"--sweep: {path}: no such file")
    return key


def check_sweep_contexts(sweepdir: Path, scenario) -> None:
    """DIR must be the output of the swept scenario the rules are derived for: the same
    contexts, or the rules would be another sweep's. Raises SpecError naming both."""
    import yaml

    path = sweepdir / "scenario.yaml"
    if not path.is_file():
        raise SpecError(f"{path}: no such file (DIR: a sweep's output)")
    data = yaml.safe_load(path.read_text()) or {}
    sweep = data.get("sweep") if isinstance(data, dict) else None
    ran = sorted((sweep or {}).get("contexts") or {}) if isinstance(sweep, dict) else []
    want = sorted((scenario.data.get("sweep") or {}).get("contexts") or {})
    if ran != want:
        missing = sorted(set(want) - set(ran)) or sorted(set(ran) - set(want))
        raise SpecError(
            f"{path}: sweep: contexts differ from the swept scenario's ({', '.join(missing)})"
        )


def fix(scenario, fixed: dict[str, float]):
    """The scenario with ``fixed`` in its ``set``: every case copies it (``case_data``), so the
    robust gain, the rules and the oracle all run with it, as the sweep's runs did."""
    if fixed:
        scenario.data["set"] = {**(scenario.data.get("set") or {}), **fixed}
    return scenario


def stalls(
    t: Iterable[float],
    speed: Iterable[float],
    distance: Iterable[float],
    slow: float = SLOW,
    far: float = FAR,
    least: float = LEAST,
) -> list[tuple[float, float]]:
    """The spells (start, end) of ``least`` s or more with |speed| < ``slow`` and
    distance > ``far`` throughout: the follower standing while the leader gets away."""
    spells = []
    start = last = None
    for ti, v, d in zip(t, speed, distance, strict=True):
        if abs(v) < slow and d > far:
            if start is None:
                start = ti
            last = ti
            continue
        if start is not None and last - start >= least:
            spells.append((start, last))
        start = None
    if start is not None and last - start >= least:
        spells.append((start, last))
    return spells


@dataclass
class Stats:
    """One sequence's seeds as the docs read them."""

    change: float  # the rules' seed mean relative to the robust gain's (-0.1: 10 % better)
    se: float  # standard error of that change, from the per-seed differences


def stats(robust: list[float], rules: list[float]) -> Stats:
    """The rules' mean change against the robust gain and its standard error.

    Paired by seed (both ways see the same noise): the error of mean(rules - robust),
    relative to mean(robust). One seed gives no error (inf).
    """
    base = statistics.fmean(robust)
    if not (math.isfinite(base) and base > 0) or not all(map(math.isfinite, rules)):
        return Stats(math.inf, math.inf)
    change = statistics.fmean(rules) / base - 1.0
    if len(robust) < 2:
        return Stats(change, math.inf)
    diffs = [a - b for a, b in zip(rules, robust, strict=True)]
    return Stats(change, statistics.stdev(diffs) / math.sqrt(len(diffs)) / base)


def summary(rows: list[dict[str, Any]], seeds: list[int], pick: list[int]) -> dict[str, Any]:
    """A draw's counts over the seeds ``pick`` (a subset of ``seeds``): reached, lost, worst,
    mean change, and the rules' change per sequence."""
    idx = [seeds.index(s) for s in pick]
    worth = reached = 0
    changes = []
    for r in rows:
        means = {w: statistics.fmean(r["seeds"][w][i] for i in idx) for w in WAYS}
        change = stats(
            [r["seeds"]["robust"][i] for i in idx], [r["seeds"]["rules"][i] for i in idx]
        )
        changes.append(change)
        if math.isfinite(means["robust"]) and means["oracle"] <= 0.9 * means["robust"]:
            worth += 1
            reached += means["rules"] <= 0.9 * means["robust"]
    lost = [i for i, c in enumerate(changes) if c.change > TOLERANCE]
    finite = [c.change for c in changes]
    return {
        "reached": reached,
        "worth": worth,
        "lost": lost,
        "worst": max(finite),
        "mean": statistics.fmean(finite),
        "changes": [[c.change, c.se] for c in changes],
    }


def run_case(scenario, sequence, settings, seed, duration, rules=None, plan=None):
    """One case as ``tune.evaluate`` runs it, traced: (rms error or inf, stall spells)."""
    from amsa_phys.engine import interrupt
    from amsa_phys.engine.tracemem import TraceMemory
    from amsa_phys.errors import RunFault
    from amsa_phys.model.configure import configure_scenario
    from amsa_phys.model.scenario import traced_columns
    from amsa_phys.model.yamlio import YamlDoc
    from amsa_phys.runs.single import execute
    from amsa_phys.tune.evaluate import add_timeline_settings, case_data
    from amsa_phys.tune.objective import objective_value

    data = case_data(scenario, sequence, settings, duration, rules)
    add_timeline_settings(data, plan or [])  # the oracle's switches, as evaluate() adds them
    signal = data["quality"]["signal"]
    data["trace_columns"] = [signal, SPEED]
    case = configure_scenario(YamlDoc(path=Path(scenario.path), data=data), None, seed)
    memory = TraceMemory(traced_columns(case))
    with interrupt.deferred():
        ended = execute(case, memory, progress=False)
    if isinstance(ended.error, RunFault):
        return math.inf, []
    if ended.error is not None:
        raise ended.error
    value, _ = objective_value(ended.metrics, "rms_error")
    trace = memory.structured()
    spells = stalls(trace["t"], trace[SPEED], trace[signal])
    return (math.inf if value is None else value), spells


def score_draw(scenario, found, draw: int, count: int, seeds: list[int]) -> list[dict[str, Any]]:
    """Every sequence of a draw, every seed, three ways: values and stall spells."""
    from amsa_phys.adapt.validate import nearest
    from amsa_phys.tune.contexts import box, sequences

    contexts = dict(scenario.data["sweep"]["contexts"])
    axes = box(scenario, {k: v for k, v in contexts.items() if k not in found.catch_ups})
    rows = []
    for index, sequence in enumerate(sequences(axes, count, 600.0, draw)):
        plan = [(at, nearest(found.cells, axes, sets).best) for at, sets in sequence.segments]
        row: dict[str, Any] = {
            "index": index,
            "sequence": sequence.describe(),
            "segments": [[at, sets] for at, sets in sequence.segments],
            "seeds": {w: [] for w in WAYS},
            "stalls": {w: [] for w in WAYS},
        }
        for s in seeds:
            cases = {
                "robust": run_case(scenario, sequence, found.robust, s, 600.0),
                "rules": run_case(scenario, sequence, found.robust, s, 600.0, found.rules),
                "oracle": run_case(scenario, sequence, {}, s, 600.0, None, plan),
            }
            for way, (value, spells) in cases.items():
                row["seeds"][way].append(value)
                row["stalls"][way].append([[round(a, 2), round(b, 2)] for a, b in spells])
        change = stats(row["seeds"]["robust"], row["seeds"]["rules"])
        stalled = ", ".join(f"{w} {sum(map(bool, row['stalls'][w]))}" for w in WAYS)
        print(
            f"{draw} sequence {index}: {100 * change.change:+.1f} % ± {100 * change.se:.1f} | "
            f"stalls {stalled} | {row['sequence']}",
            flush=True,
        )
        rows.append(row)
    return rows


BEHAVIOR, MOTORS = "Leader.behavior", "MyNormalizePower.motorCoef"
LEADERS = {1: "straight", 4: "random"}


def stall_contexts(rows: list[dict[str, Any]], way: str) -> list[tuple[int, float]]:
    """(leader behaviour, motor level) in force where each of ``way``'s stalls began."""
    found = []
    for r in rows:
        for spells in r["stalls"][way]:
            for start, _ in spells:
                sets = [s for at, s in r.get("segments", []) if at <= start]
                if sets:
                    found.append((sets[-1].get(BEHAVIOR), sets[-1].get(MOTORS)))
    return found


def stalled_both(rows: list[dict[str, Any]]) -> int:
    """Runs where the robust gain alone stalls and the rules, same sequence and seed, too."""
    return sum(
        bool(a) and bool(b)
        for r in rows
        for a, b in zip(r["stalls"]["robust"], r["stalls"]["rules"], strict=True)
    )


def beyond(changes: list[list[float]], tolerance: float = TOLERANCE) -> tuple[int, int]:
    """(gains, losses) beyond the seed noise: a mean change more than two standard errors
    below zero, or more than two above the tolerance."""
    gains = sum(c < 0 and c < -2 * se for c, se in changes)
    losses = sum(c - tolerance > 2 * se for c, se in changes)
    return gains, losses


def _beyond(s: dict[str, Any]) -> str:
    gains, losses = beyond(s["changes"])
    median = statistics.median(se for _, se in s["changes"])
    return f"{gains}, {losses}; {100 * median:.1f} points"


def stall_cost(rows: list[dict[str, Any]]) -> list[tuple[float, float]]:
    """(mean rms of the stalled seeds, of the other seeds) of each sequence in which the
    robust gain alone stalls in some seeds but not all: what a stall costs, seed noise aside."""
    found = []
    for r in rows:
        pairs = list(zip(r["seeds"]["robust"], r["stalls"]["robust"], strict=True))
        stalled = [v for v, spells in pairs if spells]
        other = [v for v, spells in pairs if not spells]
        if stalled and other:
            found.append((statistics.fmean(stalled), statistics.fmean(other)))
    return found


def _cost(found: list[tuple[float, float]]) -> str:
    if not found:
        return "–"
    a = statistics.fmean(s for s, _ in found)
    b = statistics.fmean(o for _, o in found)
    return f"{a:.3g} / {b:.3g} ({len(found)} seq.)"


def _contexts(found: list[tuple[int, float]]) -> str:
    """``random leader 5 (motors 34–60 %)``: the stalls' contexts, per leader behaviour."""
    parts = []
    for behavior in sorted({b for b, _ in found}, key=str):
        levels = [m for b, m in found if b == behavior]
        name = LEADERS.get(behavior, f"behavior {behavior}")
        span = f"{min(levels):g}" + ("" if min(levels) == max(levels) else f"–{max(levels):g}")
        parts.append(f"{name} leader {len(levels)} (motors {span} %)")
    return "; ".join(parts) or "–"


def with_segments(scenario, found, entry: dict[str, Any]) -> dict[str, Any]:
    """A saved draw's rows with their sequences' segments (drawn again: deterministic)."""
    from amsa_phys.tune.contexts import box, sequences

    if all("segments" in r for r in entry["rows"]):
        return entry
    contexts = dict(scenario.data["sweep"]["contexts"])
    axes = box(scenario, {k: v for k, v in contexts.items() if k not in found.catch_ups})
    drawn = sequences(axes, len(entry["rows"]), 600.0, entry["draw"])
    for r, sequence in zip(entry["rows"], drawn, strict=True):
        if r["sequence"] != sequence.describe():
            raise SystemExit(
                f"adapt_seeds: draw {entry['draw']}, sequence {r['index']} drawn otherwise"
            )
        r["segments"] = [[at, sets] for at, sets in sequence.segments]
    return entry


def _pct(x: float) -> str:
    return f"{100 * x:+.1f} %".replace("-", "−")


def _cell(s: dict[str, Any]) -> str:
    return (
        f"{s['reached']} of {s['worth']}, {len(s['lost'])}, {_pct(s['worst'])}, {_pct(s['mean'])}"
    )


def tables(doc: dict[str, Any]) -> dict[str, Any]:
    """The docs' three tables of a results file: per draw, lost sequences, stalls."""
    seeds = doc["seeds"]
    first = [s for s in seeds if s <= 3]
    label = (
        f"{seeds[0]}–{seeds[-1]}" if seeds == list(range(seeds[0], seeds[-1] + 1)) else str(seeds)
    )
    per_draw, lost_rows, stall_rows = [], [], []
    totals = {w: [0, 0] for w in WAYS}
    every: list[tuple[int, float]] = []
    costs: list[tuple[float, float]] = []
    together = 0
    for d in doc["draws"]:
        rows = d["rows"]
        few = summary(rows, seeds, first)
        many = summary(rows, seeds, seeds)
        per_draw.append(
            [NAMES.get(d["draw"], str(d["draw"])), _cell(few), _cell(many), _beyond(many)]
        )
        for i in sorted(set(few["lost"]) | set(many["lost"])):
            r = rows[i]
            per_seed = ", ".join(
                f"{b:.3g}/{a:.3g}"
                for a, b in zip(r["seeds"]["robust"], r["seeds"]["rules"], strict=True)
            )
            (c3, e3), (cn, en) = few["changes"][i], many["changes"][i]
            lost_rows.append(
                [
                    f"{NAMES.get(d['draw'], d['draw'])}, sequence {i}",
                    f"{_pct(c3)} ± {100 * e3:.1f}",
                    f"{_pct(cn)} ± {100 * en:.1f}",
                    per_seed,
                    r["sequence"],
                ]
            )
        cells = [NAMES.get(d["draw"], str(d["draw"]))]
        for w in WAYS:
            runs = sum(bool(x) for r in rows for x in r["stalls"][w])
            seqs = sum(any(r["stalls"][w]) for r in rows)
            totals[w][0] += runs
            totals[w][1] += seqs
            cells.append(f"{runs} ({seqs} seq.)")
        cells.append(str(len(rows) * len(seeds)))
        shared = stalled_both(rows)
        together += shared
        cells.append(str(shared))
        cost = stall_cost(rows)
        costs.extend(cost)
        cells.append(_cost(cost))
        found = stall_contexts(rows, "robust")
        every.extend(found)
        cells.append(_contexts(found))
        stall_rows.append(cells)
    n_runs = sum(len(d["rows"]) for d in doc["draws"]) * len(seeds)
    stall_rows.append(
        [
            "all",
            *(f"{a} ({b} seq.)" for a, b in totals.values()),
            str(n_runs),
            str(together),
            _cost(costs),
            _contexts(every),
        ]
    )
    found = {
        "per_draw": {
            "columns": [
                "draw",
                "seeds 1–3",
                f"seeds {label}",
                f"seeds {label}: gains, losses beyond the noise; median s.e.",
            ],
            "rows": per_draw,
        },
        "lost": {
            "columns": [
                "sequence",
                "change ± s.e., seeds 1–3",
                f"change ± s.e., seeds {label}",
                "rules/robust per seed (rms m)",
                "held-out sequence",
            ],
            "rows": lost_rows,
        },
        "stalls": {
            "columns": [
                "draw",
                "robust alone: runs (sequences)",
                "rules",
                "oracle",
                "runs",
                "robust stalls in a seed whose rules run stalls too",
                "robust rms, stalled seeds / the others (m)",
                "in force where the robust gain's stalls began (spells)",
            ],
            "rows": stall_rows,
        },
    }
    if seeds == first:  # seeds 1-3 only: the "all the seeds" columns would repeat them
        for key in ("per_draw", "lost"):
            found[key]["columns"].pop(1)
            for r in found[key]["rows"]:
                r.pop(1)
    return found


def robust_text(doc: dict[str, Any]) -> str:
    """``Kv 0.2``: the robust point the rules fall back on, read from the rules scored (the
    doc's own, or the committed file's): a sweep run with another setting may have another."""
    import yaml

    rules = doc.get("rules")
    if rules is None:
        rules = yaml.safe_load(RULES.read_text())["adapt"]
    for rule in rules:
        if str(rule.get("label", "")).startswith("robust"):
            return ", ".join(f"{k.rsplit('.', 1)[-1]} {v:g}" for k, v in dict(rule["set"]).items())
    return "fixed choice"


def markdown(doc: dict[str, Any]) -> str:
    """The page's block: the three tables, then how they were made."""
    parts = []
    for t in tables(doc).values():
        lines = [
            "| " + " | ".join(t["columns"]) + " |",
            "| " + " | ".join("---" for _ in t["columns"]) + " |",
        ]
        lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in t["rows"]]
        parts.append("\n".join(lines))
    load_ = "–".join(f"{x:g}" for x in doc["load"])
    fixed = doc.get("set") or {}
    at = ", ".join(f"{k} {v:g}" for k, v in fixed.items())
    robust = robust_text(doc)
    if fixed:
        what = f"Rules derived from a sweep with {at} vs the robust {robust}, every way with {at}"
    elif doc.get("sweep"):
        what = f"Rules derived from `{doc['sweep']}` vs the robust {robust}"
    else:
        what = f"Rules vs the robust {robust}"
    parts.append(
        f"*{what}, 600 s: reached, losses above 2 %, worst, mean change; "
        f"s.e.: standard error of the mean change, paired by seed; a stall: {LEAST:g} s or "
        f"more below {SLOW:g} m/s farther than {FAR:g} m from the leader (load {load_}, "
        f"{doc['date'][:10]}). Regenerate, DIR the sweep's output: `{doc['command']}`.*"
    )
    return "\n\n".join(parts) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Derive, check, score every draw over the seeds; write the results as they come."""
    import datetime
    import os

    import yaml

    from amsa_phys.adapt.derive import derive
    from amsa_phys.cli.adapt import load_scenario
    from benchmarks import results as bench_results

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sweepdir", type=Path, help="the sweep's output directory")
    ap.add_argument("--seeds", default="10", help="N (seeds 1..N), A-B, or a comma list")
    ap.add_argument("--draws", help="DRAW:COUNT,... (default: the docs' five draws)")
    ap.add_argument("--no-save", action="store_true", help="print only")
    ap.add_argument("--resume", action="store_true", help="keep the draws already saved")
    ap.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="a fixed setting of every way (the sweep in DIR run with it too); "
        f"results to benchmarks/results/{OUT_SET.name}",
    )
    ap.add_argument(
        "--sweep",
        type=Path,
        metavar="FILE",
        help="the swept scenario DIR is the output of (default: scenarios/adaptive_sweep.yaml); "
        "results to benchmarks/results/adapt_seeds_NAME.json",
    )
    args = ap.parse_args(argv)
    try:
        key = sweep_key(args.sweep) if args.sweep is not None else None
        if key is not None and args.set:
            raise SpecError("--sweep and --set: one at a time")
        seeds = parse_seeds(args.seeds)
        draws = parse_draws(args.draws) if args.draws else list(DRAWS)
        fixed = parse_set(args.set)
        if fixed:
            check_sweep_set(args.sweepdir, fixed)
    except SpecError as e:
        print(f"adapt_seeds: {e}", file=sys.stderr)
        return 2
    out = OUT_SET if fixed else OUT
    if key is not None:
        out = OUT.with_name(f"adapt_seeds_{key}.json")
    if sorted(draws) != sorted(DRAWS):
        args.no_save = True  # the committed table holds the docs' five draws
    results = args.sweepdir / "results.csv"
    if not results.is_file():
        print(f"adapt_seeds: {results}: no such file (DIR: a sweep's output)", file=sys.stderr)
        return 2
    swept = SWEEP if args.sweep is None else args.sweep
    scenario = fix(load_scenario(str(swept)), fixed)
    if key is not None:
        try:
            check_sweep_contexts(args.sweepdir, scenario)
        except SpecError as e:
            print(f"adapt_seeds: {e}", file=sys.stderr)
            return 2
    found = derive(results, scenario)
    if fixed or key is not None:
        what = f"with {fixed}" if fixed else f"of {swept.name}"
        print(f"rules derived from {args.sweepdir} {what}: {len(found.rules)} rules")
    elif found.rules != yaml.safe_load(RULES.read_text())["adapt"]:
        print(f"warning: the rules derived from {args.sweepdir} differ from {RULES.name}")
    done: dict[int, dict[str, Any]] = {}
    if args.resume and out.exists():
        old = json.loads(out.read_text())
        same = old.get("rules") == found.rules if key is not None else True
        if old.get("seeds") == seeds and (old.get("set") or {}) == fixed and same:
            done = {d["draw"]: d for d in old["draws"]}
    command = (
        "python -m benchmarks.adapt_seeds DIR"
        + "".join(f" --set {k}={v:g}" for k, v in fixed.items())
        + (f" --sweep scenarios/{swept.name}" if key is not None else "")
        + ("" if args.seeds == "10" else f" --seeds {args.seeds}")
    )
    doc: dict[str, Any] = {"seeds": seeds, "command": command, "draws": []}
    if fixed:
        doc["set"] = fixed
    if fixed or key is not None:
        doc["rules"] = found.rules
    if key is not None:
        doc["sweep"] = f"scenarios/{swept.name}"
    for draw, count in draws:
        if draw in done and len(done[draw]["rows"]) == count:
            entry = with_segments(scenario, found, done[draw])
        else:
            entry = {"draw": draw, "rows": score_draw(scenario, found, draw, count, seeds)}
        doc["draws"] = sorted([*doc["draws"], entry], key=lambda d: d["draw"])
        doc["load"] = [round(x, 2) for x in os.getloadavg()]
        doc["date"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
        if not args.no_save:
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_text(json.dumps(doc, indent=1, ensure_ascii=False) + "\n")
    print(markdown(doc))
    if not args.no_save:
        for page in bench_results.write_pages():
            print(f"rewrote {page.relative_to(ROOT)}", file=sys.stderr)
    lost, noisy, count = verdict(doc)
    print(
        f"the rules lose (by more than {100 * TOLERANCE:g} % in the mean over {len(seeds)} "
        f"seeds) on {lost} of {count} held-out sequences, {noisy} of them within the seed noise"
    )
    return 1 if lost else 0


def verdict(doc: dict[str, Any]) -> tuple[int, int, int]:
    """(sequences lost over all the seeds, those of them within two standard errors of the
    bound, sequences): the bound as ``--validate`` checks it, and how much of it is noise."""
    seeds = doc["seeds"]
    lost = noisy = count = 0
    for d in doc["draws"]:
        changes = summary(d["rows"], seeds, seeds)["changes"]
        count += len(changes)
        for c, se in changes:
            if c > TOLERANCE:
                lost += 1
                noisy += not c - TOLERANCE > 2 * se
    return lost, noisy, count


if __name__ == "__main__":
    sys.exit(main())
