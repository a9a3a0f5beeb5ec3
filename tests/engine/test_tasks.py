"""Tasks (engine/tasks.py): one verdict on what a component publishes, on every path."""

from __future__ import annotations

import re
from fractions import Fraction
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine.tasks import Steppers, Task, checked_writes
from amsa_phys.errors import RunFault

NOW = Fraction(3, 2)


class Comp:
    """Returns (or raises) whatever the test set."""

    def __init__(self, out: Any = None, exc: BaseException | None = None) -> None:
        self.out = out
        self.exc = exc
        self.seen: list[dict[str, Any]] = []

    def do_step(self, t: Fraction, inp: dict[str, Any]) -> Any:
        self.seen.append(inp)
        if self.exc is not None:
            raise self.exc
        return self.out


def _steppers(values: dict[str, float], sent: list[Any]) -> Steppers:
    return Steppers(values, lambda line, writes: sent.append(writes), lambda p: f"{p} (T)")


def _task(comp: Comp, *, delayed: bool = False, arrays: bool = False) -> Task:
    task = Task("C", comp, 1, [("x", "S.x")], {"u": "C.u", "v": "C.v"})  # type: ignore[arg-type]
    if delayed:
        task.delay = object()  # type: ignore[assignment]  # only handed to ``send``
    if arrays:
        task.arrays_out["w"] = ["C.w[0]", "C.w[1]"]
    task.bind(lambda name: name)  # positions are the names: the values here are a dict
    return task


def _fault(fn: Any) -> str:
    with pytest.raises(RunFault) as info:
        fn()
    return str(info.value)


BAD_OUTPUTS = [
    {"u": float("nan")},
    {"u": float("inf")},
    {"u": "fast"},
    {"u": 10**400},  # OverflowError: the scalar path once let it through as a crash
    {"nope": 1.0},
    {"u": object()},
    [("u", 1.0)],  # not a mapping: AttributeError, once a traceback
    (1.0,),
]


def _id(out: Any) -> str:
    """A stable test id (an ``object()``'s repr carries its address, which differs between
    processes: pytest-xdist's workers must collect the same ids)."""
    return re.sub(r" at 0x[0-9a-f]+", "", repr(out))[:30]


@pytest.mark.parametrize("out", BAD_OUTPUTS, ids=_id)
def test_every_path_gives_the_same_verdict_as_checked_writes(out: Any) -> None:
    reference = _fault(lambda: checked_writes(_task(Comp()), out, {}, NOW, lambda p: f"{p} (T)"))
    assert "in C (T): " in reference
    for kind in ("scalar", "delayed", "arrays"):
        values = {"S.x": 1.0, "C.u": 0.0, "C.v": 0.0, "C.w[0]": 0.0, "C.w[1]": 0.0}
        sent: list[Any] = []
        st = _steppers(values, sent)
        task = _task(Comp(out), delayed=kind == "delayed", arrays=kind == "arrays")
        step = st.for_task(task)
        assert _fault(lambda: step(task, NOW)) == reference, kind  # noqa: B023
        assert sent == [], kind  # nothing refused is ever put in flight


def test_good_outputs_land_as_floats_on_each_path() -> None:
    values = {"S.x": 4.0, "C.u": 0.0, "C.v": 0.0, "C.w[0]": 0.0, "C.w[1]": 0.0}
    sent: list[Any] = []
    st = _steppers(values, sent)
    st.step(_task(Comp({"u": 2, "v": np.float64(0.5)})), NOW)
    assert values["C.u"] == 2.0
    assert type(values["C.u"]) is float
    delayed = _task(Comp({"u": 7}), delayed=True)
    st.step_delayed(delayed, NOW)
    assert sent == [[("C.u", 7.0)]]
    assert values["C.u"] == 2.0  # not visible until delivered
    assert delayed.own == {"C.u": 7.0}  # but read back by its producer at once
    st.step_arrays(_task(Comp({"w": [1, 2], "v": 3}), arrays=True), NOW)
    assert (values["C.w[0]"], values["C.w[1]"], values["C.v"]) == (1.0, 2.0, 3.0)


@pytest.mark.parametrize("kind", ["scalar", "delayed", "arrays"])
def test_sys_exit_in_any_component_is_its_fault_and_ctrl_c_stays_the_users(kind: str) -> None:
    def task(exc: BaseException) -> Task:
        return _task(Comp(exc=exc), delayed=kind == "delayed", arrays=kind == "arrays")

    st = _steppers({"S.x": 1.0}, [])
    t = task(SystemExit(3))
    message = _fault(lambda: st.for_task(t)(t, NOW))
    assert message.endswith("do_step raised SystemExit(3)")
    t = task(KeyboardInterrupt())
    with pytest.raises(KeyboardInterrupt):
        st.for_task(t)(t, NOW)


def test_array_outputs_are_checked_whole() -> None:
    st = _steppers({"S.x": 1.0}, [])
    wrong = _task(Comp({"w": [1.0]}), arrays=True)
    assert "has shape (1,), expected (2,)" in _fault(lambda: st.step_arrays(wrong, NOW))
    nan = _task(Comp({"w": [1.0, float("nan")]}), arrays=True)
    assert _fault(lambda: st.step_arrays(nan, NOW)).endswith("output w[1] is nan")
