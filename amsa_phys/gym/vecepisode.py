"""N episodes of one scenario as the runs of one batched simulation over columns.

The runs are one :class:`~amsa_phys.engine.multirun.MultiRun` as a batched sweep makes
them: every component's copies in the N runs are one group stepped as arrays over the
store's columns (each run with its own seed tree, parameters and events), and the rovers
of all runs are columns too (``physics/columns.py``: every rover's forces and integration
in one C call, the physics steps between two instants with components in one call,
instead of N pymunk Spaces; numpy on the pure path). The agent
replaces the same component in every run: its copies form one group, so the batch pauses
once per *vector* step, at the exact place in the instant where the component would run,
with every run's inputs as one array (a greenlet, as the single env's ``gym/episode.py``).

Contacts are the one thing columns do not make. A run whose shapes come within reach of
each other is frozen in the columns (``gym/veccolumns.py``) and, at the agent's next
instant, continues alone: its own episode replayed from t = 0 with the agent's past outputs
to that instant (``gym/solo.py``) — a single episode, or, when several runs go alone at the
same instant, a batch of them with per-run Spaces (this class with ``columns=False``, at
most :data:`CHUNK` runs). So every run is the episode the single env gives with the same
seed and actions, contacts included; the tests compare them step for step.

Worlds whose runs a batched sweep cannot hold as columns (terrain zones, lidars, rovers
changed during the run: ``runs/batched.py``) run as that batch of per-run Spaces from the
start: every other component still steps as one group of all runs.
"""

from __future__ import annotations

import contextlib
import dataclasses
import sys
from collections.abc import Callable, Mapping, Sequence
from fractions import Fraction
from typing import Any

import greenlet
import numpy as np

from ..engine.clock import at_or_after
from ..engine.multirun import MultiRun
from ..model.scenario import Scenario
from ..model.template import Template
from ..templatemarks import StandIn
from .episode import STOP, EpisodeStop
from .solo import Solo
from .veccolumns import EpisodeColumns

#: Runs found within reach at the same instant go alone together, in batches of per-run
#: Spaces of at most this many (such a batch's speed peaks near 64 runs: measured 22,000
#: env-steps/s at 16, 34,000 at 64, 24,000 at 256, 6,200 at 1,000, where 1,000 Spaces no
#: longer fit in the CPU's caches) ...
CHUNK = 64
#: ... when there are at least this many; fewer go one by one as single episodes (a single
#: episode does ~15,000 env-steps/s, a batch of 4 per-run Spaces ~12,000)
TOGETHER_MIN = 4

ExchangeMany = Callable[[Fraction, Mapping[str, np.ndarray], Sequence[Any]], Any]


def stand_in_many(original: type[Template], exchange: ExchangeMany) -> type[Template]:
    """A template with ``original``'s declaration, stepped as a group by the agent."""

    class Agents(Template):
        """The agent, in place of a component in every run of a batch (amsa_phys.gym)."""

        kind = original.kind
        inputs = original.inputs
        outputs = original.outputs
        params = original.params
        template_name = "agent"
        #: its parameters act on nothing: the HUD does not list them as acting
        marks = (StandIn(),)
        batchable = True

        def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
            """Never called: a batch steps every copy through ``step_many``."""
            raise RuntimeError("the vector env's agent is stepped as a group")

        @classmethod
        def step_many(
            cls, comps: Sequence[Any], t: Fraction, inputs: Mapping[str, Any], p: Any, state: Any
        ) -> tuple[Mapping[str, Any], Any]:
            return exchange(t, inputs, comps)  # type: ignore[no-any-return]

    return Agents


def _why_not_columns(scenario: Scenario) -> str | None:
    """Why the runs of ``scenario`` cannot be columns: what a batched sweep cannot hold
    (terrain zones, lidars, rovers changed during the run, ...: ``runs/batched.py``)."""
    from ..runs.batched import unbatchable  # the sweep's rules; imports the pool lazily

    return unbatchable(scenario)


def _holds_physics(comp: Any) -> bool:
    """Whether ``comp`` holds its run's physics world (a robot: its ``step_many`` would
    command every run's rovers through the first one's world)."""
    return getattr(comp, "physics", None) is not None


class VecEpisode:
    """``len(seeds)`` runs of ``scenario`` with the agent in place of the Leaf ``path``.

    After construction and each :meth:`step` the batch is paused at the agent's next
    instant (:attr:`t`; :meth:`observed_rows`: one row per run, in the template's port order
    of ``observed``) or has ended (:attr:`done`). Like the single env's episode it belongs
    to the thread that made it.
    """

    def __init__(
        self,
        scenario: Scenario,
        path: str,
        seeds: Sequence[int],
        observed: Sequence[str],
        acted: Sequence[str],
        columns: bool = True,
        threads: int = 1,
    ) -> None:
        world = scenario.world
        leaf = world.leaves[path]
        agent = dataclasses.replace(leaf, template=stand_in_many(leaf.template, self._exchange))
        world = dataclasses.replace(world, leaves={**world.leaves, path: agent})
        #: each run's scenario, with the component itself (what a run made alone replaces)
        self.scenarios = [dataclasses.replace(scenario, seed=int(s)) for s in seeds]
        runs = [dataclasses.replace(sc, world=world) for sc in self.scenarios]
        #: why the runs cannot be columns (None: they are), ``runs/batched.py``'s reasons
        self.why_not_columns = _why_not_columns(runs[0]) if columns else "asked for Spaces"
        #: the runs' column physics, or None: each run steps its own Space
        self.columns = EpisodeColumns(threads) if self.why_not_columns is None else None
        # no log kept (as the single env's run, ``episode.py``): nothing here reads the
        # quality samples, and without them the physics steps between the components'
        # instants go in fewer, longer calls (the same steps: ``Simulation.batch_hook``)
        if self.columns is not None:
            self.sim = MultiRun(runs, columns=self.columns, keep_log=False)
        else:  # a robot's group step would command every run's rovers through one Space
            self.sim = MultiRun(runs, ungrouped=_holds_physics, keep_log=False)
        self.n = len(self.scenarios)
        self.path = path
        self.observed = list(observed)
        self.acted = list(acted)
        self._inputs = [leaf.inputs[p] for p in self.observed]
        self.end = self.sim.duration
        self._end_s = float(self.end)
        self.t = Fraction(0)
        self.done = False
        #: the episode was ended by a Ctrl-C inside a step (not by a run's fault)
        self.interrupted = False
        #: the runs made alone (within reach of a contact): their indices and what makes
        #: them (a :class:`Solo`, or a VecEpisode of per-run Spaces), in hand-off order
        self.alone: list[tuple[np.ndarray, Solo | VecEpisode]] = []
        #: the runs made alone, by run
        self.solo: set[int] = set()
        #: the outputs given at each agent instant so far, (n, len(acted)) each: what the
        #: runs made alone replay (kept only where runs can go alone: on columns)
        self.past: list[np.ndarray] = []
        self._rows = np.zeros((self.n, len(self.observed)))
        self._order: tuple[int, np.ndarray | None, np.ndarray | None] | None = None
        self._batch_rows = self._rows  # the inputs at the agent's instant (``_exchange``)
        self._agent = greenlet.getcurrent()
        self._run = greenlet.greenlet(self._main, parent=self._agent)
        self._answer(self._run.switch())

    # -- the batch's greenlet -------------------------------------------------------------
    def _main(self) -> tuple[str, Any, Any]:
        try:
            self.sim.run()
        except EpisodeStop:
            return ("stopped", None, None)
        return ("done", None, None)  # an exception goes to the parent: raised by switch()

    def _exchange(
        self, t: Fraction, inputs: Mapping[str, Any], comps: Sequence[Any]
    ) -> tuple[Mapping[str, Any], Any]:
        order, back = self._run_order(comps)
        if at_or_after(t, self.end, self._end_s):  # ended: publish nothing, keep the last action
            zeros = {name: np.zeros(len(comps)) for name in self.acted}
            return zeros, np.zeros(len(comps), dtype=bool)
        rows = self._rows
        for j, port in enumerate(self.observed):
            rows[:, j] = inputs[port]
        answer = self._agent.switch(("ask", t, rows if order is None else rows[order]))
        if answer is STOP:
            raise EpisodeStop
        if back is None:
            return answer, None
        return {name: col[back] for name, col in answer.items()}, None

    def _run_order(self, comps: Sequence[Any]) -> tuple[np.ndarray | None, np.ndarray | None]:
        """The group's member order -> run order (None, None: the same), computed once."""
        if self._order is None or self._order[0] != id(comps):
            run_of = {id(m[self.path]): r for r, m in enumerate(self.sim.members)}
            runs = np.array([run_of[id(c)] for c in comps])
            if (runs == np.arange(len(runs))).all():
                self._order = (id(comps), None, None)
            else:
                order = np.argsort(runs)
                back = np.empty_like(order)
                back[order] = np.arange(len(order))
                self._order = (id(comps), order, back)
        return self._order[1], self._order[2]

    # -- the agent's side -----------------------------------------------------------------
    def _answer(self, message: tuple[str, Any, Any]) -> None:
        kind, a, b = message
        if kind == "ask":
            self.t = a
            self._batch_rows = b
        else:
            self.done = True
            self.t = self.end

    def step(self, outputs: np.ndarray) -> None:
        """Publish one row of ``outputs`` (``(n, len(acted))``, ``acted`` order) per run; run
        every run to the agent's next instant (or the end)."""
        if self.done:
            raise RuntimeError("the episode has ended")
        outputs = np.array(outputs, dtype=np.float64)  # a copy: the replays keep it
        try:
            message = self._run.switch({name: outputs[:, j] for j, name in enumerate(self.acted)})
        except greenlet.error:  # greenlets switch only within their thread
            raise RuntimeError(
                "step() must be called from the thread that called reset()"
            ) from None
        except BaseException as exc:  # a run's fault (or Ctrl-C inside it) ends the episode
            self.done = True
            self.interrupted = isinstance(exc, KeyboardInterrupt)
            raise
        self._answer(message)
        if self.columns is None:
            return  # each run's own Space makes its contacts: no run goes alone
        self.past.append(outputs)
        try:
            for runs, member in self.alone:
                member.step(outputs[runs])
            self._hand_off()
        except BaseException as exc:
            self.done = True
            self.interrupted = isinstance(exc, KeyboardInterrupt)
            raise

    def _hand_off(self) -> None:
        """Continue alone every run newly found within reach (``gym/solo.py``): one or a
        few as single episodes, more as batches of per-run Spaces (:data:`CHUNK` at most),
        each replayed with the agent's past outputs to this instant."""
        assert self.columns is not None
        if self.columns.touched_count() == len(self.solo):
            return  # no run newly within reach (the touched only grow; solo are touched)
        new = sorted(self.columns.touched.difference(self.solo))
        if not new:
            return
        self.solo.update(new)
        if len(new) < TOGETHER_MIN:
            groups = [[run] for run in new]
        else:
            groups = [new[k : k + CHUNK] for k in range(0, len(new), CHUNK)]
        for group in groups:
            runs = np.array(group, dtype=np.intp)
            member: Solo | VecEpisode
            if len(group) == 1:
                member = Solo(self.scenarios[group[0]], self.path, self.observed, self.acted)
            else:
                seeds = [self.scenarios[r].seed for r in group]
                member = VecEpisode(
                    self.scenarios[0], self.path, seeds, self.observed, self.acted, columns=False
                )
            self.alone.append((runs, member))
            for past in self.past:
                member.step(past[runs])

    def observed_rows(self) -> np.ndarray:
        """What every run's component reads now, ``(n, len(observed))``: at the agent's
        instant, or at the end (the last observation)."""
        if self.done:
            rows = np.column_stack([self.sim.column(b) for b in self._inputs])
        else:
            rows = self._batch_rows.copy()
        for runs, member in self.alone:
            rows[runs] = member.observed_rows()
        return rows

    def signals(self, signal: str) -> np.ndarray:
        """The quality signal of every run now."""
        values = self.sim.column(signal).copy()
        for runs, member in self.alone:
            values[runs] = member.signals(signal)
        return values

    def collisions(self) -> np.ndarray:
        """Collisions so far, per run. On columns only a run made alone can have any (the
        columns make no contacts, and a run within reach goes alone before it can touch);
        on per-run Spaces each run's events count them."""
        if self.columns is None:
            return np.array(
                [sum(1 for e in run.events if e.kind == "collision") for run in self.sim.runs]
            )
        counts = np.zeros(self.n, dtype=np.int64)
        for runs, member in self.alone:
            counts[runs] = member.collisions()
        return counts

    def close(self) -> None:
        """Stop the batch and the runs made alone (safe to call twice). From another thread
        or at interpreter shutdown the paused batch is dropped as it is (``episode.py``)."""
        for _, member in self.alone:
            member.close()
        run = self._run
        self.done = True
        if not run.dead:
            if greenlet.getcurrent() is not self._agent or sys.is_finalizing():
                return
            with contextlib.suppress(EpisodeStop, greenlet.error):
                run.switch(STOP)
        if run.dead:  # ended: freed at once by reference counting (``MultiRun.release``)
            self.sim.release()
