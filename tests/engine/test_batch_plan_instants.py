"""A batch's plan steps, at each instant, exactly that instant's components: each once, as
itself or in its group, in the instant's order. The plan is made once per distinct list of
an instant's tasks (instants repeat a few patterns): instants whose task lists differ, even
when as long, each get their own."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from amsa_phys.engine import batch
from amsa_phys.engine.multirun import MultiRun
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def planned(monkeypatch: pytest.MonkeyPatch, sets: list[str]) -> list[tuple[list, list]]:
    """Every (instant's tasks, its plan) of a 3-run batch of scenario1 with ``sets``."""
    seen: list[tuple[list, list]] = []
    plan = batch.plan

    def spy(instants: Any, *args: Any, **kwargs: Any) -> list[list[Any]]:
        out = plan(instants, *args, **kwargs)
        seen.extend(zip([list(ts) for ts in instants], out, strict=True))
        return out

    monkeypatch.setattr(batch, "plan", spy)
    runs = [load_scenario(SCENARIO1, sets, duration=2.0, seed=s) for s in (1, 2, 3)]
    MultiRun(runs).initialize()  # the plan is made as the batch starts
    return seen


def covers(tasks: list[Any], seq: list[Any]) -> None:
    """``seq`` steps exactly ``tasks``, each once, a task alone where the instant has it."""
    stepped = [t for item in seq for t in (item.tasks if isinstance(item, batch.Group) else [item])]
    assert sorted(map(id, stepped)) == sorted(map(id, tasks)), "another instant's tasks"
    alone = [item for item in seq if not isinstance(item, batch.Group)]
    assert alone == [t for t in tasks if t in alone], "the instant's order"


def test_each_instant_of_a_batch_steps_its_own_tasks(monkeypatch: pytest.MonkeyPatch) -> None:
    seen = planned(monkeypatch, [])
    assert len({tuple(map(id, tasks)) for tasks, _ in seen}) > 1
    assert len(seen) > len({tuple(map(id, tasks)) for tasks, _ in seen})  # patterns repeat
    for tasks, seq in seen:
        covers(tasks, seq)


class Comp:
    """A component type the plan may group (it never steps here)."""

    @classmethod
    def step_many(cls, *args: Any) -> Any:
        raise AssertionError("not stepped")


@dataclass(eq=False)
class FakeTask:
    """What ``batch.plan`` reads of a task."""

    path: str
    run: int
    comp: Comp = field(default_factory=Comp)
    reads: list = field(default_factory=list)
    writes: dict = field(default_factory=dict)
    inputs: list = field(default_factory=list)
    delay: Any = None


def test_instants_as_long_as_each_other_get_their_own_plans() -> None:
    a = [FakeTask("A.p", r, writes={"out": 10 + r}) for r in range(2)]
    b = [FakeTask("B.p", r, writes={"out": 20 + r}) for r in range(2)]
    x, y = FakeTask("X.p", 0, writes={"out": 30}), FakeTask("Y.p", 0, writes={"out": 40})
    keys = {batch.ident(t): ("A",) for t in a} | {batch.ident(t): ("B",) for t in b}
    keys |= {batch.ident(x): None, batch.ident(y): None}
    first, second = [*a, x], [y, *b]  # as long, different tasks
    instants = [first, second, first, second, [x], [y]]
    out = batch.plan(instants, keys, min_group=2)
    for tasks, seq in zip(instants, out, strict=True):
        covers(tasks, seq)
    assert [len(seq) for seq in out] == [2, 2, 2, 2, 1, 1]  # the groups formed
