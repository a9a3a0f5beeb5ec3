"""N episodes of one scenario as the runs of one batched simulation (``engine/multirun.py``).

The agent replaces the same component in every run. The runs' copies of it form one batch
group, so the engine calls the stand-in's ``step_many`` once per instant with every run's
inputs as arrays: one handoff between the worker thread and the agent per *vector* step
(not one per run), at the exact place in the instant where the component would run
(``gym/episode.py`` explains the thread). Each run keeps its own seed tree, parameters,
events and physics world (``MultiRun``), so run ``i`` is the episode a single env with the
same seed gives (``tests/e2e/test_gym_vector.py``).

Only the agent is grouped. Column physics (``physics/columns.py``) is not used: it leaves
contacts to the run made alone, which an episode cannot do; each run steps its own pymunk
Space, and the other components step one by one, so each run's arithmetic is exactly a
single run's (the grouped numpy paths may round differently, ``engine/multirun.py``).
"""

from __future__ import annotations

import dataclasses
import queue
import threading
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from ..engine.multirun import MultiRun
from ..model.scenario import Scenario
from ..model.template import Template
from .episode import JOIN_TIMEOUT_S, _Stop

_STOP = object()

ExchangeMany = Callable[[Fraction, Mapping[str, np.ndarray], Sequence[Any]], Mapping[str, Any]]


def stand_in_many(original: type[Template], exchange: ExchangeMany) -> type[Template]:
    """A template with ``original``'s declaration, stepped as a group by the agent."""

    class Agents(Template):
        """The agent, in place of a component in every run of a batch (amsa_phys.gym)."""

        kind = original.kind
        inputs = original.inputs
        outputs = original.outputs
        params = original.params
        template_name = "agent"
        batchable = True

        def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
            """Never called: a batch steps every copy through ``step_many``."""
            raise RuntimeError("the vector env's agent is stepped as a group")

        @classmethod
        def step_many(
            cls, comps: Sequence[Any], t: Fraction, inputs: Mapping[str, Any], p: Any, state: Any
        ) -> tuple[Mapping[str, Any], Any]:
            return exchange(t, inputs, comps)

    return Agents


def _holds_physics(comp: Any) -> bool:
    """Whether ``comp`` holds its run's physics world (a robot: its ``step_many`` would
    command every run's rovers through the first one's world)."""
    return getattr(comp, "physics", None) is not None


class VecEpisode:
    """``len(seeds)`` runs of ``scenario`` with the agent in place of the Leaf ``path``.

    After construction and each :meth:`step` the batch is paused at the agent's next
    instant (:attr:`t`, :attr:`inputs`: one row per run, in the template's port order of
    ``observed``) or has ended (:attr:`done`).
    """

    def __init__(
        self, scenario: Scenario, path: str, seeds: Sequence[int], observed: Sequence[str]
    ) -> None:
        world = scenario.world
        leaf = world.leaves[path]
        agent = dataclasses.replace(leaf, template=stand_in_many(leaf.template, self._exchange))
        world = dataclasses.replace(world, leaves={**world.leaves, path: agent})
        scenarios = [dataclasses.replace(scenario, world=world, seed=int(s)) for s in seeds]
        # the runs' robots live in separate Spaces (contacts are each run's own): a component
        # that holds its run's physics world steps one by one; the others step as groups
        # over the store's columns, with each run's own streams and arithmetic
        self.sim = MultiRun(scenarios, ungrouped=_holds_physics)
        #: each run's agent (by identity) -> its run
        self._run_of = {id(m[path]): r for r, m in enumerate(self.sim.members)}
        self.n = len(scenarios)
        self.path = path
        self.observed = list(observed)
        self.end = self.sim.duration
        self.t = Fraction(0)
        self.inputs = np.zeros((self.n, len(self.observed)))
        self.done = False
        self._outputs: list[str] = []
        self._to_sim: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._to_agent: queue.SimpleQueue[tuple[str, Any, Any]] = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._main, name=f"amsa-phys vec {path}")
        self._thread.daemon = True
        self._thread.start()
        self._wait()

    def _main(self) -> None:
        try:
            self.sim.run()
        except _Stop:
            return
        except BaseException as exc:
            self._to_agent.put(("error", exc, None))
            return
        self._to_agent.put(("done", None, None))

    def _exchange(
        self, t: Fraction, inputs: Mapping[str, Any], comps: Sequence[Any]
    ) -> tuple[Mapping[str, Any], Any]:
        runs = [self._run_of[id(c)] for c in comps]
        order = np.argsort(runs)  # the group's member order -> run order
        back = np.empty_like(order)
        back[order] = np.arange(len(order))
        if t >= self.end:  # the episode ended: publish nothing, keep the last action
            zeros = {name: np.zeros(len(runs)) for name in self._outputs}
            return zeros, np.zeros(len(runs), dtype=bool)
        rows = np.column_stack([np.asarray(inputs[p], dtype=np.float64) for p in self.observed])
        self._to_agent.put(("ask", t, rows[order]))
        answer = self._to_sim.get()
        if answer is _STOP:
            raise _Stop
        return {name: col[back] for name, col in answer.items()}, None

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

    def step(self, outputs: Mapping[str, np.ndarray]) -> None:
        """Publish one row of ``outputs`` per run; run to the agent's next instant (or end)."""
        if self.done:
            raise RuntimeError("the episode has ended")
        self._outputs = list(outputs)
        self._to_sim.put(dict(outputs))
        self._wait()

    def final_inputs(self) -> np.ndarray:
        """What every run's component reads at the end (the last observation)."""
        inputs = self.sim.world.leaves[self.path].inputs
        return np.column_stack([self.sim.column(inputs[p]) for p in self.observed])

    def signals(self, signal: str) -> np.ndarray:
        """The quality signal of every run now (its column in the store)."""
        return self.sim.column(signal)

    def collisions(self) -> np.ndarray:
        """Collisions so far, per run."""
        return np.array(
            [sum(1 for e in run.events if e.kind == "collision") for run in self.sim.runs]
        )

    def close(self) -> None:
        """Stop the worker (safe to call twice)."""
        if self._thread.is_alive():
            if not self.done:
                self._to_sim.put(_STOP)
            self._thread.join(JOIN_TIMEOUT_S)
        self.done = True
