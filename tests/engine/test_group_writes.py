"""A group's outputs reach the store the same way with the compiled writer as without it.

``Steppers.step_group`` writes a group's usual outputs (finite float64 columns, one value a
member) in one compiled call (``_groupbodies.write_outputs``) and leaves anything else to its
Python loop. Every case here runs both ways, the compiled one where built, and must give
the same store (bit for bit) and the same fault: the same member, the same output.
"""

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

N = 5
PORTS = ("a", "b", "c", "d")
COMPILED = batch_bodies.write_outputs() is not None


class Reply:
    """A template whose ``step_many`` returns what the test set (``Reply.result``)."""

    result: Any = ({}, None)
    seen: ClassVar[dict[str, np.ndarray]] = {}

    @classmethod
    def step_many(cls, comps: Any, now: Any, inp: Any, params: Any, state: Any) -> Any:
        cls.seen = inp
        return cls.result


def _group(spread: bool) -> tuple[batch.Group, int]:
    """N members with inputs ``x`` and outputs PORTS: their buffers evenly spaced (a slice)
    or, with ``spread``, not (an index array). Returns the group and the store's size."""
    names: list[str] = []
    tasks = []
    for k in range(N):
        t = Task(
            path=f"Car{k + 1}.Pilot",
            comp=Reply(),  # type: ignore[arg-type]
            period=1,
            inputs=[("x", f"Car{k + 1}.In.x")],
            targets={p: f"Car{k + 1}.Pilot.{p}" for p in PORTS},
        )
        tasks.append(t)
    for k in range(N):  # member k's buffers; a spread store puts a gap after the third
        names.append(f"Car{k + 1}.In.x")
        if spread and k == 2:
            names.append("gap.x")
    for p in PORTS:
        for k in range(N):
            names.append(f"Car{k + 1}.Pilot.{p}")
            if spread and k == 2:
                names.append(f"gap.{p}")
    at = {name: i for i, name in enumerate(names)}
    for t in tasks:
        t.bind(at.__getitem__)
    return batch.Group(tasks), len(names)


def _run(
    result: Any, spread: bool, compiled: bool, delayed: bool = False
) -> tuple[np.ndarray, RunFault | None, list[Any]]:
    """The store after one group step returning ``result``, the fault if any, and what was
    sent to the group's delay line (``delayed``: the group's outputs go there instead)."""
    group, size = _group(spread)
    if delayed:
        group.delay = "line"  # type: ignore[assignment]  # only handed to send
    values = array("d", [-7.0] * size)
    col = np.frombuffer(values, dtype=np.float64)
    col[group.inputs[0][1]] = np.arange(N, dtype=float)
    sent: list[Any] = []

    def send(line: Any, writes: list[tuple[Any, np.ndarray]]) -> None:
        assert line == "line"
        for at, arr in writes:  # where, and the values: as plain positions and bytes
            where = np.arange(size)[at] if type(at) is slice else np.asarray(at)
            sent.append((where.tolist(), np.array(arr).tobytes()))

    steppers = Steppers(values, send, lambda path: path, col)
    if not compiled:
        steppers._write = None
    elif steppers._write is None:
        pytest.skip("the compiled group writer is not built here")
    Reply.result = result
    fault = None
    try:
        steppers.step_group(group, Fraction(1, 4))
    except RunFault as exc:
        fault = exc
    return col.copy(), fault, sent


def _both(result_of: Callable[[], Any], spread: bool) -> tuple[np.ndarray, RunFault | None]:
    """The compiled and the Python path's store and fault, held equal; the compiled one."""
    pure = _run(result_of(), spread, compiled=False)
    fast = _run(result_of(), spread, compiled=True)
    assert fast[0].tobytes() == pure[0].tobytes()
    assert (fast[1] is None) == (pure[1] is None)
    if fast[1] is not None and pure[1] is not None:
        assert str(fast[1]) == str(pure[1])
        assert getattr(fast[1], "run", None) == getattr(pure[1], "run", None)
    return fast[0], fast[1]


@pytest.mark.parametrize("spread", [False, True])
@pytest.mark.parametrize("mask", [None, (0, 2, 3)])
@pytest.mark.parametrize("bad_at", [None, "c"])
def test_a_delayed_group_sends_the_same(spread: bool, mask: Any, bad_at: Any) -> None:
    """A group with latency sends each output's column (or its published rows) in order;
    with a bad output the ones before it were sent, the fault names it, none after."""

    def result() -> Any:
        out = {p: np.arange(N, dtype=float) + 10 * i for i, p in enumerate(PORTS)}
        out["b"] = out["b"][::-1]  # a view of reversed strides
        if bad_at is not None:
            out[bad_at][2] = np.inf
        return out, None if mask is None else _mask(*mask)

    pure = _run(result(), spread, compiled=False, delayed=True)
    fast = _run(result(), spread, compiled=True, delayed=True)
    assert fast[2] == pure[2]
    assert fast[0].tobytes() == pure[0].tobytes()  # the store itself: untouched
    assert str(fast[1]) == str(pure[1])
    assert len(fast[2]) == (2 if bad_at else len(PORTS))
    if bad_at is not None:
        assert fast[1] is not None
        assert fast[1].cause == "output c is inf"
    rows = list(range(N)) if mask is None else list(mask)
    group, _ = _group(spread)
    assert fast[2][0][0] == [int(i) for i in np.arange(len(fast[0]))[group.outputs["a"]][rows]]
    assert np.frombuffer(fast[2][1][1]).tolist() == [float(4 - r) + 10 for r in rows]


def _cols(store: np.ndarray, spread: bool) -> dict[str, np.ndarray]:
    """Each output's members' values as the store holds them."""
    group, _ = _group(spread)
    return {p: store[group.outputs[p]] for p in PORTS}


def _mask(*rows: int) -> np.ndarray:
    m = np.zeros(N, dtype=bool)
    m[list(rows)] = True
    return m


@pytest.mark.parametrize("spread", [False, True])
def test_every_output_lands_at_its_members_buffers(spread: bool) -> None:
    values = {p: np.arange(N, dtype=float) * (i + 1) + 0.5 for i, p in enumerate(PORTS)}
    store, fault = _both(lambda: (dict(values), None), spread)
    assert fault is None
    got = _cols(store, spread)
    for p in PORTS:
        assert got[p].tolist() == values[p].tolist()
    if spread:  # a gap between members is no member's: never written
        group, _ = _group(spread)
        written = {int(i) for p in PORTS for i in group.outputs[p]}
        gaps = sorted(set(range(N + 1, len(store))) - written)  # past the inputs
        assert len(gaps) == len(PORTS)
        assert store[gaps].tolist() == [-7.0] * len(PORTS)


@pytest.mark.parametrize("spread", [False, True])
def test_only_published_rows_are_written(spread: bool) -> None:
    arr = np.array([1.0, np.nan, 3.0, np.inf, 5.0])  # the lost rows may hold anything
    store, fault = _both(lambda: ({"a": arr.copy(), "c": arr * 2}, _mask(0, 2, 4)), spread)
    assert fault is None
    got = _cols(store, spread)
    assert got["a"].tolist() == [1.0, -7.0, 3.0, -7.0, 5.0]
    assert got["c"].tolist() == [2.0, -7.0, 6.0, -7.0, 10.0]
    assert got["b"].tolist() == [-7.0] * N  # not published at all: untouched


@pytest.mark.parametrize("spread", [False, True])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_the_first_bad_output_and_member_are_named(spread: bool, bad: float) -> None:
    def result() -> Any:
        out = {p: np.full(N, float(i)) for i, p in enumerate(PORTS)}
        out["c"][3] = bad
        out["d"][1] = np.nan  # a later output's fault is never the one named
        return out, None

    store, fault = _both(result, spread)
    assert fault is not None
    assert fault.component == "Car4.Pilot"
    assert fault.cause == f"output c is {bad}"
    got = _cols(store, spread)  # the outputs before it were written, as before
    assert got["a"].tolist() == [0.0] * N
    assert got["b"].tolist() == [1.0] * N


@pytest.mark.parametrize("spread", [False, True])
def test_a_strided_column_is_judged_by_its_own_values(spread: bool) -> None:
    """A view of every other element of a wider array (a template's slice of its state)."""

    def result() -> Any:
        wide = np.arange(2.0 * N)
        wide[6] = np.nan  # the view's member 3; its neighbours in memory are finite
        return {"a": wide[::2]}, None

    fault = _both(result, spread)[1]
    assert fault is not None
    assert fault.component == "Car4.Pilot"
    assert fault.cause == "output a is nan"


def test_a_bad_value_in_an_unpublished_row_is_no_fault() -> None:
    arr = np.array([1.0, 2.0, np.nan, 4.0, 5.0])
    store, fault = _both(lambda: ({"b": arr.copy()}, _mask(0, 1, 3, 4)), False)
    assert fault is None
    assert _cols(store, False)["b"].tolist() == [1.0, 2.0, -7.0, 4.0, 5.0]


@pytest.mark.parametrize("spread", [False, True])
def test_other_kinds_of_columns_are_written_alike(spread: bool) -> None:
    """What the compiled writer declines (a number for all, a list, float32, a strided
    view, an ndarray subclass) takes the Python path from there on, with the same result."""

    class Sub(np.ndarray):
        pass

    def result() -> Any:
        wide = np.arange(2 * N, dtype=float)
        return {
            "a": np.arange(N, dtype=float) + 0.25,  # taken
            "b": wide[::2],  # strided: taken, read with its stride
            "c": 3.5,  # one number for every member
            "d": np.arange(N, dtype=np.float32).view(Sub) / 3,
        }, None

    store, fault = _both(result, spread)
    assert fault is None
    got = _cols(store, spread)
    assert got["b"].tolist() == [0.0, 2.0, 4.0, 6.0, 8.0]
    assert got["c"].tolist() == [3.5] * N
    assert got["d"].tolist() == (np.arange(N, dtype=np.float32) / 3).astype(float).tolist()


@pytest.mark.parametrize(
    ("out", "says"),
    [
        ({"a": np.zeros(N), "nope": np.zeros(N)}, "published unknown output 'nope'"),
        ({"a": np.zeros(N), "b": np.zeros(N + 1)}, "output b of step_many has shape (6,)"),
        ({"a": np.zeros(N), "b": np.zeros((N, 1))}, "output b of step_many has shape (5, 1)"),
    ],
)
def test_a_wrong_output_is_refused_with_the_same_message(out: Any, says: str) -> None:
    store, fault = _both(lambda: ({k: v.copy() for k, v in out.items()}, None), False)
    assert fault is not None
    assert says in fault.cause
    assert _cols(store, False)["a"].tolist() == [0.0] * N


def test_huge_finite_values_are_written() -> None:
    arr = np.array([1e300, -1.7976931348623157e308, 5e-324, -0.0, 0.0])
    store, fault = _both(lambda: ({"a": arr.copy()}, None), False)
    assert fault is None
    assert _cols(store, False)["a"].tobytes() == arr.tobytes()


@pytest.mark.parametrize("spread", [False, True])
@pytest.mark.parametrize("compiled", [False, True])
def test_inputs_are_copies_the_template_may_keep(spread: bool, compiled: bool) -> None:
    """Each member's input, in members' order; the template's to keep or edit: editing it
    changes neither the store nor another input, and the next step's inputs are new."""
    group, size = _group(spread)
    values = array("d", [-7.0] * size)
    col = np.frombuffer(values, dtype=np.float64)
    x = group.inputs[0][1]
    col[x] = np.arange(N, dtype=float) * 1.5
    steppers = Steppers(values, lambda line, w: None, lambda path: path, col)
    if not compiled:
        steppers._write = steppers._gather_in = None
    elif steppers._gather_in is None:
        pytest.skip("the compiled group gather is not built here")
    Reply.result = ({}, None)
    steppers.step_group(group, Fraction(1, 4))
    kept = Reply.seen["x"]
    assert kept.tolist() == [0.0, 1.5, 3.0, 4.5, 6.0]
    kept[:] = 99.0
    assert col[x].tolist() == [0.0, 1.5, 3.0, 4.5, 6.0]
    col[x] = -np.arange(N, dtype=float)
    steppers.step_group(group, Fraction(1, 2))
    assert Reply.seen["x"].tolist() == [-0.0, -1.0, -2.0, -3.0, -4.0]
    assert kept.tolist() == [99.0] * N


@pytest.mark.skipif(not COMPILED, reason="the compiled group writer is not built here")
def test_the_gather_copies_each_row_from_its_positions() -> None:
    gather = batch_bodies.gather_inputs()
    col = np.arange(20, dtype=float) * 2.0
    ats = (slice(1, 11, 2), np.array([19, 3, 0, 7, 5], dtype=np.intp), slice(4, 9, 1))
    block = np.full((3, 5), -1.0)
    gather(col, ats, block)
    assert block.tolist() == [
        [2.0, 6.0, 10.0, 14.0, 18.0],
        [38.0, 6.0, 0.0, 14.0, 10.0],
        [8.0, 10.0, 12.0, 14.0, 16.0],
    ]
    with pytest.raises(ValueError, match="input 0"):
        gather(col, (np.array([0, 1, 2, 3, 20], dtype=np.intp),), np.empty((1, 5)))
    with pytest.raises(ValueError, match="input 0"):
        gather(col, (slice(16, 26, 1),), np.empty((1, 5)))


@pytest.mark.skipif(not COMPILED, reason="the compiled group writer is not built here")
def test_the_writer_says_how_many_it_wrote() -> None:
    """Its contract with ``step_group``: outputs in order up to the first it declines."""
    write = batch_bodies.write_outputs()
    col = np.zeros(20)
    outputs = {"a": slice(0, 5, 1), "b": np.array([19, 17, 15, 13, 11], dtype=np.intp)}
    good = np.arange(5, dtype=float) + 1
    assert write({"a": good, "b": good}, outputs, col, None, np.ndarray, 5) == 2
    assert col[[19, 17, 15, 13, 11]].tolist() == good.tolist()
    col[:] = 0
    assert write({"a": good, "x": good, "b": good}, outputs, col, None, np.ndarray, 5) == 1
    assert col[[19, 17, 15, 13, 11]].tolist() == [0.0] * 5  # nothing after the declined one
    assert write({"b": good.tolist()}, outputs, col, None, np.ndarray, 5) == 0
    assert write({"a": good, 7: good}, {**outputs, 7: slice(5, 10)}, col, None, np.ndarray, 5) == 1
    assert write({"a": np.zeros(4)}, outputs, col, None, np.ndarray, 5) == 0
    out_of_range = {"a": np.array([0, 1, 2, 3, 20], dtype=np.intp)}
    assert write({"a": good}, out_of_range, col, None, np.ndarray, 5) == 0
    with pytest.raises(ValueError, match="published"):
        write({"a": good}, outputs, col, np.ones(4, dtype=bool), np.ndarray, 5)
    with pytest.raises(ValueError, match="col"):
        write({"a": good}, outputs, col.astype(np.float32), None, np.ndarray, 5)
