"""Does a stronger turning gain remove the fixed controller's stall, and at what cost?

The robust fixed controller (Kv 0.2, Kw 0.04) stalls on its own in some held-out runs of the
shipped box: side-on to a leader that wandered past it, its forward command scaled by the
cosine of the bearing, the turning gain too weak to turn it round (``adapt_seeds``' stalls).
Adaptation schedules Kv only and cannot remove it. ``python -m benchmarks.adapt_stall`` reads
``benchmarks/results/adapt_seeds.json``, takes every held-out sequence in which the robust
gain alone stalls in some seed, and runs it for the same seeds (600 s, as ``--validate``
runs it, Kv 0.2) with each turning gain of :data:`KW` (0.04 as shipped). Per Kw it reports
the stalled runs, the mean rms of the seeds that stall at Kw 0.04 and of the other seeds of
the same sequences, and the sequences gained and lost (seed mean more than 2 % below, above
Kw 0.04's); and, on the sweep's own contexts (``scenarios/adaptive_sweep.yaml``'s seven,
seeds 1-3, its 200 s: what ``amsa-phys tune`` scores), the worst case, the CVaR (0.2) and
the mean. Then it tunes both gains as ``amsa-phys tune scenarios/adaptive_sweep.yaml --range
MyFollowerController.Kv=0.1:0.4 --range MyFollowerController.Kw=0.02:0.2 --seeds 3 --budget
N --measure cvar`` does (``--budget``, 24 by default) and runs its answer on the stalled
sequences too. Last, the longest part: Kw :data:`FULL_KW` on every held-out sequence (the
shipped gains' runs there are ``adapt_seeds``' own), counted the same way.

It writes ``benchmarks/results/adapt_stall.json`` and rewrites docs/adaptation.md's
``<!-- results: adapt-stall -->`` block, once before the full pass and once after;
``--no-save`` prints only. Deterministic: the same numbers at any load. It changes no
default: Kw stays 0.04 in the shipped world.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run as a script: `benchmarks` is the repository's package

SWEEP = ROOT / "scenarios" / "adaptive_sweep.yaml"
SEEDS_FILE = ROOT / "benchmarks" / "results" / "adapt_seeds.json"
OUT = ROOT / "benchmarks" / "results" / "adapt_stall.json"
KV, KW_KEY = "MyFollowerController.Kv", "MyFollowerController.Kw"
#: the turning gains tried at Kv 0.2; the first is the shipped one, the baseline
KW = (0.04, 0.06, 0.08, 0.1, 0.15)
SHIPPED_KW = 0.04
#: the turning gain run on every held-out sequence, not only on the stalled ones
FULL_KW = 0.1
ROBUST_KV = 0.2
TUNE_RANGES = ((0.1, 0.4), (0.02, 0.2))
TUNE_SEEDS, ALPHA, TOLERANCE = 3, 0.2, 0.02
MAX_BUDGET = 200


def held_out(doc: dict[str, Any]) -> list[dict[str, Any]]:
    """Every held-out sequence of an ``adapt_seeds`` results file with the shipped gains'
    runs: draw, index, ``stalled`` (the seeds in which the robust gain alone stalls) and
    ``robust`` (its rms per seed)."""
    seeds = doc["seeds"]
    found = []
    for d in doc["draws"]:
        for r in d["rows"]:
            pairs = zip(seeds, r["stalls"]["robust"], strict=True)
            found.append(
                {
                    "draw": d["draw"],
                    "index": r["index"],
                    "stalled": [s for s, spells in pairs if spells],
                    "robust": r["seeds"]["robust"],
                    "robust_stalls": r["stalls"]["robust"],
                }
            )
    return found


def stalled_cases(doc: dict[str, Any]) -> list[dict[str, Any]]:
    """The held-out sequences in which the robust gain alone stalls in at least one seed."""
    return [c for c in held_out(doc) if c["stalled"]]


def summarise(runs: list[dict[str, Any]], seeds: list[int]) -> dict[str, Any]:
    """One gain pair over the held-out sequences, against the shipped gains.

    ``runs``: per sequence, ``stalled`` (the seeds that stall at the shipped gains),
    ``robust`` (the shipped gains' rms per seed) and ``rms``/``stalls`` (this pair's, per
    seed). On the sequences with a stall at the shipped gains, the seeds that stall there and
    the others are averaged apart: a stall costs several times the rms, so one mean over both
    would hide what the others pay. A sequence is lost (gained) when this pair's seed mean is
    more than 2 % above (below) the shipped gains'.
    """
    stalled_rms, other_rms = [], []
    lost = gained = stalled_runs = stalled_seqs = 0
    losses: list[list[float]] = []  # [draw, index, change] of each sequence lost
    every = []
    for r in runs:
        every += r["rms"]
        stalled_runs += sum(bool(x) for x in r["stalls"])
        stalled_seqs += any(r["stalls"])
        mine, base = statistics.fmean(r["rms"]), statistics.fmean(r["robust"])
        lost += mine > (1 + TOLERANCE) * base
        gained += mine < (1 - TOLERANCE) * base
        if mine > (1 + TOLERANCE) * base:
            losses.append([r["draw"], r["index"], mine / base - 1.0])
        if r["stalled"]:
            pick = [i for i, s in enumerate(seeds) if s in r["stalled"]]
            stalled_rms += [r["rms"][i] for i in pick]
            other_rms += [r["rms"][i] for i in range(len(seeds)) if i not in pick]
    return {
        "stalled_runs": stalled_runs,
        "stalled_sequences": stalled_seqs,
        "runs": len(runs) * len(seeds),
        "sequences": len(runs),
        "mean_rms": statistics.fmean(every),
        "lost": lost,
        "gained": gained,
        "losses": losses,
        "worst": max((c for *_, c in losses), default=0.0),
        "stalled_seeds_rms": statistics.fmean(stalled_rms) if stalled_rms else math.nan,
        "other_seeds_rms": statistics.fmean(other_rms) if other_rms else math.nan,
    }


def row(label: str, stalled: dict[str, Any], every: dict[str, Any] | None, sweep) -> list[str]:
    """A table row: the pair on the stalled sequences, on every held-out sequence (``None``:
    not run there), and the sweep's tail."""
    cells = [
        label,
        f"{stalled['stalled_runs']} of {stalled['runs']}",
        f"{stalled['stalled_seeds_rms']:.3g} / {stalled['other_seeds_rms']:.3g}",
        f"{stalled['gained']}, {stalled['lost']}",
    ]
    if every is None:
        cells += ["–", "–", "–"]
    else:
        cells += [
            f"{every['stalled_runs']} of {every['runs']}",
            f"{every['mean_rms']:.3g}",
            f"{every['gained']}, {every['lost']}"
            + (f" (worst +{100 * every['worst']:.1f} %)" if every["lost"] else ""),
        ]
    return [*cells, f"{sweep['worst']:.3g} / {sweep['cvar']:.3g} / {sweep['mean']:.3g}"]


COLUMNS = [
    "Kv, Kw",
    "stalled sequences: runs stalled",
    "rms, seeds stalled at Kw 0.04 / the others (m)",
    "sequences gained, lost (> 2 % vs Kw 0.04)",
    "every held-out sequence: runs stalled",
    "mean rms (m)",
    "sequences gained, lost",
    "sweep's contexts: worst / CVaR 0.2 / mean rms (m)",
]


def run_sequences(scenario, cases, seeds, settings, axes) -> list[dict[str, Any]]:
    """Every case (a held-out sequence) with ``settings``, each seed: rms and stall spells."""
    from amsa_phys.tune.contexts import sequences
    from benchmarks.adapt_seeds import run_case

    counts: dict[int, int] = {}
    for c in cases:
        counts[c["draw"]] = max(counts.get(c["draw"], 0), c["index"] + 1)
    drawn = {d: list(sequences(axes, n, 600.0, d)) for d, n in counts.items()}
    out = []
    for c in cases:
        sequence = drawn[c["draw"]][c["index"]]
        rms, spells = [], []
        for s in seeds:
            value, found = run_case(scenario, sequence, settings, s, 600.0)
            rms.append(value)
            spells.append([[round(float(a), 2), round(float(b), 2)] for a, b in found])
        out.append({**c, "rms": rms, "stalls": spells})
    return out


def _row(entry: dict[str, Any]) -> list[str]:
    label = f"{entry['kv']:g}, {entry['kw']:g}" + (" (tune, CVaR)" if entry.get("tuned") else "")
    return row(label, entry["stalled"], entry.get("every"), entry["sweep"])


def sweep_tail(scenario, settings: dict[str, float]) -> dict[str, float]:
    """The sweep's named contexts x seeds 1-3 at its duration, as ``tune`` scores them."""
    from amsa_phys.tune.contexts import Sequence
    from amsa_phys.tune.evaluate import evaluate
    from amsa_phys.tune.robust import tail

    contexts = dict(scenario.data["sweep"]["contexts"])
    values = [
        evaluate(
            scenario,
            Sequence(((0.0, dict(sets)),)),
            settings,
            seed,
            "rms_error",
            float(scenario.duration),
        )
        for sets in contexts.values()
        for seed in range(1, TUNE_SEEDS + 1)
    ]
    finite = [math.inf if v is None else v for v in values]
    return {
        "worst": tail(values, "worst"),
        "cvar": tail(values, "cvar", ALPHA),
        "mean": statistics.fmean(finite),
    }


def main(argv: list[str] | None = None) -> int:
    """Run the grid and the tune; write the results and the page's block."""
    from amsa_phys.cli.adapt import load_scenario
    from amsa_phys.tune.contexts import box
    from amsa_phys.tune.search import minimise
    from benchmarks import results as bench_results

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budget", type=int, default=24, help="the two-gain tune's evaluations")
    ap.add_argument("--no-save", action="store_true", help="print only")
    args = ap.parse_args(argv)
    if not 1 <= args.budget <= MAX_BUDGET:
        print(f"adapt_stall: --budget: must be 1..{MAX_BUDGET}, got {args.budget}", file=sys.stderr)
        return 2
    if not SEEDS_FILE.is_file():
        print(
            f"adapt_stall: {SEEDS_FILE.relative_to(ROOT)}: no such file "
            "(run python -m benchmarks.adapt_seeds DIR first)",
            file=sys.stderr,
        )
        return 2
    doc = json.loads(SEEDS_FILE.read_text())
    seeds, cases = doc["seeds"], held_out(doc)
    scenario = load_scenario(str(SWEEP))
    axes = box(scenario, dict(scenario.data["sweep"]["contexts"]))
    stalled = stalled_cases(doc)
    grid = []
    for kw in KW:
        settings = {KV: ROBUST_KV, KW_KEY: kw}
        runs = run_sequences(scenario, stalled, seeds, settings, axes)
        if kw == SHIPPED_KW:  # adapt_seeds' own runs: they must come back
            for r in runs:
                if any(abs(a - b) > 1e-9 for a, b in zip(r["rms"], r["robust"], strict=True)):
                    where = f"draw {r['draw']} sequence {r['index']}"
                    print(f"warning: {where} differs from {SEEDS_FILE.name}")
        entry = {"kv": ROBUST_KV, "kw": kw, "stalled": summarise(runs, seeds)}
        entry["sweep"] = sweep_tail(scenario, settings)
        if kw == SHIPPED_KW:  # on every sequence: adapt_seeds' runs as they are
            base = [{**c, "rms": c["robust"], "stalls": c["robust_stalls"]} for c in cases]
            entry["every"] = summarise(base, seeds)
        grid.append(entry)
        print(" | ".join(_row(entry)), flush=True)

    def objective(point: tuple[float, ...]) -> float:
        score = sweep_tail(scenario, {KV: point[0], KW_KEY: point[1]})["cvar"]
        print(f"  tune Kv {point[0]:g}, Kw {point[1]:g}: cvar {score:.4g}", flush=True)
        return score

    found = minimise(objective, list(TUNE_RANGES), args.budget)
    kv, kw = found.best.values
    settings = {KV: kv, KW_KEY: kw}
    tuned = {"kv": kv, "kw": kw, "tuned": True, "sweep": sweep_tail(scenario, settings)}
    tuned["stalled"] = summarise(run_sequences(scenario, stalled, seeds, settings, axes), seeds)
    print(" | ".join(_row(tuned)), flush=True)

    def save() -> None:
        """The table so far (the full pass is the longest: an interrupted run keeps the rest)."""
        rows = [_row(g) for g in [*grid, tuned]]
        command = "python -m benchmarks.adapt_stall" + (
            "" if args.budget == 24 else f" --budget {args.budget}"
        )
        out = bench_results.table_doc(
            COLUMNS,
            rows,
            f"Held-out sequences of adapt_seeds' five draws ({len(cases)}; stalled sequences: the "
            f"{len(stalled)} in which Kv 0.2, Kw 0.04 stalls in some seed), seeds "
            f"{seeds[0]}–{seeds[-1]}, 600 s; gained, lost: seed mean more than 2 % below, above Kv "
            f"0.2, Kw 0.04's; every held-out sequence run with Kw {FULL_KW:g} only; the sweep's "
            f"{len(scenario.data['sweep']['contexts'])} contexts x seeds 1–{TUNE_SEEDS}, "
            f"{float(scenario.duration):g} s; the last row: tune over Kv "
            f"{TUNE_RANGES[0][0]:g}–{TUNE_RANGES[0][1]:g}, Kw {TUNE_RANGES[1][0]:g}–"
            f"{TUNE_RANGES[1][1]:g}, CVaR {ALPHA:g}, {len(found.trials)} evaluations",
            command,
            grid=grid,
            tuned=tuned,
            trials=[[*t.values, t.score] for t in found.trials],
        )
        print(bench_results.table_markdown(out))
        if not args.no_save:
            OUT.write_text(json.dumps(out, indent=1, ensure_ascii=False) + "\n")
            for page in bench_results.write_pages():
                print(f"rewrote {page.relative_to(ROOT)}", file=sys.stderr)

    save()
    # the recommended turning gain on every held-out sequence (the longest part of the run)
    full = next(g for g in grid if g["kw"] == FULL_KW)
    runs = run_sequences(scenario, cases, seeds, {KV: ROBUST_KV, KW_KEY: FULL_KW}, axes)
    full["every"] = summarise(runs, seeds)
    print(" | ".join(_row(full)), flush=True)
    save()
    return 0


if __name__ == "__main__":
    sys.exit(main())
