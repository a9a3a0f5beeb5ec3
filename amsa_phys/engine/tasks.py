"""Tasks: one component's step at its instants, and the checks on what it publishes.

A :class:`Task` is a Leaf as the schedule runs it: its inputs and outputs resolved to buffer
names, its period and timer phase in ticks, its delay line. :class:`Steppers` holds the four
ways a task steps — the lean scalar path, a Leaf with latency or jitter (its outputs go into
the delivery heap), a Leaf with array ports, and a group of like copies stepped as arrays
(``engine/batch.py``; its steps in ``groupstep.py``, mixed in) — and every one of them
judges a component the same way:

* what its code raises is :data:`COMPONENT_ERRORS` (any exception, and ``sys.exit()``, which
  would otherwise end the whole program silently); KeyboardInterrupt is the user's and is
  never caught;
* what it publishes goes through :func:`checked_writes`, one function with one set of
  refusals (:data:`OUTPUT_ERRORS`) and one message (:func:`bad_output`): the three copies
  this replaced had drifted apart. The scalar path (:meth:`Steppers.step`) runs the same
  loop inlined, because the call alone cost ~2 % of a headless run (CPU time, measured);
  it uses the same exception set and message, and ``tests/engine/test_tasks.py`` holds the
  two to the same verdict on every kind of bad output.

The exception sets and the fault messages live in ``verdicts.py`` (re-exported here); a
delayed Leaf's packed step in ``delayedstep.py``.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Mapping, MutableMapping
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from ..errors import RunFault
from ..model.template import Template
from . import batch_bodies, interrupt, kernels, publish
from .delayedstep import packed_delayed
from .groupstep import GroupSteps
from .timing import DelayLine
from .verdicts import (  # in_run re-exported: the engine's modules take it from here
    COMPONENT_ERRORS,
    OUTPUT_ERRORS,
    as_number,
    bad_output,
    in_run,
    own_interrupt,
)

__all__ = ["COMPONENT_ERRORS", "Steppers", "Task", "checked_writes", "in_run"]


@dataclass
class Task:
    """A Leaf as the schedule runs it (see the module docstring)."""

    path: str
    comp: Template
    period: int
    inputs: list[tuple[str, str]]
    targets: dict[str, str]  # output port -> buffer name ("Component.port")
    #: array ports (a lidar's ranges): port -> element buffer names, in order
    arrays_in: dict[str, list[str]] = field(default_factory=dict)
    arrays_out: dict[str, list[str]] = field(default_factory=dict)
    #: loop timing (``engine/timing.py``): the timer's phase in ticks, and the delay line of
    #: a Leaf with latency or jitter (None: its outputs are visible at once)
    phase: int = 0
    delay: DelayLine | None = None
    #: a delayed Leaf's own last outputs, which it reads back at once (as its node does)
    own: dict[Any, float] = field(default_factory=dict)
    #: the same inputs, outputs and array ports by their position in the buffer store
    #: (:meth:`bind`); until bound, by name (a test's dict of values)
    reads: list[tuple[str, Any]] = field(default_factory=list)
    writes: dict[str, Any] = field(default_factory=dict)
    reads_arrays: dict[str, list[Any]] = field(default_factory=dict)
    writes_arrays: dict[str, list[Any]] = field(default_factory=dict)
    #: the run of a batch this task belongs to (``engine/multirun.py``); 0 alone
    run: int = 0

    def __post_init__(self) -> None:
        self.reads = list(self.inputs)
        self.writes = dict(self.targets)

    def bind(self, at: Callable[[str], int]) -> None:
        """Resolve every buffer name to its position in the store (``at(name)``): the
        steppers index the store's array, never a dict by name."""
        arrays = self.arrays_in  # an array port's name is no buffer: its elements are
        self.reads = [(port, -1 if port in arrays else at(buf)) for port, buf in self.inputs]
        self.writes = {
            port: -1 if port in self.arrays_out else at(buf) for port, buf in self.targets.items()
        }
        self.reads_arrays = {p: [at(n) for n in ns] for p, ns in self.arrays_in.items()}
        self.writes_arrays = {p: [at(n) for n in ns] for p, ns in self.arrays_out.items()}


def checked_writes(
    task: Task,
    out: Any,
    into: MutableMapping[str, float],
    now: Fraction,
    who: Callable[[str], str],
) -> None:
    """Put ``task``'s scalar outputs ``out`` into ``into`` at their buffers' positions
    (:meth:`Task.bind`), each a finite float.

    The one judge of published scalars: anything refused raises the RunFault that names the
    first bad output (:func:`bad_output`). Outputs before a refused one may already be in
    ``into``; the fault ends the run, so nothing reads them.
    """
    targets = task.writes
    try:
        for key, value in out.items():
            number = value if value.__class__ is float else as_number(value)
            if number - number != 0.0:  # inf or nan
                raise ValueError
            into[targets[key]] = number
    except OUTPUT_ERRORS:
        raise bad_output(who(task.path), now, targets, out) from None


class Steppers(GroupSteps):
    """The ways a task steps, over one run's buffers (see the module docstring).

    ``send(line, writes)`` puts a delayed publication in flight (the delivery heap);
    ``who(path)`` names a component in a fault; ``values`` and ``col`` are the buffer
    store's two views of its one array (``store.py``).
    """

    def __init__(
        self,
        values: MutableMapping[Any, float] | array,
        send: Callable[[DelayLine, list[tuple[Any, float]]], None],
        who: Callable[[str], str],
        col: np.ndarray | None = None,
    ) -> None:
        #: what the scalar paths index: the store's ``array('d')`` by position (a test's
        #: dict by name works alike)
        self.values = values
        #: the same memory as a numpy array: what groups read and write (``store.py``)
        self.col = col
        self.send = send
        self.who = who
        #: the compiled steps (``publish.py``) where the store is an array of doubles
        packed = isinstance(values, array)
        self._gather = publish.gather() if packed else None
        self._scalar = publish.scalar() if packed else None
        #: the compiled bodies' type (``kernels.py``), asked once per run, not per task
        self._kernel = publish.kernel() if packed else None
        self._made: dict[int, tuple[Task, Callable[[Task, Fraction], None]]] = {}
        #: a group's outputs judged and written in one compiled call (``_groupbodies.c``)
        #: where built and the store is one float64 array
        #: and its inputs gathered in one (both None on the pure path)
        store = isinstance(col, np.ndarray) and col.dtype == np.float64 and col.ndim == 1
        self._write = batch_bodies.write_outputs() if store else None
        self._gather_in = batch_bodies.gather_inputs() if store else None

    def release(self) -> None:
        """Forget the steps made (a delayed Leaf's, in Python, is a method of this object)."""
        self._made.clear()

    def for_task(self, task: Task) -> Callable[[Task, Fraction], None]:
        """How ``task`` steps: the lean scalar path, array ports, or through its delay line.
        Made once per task, however many instants of the cycle it runs at."""
        made = self._made.get(id(task))
        if made is not None and made[0] is task:
            return made[1]
        if task.arrays_in or task.arrays_out:
            step = self.step_arrays
        elif task.delay is not None:
            step = self.delayed(task)
        else:
            step = self.scalar(task)
            if self._kernel is not None:  # packed and compiled: an arithmetic body in C
                step = kernels.kernel(self._kernel, task, self.values, step, self._judges) or step
        self._made[id(task)] = (task, step)
        return step

    def scalar(self, task: Task) -> Callable[[Task, Fraction], None]:
        """:meth:`step` for ``task`` alone, what the loop calls in its place: in C where
        built (``publish.Scalar``), else positions bound once and up to two inputs read into
        a dict display (a comprehension is a call of its own on CPython 3.11). The same
        verdicts as :meth:`step` (``tests/engine/test_tasks.py``, ``test_publish.py``)."""
        values, who, path, comp = self.values, self.who, task.path, task.comp
        reads, targets = task.reads, task.writes
        n = len(reads)
        if self._scalar is not None and type(targets) is dict:
            ports, ats = tuple(p for p, _ in reads), tuple(a for _, a in reads)
            return self._scalar(comp, ports, ats, values, targets, *self._judges(task))  # type: ignore[no-any-return]
        (p0, a0), (p1, a1) = [*reads, ("", 0), ("", 0)][:2]

        def step(_task: Task, now: Fraction) -> None:
            if n == 2:
                inp = {p0: values[a0], p1: values[a1]}
            elif n == 1:
                inp = {p0: values[a0]}
            elif n == 0:
                inp = {}
            else:
                inp = {port: values[at] for port, at in reads}
            try:
                out = comp.do_step(now, inp)
            except RunFault:
                raise
            except KeyboardInterrupt as exc:  # the user's Ctrl-C, or the component's own
                if interrupt.users_interrupt():
                    raise
                raise own_interrupt(who(path), now) from exc
            except COMPONENT_ERRORS as exc:  # inlined :meth:`_call`, as in :meth:`step`
                raise RunFault(who(path), now, f"do_step raised {exc!r}") from exc
            if not out:
                if out.__class__ is not dict and not isinstance(out, Mapping):
                    raise bad_output(who(path), now, targets, out)
                return
            # checked_writes, inlined as in :meth:`step`
            try:
                for key, value in out.items():
                    number = value if value.__class__ is float else as_number(value)
                    if number - number != 0.0:  # inf or nan
                        raise ValueError
                    values[targets[key]] = number
            except OUTPUT_ERRORS:
                raise bad_output(who(path), now, targets, out) from None

        return step

    def _judges(self, task: Task) -> tuple[Callable[..., None], Callable[..., None]]:
        """``publish.Scalar``'s way back: ``failed(exc, now)`` raises :meth:`scalar`'s fault
        for what ``do_step`` raised, ``judge(out, now)`` judges an output C declined."""
        values, who, path, targets = self.values, self.who, task.path, task.writes

        def failed(exc: BaseException, now: Fraction) -> None:
            try:
                raise exc
            except RunFault:
                raise
            except KeyboardInterrupt as err:  # the user's Ctrl-C, or the component's own
                if interrupt.users_interrupt():
                    raise
                raise own_interrupt(who(path), now) from err
            except COMPONENT_ERRORS as err:
                raise RunFault(who(path), now, f"do_step raised {err!r}") from err

        def judge(out: Any, now: Fraction) -> None:
            if not out:
                if out.__class__ is not dict and not isinstance(out, Mapping):
                    raise bad_output(who(path), now, targets, out)
                return
            try:
                for key, value in out.items():
                    number = value if value.__class__ is float else as_number(value)
                    if number - number != 0.0:  # inf or nan
                        raise ValueError
                    values[targets[key]] = number
            except OUTPUT_ERRORS:
                raise bad_output(who(path), now, targets, out) from None

        return failed, judge

    def _call(self, task: Task, now: Fraction, inp: dict[str, Any]) -> Any:
        try:
            return task.comp.do_step(now, inp)
        except RunFault:
            raise
        except KeyboardInterrupt as exc:  # the user's Ctrl-C, or the component's own
            if interrupt.users_interrupt():
                raise
            raise own_interrupt(self.who(task.path), now) from exc
        except COMPONENT_ERRORS as exc:  # a component's own bug or bad configuration
            raise RunFault(self.who(task.path), now, f"do_step raised {exc!r}") from exc

    def step(self, task: Task, now: Fraction) -> None:
        """Run one component: read its inputs, call ``do_step``, publish its outputs."""
        values = self.values
        inp = {port: values[at] for port, at in task.reads}
        try:
            out = task.comp.do_step(now, inp)
        except RunFault:
            raise
        except KeyboardInterrupt as exc:  # the user's Ctrl-C, or the component's own
            if interrupt.users_interrupt():
                raise
            raise own_interrupt(self.who(task.path), now) from exc
        except COMPONENT_ERRORS as exc:  # inlined :meth:`_call`: the hot path
            raise RunFault(self.who(task.path), now, f"do_step raised {exc!r}") from exc
        if not out:
            if out.__class__ is not dict and not isinstance(out, Mapping):
                raise bad_output(self.who(task.path), now, task.writes, out)
            return
        # checked_writes(task, out, values, now, self.who), inlined (module doc)
        targets = task.writes
        try:
            for key, value in out.items():
                number = value if value.__class__ is float else as_number(value)
                if number - number != 0.0:  # inf or nan
                    raise ValueError
                values[targets[key]] = number
        except OUTPUT_ERRORS:
            raise bad_output(self.who(task.path), now, targets, out) from None

    def delayed(self, task: Task) -> Callable[[Task, Fraction], None]:
        """:meth:`step_delayed` for ``task``, its inputs gathered in C (``publish.py``), in
        one frame (``delayedstep.py``)."""
        take = self._gather
        if take is None:
            return self.step_delayed
        ports, ats = tuple(p for p, _ in task.reads), tuple(a for _, a in task.reads)
        return packed_delayed(self, task, take, ports, ats)

    def step_delayed(self, task: Task, now: Fraction) -> None:
        """:meth:`step` for a Leaf with latency or jitter: its outputs go into its delay
        line instead of the buffers (it reads its own outputs back at once)."""
        values = self.values
        own = task.own
        self._delayed(task, now, {port: own.get(at, values[at]) for port, at in task.reads})

    def _delayed(self, task: Task, now: Fraction, inp: dict[str, Any]) -> None:
        """:meth:`step_delayed` once its inputs ``inp`` are read."""
        try:
            out = task.comp.do_step(now, inp)
        except RunFault:
            raise
        except KeyboardInterrupt as exc:  # the user's Ctrl-C, or the component's own
            if interrupt.users_interrupt():
                raise
            raise own_interrupt(self.who(task.path), now) from exc
        except COMPONENT_ERRORS as exc:  # inlined :meth:`_call`: once per step of the Leaf
            raise RunFault(self.who(task.path), now, f"do_step raised {exc!r}") from exc
        if not out:
            if out.__class__ is not dict and not isinstance(out, Mapping):
                raise bad_output(self.who(task.path), now, task.writes, out)
            return
        writes: dict[Any, float] = {}
        checked_writes(task, out, writes, now, self.who)
        task.own.update(writes)
        assert task.delay is not None
        self.send(task.delay, list(writes.items()))

    def step_arrays(self, task: Task, now: Fraction) -> None:
        """:meth:`step` for a leaf with array ports (a lidar and its readers).

        An array input arrives as a float numpy array of its elements; an array output must
        be a sequence of exactly its length, every element finite, and is published whole
        (or not at all, if the key is missing). Kept apart so the scalar path stays lean.
        """
        values = self.values
        arrays_in = task.reads_arrays
        inp: dict[str, Any] = {}
        for port, at in task.reads:
            names = arrays_in.get(port)
            inp[port] = values[at] if names is None else np.array([values[n] for n in names])
        out = self._call(task, now, inp)
        if not out:
            if out.__class__ is not dict and not isinstance(out, Mapping):
                raise bad_output(self.who(task.path), now, task.writes, out)
            return
        writes: list[tuple[Any, float]] = []
        scalars: dict[str, Any] = {}
        try:
            items = list(out.items())
        except AttributeError:
            raise bad_output(self.who(task.path), now, task.writes, out) from None
        for key, value in items:
            names = task.writes_arrays.get(key)
            if names is None:
                scalars[key] = value
                continue
            writes.extend(
                zip(names, self._checked_array(task, now, key, value, len(names)), strict=True)
            )
        checked: dict[Any, float] = {}
        checked_writes(task, scalars, checked, now, self.who)
        writes.extend(checked.items())
        if task.delay is not None:
            self.send(task.delay, writes)
        else:
            for at, value in writes:
                values[at] = value

    def _checked_array(self, task: Task, now: Fraction, key: str, value: Any, n: int) -> list:
        """An array output as ``n`` finite floats, or the fault that says what is wrong."""
        try:
            arr = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            raise RunFault(
                self.who(task.path), now, f"output {key} is not numbers: {value!r}"
            ) from None
        if arr.shape != (n,):
            raise RunFault(
                self.who(task.path), now, f"output {key} has shape {arr.shape}, expected ({n},)"
            )
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            k = int(bad[0])
            raise RunFault(self.who(task.path), now, f"output {key}[{k}] is {arr[k]}")
        return arr.tolist()
