"""Where a batch's CPU goes: the rovers' column physics, each component group, the rest.

The vector env (``FollowVecEnv``, random actions) at each size in ``--vector``, per vector
step, and a batched sweep (``--sweep``: ``--runs`` runs of 60 s, 25 Kv values, as
``bench_engine.py`` plans them, in this process), per run. Every group's ``step_many`` and
every call of the column physics is timed (CPU), with the engine's share of each group's
time (gathering its inputs, judging and writing its outputs: the group's time less its
template's own ``step_many``), and in a sweep each batch's set-up (its
runs' components built, then initialized and the schedule planned) and end (verdicts,
metrics); "the rest" is the engine's loop, the agent's side of the vector env (actions,
rewards, observations) and, in a sweep, the jobs' planning and preparation. The
physics line is the floor no work on the rest can pass: the ceiling it gives is the rate
with everything else free.

Run: ``python benchmarks/bench_breakdown.py [--vector 2 16 64 1000] [--sweep scenario1
scenario2] [--runs 1000]``. Prints a table; measures nothing against a baseline (the
ratios are ``bench_speed.py``'s and ``bench_engine.py``'s).
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent

PHYSICS = "(column physics)"


@contextmanager
def own_steps(inner: collections.Counter) -> Iterator[None]:
    """CPU seconds inside each group template's own ``step_many`` (by class name), summed
    while open: a group's time less this is the engine's (its inputs gathered, its outputs
    judged and written). A template is timed from the first time a group of it steps (a
    world's templates are imported as it is built); enter this after :func:`timers`."""
    from amsa_phys.engine.tasks import Steppers

    clock = time.process_time
    saved: dict[type, Any] = {}
    depth = [0]  # a template's step_many may call another's (a random leader's, a robot's)

    def timed(cls: type, fn: Callable[..., Any]) -> classmethod:
        def wrapper(klass: type, *args: Any) -> Any:
            depth[0] += 1
            t0 = clock()
            try:
                return fn(klass, *args)
            finally:
                depth[0] -= 1
                if depth[0] == 0:  # the group's own template: the outermost call
                    inner[cls.__name__] += clock() - t0

        return classmethod(wrapper)

    def wrap(cls: type) -> None:
        for klass in cls.__mro__:  # the class that defines it (a subclass may inherit it)
            method = klass.__dict__.get("step_many")
            if isinstance(method, classmethod) and klass not in saved:
                saved[klass] = method
                klass.step_many = timed(klass, method.__func__)  # type: ignore[attr-defined]
                return

    step_group = Steppers.step_group

    def seen(self: Any, group: Any, now: Any) -> Any:
        if group.template not in saved:
            wrap(group.template)
        return step_group(self, group, now)

    Steppers.step_group = seen  # type: ignore[method-assign]
    try:
        yield
    finally:
        Steppers.step_group = step_group  # type: ignore[method-assign]
        for klass, method in saved.items():
            klass.step_many = method  # type: ignore[attr-defined]


@contextmanager
def timers() -> Iterator[tuple[collections.Counter, collections.Counter]]:
    """CPU seconds and calls per group template (and :data:`PHYSICS`), summed while open.
    Patches the classes, so only simulations built inside see the timers."""
    from amsa_phys.engine.tasks import Steppers
    from amsa_phys.physics.columns import ColumnPhysics

    cpu: collections.Counter = collections.Counter()
    calls: collections.Counter = collections.Counter()
    clock = time.process_time

    def timed(name: Callable[[Any], str], fn: Callable[..., Any]) -> Callable[..., Any]:
        def wrapper(self: Any, *args: Any) -> Any:
            t0 = clock()
            try:
                return fn(self, *args)
            finally:
                key = name(args)
                cpu[key] += clock() - t0
                calls[key] += 1

        return wrapper

    saved = Steppers.step_group, ColumnPhysics.step, ColumnPhysics.step_many
    Steppers.step_group = timed(lambda a: a[0].template.__name__, saved[0])  # type: ignore[method-assign]
    ColumnPhysics.step = timed(lambda a: PHYSICS, saved[1])  # type: ignore[method-assign]
    ColumnPhysics.step_many = timed(lambda a: PHYSICS, saved[2])  # type: ignore[method-assign]
    try:
        yield cpu, calls
    finally:
        Steppers.step_group, ColumnPhysics.step, ColumnPhysics.step_many = saved  # type: ignore[method-assign]


def table(
    total: float,
    per: float,
    unit: str,
    cpu: collections.Counter,
    calls: dict,
    each: str,
    inner: collections.Counter | None = None,
) -> None:
    """``cpu`` (seconds over ``per`` vector steps or runs) as one line per part, with its
    ``calls`` (counted ``each``) and, for a group whose template's own time is in ``inner``,
    the engine's share of it."""
    scale, digits = (1e6, 1) if unit == "us" else (1e3, 3)
    for name, sec in cpu.most_common():
        engine = ""
        if inner is not None and name in inner:
            engine = f"; the engine's {(sec - inner[name]) / per * scale:.{digits}f} {unit}"
        print(
            f"  {name:24s} {sec / per * scale:9.{digits}f} {unit} ({sec / total:4.0%}), "
            f"{calls[name]:,.1f} calls {each}{engine}"
        )
    rest = total - sum(cpu.values())
    print(f"  {'the rest':24s} {rest / per * scale:9.{digits}f} {unit} ({rest / total:4.0%})")


def vector(n: int, steps: int) -> None:
    """The vector env at ``n`` envs (batched), ``steps`` vector steps after a warm-up."""
    from amsa_phys.gym.vector import FollowVecEnv

    actions = np.random.default_rng(n).uniform(-1, 1, (steps + 3, n, 2))
    inner: collections.Counter = collections.Counter()
    with timers() as (cpu, calls), own_steps(inner):
        env = FollowVecEnv(n, stepping="batch")
        env.reset(seed=0)
        for a in actions[:3]:  # the columns and groups start at the first steps
            env.step(a)
        cpu.clear()
        calls.clear()
        inner.clear()
        t0 = time.process_time()
        for a in actions[3:]:
            env.step(a)
        total = time.process_time() - t0
        env.close()
    physics = cpu[PHYSICS]
    ceiling = f"; the physics alone would allow {steps * n / physics:,.0f}" if physics else ""
    print(
        f"vector env, {n} envs: {total / steps * 1e6:,.0f} us a vector step, "
        f"{steps * n / total:,.0f} env-steps/s{ceiling}"
    )
    table(total, steps, "us", cpu, {k: v / steps for k, v in calls.items()}, "a vector step", inner)


#: A sweep's parts outside the loop, timed on their own lines: the batch's set-up and end
SETUP = "(set-up: build)"
INIT = "(set-up: initialize, plan)"
END = "(end: verdicts, metrics)"


@contextmanager
def phases(cpu: collections.Counter, calls: collections.Counter) -> Iterator[None]:
    """Time a batch's set-up (its runs' components built; their ``initialize`` and the
    schedule's and groups' planning) and its end (requirements judged, each run's metrics)
    into ``cpu`` and ``calls``, beside the loop's groups and physics."""
    from amsa_phys.engine.multirun import MultiRun
    from amsa_phys.engine.runner import Simulation
    from amsa_phys.runs import batched

    clock = time.process_time

    def timed(key: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            t0 = clock()
            try:
                return fn(*args, **kwargs)
            finally:
                cpu[key] += clock() - t0
                calls[key] += 1

        return wrapper

    saved = MultiRun.__init__, Simulation.initialize, MultiRun.outcomes, batched.compute_metrics
    MultiRun.__init__ = timed(SETUP, saved[0])  # type: ignore[method-assign]
    Simulation.initialize = timed(INIT, saved[1])  # type: ignore[method-assign]
    MultiRun.outcomes = timed(END, saved[2])  # type: ignore[method-assign]
    batched.compute_metrics = timed(END, saved[3])
    try:
        yield
    finally:
        MultiRun.__init__, Simulation.initialize, MultiRun.outcomes = saved[:3]  # type: ignore[method-assign]
        batched.compute_metrics = saved[3]


def sweep(scenario: str, runs: int) -> None:
    """A batched sweep of ``runs`` runs of ``scenario`` in this process, as two workers'
    batches would be cut; the batches' set-up and end on lines of their own."""
    sys.path.insert(0, str(ROOT))
    from amsa_phys.runs.batched import iter_batched, plan_units
    from amsa_phys.runs.sweep import iter_local
    from benchmarks.bench_engine import sweep_plan

    jobs = sweep_plan(scenario, runs).jobs()
    inner: collections.Counter = collections.Counter()
    with timers() as (cpu, calls), phases(cpu, calls), own_steps(inner):
        t0 = time.process_time()
        units, _ = plan_units(jobs, 2)
        rows = list(iter_batched(units, 1, iter_local))
        total = time.process_time() - t0
    n = len(rows)
    print(
        f"batched sweep, {scenario}, {n} runs in {len(units)} batches: "
        f"{total / n * 1e3:.2f} ms CPU a run"
    )
    table(total, n, "ms", cpu, {k: v / len(units) for k, v in calls.items()}, "a batch", inner)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vector", type=int, nargs="*", default=[2, 16, 64, 1000])
    ap.add_argument("--sweep", nargs="*", default=["scenario1", "scenario2"])
    ap.add_argument("--runs", type=int, default=1000)
    args = ap.parse_args()
    for n in args.vector:
        vector(n, max(20, min(480, 20_000 // n)))
    for scenario in args.sweep:
        sweep(scenario, args.runs)


if __name__ == "__main__":
    main()
