"""A group of like components stepped as arrays: :class:`GroupSteps`, the group half of
``tasks.Steppers`` (which it is mixed into).

A group's inputs are gathered from the store's columns, its template's ``step_many`` called
once for all members, its outputs judged and written back (``engine/batch.py``). The
schedule calls each group through a step bound to it (:meth:`GroupSteps.for_group`); the
method :meth:`GroupSteps.step_group` is the reference that step falls back to, and both
judge an answer with the same code, so every fault reads the same
(``tests/engine/test_group_step_bound.py``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from fractions import Fraction
from itertools import islice
from typing import Any

import numpy as np

from ..errors import RunFault
from ..model.params import short_repr
from . import batch, interrupt
from .timing import DelayLine
from .verdicts import COMPONENT_ERRORS, in_run, own_interrupt

#: numpy's boolean dtype: ``arr.dtype is _BOOL`` for a mask's usual dtype (``_is_mask``
#: still decides any other, equal, dtype object)
_BOOL = np.dtype(np.bool_)


def _is_mask(published: Any, n: int) -> bool:
    """Whether ``published`` is a boolean array with one entry per copy."""
    return (
        isinstance(published, np.ndarray)
        and published.dtype == np.bool_
        and published.shape == (n,)
    )


class GroupSteps:
    """Group steps over a run's store (mixed into ``tasks.Steppers``, which sets these)."""

    col: Any
    who: Callable[[str], str]
    send: Callable[[DelayLine, list[tuple[Any, Any]]], None]
    _gather_in: Any
    _write: Any

    def step_group(self, group: batch.Group, now: Fraction) -> None:
        """Run a group of like components in one call (``engine/batch.py``).

        Each input port is the members' column, a copy (a template may keep or edit its
        inputs), each output written back into the store's array in place (only the
        published rows, under a mask). Compiled where built (``_groupbodies.c``): the inputs
        gathered into one block's rows in one call, the usual outputs (finite float64
        columns) judged and written in one; what the writer declines, and every output of a
        delayed group, goes through the loop below, which names a bad output as ever.
        """
        col = self.col
        n = len(group.paths)
        if self._gather_in is None:
            inp = {p: col[at].copy() if type(at) is slice else col[at] for p, at in group.inputs}
        elif group.ats:  # one new block, a row an input: each row the template's to keep
            block = np.empty((len(group.ats), n))
            self._gather_in(col, group.ats, block)
            inp = dict(zip(group.ports, block, strict=True))
        else:
            inp = {}
        who = self.who
        try:
            out, published = group.template.step_many(
                group.comps, now, inp, group.params, group.state
            )
        except RunFault:
            raise
        except KeyboardInterrupt as exc:  # the user's Ctrl-C, or the component's own
            if interrupt.users_interrupt():
                raise
            raise own_interrupt(who(group.paths[0]), now) from exc
        except COMPONENT_ERRORS as exc:
            raise RunFault(who(group.paths[0]), now, f"step_many raised {exc!r}") from exc
        except (TypeError, ValueError) as exc:  # not a pair (outputs, published)
            raise RunFault(
                who(group.paths[0]), now, f"step_many must return (outputs, published): {exc}"
            ) from exc
        self._group_outputs(group, now, out, published, n)

    def for_group(self, group: batch.Group) -> Callable[[batch.Group, Fraction], None]:
        """:meth:`step_group` for ``group``, what the schedule calls in its place: with the
        group's inputs gathered and its outputs written in C, its lookups bound once and the
        usual answer (a dict, no mask or a boolean one, every output taken by the writer)
        told in a few type checks; anything else goes on through the same methods as
        :meth:`step_group`, so every fault is the same. Why: a vector env steps ~10 groups
        an agent step, and the method's lookups and checks were ~1.3 µs of each call."""
        gather, write = self._gather_in, self._write
        if gather is None or write is None or group.delay is not None:
            return self.step_group
        col, ats, ports, k, n = self.col, group.ats, group.ports, len(group.ats), len(group.paths)
        step_many = group.template.step_many
        comps, params, state, outputs = group.comps, group.params, group.state, group.outputs
        empty, ndarray, rest, who = np.empty, np.ndarray, self._group_outputs, self.who
        step_group, first = self.step_group, group.paths[0]

        def step(g: batch.Group, now: Fraction) -> None:
            if g is not group:  # never in a schedule; a caller with another group
                step_group(g, now)
                return
            if k:  # as step_group: a new block, a row an input
                block = empty((k, n))
                gather(col, ats, block)
                inp = dict(zip(ports, block, strict=True))
            else:
                inp = {}
            try:  # step_group's handlers, inlined (what they do not catch passes as ever)
                out, published = step_many(comps, now, inp, params, state)
            except RunFault:
                raise
            except KeyboardInterrupt as exc:
                if interrupt.users_interrupt():
                    raise
                raise own_interrupt(who(first), now) from exc
            except COMPONENT_ERRORS as exc:
                raise RunFault(who(first), now, f"step_many raised {exc!r}") from exc
            except (TypeError, ValueError) as exc:
                raise RunFault(
                    who(first), now, f"step_many must return (outputs, published): {exc}"
                ) from exc
            if type(out) is dict and (
                published is None
                or (
                    type(published) is ndarray
                    and published.dtype is _BOOL
                    and published.shape == (n,)
                )
            ):
                done = write(out, outputs, col, published, ndarray, n)
                if done == len(out):
                    return
                rest(group, now, out, published, n, done)
                return
            rest(group, now, out, published, n)

        return step

    def _group_outputs(
        self,
        group: batch.Group,
        now: Fraction,
        out: Any,
        published: Any,
        n: int,
        done: int | None = None,
    ) -> None:
        """Judge and write a group's answer ``(out, published)`` (:meth:`step_group`); with
        ``done``, the writer has already taken that many outputs of a judged answer."""
        who = self.who
        col = self.col
        outputs = group.outputs
        if done is None:
            # the usual answer (a dict, and None or a boolean array) told by its types
            # first: ``isinstance(out, Mapping)`` asks the ABC machinery, ~1 µs a step
            if not (
                (type(out) is dict or isinstance(out, Mapping))
                and (
                    published is None
                    or (
                        type(published) is np.ndarray
                        and published.dtype is _BOOL
                        and published.shape == (n,)
                    )
                    or _is_mask(published, n)
                )
            ):
                raise RunFault(
                    who(group.paths[0]),
                    now,
                    f"step_many must return (outputs, published) with a mapping of outputs and "
                    f"None or a boolean mask of {n} rows, got ({short_repr(out)}, "
                    f"{short_repr(published)})",
                )
            items: Any = out.items()
            if self._write is not None and type(out) is dict:
                # the usual outputs in one call; the loop below takes whatever it left, from
                # the first output it did not take, so a fault names the same output as before
                if group.delay is None:
                    done = self._write(out, outputs, col, published, np.ndarray, n)
                else:  # judged in one call, then sent in order as the loop sends them
                    done = self._write(out, outputs, None, published, np.ndarray, n)
                    for port, arr in islice(items, done):
                        self._send_group(group, port, arr, published)
                if done == len(out):
                    return
                items = islice(items, done, None)
        else:
            items = islice(out.items(), done, None)
        for port, arr in items:
            at = outputs.get(port)
            if at is None:
                raise RunFault(
                    who(group.paths[0]), now, f"published unknown output {short_repr(port)}"
                )
            if not (type(arr) is np.ndarray and arr.shape == (n,) and arr.dtype == np.float64):
                try:
                    arr = np.broadcast_to(np.asarray(arr, dtype=np.float64), (n,))
                except (TypeError, ValueError, OverflowError):
                    raise RunFault(
                        who(group.paths[0]),
                        now,
                        f"output {port} of step_many has shape {np.shape(arr)}, expected "
                        f"({n},): one number per copy",
                    ) from None
            k = batch.first_bad(arr, published)
            if k is not None:
                fault = RunFault(who(group.paths[k]), now, f"output {port} is {arr[k]}")
                raise in_run(fault, group.tasks[k].run)
            if group.delay is not None:
                self._send_group(group, port, arr, published)
            elif published is None:
                col[at] = arr
            elif type(at) is slice:
                np.copyto(col[at], arr, where=published)
            else:
                col[at[published]] = arr[published]

    def _send_group(
        self, group: batch.Group, port: str, arr: np.ndarray, published: np.ndarray | None
    ) -> None:
        """A delayed group's judged output ``port`` put in flight: the copies' common
        latency (no jitter: ``batch.py``), the whole column (a copy: the template may reuse
        its array) or its published rows."""
        assert group.delay is not None
        if published is None:
            self.send(group.delay, [(group.outputs[port], arr.copy())])
        else:
            where = np.asarray(group.targets[port], dtype=np.intp)[published]
            self.send(group.delay, [(where, arr[published])])
