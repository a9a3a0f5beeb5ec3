"""One episode: the scenario runs in a worker thread that pauses where the agent steps.

Why a thread: the agent *replaces* a component, so it must act exactly where that component
would — in the middle of an instant, after the components ordered before it have run and
before those after it (which may read its outputs in the same instant). The engine calls a
component (``do_step``) from deep inside its loop; Gymnasium's agent calls ``step`` from the
outside. A thread lets the engine call out and *wait*: the stand-in component
(:func:`stand_in`) hands its inputs to the agent and blocks until the agent's outputs come
back. Nothing else runs meanwhile (the two threads strictly alternate through two queues), so
the run is exactly the run the replaced component would have had, instant for instant and
bit for bit, and as deterministic.

At the final instant (``t`` = the duration) the episode is over: the stand-in publishes
nothing there (its outputs keep the last action) and the agent gets the final observation.
"""

from __future__ import annotations

import dataclasses
import queue
import threading
from collections.abc import Callable, Mapping
from fractions import Fraction
from typing import Any

from ..engine.runner import Simulation
from ..model.scenario import Scenario
from ..model.template import Template

#: How long ``close`` waits for the worker to leave (it is a daemon thread either way).
JOIN_TIMEOUT_S = 10.0


class _Stop(BaseException):
    """Ends the worker from inside the stand-in's step (not an Exception: the engine must
    not turn it into a RunFault)."""


_STOP = object()

Exchange = Callable[[Fraction, Mapping[str, float]], Mapping[str, float]]


def stand_in(original: type[Template], exchange: Exchange) -> type[Template]:
    """A template with ``original``'s declaration whose ``do_step`` is the agent's."""

    class Agent(Template):
        """The agent, in place of a component (amsa_phys.gym)."""

        kind = original.kind
        inputs = original.inputs
        outputs = original.outputs
        params = original.params
        template_name = "agent"

        def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
            """The paper's doStep, answered by the agent."""
            return exchange(t, inp)

    return Agent


class Episode:
    """The scenario running with the agent in place of the Leaf ``path``.

    After construction (and after each :meth:`step`) the run is paused at the agent's next
    instant: :attr:`t` is its time and :attr:`inputs` what the component reads there; or
    the run has ended (:attr:`done`). A fault in the run is raised by the call that meets it.
    """

    def __init__(
        self,
        scenario: Scenario,
        path: str,
        trace: Callable[[float, list[float]], None] | None = None,
    ) -> None:
        world = scenario.world
        leaf = world.leaves[path]
        agent = dataclasses.replace(leaf, template=stand_in(leaf.template, self._exchange))
        world = dataclasses.replace(world, leaves={**world.leaves, path: agent})
        self.sim = Simulation.from_scenario(dataclasses.replace(scenario, world=world), trace=trace)
        self.end = self.sim.duration
        self.t = Fraction(0)
        self.inputs: dict[str, float] = {}
        self.done = False
        self._to_sim: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._to_agent: queue.SimpleQueue[tuple[str, Any, Any]] = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._main, name=f"amsa-phys {path}", daemon=True)
        self._thread.start()
        self._wait()

    # -- the worker thread ----------------------------------------------------------------
    def _main(self) -> None:
        try:
            self.sim.run()
        except _Stop:
            return
        except BaseException as exc:  # handed to the agent's thread, raised there
            self._to_agent.put(("error", exc, None))
            return
        self._to_agent.put(("done", None, None))

    def _exchange(self, t: Fraction, inp: Mapping[str, float]) -> Mapping[str, float]:
        if t >= self.end:
            return {}  # the episode ended: publish nothing, keep the last action
        self._to_agent.put(("ask", t, dict(inp)))
        answer = self._to_sim.get()
        if answer is _STOP:
            raise _Stop
        return answer  # type: ignore[no-any-return]

    # -- the agent's thread ---------------------------------------------------------------
    def _wait(self) -> None:
        kind, a, b = self._to_agent.get()
        if kind == "ask":
            self.t, self.inputs = a, b
        elif kind == "done":
            self.done = True
            self.t = self.end
        else:
            self.done = True
            raise a

    def step(self, outputs: Mapping[str, float]) -> None:
        """Publish ``outputs`` as the component's, run to the agent's next instant (or end)."""
        if self.done:
            raise RuntimeError("the episode has ended")
        self._to_sim.put(dict(outputs))
        self._wait()

    def close(self) -> None:
        """Stop the worker (it leaves at the instant it is paused at)."""
        if self._thread.is_alive():
            if not self.done:
                self._to_sim.put(_STOP)
            self._thread.join(JOIN_TIMEOUT_S)
        self.done = True
