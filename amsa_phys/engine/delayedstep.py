"""A Leaf with latency, stepped in one frame where the store is packed.

:meth:`Steppers.step_delayed <amsa_phys.engine.tasks.Steppers.step_delayed>` reads the
inputs, calls ``do_step``, judges the outputs (:func:`~amsa_phys.engine.tasks.checked_writes`)
and puts them in flight through three frames. Where the store is an ``array('d')`` the
inputs are gathered in C (``publish.gather``) and the rest is this one closure, or, where the
``_kernels`` extension is built, the whole step is one C call (``_kernels.Delayed``) that
hands anything but the usual dict of finite floats to the same Python judging: the same
verdicts, the same faults (``tests/engine/test_delayed_paths.py``,
``test_delayed_compiled.py``). The single env's agent in place of a delayed controller steps
here at every env step.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from fractions import Fraction
from typing import TYPE_CHECKING, Any

from ..errors import RunFault
from . import interrupt, publish
from .verdicts import COMPONENT_ERRORS, OUTPUT_ERRORS, as_number, bad_output, own_interrupt

if TYPE_CHECKING:
    from .tasks import Steppers, Task


def packed_delayed(
    steppers: Steppers,
    task: Task,
    take: Callable[..., dict[str, Any]],
    ports: tuple[str, ...],
    ats: tuple[Any, ...],
) -> Callable[[Task, Fraction], None]:
    """``task``'s step as the loop calls it, ``step(task, now)`` (see the module docstring):
    ``_kernels.Delayed`` where built (the whole step in C, what it does not take handed to
    :func:`finish`'s Python), else the Python closure below."""
    values, own, comp, path, who = steppers.values, task.own, task.comp, task.path, steppers.who
    targets, line, send = task.writes, task.delay, steppers.send
    assert line is not None
    finish = _finisher(steppers, task)
    module = publish._extension("_kernels")
    compiled = getattr(module, "Delayed", None) if module is not None else None
    if compiled is not None and type(own) is dict and type(targets) is dict:
        failed, _ = steppers._judges(task)
        return compiled(comp, ports, ats, values, own, targets, line, send, take, failed, finish)  # type: ignore[no-any-return]

    def step(_task: Task, now: Fraction) -> None:
        # ``Steppers._delayed`` inlined (with ``checked_writes``): one frame a step, not
        # three (a Gymnasium agent in place of a delayed controller is this, every step)
        inp = take(ports, ats, values, own)
        try:
            out = comp.do_step(now, inp)
        except RunFault:
            raise
        except KeyboardInterrupt as exc:  # the user's Ctrl-C, or the component's own
            if interrupt.users_interrupt():
                raise
            raise own_interrupt(who(path), now) from exc
        except COMPONENT_ERRORS as exc:
            raise RunFault(who(path), now, f"do_step raised {exc!r}") from exc
        finish(out, now)

    return step


def _finisher(steppers: Steppers, task: Task) -> Callable[[Any, Fraction], None]:
    """``finish(out, now)``: judge what ``task``'s ``do_step`` returned and put it in flight
    (``checked_writes``'s verdicts, then ``own`` and the delay line), the one place both
    steps above do it."""
    own, path, who = task.own, task.path, steppers.who
    targets, line, send = task.writes, task.delay, steppers.send

    def finish(out: Any, now: Fraction) -> None:
        if not out:
            if out.__class__ is not dict and not isinstance(out, Mapping):
                raise bad_output(who(path), now, targets, out)
            return
        writes: dict[Any, float] = {}
        try:
            for key, value in out.items():
                number = value if value.__class__ is float else as_number(value)
                if number - number != 0.0:  # inf or nan
                    raise ValueError
                writes[targets[key]] = number
        except OUTPUT_ERRORS:
            raise bad_output(who(path), now, targets, out) from None
        own.update(writes)
        send(line, list(writes.items()))

    return finish
