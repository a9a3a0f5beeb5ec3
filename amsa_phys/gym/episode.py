"""One episode: the scenario runs in a greenlet that pauses where the agent steps.

Why a coroutine: the agent *replaces* a component, so it must act exactly where that
component would — in the middle of an instant, after the components ordered before it have
run and before those after it (which may read its outputs in the same instant). The engine
calls a component (``do_step``) from deep inside its loop; Gymnasium's agent calls ``step``
from the outside. The run therefore lives on a stack of its own that can be suspended: the
stand-in component (:func:`stand_in`) hands its inputs to the agent and is resumed with the
agent's outputs. Nothing else runs meanwhile, so the run is exactly the run the replaced
component would have had, instant for instant and bit for bit, and as deterministic.

That stack was once a worker thread with two queues: each env-step then paid two
thread hand-offs (a futex wake-up and a GIL transfer each, ~11 us CPU per round trip and
more on a busy machine), a sixth of the step. A greenlet (the package made for exactly this:
gevent and SQLAlchemy's asyncio bridge switch stacks with it) switches in ~1 us, in the
same thread, so the episode belongs to the thread that reset it.

At the final instant (``t`` = the duration) the episode is over: the stand-in publishes
nothing there (its outputs keep the last action) and the agent gets the final observation.
"""

from __future__ import annotations

import contextlib
import dataclasses
import sys
import weakref
from collections.abc import Callable, Mapping
from fractions import Fraction
from typing import Any

import greenlet

from ..engine.runner import Simulation
from ..model.scenario import Scenario
from ..model.template import Template
from ..model.world import WorldSpec
from ..templatemarks import StandIn


class EpisodeStop(BaseException):
    """Ends the run from inside the stand-in's step (not an Exception: the engine must not
    turn it into a RunFault)."""


STOP = object()
#: What the run's greenlet returns when the run is over (or was stopped)
_ENDED = object()

#: each template's stand-in class, made once: a class is always in a reference cycle (its
#: ``__mro__`` holds it), so one made per reset was garbage only the collector could free
_STAND_INS: weakref.WeakKeyDictionary[type[Template], type[Template]] = weakref.WeakKeyDictionary()


def stand_in(original: type[Template]) -> type[Template]:
    """A template with ``original``'s declaration whose ``do_step`` is the agent's: each
    instance's own ``do_step`` (:class:`Episode` sets it to its exchange), so one class
    serves every episode."""
    agent = _STAND_INS.get(original)
    if agent is not None:
        return agent

    class Agent(Template):
        """The agent, in place of a component (amsa_phys.gym)."""

        kind = original.kind
        inputs = original.inputs
        outputs = original.outputs
        params = original.params
        template_name = "agent"
        #: its parameters act on nothing: the HUD does not list them as acting
        marks = (StandIn(),)

        def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
            """Replaced on each instance by its episode's exchange (the engine looks
            ``do_step`` up at every call: the exchange itself, not a method calling it, a
            frame less per env-step)."""
            raise RuntimeError("the agent's stand-in steps only inside its episode")

    _STAND_INS[original] = Agent
    return Agent


#: the world with the agent in place, by (id of the scenario's world, path): each reset of
#: one env makes the same one, and the same object lets the next run reuse the structure the
#: last one compiled (``engine/skeleton.py``); an entry holds its world, checked with ``is``
_AGENT_WORLDS: dict[tuple[int, str], tuple[WorldSpec, WorldSpec]] = {}
#: how many agent worlds are kept (the oldest dropped first): one env needs one
MAX_AGENT_WORLDS = 8


def agent_world(world: WorldSpec, path: str) -> WorldSpec:
    """``world`` with the agent's stand-in in place of the Leaf ``path`` (made once per
    world and path: a WorldSpec is frozen, a change is a new one)."""
    key = (id(world), path)
    found = _AGENT_WORLDS.get(key)
    if found is not None and found[0] is world:
        return found[1]
    leaf = world.leaves[path]
    agent = dataclasses.replace(leaf, template=stand_in(leaf.template))
    made = dataclasses.replace(world, leaves={**world.leaves, path: agent})
    if len(_AGENT_WORLDS) >= MAX_AGENT_WORLDS:
        _AGENT_WORLDS.pop(next(iter(_AGENT_WORLDS), key), None)
    _AGENT_WORLDS[key] = (world, made)
    return made


class Episode:
    """The scenario running with the agent in place of the Leaf ``path``.

    After construction (and after each :meth:`step`) the run is paused at the agent's next
    instant: :attr:`t` is its time and :attr:`inputs` what the component reads there; or
    the run has ended (:attr:`done`). A fault in the run is raised by the call that meets it.
    The episode belongs to the thread that made it: a greenlet switches only within one.

    The run keeps a log only for ``trace`` or with ``keep_log`` (a picture samples it): the
    agent reads the store, never the log, and without the log's instants the physics steps
    between the components' instants go in one batch (``Simulation``'s ``keep_log``).
    """

    def __init__(
        self,
        scenario: Scenario,
        path: str,
        trace: Callable[[float, list[float]], None] | None = None,
        *,
        keep_log: bool = False,
    ) -> None:
        self.path = path
        world = agent_world(scenario.world, path)
        self.sim = Simulation.from_scenario(
            dataclasses.replace(scenario, world=world), trace=trace, keep_log=keep_log
        )
        self.sim.components[path].do_step = self._exchange  # type: ignore[method-assign]
        self.end = self.sim.duration
        self._end_num, self._end_den = self.end.numerator, self.end.denominator
        self.t = Fraction(0)
        self.inputs: dict[str, float] = {}
        self.done = False
        #: why the episode ended before its end, for the next step's refusal (None: it
        #: did not, or it reached its end)
        self.ended_by: str | None = None
        self._agent = greenlet.getcurrent()
        self._run = greenlet.greenlet(self._main, parent=self._agent)
        self._answer(self._run.switch())

    # -- the run's greenlet ---------------------------------------------------------------
    def _main(self) -> object:
        try:
            self.sim.run()
        except EpisodeStop as stop:
            # its traceback's frames hold the run (and one of them the exception): a cycle
            # that would keep the whole episode for the garbage collector
            stop.__traceback__ = None
            return _ENDED
        return _ENDED  # an exception goes to the parent: raised by switch()

    def _exchange(self, t: Fraction, inp: Mapping[str, float]) -> Mapping[str, float]:
        # t >= end in integers: a Fraction comparison costs ~0.8 us, a tenth of the env's
        # own share of a step (``follow.py``); ``_numerator``/``_denominator`` are the slots
        # behind the properties (CPython's ``fractions``), read without two property calls
        if t._numerator * self._end_den >= self._end_num * t._denominator:
            return {}  # the episode ended: publish nothing, keep the last action
        self.t = t
        self.inputs = inp  # type: ignore[assignment]
        answer = self._agent.switch(inp)
        if answer is STOP:
            raise EpisodeStop
        return answer  # type: ignore[no-any-return]

    # -- the agent's side -----------------------------------------------------------------
    def _answer(self, message: object) -> None:
        """After a switch to the run: it paused at the agent's next instant (``_exchange``
        set :attr:`t` and :attr:`inputs`), or it ended."""
        if message is _ENDED:
            self.done = True
            self.t = self.end

    def step(self, outputs: Mapping[str, float]) -> None:
        """Publish ``outputs`` as the component's, run to the agent's next instant (or end)."""
        if self.done:
            raise RuntimeError("the episode has ended")
        try:
            message = self._run.switch(outputs)
        except greenlet.error as exc:  # greenlets switch only within their thread
            # greenlet's own message spans several lines (the greenlets' reprs): not said
            raise RuntimeError("step() must be called from the thread that called reset()") from exc
        except BaseException as exc:  # the run's fault (or Ctrl-C inside it) ends the episode
            self.done = True
            self.ended_by = (
                "a step was interrupted"
                if isinstance(exc, KeyboardInterrupt)
                else "its run faulted"
            )
            raise
        if message is _ENDED:  # ``_answer`` inlined: once per env-step
            self.done = True
            self.t = self.end

    def close(self) -> None:
        """Stop the run (it leaves at the instant it is paused at) and free it at once
        (:meth:`_release`); safe to call twice.

        From another thread, or while the interpreter shuts down, the paused run cannot be
        resumed to leave: it is dropped as it is (greenlet unwinds it when it is collected)."""
        run = self._run
        self.done = True
        if not run.dead:
            if greenlet.getcurrent() is not self._agent or sys.is_finalizing():
                return
            with contextlib.suppress(EpisodeStop, greenlet.error):
                run.switch(STOP)
        if run.dead:
            self._release()

    def _release(self) -> None:
        """Free the ended run by reference counting (``Simulation.release`` says why). The
        episode keeps :attr:`t`, :attr:`done` and :attr:`end`."""
        self.sim.release()
