"""amsa-phys's falsification side by side with PSY-TaLiRo, as ARCH-COMP measures it.

Both search the same boxes of the same scenarios for a run whose robustness is below 0, with
the same budget, over the same simulator: PSY-TaLiRo's cost function calls ``amsa_phys.run``
in this process and computes the same robustness from the run's metrics that ``ap.falsify``
computes from its result row. amsa-phys runs its generations in this process one run after
another (``executor="local"``, one worker): for generations of 6-30 runs that costs a
third to a fifth of the CPU of a batch (measured: 0.7 s against 2.2-3.3 s for 20 runs).
Each problem is searched in N trials (seeds 1..N); a trial
stops at its first falsifying run (PSY-TaLiRo's ``min_cost=0``; amsa-phys's default). The
table: falsification rate, mean simulations to the first violation (over falsified trials),
CPU seconds per trial (this process and its children).

Problems (the issue's three):

* ``resonance-rms``: ``scenarios/falsify_resonance.yaml``, changePeriod 2-40 s x cruisePower
  3-12, requirement rms_error below 1.35 (robustness 1.35 - rms_error);
* ``resonance-stl``: the same box, the STL timing requirement
  ``always[10:120](abs(distance - 15) <= 2.5)`` (the scenario's ``band`` requirement, 15 +- 1.5
  m, with 1 m more tolerance: its robustness plus 1, exactly);
* ``fig5``: ``scenarios/paper_fig5_kv01.yaml`` cut to 120 s, the paper's Fig. 5 box
  motorCoef 40-100 x cruisePower 3-12 x lostDataGPS 0-60, rms_error below 4.8.

PSY-TaLiRo is a benchmark-only dependency: ``pip install psy-taliro`` (without it, its rows
say so).

    python benchmarks/bench_falsify_peers.py [--trials 10] [--budget 150] [--out FILE.json]
    python -m benchmarks.perf --only falsify_peers   # --reps trials, into the results file
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import resource
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import amsa_phys as ap  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import results  # noqa: E402

Cost = Callable[[dict[str, Any]], float]

PROBLEMS: dict[str, dict[str, Any]] = {
    "resonance-rms": {
        "scenario": ROOT / "scenarios" / "falsify_resonance.yaml",
        "box": {"Leader.changePeriod": (2.0, 40.0), "Leader.cruisePower": (3.0, 12.0)},
        "duration": None,
        "executor": "local",
        "row": lambda r: 1.35 - r["rms_error"],
        "metrics": lambda m: 1.35 - m["overall"]["rms_error"],
    },
    "resonance-stl": {
        "scenario": ROOT / "scenarios" / "falsify_resonance.yaml",
        "box": {"Leader.changePeriod": (2.0, 40.0), "Leader.cruisePower": (3.0, 12.0)},
        "duration": None,
        "executor": "local",
        "row": lambda r: r["robustness.band"] + 1.0,
        "metrics": lambda m: m["requirements"]["band"]["robustness"] + 1.0,
    },
    "fig5": {
        "scenario": ROOT / "scenarios" / "paper_fig5_kv01.yaml",
        "box": {
            "MyNormalizePower.motorCoef": (40.0, 100.0),
            "Leader.cruisePower": (3.0, 12.0),
            "LeaderGPS.lostDataGPS": (0.0, 60.0),
        },
        "duration": 120.0,
        "executor": "local",  # its rovers start within reach: a batch runs them alone anyway
        # int parameters: PSY-TaLiRo's floats rounded (ap.falsify searches them as integers)
        "ints": ("MyNormalizePower.motorCoef", "LeaderGPS.lostDataGPS"),
        "row": lambda r: 4.8 - r["rms_error"],
        "metrics": lambda m: 4.8 - m["overall"]["rms_error"],
    },
}


def cpu() -> float:
    """CPU seconds of this process and its finished children."""
    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def amsa_trial(p: dict[str, Any], budget: int, seed: int) -> dict[str, Any]:
    """One ``ap.falsify`` search, stopping at its first falsifying run."""
    t0 = cpu()
    found = ap.falsify(
        p["scenario"],
        p["box"],
        budget=budget,
        cost=p["row"],
        seed=seed,
        duration=p["duration"],
        executor=p["executor"],
        workers=1,
    )
    trial = found.trials[0]
    least = min(
        (p["row"](r) for r in found.rows[0] if r.get("rms_error") is not None), default=None
    )
    return {
        "falsified": trial.falsified,
        "simulations": trial.simulations,
        "runs": trial.runs,
        "least": least,
        "cpu_s": cpu() - t0,
    }


def psy_trial(p: dict[str, Any], budget: int, seed: int, optimizer: str) -> dict[str, Any]:
    """One PSY-TaLiRo search over ``amsa_phys.run``, stopping at its first cost below 0."""
    import staliro
    from staliro.optimizers import DualAnnealing, UniformRandom

    names = list(p["box"])

    @staliro.costfunc
    def cost(inputs: Any) -> float:
        values: dict[str, float | int] = {k: float(inputs.static[k]) for k in names}
        for k in p.get("ints", ()):
            values[k] = round(values[k])
        run = ap.run(p["scenario"], duration=p["duration"], set=values)
        return float(p["metrics"](run.metrics))

    opt = DualAnnealing(min_cost=0.0) if optimizer == "dual-annealing" else UniformRandom(0.0)
    options = staliro.TestOptions(
        static_inputs={k: list(v) for k, v in p["box"].items()},
        iterations=budget,
        runs=1,
        seed=seed,
    )
    t0 = cpu()
    runs = staliro.staliro(cost, opt, options)
    costs = [float(e.cost) for e in runs[0].evaluations]
    first = next((i for i, c in enumerate(costs) if c < 0), None)
    return {
        "falsified": first is not None,
        "simulations": None if first is None else first + 1,
        "runs": len(costs),
        "least": min(costs) if costs else None,
        "cpu_s": cpu() - t0,
    }


def table(trials: list[dict[str, Any]]) -> dict[str, Any]:
    """Falsification rate, mean/median simulations, mean CPU per trial."""
    sims = [t["simulations"] for t in trials if t["falsified"]]
    return {
        "trials": len(trials),
        "falsified": len(sims),
        "rate": len(sims) / len(trials),
        "mean_simulations": statistics.fmean(sims) if sims else None,
        "median_simulations": statistics.median(sims) if sims else None,
        "mean_cpu_s": statistics.fmean(t["cpu_s"] for t in trials),
        "table": trials,
    }


#: The tools compared, as the results table names them
TOOLS = {
    "amsa-phys": "amsa-phys (ap.falsify)",
    "dual-annealing": "PSY-TaLiRo dual annealing",
    "uniform-random": "PSY-TaLiRo uniform random",
}


def perf(reps: int, report: results.Report = results.print_report, budget: int = 150) -> None:
    """Per problem and tool: the falsification rate over ``reps`` trials, the simulations to
    the first violation, and the CPU a trial against amsa-phys's in the same sitting."""
    have_psy = importlib.util.find_spec("staliro") is not None
    first = next(iter(PROBLEMS.values()))
    amsa_trial(first, 12, 1)  # warm: the first search imports the optimizer and the engine
    for name, p in PROBLEMS.items():
        mine = 0.0
        for tool, label in TOOLS.items():
            figure = f"falsify vs PSY-TaLiRo, {name}, budget {budget}: {label}, falsification rate"
            if tool != "amsa-phys" and not have_psy:
                why = "not measured: PSY-TaLiRo is not installed here (pip install psy-taliro)"
                report(figure, why, "", None, skipped=True)
                continue
            trials = [
                amsa_trial(p, budget, seed)
                if tool == "amsa-phys"
                else psy_trial(p, budget, seed, tool)
                for seed in range(1, reps + 1)
            ]
            row = table(trials)
            mine = mine or row["mean_cpu_s"]
            sims = (
                "none falsified"
                if row["mean_simulations"] is None
                else f"mean (median) simulations to the first violation "
                f"{row['mean_simulations']:.1f} ({row['median_simulations']:g})"
            )
            vs = f" ({row['mean_cpu_s'] / mine:.3g}x amsa-phys's)" if tool != "amsa-phys" else ""
            report(
                figure,
                f"{row['rate']:.3g}; {row['falsified']}/{row['trials']} trials; {sims}; "
                f"CPU a trial {row['mean_cpu_s']:.1f} s{vs}",
                "",
                None,
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--budget", type=int, default=150)
    parser.add_argument("--problems", default=",".join(PROBLEMS))
    parser.add_argument("--out", default="bench_falsify_peers.json")
    parser.add_argument("--tools", default="amsa-phys,dual-annealing,uniform-random")
    args = parser.parse_args()
    load0 = os.getloadavg()
    found: dict[str, Any] = {"budget": args.budget, "load_before": load0, "problems": {}}
    for name in args.problems.split(","):
        p = PROBLEMS[name]
        found["problems"][name] = {}
        for tool in args.tools.split(","):
            trials = []
            for seed in range(1, args.trials + 1):
                if tool == "amsa-phys":
                    trials.append(amsa_trial(p, args.budget, seed))
                else:
                    trials.append(psy_trial(p, args.budget, seed, tool))
            row = table(trials)
            found["problems"][name][tool] = row
            mean = row["mean_simulations"]
            print(
                f"{name:14} {tool:15} falsified {row['falsified']:2}/{row['trials']}"
                f"  mean sims {'-' if mean is None else f'{mean:6.1f}'}"
                f"  CPU/trial {row['mean_cpu_s']:6.2f} s  load {os.getloadavg()[0]:.1f}",
                flush=True,
            )
            Path(args.out).write_text(json.dumps(found, indent=1))
    found["load_after"] = os.getloadavg()
    found["wall_s"] = time.perf_counter()
    Path(args.out).write_text(json.dumps(found, indent=1))


if __name__ == "__main__":
    main()
