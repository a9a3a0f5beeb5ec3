"""The compiled write of published outputs (``engine/_publish.c``) leaves the store exactly as
the scalar step's Python loop does, and every fault the same, whatever a component returns."""

from __future__ import annotations

import importlib.util
from array import array
from fractions import Fraction
from typing import Any

import numpy as np
import pytest

from amsa_phys.engine import publish
from amsa_phys.engine.tasks import Steppers, Task
from amsa_phys.errors import RunFault

NOW = Fraction(7, 4)
BUILT = importlib.util.find_spec("amsa_phys.engine._publish") is not None

OUTPUTS: list[Any] = [
    {"u": 1.5, "v": -2.25},
    {"v": 0.1},  # one of two
    {},
    {"u": 3},  # an int: the Python loop converts it
    {"u": True},
    {"u": np.float64(2.5), "v": 1.0},
    {"u": 1.0, "v": 7},  # a float written, then one the C call declines
    {"u": 1.0, "v": float("nan")},  # a float written, then a refused one
    {"u": float("-inf")},
    {"u": 1.0, "nope": 2.0},
    {"u": "fast"},
    {"u": 10**400},
    [("u", 1.0)],
    None,
    (1.0,),
]


class Comp:
    def __init__(self, out: Any) -> None:
        self.out = out

    def do_step(self, t: Fraction, inp: dict[str, Any]) -> Any:
        return self.out


def stepped(out: Any, pure: bool, monkeypatch: pytest.MonkeyPatch) -> tuple[list[float], str]:
    """The store after one scalar step that published ``out``, and its fault (if any)."""
    if pure:
        monkeypatch.setenv(publish.PURE_ENV, "1")
    else:
        monkeypatch.delenv(publish.PURE_ENV, raising=False)
    values = array("d", [0.5, -1.0, 9.0, 4.0])
    task = Task("C", Comp(out), 1, [("x", "S.x")], {"u": "C.u", "v": "C.v"})  # type: ignore[arg-type]
    task.bind({"S.x": 0, "C.u": 2, "C.v": 3}.__getitem__)
    step = Steppers(values, lambda *_: None, lambda p: f"{p} (T)").for_task(task)
    try:
        step(task, NOW)
    except RunFault as exc:
        return values.tolist(), str(exc)
    return values.tolist(), ""


@pytest.mark.parametrize("out", OUTPUTS, ids=lambda o: repr(o)[:30])
def test_the_compiled_write_and_the_python_loop_agree(
    out: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert stepped(out, False, monkeypatch) == stepped(out, True, monkeypatch)


def test_good_floats_land_at_their_positions(monkeypatch: pytest.MonkeyPatch) -> None:
    values, fault = stepped({"u": 1.5, "v": -2.25}, False, monkeypatch)
    assert fault == ""
    assert values == [0.5, -1.0, 1.5, -2.25]


@pytest.mark.skipif(not BUILT, reason="the extension was not built (no C compiler)")
def test_the_extension_writes_what_it_accepts_and_declines_the_rest(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv(publish.PURE_ENV, raising=False)
    fast = publish.compiled()
    assert fast is not None
    store = array("d", [0.0] * 4)
    assert fast({"a": 1.5, "b": -0.0}, {"a": 3, "b": 0}, store)
    assert store.tolist() == [-0.0, 0.0, 0.0, 1.5]
    declined = [
        ({"a": 1}, {"a": 0}, store),
        ({"a": float("nan")}, {"a": 0}, store),
        ({"a": 1.0}, {"b": 0}, store),
        ({"a": 1.0}, {"a": 4}, store),  # past the end
        ({"a": 1.0}, {"a": -1}, store),
        ({"a": 1.0}, {"a": 0}, [0.0]),  # not an array of doubles
        ({"a": 1.0}, {"a": 0}, array("f", [0.0])),
        ([("a", 1.0)], {"a": 0}, store),
    ]
    for args in declined:
        assert not fast(*args), args
    monkeypatch.setenv(publish.PURE_ENV, "1")
    assert publish.compiled() is None


@pytest.mark.skipif(not BUILT, reason="the extension was not built (no C compiler)")
def test_gather_builds_the_dict_the_comprehension_builds(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(publish.PURE_ENV, raising=False)
    take = publish.gather()
    assert take is not None
    rng = np.random.default_rng(5)
    store = array("d", [*rng.normal(size=50).tolist(), float("nan"), -0.0, float("inf")])
    for _ in range(200):
        k = int(rng.integers(0, 8))
        ats = tuple(int(a) for a in rng.integers(0, len(store), k))
        ports = tuple(f"p{i}" for i in range(k))
        own = {int(a): float(rng.normal()) for a in rng.integers(0, len(store), 3)}
        for mine in (None, own):
            got = take(ports, ats, store, mine)
            want = {p: (mine or {}).get(a, store[a]) for p, a in zip(ports, ats, strict=True)}
            assert list(got.items()).__repr__() == list(want.items()).__repr__()
    with pytest.raises(IndexError):
        take(("a",), (len(store),), store, None)


class Echo:
    """Publishes its inputs, each doubled, as its two outputs."""

    def do_step(self, t: Fraction, inp: dict[str, Any]) -> dict[str, float]:
        return {"u": 2 * inp["a"] + inp["b"], "v": inp["c"] - inp["d"]}


@pytest.mark.parametrize("delayed", [False, True])
def test_a_step_reads_the_same_inputs_on_both_paths(
    delayed: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    def run(pure: bool) -> tuple[list[float], list[Any]]:
        if pure:
            monkeypatch.setenv(publish.PURE_ENV, "1")
        else:
            monkeypatch.delenv(publish.PURE_ENV, raising=False)
        values = array("d", [0.25, -1.5, 3.0, 7.0, 0.0, 0.0])
        sent: list[Any] = []
        reads = [("a", "S.a"), ("b", "S.b"), ("c", "S.c"), ("d", "C.u")]
        task = Task("C", Echo(), 1, reads, {"u": "C.u", "v": "C.v"})  # type: ignore[arg-type]
        task.bind({"S.a": 0, "S.b": 1, "S.c": 2, "S.d": 3, "C.u": 4, "C.v": 5}.__getitem__)
        if delayed:
            task.delay = object()  # type: ignore[assignment]  # only handed to ``send``
        step = Steppers(values, lambda _l, w: sent.append(w), str).for_task(task)
        for k in range(4):  # a delayed Leaf reads its own last output back (own)
            step(task, NOW + k)
            values[0] += 1.0
        return values.tolist(), sent

    assert run(False) == run(True)


class Stop(BaseException):
    """Not a component's fault (as the gym episode's own stop): passes through."""


class Raises:
    def __init__(self, exc: BaseException) -> None:
        self.exc = exc

    def do_step(self, t: Fraction, inp: dict[str, Any]) -> Any:
        raise self.exc


RAISED = [
    ValueError("bad"),
    ZeroDivisionError(),
    SystemExit(3),
    KeyboardInterrupt(),  # raised by the component itself: no Ctrl-C was noted
    RunFault("C (T)", NOW, "its own fault"),
    Stop(),
]


@pytest.mark.parametrize("exc", RAISED, ids=lambda e: type(e).__name__)
def test_what_do_step_raises_becomes_the_same_fault_on_both_paths(
    exc: BaseException, monkeypatch: pytest.MonkeyPatch
) -> None:
    from amsa_phys.engine import interrupt

    monkeypatch.setattr(interrupt, "users_interrupt", lambda: False)

    def raised(pure: bool) -> tuple[type, str, type | None]:
        if pure:
            monkeypatch.setenv(publish.PURE_ENV, "1")
        else:
            monkeypatch.delenv(publish.PURE_ENV, raising=False)
        values = array("d", [0.5, 0.0, 0.0])
        task = Task("C", Raises(exc), 1, [("x", "S.x")], {"u": "C.u"})  # type: ignore[arg-type]
        task.bind({"S.x": 0, "C.u": 1}.__getitem__)
        step = Steppers(values, lambda *_: None, lambda p: f"{p} (T)").for_task(task)
        try:
            step(task, NOW)
        except BaseException as caught:  # every kind, compared below
            cause = caught.__cause__
            return type(caught), str(caught), None if cause is None else type(cause)
        raise AssertionError("nothing raised")

    compiled, pure = raised(False), raised(True)
    assert compiled == pure
    if isinstance(exc, Stop | RunFault):
        assert compiled[0] is type(exc)  # passed through as it is
    else:
        assert compiled[0] is RunFault
        assert compiled[2] is type(exc)


def test_the_compiled_step_is_the_one_the_engine_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(publish.PURE_ENV, raising=False)
    values = array("d", [0.5, 0.0, 0.0, 0.0])
    task = Task("C", Comp({"u": 1.0}), 1, [("x", "S.x")], {"u": "C.u"})  # type: ignore[arg-type]
    task.bind({"S.x": 0, "C.u": 2}.__getitem__)
    step = Steppers(values, lambda *_: None, str).for_task(task)
    kind = publish.scalar()
    if kind is None:
        pytest.skip("the extension was not built (no C compiler)")
    assert type(step) is kind
    monkeypatch.setenv(publish.PURE_ENV, "1")
    assert type(Steppers(values, lambda *_: None, str).for_task(task)) is not kind
