"""Repeated falsification trials, measured as ARCH-COMP's falsification track measures them.

A search's result depends on its seed; one lucky trial says little. ``--trials N`` runs the
search with seeds S, S+1, ..., S+N-1 and reports the **falsification rate** (trials that
found a run with robustness below 0), the **mean and median simulations** to the first
falsifying run (its run number + 1: runs are numbered in the order the search proposed
them, so the count is the one a sequential search would pay, whatever the batching), and
the **robustness reached** by trials that did not falsify. ``summary.json`` holds the table;
``trials.png`` draws it.

An interrupted search resumes (``--resume``): a finished trial is read back from its
``trial.json``; an unfinished one replays its search, which is deterministic, taking every
row its ``results.csv`` already holds instead of running it again. What it reads back is
judged as data in ``resume.py``.
"""

from __future__ import annotations

import json
import math
import statistics
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from ..atomic import write_atomic
from .search import Progress


@dataclass
class Trial:
    """One trial's outcome: its seed, whether and when it falsified, what it reached."""

    seed: int
    falsified: bool
    simulations: int | None  # runs to the first falsifying one (None: none falsified)
    runs: int  # runs the trial spent (whole generations)
    least: float | None  # the least objective value reached (robustness)
    cpu_s: float

    @classmethod
    def of(cls, seed: int, progress: Progress, cpu_s: float) -> Trial:
        """The outcome of a finished search."""
        first = progress.first_violation()
        k = progress.worst()
        least = progress.verdicts[k].value if k is not None else None
        if least is not None and not math.isfinite(least):
            least = None
        return cls(
            seed,
            first is not None,
            None if first is None else first + 1,
            len(progress.rows),
            least,
            round(cpu_s, 3),
        )


def summarize(trials: list[Trial], budget: int, label: str) -> dict[str, Any]:
    """``summary.json``: the falsification rate, simulations to falsify, the robustness
    reached when not falsified, and every trial."""
    sims = [t.simulations for t in trials if t.simulations is not None]
    missed = [t.least for t in trials if not t.falsified and t.least is not None]
    return {
        "objective": label,
        "budget": budget,
        "trials": len(trials),
        "falsified": len(sims),
        "falsification_rate": len(sims) / len(trials) if trials else None,
        "mean_simulations": statistics.fmean(sims) if sims else None,
        "median_simulations": statistics.median(sims) if sims else None,
        "robustness_not_falsified": {
            "min": min(missed) if missed else None,
            "mean": statistics.fmean(missed) if missed else None,
        },
        "mean_cpu_s": statistics.fmean(t.cpu_s for t in trials) if trials else None,
        "table": [asdict(t) for t in trials],
    }


def write_trial(trial: Trial, path: Path) -> None:
    """``trial.json``: a finished trial (what ``--resume`` skips)."""
    write_atomic(path, json.dumps(asdict(trial), indent=1) + "\n")


def plot_trials(summary: dict[str, Any], out: Path, title: str) -> Path:
    """``trials.png``: simulations to falsify per trial (a cross at the budget for a trial
    that did not falsify), with the rate, mean and median in the title."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    from ..plots.save import save_png

    fig, ax = plt.subplots(figsize=(8, 4), dpi=100)
    table = summary["table"]
    budget = summary["budget"]
    xs = list(range(1, len(table) + 1))
    found = [(x, t["simulations"]) for x, t in zip(xs, table, strict=True) if t["falsified"]]
    missed = [x for x, t in zip(xs, table, strict=True) if not t["falsified"]]
    if found:
        ax.bar([x for x, _ in found], [s for _, s in found], color="#c0392b", label="falsified")
    if missed:
        ax.scatter(missed, [budget] * len(missed), marker="x", color="#555555", label="not")
    if summary["mean_simulations"] is not None:
        ax.axhline(summary["mean_simulations"], color="#333333", lw=1, ls="--", label="mean")
    ax.set_xlabel("trial")
    # trials are counted: a tick on each (a locator put ticks at 0.75, 1.25... of one)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True, nbins=min(len(xs), 20) or 1))
    ax.set_ylabel("simulations to the first violation")
    ax.set_ylim(0, budget * 1.05)
    rate = summary["falsification_rate"] or 0.0
    mean = summary["mean_simulations"]
    ax.set_title(
        f"{title}: falsified {summary['falsified']}/{summary['trials']} ({rate:.0%})"
        + (f", mean {mean:.3g} simulation{'' if mean == 1 else 's'}" if mean is not None else "")
    )
    ax.legend(loc="upper right")
    fig.tight_layout()
    return save_png(fig, out)
