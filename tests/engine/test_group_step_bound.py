"""A group's bound step (``Steppers.for_group``, what the schedule calls) must do exactly
what ``Steppers.step_group`` does: the same store, bit for bit, and the same fault (the same
words, the same run) for every answer a template can give, good or bad, and for what its
``step_many`` raises."""

from __future__ import annotations

from array import array
from collections.abc import Callable
from fractions import Fraction
from typing import Any, ClassVar

import numpy as np
import pytest

from amsa_phys.engine import batch, batch_bodies
from amsa_phys.engine.tasks import Steppers, Task
from amsa_phys.errors import RunFault

N = 4
PORTS = ("a", "b")
BUILT = batch_bodies.write_outputs() is not None and batch_bodies.gather_inputs() is not None


class Oops(Exception):
    pass


class Reply:
    """A template whose ``step_many`` returns (or raises) what the test set."""

    answer: ClassVar[Callable[[dict[str, np.ndarray]], Any]] = staticmethod(lambda inp: ({}, None))

    @classmethod
    def step_many(cls, comps: Any, now: Any, inp: Any, params: Any, state: Any) -> Any:
        return cls.answer(inp)


def _raise(exc: BaseException) -> Any:
    raise exc


MASK = np.array([True, False, True, True])
#: answers: the usual ones, then every kind of bad one
ANSWERS: dict[str, Callable[[dict[str, np.ndarray]], Any]] = {
    "columns": lambda inp: ({"a": inp["x"] * 2.0, "b": inp["x"] + 0.5}, None),
    "masked": lambda inp: ({"a": inp["x"] - 1.0, "b": inp["x"] * 3.0}, MASK.copy()),
    "nan in a published row": lambda inp: ({"a": inp["x"], "b": inp["x"] / 0.0}, None),
    "nan in a lost row": lambda inp: (
        {"a": np.where(MASK, inp["x"], np.nan), "b": inp["x"]},
        MASK.copy(),
    ),
    "one number": lambda inp: ({"a": 2.5, "b": inp["x"]}, None),
    "ints": lambda inp: ({"a": np.arange(N), "b": inp["x"]}, None),
    "wrong length": lambda inp: ({"a": np.zeros(N + 1), "b": inp["x"]}, None),
    "unknown output": lambda inp: ({"a": inp["x"], "zz": inp["x"]}, None),
    "no outputs": lambda inp: ({}, None),
    "not a mapping": lambda inp: ([1.0, 2.0], None),
    "a mask of ints": lambda inp: ({"a": inp["x"], "b": inp["x"]}, np.ones(N, dtype=int)),
    "a short mask": lambda inp: ({"a": inp["x"], "b": inp["x"]}, np.ones(N - 1, dtype=bool)),
    "not a pair": lambda inp: {"a": inp["x"]},
    "raises": lambda inp: _raise(Oops("bad")),
    "raises a fault": lambda inp: _raise(RunFault("Car2.Pilot", Fraction(1), "its own")),
}


def _group(inputs: bool = True) -> tuple[batch.Group, int]:
    tasks = []
    for k in range(N):
        tasks.append(
            Task(
                path=f"Car{k + 1}.Pilot",
                comp=Reply(),  # type: ignore[arg-type]
                period=1,
                inputs=[("x", f"Car{k + 1}.In.x")] if inputs else [],
                targets={p: f"Car{k + 1}.Pilot.{p}" for p in PORTS},
                run=k,
            )
        )
    names = [f"Car{k + 1}.In.x" for k in range(N)]
    names += [f"Car{k + 1}.Pilot.{p}" for p in PORTS for k in range(N)]
    at = {name: i for i, name in enumerate(names)}
    for t in tasks:
        t.bind(at.__getitem__)
    return batch.Group(tasks), len(names)


def _step(answer: str, bound: bool, inputs: bool = True) -> tuple[bytes, str | None, Any]:
    group, size = _group(inputs)
    values = array("d", [-7.0] * size)
    col = np.frombuffer(values, dtype=np.float64)
    if inputs:
        col[group.inputs[0][1]] = np.arange(N, dtype=float) + 0.25
    steppers = Steppers(values, lambda line, writes: None, lambda path: f"<{path}>", col)
    step = steppers.for_group(group) if bound else steppers.step_group
    if bound:
        assert step != steppers.step_group  # the bound step itself is what runs here
    if inputs:
        Reply.answer = staticmethod(ANSWERS[answer])  # type: ignore[assignment]
    else:  # a group without inputs (a leader's): its step gets an empty dict, its own
        x = np.arange(N, dtype=float) + 0.25

        def no_inputs(inp: dict[str, np.ndarray]) -> Any:
            assert inp == {}
            inp["x"] = x  # a template may use its dict as it likes
            return ANSWERS[answer](inp)

        Reply.answer = staticmethod(no_inputs)  # type: ignore[assignment]
    try:
        with np.errstate(all="ignore"):
            step(group, Fraction(1, 4))
    except RunFault as exc:
        return col.tobytes(), str(exc), getattr(exc, "run", None)
    return col.tobytes(), None, None


@pytest.mark.skipif(not BUILT, reason="the group bodies were not built, or the pure path")
@pytest.mark.parametrize("answer", list(ANSWERS))
def test_the_bound_step_is_step_group(answer: str) -> None:
    assert _step(answer, True) == _step(answer, False)
    assert _step(answer, True, inputs=False) == _step(answer, False, inputs=False)


@pytest.mark.skipif(not BUILT, reason="the group bodies were not built, or the pure path")
def test_the_answers_are_told_apart() -> None:
    """The cases reach different ends: stores written, faults of several kinds."""
    ends = {answer: _step(answer, True) for answer in ANSWERS}
    assert ends["columns"][1] is None
    assert ends["masked"][1] is None
    assert ends["columns"][0] != ends["masked"][0]
    faults = {end[1] for end in ends.values() if end[1] is not None}
    assert len(faults) >= 8


def test_without_the_compiled_bodies_the_step_is_step_group() -> None:
    group, size = _group()
    values = array("d", [0.0] * size)
    steppers = Steppers(values, lambda line, writes: None, str, np.frombuffer(values))
    steppers._gather_in = None
    assert steppers.for_group(group) == steppers.step_group
