"""The search: a Latin-hypercube generation, then CMA-ES generations, each one batch.

CMA-ES (``cmaes.CatCMAwM``: CMA-ES with margin for integer axes and a categorical
distribution for ``--grid`` axes, Hamano et al. 2025) adapts a Gaussian over the unit box to
where the worst runs are; it ranks runs, so only the order of the scores matters, never
their scale. It starts at the best point of the Latin hypercube, which spreads the first
runs over every stratum of every axis. When it has converged (its own stop test), has not
found a worse case for :data:`STALL_GENERATIONS` generations, or proposes nothing new, it
restarts with twice the population (IPOP-CMA-ES), so the budget is spent
looking elsewhere instead of polishing one corner: from the candidate point farthest from
every run so far, where the box is least explored.

Everything random comes from ``--seed``: the hypercube from a ``numpy`` Generator, the
optimizer's from a seed drawn from it; runs are told in point order, never completion
order. Same seed, same points, same rows, whatever the executor or ``-j``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..engine import interrupt
from ..runs.evaluate import evaluate
from .objective import Objective, Verdict
from .space import Space

#: Share of the budget the Latin hypercube spends before the optimizer starts (at least
#: :data:`MIN_START` runs): enough for its best point to lie in the worst basin.
START_SHARE = 0.2
MIN_START = 10
#: CMA-ES's first step size in the unit box: the best start point's neighbourhood, a fifth
#: of each axis.
SIGMA0 = 0.2
#: Generations without a better worst (relative :data:`STALL_TOL`) before CMA-ES restarts
#: elsewhere: a box often has several bad corners, and CMA-ES settles on the one nearest its
#: start (the Fig. 5 box's motorCoef = 100 edge is 94 % of its motorCoef = 40 corner).
STALL_GENERATIONS = 4
STALL_TOL = 1e-4
#: Random points a restart chooses its start among (the one farthest from every run).
RESTART_CANDIDATES = 256
#: A generation of fewer points runs in this process, not on a local worker pool: starting
#: the pool (processes, imports, the scenario loaded in each) costs more than a handful of
#: batched runs, and a search starts one per generation. Rows are the same either way.
SMALL_GENERATION = 32
#: Restarts in a row that propose only points already run before the search gives up on
#: the rest of its budget: a box of few points (``--grid`` axes) is exhausted long before,
#: and the optimizer's population doubles at every restart.
MAX_EMPTY_GENERATIONS = 8
OPTIMIZERS = ("cma", "random")


@dataclass(frozen=True)
class Settings:
    """What the search needs besides the box and the objective."""

    scenario: Path
    budget: int
    seed: int
    run_seed: int
    duration: float | None = None
    executor: str = "batch"
    workers: int | None = None
    scheduler: str | None = None
    optimizer: str = "cma"
    #: CMA-ES's first population (None: its default, 4 + 3 ln(dimensions))
    popsize: int | None = None
    #: stop after the generation holding the first violation (``--requirement``), instead
    #: of spending the whole budget on the worst case
    stop_at_violation: bool = False


@dataclass
class Progress:
    """What the search has seen: every row (with ``generation``), and each one's verdict."""

    rows: list[dict[str, Any]] = field(default_factory=list)
    verdicts: list[Verdict] = field(default_factory=list)
    score_of: dict[tuple[tuple[str, Any], ...], float] = field(default_factory=dict)
    #: called with the generation's number once its runs are all in (a progress line)
    on_generation: Callable[[int], None] | None = None
    #: rows of an interrupted search, by run number (``--resume``): the search replays
    #: itself (it is deterministic) and takes these instead of running them again
    cached: dict[int, dict[str, Any]] = field(default_factory=dict)
    #: how many rows were taken from ``cached`` instead of run
    reused: int = 0
    #: the search stopped before its budget: every point of a finite box (``--grid`` axes
    #: only) was run, or the optimizer proposed only points already run many times in a row
    exhausted: bool = False

    def first_violation(self) -> int | None:
        """The run number of the first violating run (in run order), or None."""
        runs = [r["run"] for r, v in zip(self.rows, self.verdicts, strict=True) if v.violated]
        return min(runs) if runs else None

    def add(
        self, row: dict[str, Any], verdict: Verdict, point: tuple[tuple[str, Any], ...]
    ) -> None:
        """Note one finished run."""
        self.rows.append(row)
        self.verdicts.append(verdict)
        self.score_of[point] = verdict.score

    def worst(self) -> int | None:
        """The position in ``rows`` of the worst run (least score; of equals, the lowest
        run number, so completion order never matters); None if no run could be judged."""
        if not self.verdicts:
            return None
        k = min(range(len(self.rows)), key=lambda i: (self.verdicts[i].score, self.rows[i]["run"]))
        return None if self.verdicts[k].score == math.inf else k


def latin_hypercube(rng: np.random.Generator, n: int, dims: int) -> np.ndarray:
    """``n`` points in [0, 1)^dims with one point in each of the ``n`` strata of every axis
    (McKay et al. 1979): each axis's strata in an independent random order."""
    u = (np.arange(n)[:, None] + rng.random((n, dims))) / n
    for j in range(dims):
        u[:, j] = u[rng.permutation(n), j]
    return u


def stratified_choices(rng: np.random.Generator, n: int, counts: list[int]) -> np.ndarray:
    """``n`` choices per categorical axis, each category as often as the others (±1)."""
    out = np.zeros((n, len(counts)), dtype=int)
    for j, k in enumerate(counts):
        out[:, j] = rng.permutation(np.arange(n) % k)
    return out


class _Cma:
    """``cmaes.CatCMAwM`` over the space's unit box, restarted IPOP-style."""

    def __init__(self, space: Space, rng: np.random.Generator) -> None:
        from cmaes import CatCMAwM  # imported when searching: `--help` stays fast

        self._cls = CatCMAwM
        self.space = space
        self.rng = rng
        self.cont = [i for i, d in enumerate(space.numeric) if not d.is_integer]
        self.ints = [i for i, d in enumerate(space.numeric) if d.is_integer]
        self.cats = [d for d in space.categorical if len(d.choices) > 1]
        self.popsize: int | None = None
        self.opt: Any = None

    def start(self, mean: list[float] | None) -> None:
        """A new optimizer at ``mean`` (a unit-box point; None: a random one)."""
        n = len(self.space.numeric)
        if mean is None:
            mean = list(self.rng.random(n))
        kwargs: dict[str, Any] = {
            "population_size": self.popsize,
            "seed": int(self.rng.integers(2**31 - 1)),
        }
        if self.cont:
            kwargs["x_space"] = [[0.0, 1.0]] * len(self.cont)
        if self.ints:
            kwargs["z_space"] = [self.space.numeric[i].levels() for i in self.ints]
        if self.cats:
            kwargs["c_space"] = [len(d.choices) for d in self.cats]
        if n:
            kwargs["mean"] = np.array([mean[i] for i in self.cont + self.ints])
            # sigma * I: without ``cov`` the library scales each axis by the mean's distance
            # to its nearer bound, so a start near an edge (a worst case often is) gets a
            # step a hundredth of the box's and never leaves that corner's neighbourhood
            kwargs["sigma"] = SIGMA0
            kwargs["cov"] = np.eye(n)
        self.opt = self._cls(**kwargs)
        self.popsize = self.opt.population_size

    def restart(self, seen: list[list[float]]) -> None:
        """IPOP: twice the population, from the point farthest from every run so far
        (``seen``, unit-box coordinates) of :data:`RESTART_CANDIDATES` random ones: the
        least explored part of the box."""
        self.popsize = 2 * int(self.popsize or self.opt.population_size)
        n = len(self.space.numeric)
        if not n or not seen:
            self.start(None)
            return
        candidates = self.rng.random((RESTART_CANDIDATES, n))
        done = np.asarray(seen, dtype=float)
        gaps = np.min(np.linalg.norm(candidates[:, None, :] - done[None, :, :], axis=2), axis=1)
        self.start([float(x) for x in candidates[int(np.argmax(gaps))]])

    def ask(self) -> list[tuple[Any, list[float], list[int]]]:
        """One generation: (the optimizer's solution, unit-box vector, category indices)."""
        out = []
        for _ in range(self.opt.population_size):
            sol = self.opt.ask()
            u = [0.0] * len(self.space.numeric)
            for k, i in enumerate(self.cont):
                u[i] = float(sol.x[k])
            for k, i in enumerate(self.ints):
                u[i] = float(sol.z[k])
            cats = []
            c = iter(np.argmax(sol.c, axis=1).tolist() if self.cats else [])
            for d in self.space.categorical:
                cats.append(int(next(c)) if len(d.choices) > 1 else 0)
            out.append((sol, u, cats))
        return out

    def tell(self, sols: list[Any], scores: list[float]) -> None:
        """Rank the generation (scores finite: see :func:`finite_scores`)."""
        self.opt.tell(list(zip(sols, scores, strict=True)))

    def should_stop(self) -> bool:
        """The optimizer's own convergence test (step size, flat values)."""
        return bool(self.space.numeric) and bool(self.opt.should_stop())


def finite_scores(scores: list[float], seen: list[float]) -> list[float]:
    """Infinite scores as finite ones beyond every finite score ``seen``: CMA-ES ranks, and
    its bound penalty scales with the spread of values, which an infinity would blow up."""
    finite = [s for s in seen if math.isfinite(s)] or [0.0]
    lo, hi = min(finite), max(finite)
    span = (hi - lo) or 1.0
    return [s if math.isfinite(s) else (lo - span if s < 0 else hi + span) for s in scores]


def search(
    space: Space, objective: Objective, settings: Settings, progress: Progress | None = None
) -> Iterator[dict[str, Any]]:
    """Rows as they complete, each with ``generation`` (and ``robustness`` with --expect);
    stops after ``settings.budget`` runs. ``progress`` (if given) receives every row and
    verdict as they come, so a caller interrupted mid-search still has them. A point
    proposed twice is judged from its first run (no run spent on a copy)."""
    progress = progress if progress is not None else Progress()
    rng = np.random.default_rng(settings.seed)
    budget = settings.budget
    n0 = min(budget, max(MIN_START, round(START_SHARE * budget)))
    if settings.optimizer == "random":
        n0 = budget
    u0 = latin_hypercube(rng, n0, len(space.numeric))
    c0 = stratified_choices(rng, n0, [len(d.choices) for d in space.categorical])
    points = [space.decode(list(u), list(c)) for u, c in zip(u0, c0, strict=True)]
    # a box of few points (``--grid`` axes) repeats some: each is run once, as later ones are
    yield from _evaluate(list(dict.fromkeys(points)), 0, objective, settings, progress)
    if len(progress.rows) >= budget or _found(settings, progress):
        return
    first = [progress.score_of[p] for p in points]
    best = min(range(n0), key=lambda i: (first[i], i))
    cma = _Cma(space, rng)
    cma.popsize = settings.popsize
    cma.start([float(x) for x in u0[best]])
    generation = 0
    best_here, stalled = math.inf, 0  # this CMA-ES run's best score, generations since
    points_in_box = box_points(space)
    empty = 0  # generations in a row that proposed nothing not run yet
    while len(progress.rows) < budget:
        if len(progress.score_of) >= points_in_box or empty >= MAX_EMPTY_GENERATIONS:
            progress.exhausted = True  # every point of a finite box run: nothing left
            return
        interrupt.check()  # a Ctrl-C noted while generations propose only old points
        generation += 1
        asked = cma.ask()
        decoded = [space.decode(u, cats) for _, u, cats in asked]
        fresh = list(dict.fromkeys(p for p in decoded if p not in progress.score_of))
        fresh = fresh[: budget - len(progress.rows)]
        if not fresh:  # converged on points already run: look elsewhere
            empty += 1
            cma.restart([space.encode(p) for p in progress.score_of])
            best_here, stalled = math.inf, 0
            continue
        empty = 0
        yield from _evaluate(fresh, generation, objective, settings, progress)
        if _found(settings, progress):
            return
        if any(p not in progress.score_of for p in decoded):
            continue  # the budget ran out inside this generation
        scores = finite_scores(
            [progress.score_of[p] for p in decoded], list(progress.score_of.values())
        )
        cma.tell([sol for sol, _, _ in asked], scores)
        here = min(progress.score_of[p] for p in decoded)
        if best_here == math.inf or here < best_here - STALL_TOL * max(1.0, abs(best_here)):
            best_here, stalled = here, 0
        else:
            stalled += 1
        if cma.should_stop() or stalled >= STALL_GENERATIONS:
            cma.restart([space.encode(p) for p in progress.score_of])
            best_here, stalled = math.inf, 0


def box_points(space: Space) -> float:
    """How many distinct points the box holds: finite only where every axis is a ``--grid``
    (or an integer axis the optimizer steps through): infinity with a continuous axis."""
    total = 1.0
    for d in space.numeric:
        if not d.is_integer:
            return math.inf
        total *= len(d.levels())
    for c in space.categorical:
        total *= len(c.choices)
    return total


def _found(settings: Settings, progress: Progress) -> bool:
    """Whether the search stops now: told to stop at a violation, and one was found."""
    return settings.stop_at_violation and any(v.violated for v in progress.verdicts)


def _evaluate(
    points: list[tuple[tuple[str, Any], ...]],
    generation: int,
    objective: Objective,
    settings: Settings,
    progress: Progress,
) -> Iterator[dict[str, Any]]:
    """One generation as one ``evaluate`` call; rows numbered on from the previous ones
    (a row of an interrupted search, ``progress.cached``, is taken instead of run again)."""
    offset = len(progress.rows)
    todo = [i for i in range(len(points)) if offset + i not in progress.cached]
    small = settings.executor == "batch" and len(todo) < SMALL_GENERATION
    ran: Iterator[dict[str, Any]] = iter(())
    if todo:
        done = evaluate(
            settings.scenario,
            [(points[i], settings.run_seed) for i in todo],
            duration=settings.duration,
            executor=settings.executor,
            workers=1 if small else settings.workers,
            scheduler=settings.scheduler,
        )
        ran = ({**row, "index": todo[row["index"]]} for row in done)
    kept = (
        {**progress.cached[offset + i], **dict(points[i]), "index": i}
        for i in range(len(points))
        if offset + i in progress.cached
    )
    for row in itertools.chain(kept, ran):
        i = row.pop("index")
        if offset + i in progress.cached:
            progress.reused += 1
        row["run"] = offset + i
        row["generation"] = generation
        verdict = objective.judge(row)
        if objective.metric is None:
            row["robustness"] = verdict.value
        progress.add(row, verdict, points[i])
        yield row
    if progress.on_generation is not None:
        progress.on_generation(generation)
