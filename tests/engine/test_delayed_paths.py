"""A Leaf with latency steps in one closure where the store is an array of doubles (the
single env's agent in place of a delayed controller is this path at every step): it must
put in flight, read back and refuse exactly what the Python step does."""

from __future__ import annotations

from array import array
from fractions import Fraction
from typing import Any

import pytest

from amsa_phys.engine import interrupt, publish
from amsa_phys.engine.tasks import Steppers, Task
from amsa_phys.errors import RunFault

NOW = Fraction(5, 4)

#: what a component may return: the usual dict of floats, what the Python loop converts,
#: and what it refuses (as ``test_publish.py``'s list)
OUTPUTS: list[Any] = [
    {"u": 1.5, "v": -2.25},
    {"v": 0.1},
    {},
    {"u": 3},
    {"u": True},
    {"u": 1.0, "v": float("nan")},
    {"u": float("-inf")},
    {"u": 1.0, "nope": 2.0},
    {"u": "fast"},
    {"u": 10**400},
    [("u", 1.0)],
    None,
]


class Stop(BaseException):
    """Not a component's fault (as the gym episode's own stop): passes through."""


RAISED = [ValueError("bad"), SystemExit(3), KeyboardInterrupt(), RunFault("C", NOW, "own"), Stop()]


class Comp:
    def __init__(self, out: Any) -> None:
        self.out = out

    def do_step(self, t: Fraction, inp: dict[str, Any]) -> Any:
        return self.out


class Raises:
    def __init__(self, exc: BaseException) -> None:
        self.exc = exc

    def do_step(self, t: Fraction, inp: dict[str, Any]) -> Any:
        raise self.exc


def delayed_step(comp: Any, pure: bool, monkeypatch: pytest.MonkeyPatch) -> tuple[Any, ...]:
    """Store, what was sent, the Leaf's own outputs and the fault (type, text, cause)."""
    if pure:
        monkeypatch.setenv(publish.PURE_ENV, "1")
    else:
        monkeypatch.delenv(publish.PURE_ENV, raising=False)
    values = array("d", [0.5, -1.0, 9.0, 4.0])
    sent: list[Any] = []
    task = Task("C", comp, 1, [("x", "S.x"), ("u", "C.u")], {"u": "C.u", "v": "C.v"})
    task.bind({"S.x": 0, "C.u": 2, "C.v": 3}.__getitem__)
    task.delay = object()  # type: ignore[assignment]  # only handed to ``send``
    step = Steppers(values, lambda line, w: sent.append((line, w)), lambda p: f"{p} (T)")
    run = step.for_task(task)
    fault: tuple[Any, ...] = ()
    try:
        run(task, NOW)
        run(task, NOW + 1)  # the second step reads its own first output back
    except BaseException as exc:  # every kind, compared below
        cause = exc.__cause__
        fault = (type(exc), str(exc), None if cause is None else type(cause))
    return values.tolist(), [w for _, w in sent], dict(task.own), fault


@pytest.mark.parametrize("out", OUTPUTS, ids=lambda o: repr(o)[:30])
def test_outputs_sent_and_refused_alike_on_both_paths(
    out: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert delayed_step(Comp(out), False, monkeypatch) == delayed_step(Comp(out), True, monkeypatch)


@pytest.mark.parametrize("exc", RAISED, ids=lambda e: type(e).__name__)
def test_what_do_step_raises_is_the_same_fault_on_both_paths(
    exc: BaseException, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(interrupt, "users_interrupt", lambda: False)
    compiled = delayed_step(Raises(exc), False, monkeypatch)
    assert compiled == delayed_step(Raises(exc), True, monkeypatch)
    passed = isinstance(exc, Stop | RunFault)  # passed through as they are
    assert compiled[3][0] is (type(exc) if passed else RunFault)
    assert compiled[1] == []  # nothing in flight


def test_a_good_publication_is_in_flight_not_in_the_store(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    values, sent, own, fault = delayed_step(Comp({"u": 1.5, "v": 2}), False, monkeypatch)
    assert fault == ()
    assert values == [0.5, -1.0, 9.0, 4.0]
    assert sent == [[(2, 1.5), (3, 2.0)]] * 2
    assert own == {2: 1.5, 3: 2.0}
    assert all(type(v) is float for _, v in sent[0])
