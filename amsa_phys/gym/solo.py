"""A run of the vector env continued alone: its single episode, replayed to where it is.

When a run of the batch comes within reach of a contact (``gym/veccolumns.py``), the
columns can no longer make it (contacts are each pymunk Space's own, and depend on the
Space's whole history: ``physics/columns.py``). The run is then made exactly as the single
env makes it: a :class:`~amsa_phys.gym.episode.Episode` of its scenario (its seed, its own
Space from t = 0) is stepped with the outputs the agent gave that run so far — recorded by
the vector env — up to the agent's current instant, and carries on from there, one step
per vector step. Up to the instant it was found within reach the run's rows in the batch
were its single run's, so the agent acted on exactly what this replay shows it, and the
replay arrives where the single env with the same seed and actions would be: contacts,
collisions and all, bit for bit.

The price is the replay, once per run and episode (~60 µs per past step on 2 shared
cores), and a single env's speed for the rest of that run's episode. Several runs going
alone at one instant are replayed together instead, as a batch of per-run Spaces
(``vecepisode.py``); this class is the one-run case, behind the same interface.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..model.scenario import Scenario
from .episode import Episode


class Solo:
    """Run ``row`` of a vector episode, made alone from t = 0 (see the module docstring),
    behind the interface of a :class:`~amsa_phys.gym.vecepisode.VecEpisode` of one run
    (rows in, rows out), so the vector env treats both alike."""

    def __init__(
        self,
        scenario: Scenario,
        path: str,
        observed: Sequence[str],
        acted: Sequence[str],
    ) -> None:
        self.observed = list(observed)
        self.acted = list(acted)
        self.episode = Episode(scenario, path)

    def step(self, outputs: np.ndarray) -> None:
        """Publish ``outputs[0]`` (the agent's outputs, ``acted`` order); run to the next
        instant."""
        self.episode.step(dict(zip(self.acted, outputs[0].tolist(), strict=True)))

    def observed_rows(self) -> np.ndarray:
        """What the component reads now (``observed`` order), at its instant or at the end,
        as one row."""
        episode = self.episode
        if episode.done:
            leaf = episode.sim.world.leaves[episode.path]
            values = episode.sim.read_many([leaf.inputs[p] for p in self.observed])
            return values.reshape(1, -1)  # type: ignore[no-any-return]
        inputs = episode.inputs
        return np.array([[inputs[p] for p in self.observed]], dtype=np.float64)

    def signals(self, name: str) -> np.ndarray:
        """The quality signal now, as one row."""
        return np.array([self.episode.sim.read(name)], dtype=np.float64)

    def collisions(self) -> np.ndarray:
        """Collisions of this run so far, as one row."""
        return np.array([sum(1 for e in self.episode.sim.events if e.kind == "collision")])

    def close(self) -> None:
        """Stop the episode (safe to call twice)."""
        self.episode.close()
