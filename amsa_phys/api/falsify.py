"""``ap.falsify``: the falsification search from Python, without the command line's files.

A notebook or a script drives the same search as ``amsa-phys falsify`` (same rows, same
worst, bit for bit, for the same seed), pays the start-up once for many trials, and may
plug in its own cost: a function of a result row (a sweep's columns, ``robustness.NAME``
included) whose value the search minimises, a run falsifying when it is below 0.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError, api_text
from ..falsify.advice import search_warnings
from ..falsify.objective import (
    Objective,
    Verdict,
    build_objective,
    has_metrics,
    requirement_objective,
)
from ..falsify.search import Progress, Settings, search
from ..falsify.space import build_space
from ..falsify.trials import Trial, summarize
from ..model.scenario import load_scenario
from .falsifyargs import check_arguments, check_metric

Cost = Callable[[dict[str, Any]], float]


class SearchWarning(UserWarning):
    """A search that will spend its budget on less than was likely meant (a requirement
    whose windows the runs cut, ``search_on=True`` without a requirement, an axis the
    scenario's timeline sets again): ``amsa-phys falsify``'s ``warning:`` lines."""


@dataclass(frozen=True)
class CostObjective(Objective):
    """A user's cost of a result row, minimised; below 0 falsifies."""

    cost: Cost | None = None

    @property
    def falsifies(self) -> bool:
        return True

    def judge(self, row: dict[str, Any]) -> Verdict:
        if not has_metrics(row):  # its settings broke a rule before it ran
            return Verdict(None, math.inf, False, row.get("error", ""))
        if row.get("error"):  # a fault: the worst there is
            return Verdict(-math.inf, -math.inf, True, row["error"])
        assert self.cost is not None
        value = float(self.cost(row))
        if math.isnan(value):
            value = -math.inf
        return Verdict(value, value, value < 0, f"cost {value:.6g}" if value < 0 else "")


@dataclass
class Falsification:
    """What :func:`falsify` found: every trial's rows, the worst row of all, the trial table
    (``summary.json``'s document: falsification rate, simulations to falsify, ...)."""

    rows: list[list[dict[str, Any]]]
    worst: dict[str, Any] | None
    summary: dict[str, Any]
    trials: list[Trial] = field(default_factory=list)

    @property
    def falsified(self) -> bool:
        """Whether any trial found a falsifying run."""
        return any(t.falsified for t in self.trials)


def _box(box: Mapping[str, Any]) -> tuple[list[str], list[str]]:
    """``{"Comp.param": (lo, hi)}`` ranges and ``{"Comp.param": [a, b, c]}`` grids."""
    ranges, grids = [], []
    for key, spec in box.items():
        if isinstance(spec, tuple) and len(spec) == 2:
            ranges.append(f"{key}={float(spec[0])!r}:{float(spec[1])!r}")
        elif isinstance(spec, Sequence) and not isinstance(spec, str) and spec:
            import yaml

            grids.append(f"{key}=" + ",".join(yaml.safe_dump(v).strip() for v in spec))
        else:
            raise ConfigError(
                "expected (lo, hi) for a range or a list of values for a grid", key=str(key)
            )
    return ranges, grids


def falsify(
    scenario: str | os.PathLike[str],
    box: Mapping[str, Any],
    *,
    budget: int,
    requirement: str | None = None,
    metric: str | None = None,
    cost: Cost | None = None,
    seed: int = 1,
    trials: int = 1,
    search_on: bool = False,
    duration: float | None = None,
    executor: str = "batch",
    workers: int = 1,
) -> Falsification:
    """Search ``box`` of ``scenario``'s context for a run that breaks a requirement.

    ``box`` maps ``Comp.param`` to ``(lo, hi)`` (a continuous or integer axis) or to a list
    of values (a categorical one). The objective is one of: ``requirement`` (an STL
    requirement's name, or ``"all"``: its robustness is minimised, and each trial stops at
    its first falsifying run unless ``search_on``), ``metric`` (maximised, the whole budget;
    ``robustness.NAME`` too), or ``cost`` (your function of a result row, minimised; below 0
    falsifies). ``trials`` repeats the search with seeds ``seed .. seed + trials - 1``.
    Errors are the CLI's :class:`~amsa_phys.errors.ConfigError`, raised.
    """
    if sum(x is not None for x in (requirement, metric, cost)) > 1:
        raise ConfigError("give one of requirement, metric or cost", key="falsify")
    check_arguments(
        scenario, box, budget=budget, cost=cost, seed=seed, trials=trials,
        duration=duration, executor=executor, workers=workers,
    )  # fmt: skip
    path = Path(scenario).resolve()
    sc = load_scenario(path)
    ranges, grids = _box(box)
    try:
        space = build_space(sc, ranges, grids)
    except ConfigError as exc:  # said as the command line says it: named as passed here
        raise exc.worded_for_api() from None
    end = duration if duration is not None else float(sc.duration)
    n_phases = len(sc.timeline.phases_before(end))
    check_metric(metric, n_phases)
    objective: Objective
    said: list[str] = []  # the objective's own warnings (a metric of a cut phase, ...)
    if cost is not None:
        objective = CostObjective(None, (), ("cost",), cost)
    elif requirement is not None:
        objective = requirement_objective(list(sc.expect), requirement, "requirement")
    else:
        objective, said = build_objective(list(sc.expect), metric, False, n_phases)
    for text in [*said, *search_warnings(sc, objective, space, end, search_on)]:
        warnings.warn(api_text(text), SearchWarning, stacklevel=2)
    stop = objective.falsifies and not search_on
    all_rows, outcomes, worst, worst_score = [], [], None, math.inf
    for k in range(trials):
        settings = Settings(
            path, budget, seed + k, sc.seed, duration, executor, workers, None,
            stop_at_violation=stop,
        )  # fmt: skip
        progress = Progress()
        t0 = time.process_time()
        for _ in search(space, objective, settings, progress):
            pass
        outcomes.append(Trial.of(seed + k, progress, time.process_time() - t0))
        all_rows.append(sorted(progress.rows, key=lambda r: r["run"]))
        w = progress.worst()
        if w is not None and progress.verdicts[w].score < worst_score:
            worst, worst_score = progress.rows[w], progress.verdicts[w].score
    summary = summarize(outcomes, budget, objective.label)
    return Falsification(all_rows, worst, summary, outcomes)
