"""``amsa_phys/Follow-v0``'s vector entry point: N agents in N runs of one scenario, in one process.

A ``gymnasium.vector.VectorEnv`` over one batched simulation on columns
(``gym/vecepisode.py``): every sub-environment is the episode
:class:`~amsa_phys.gym.follow.FollowEnv` gives with the same seed and actions (same
observation, reward, end, contacts included), but the N runs are stepped together — their
components as groups, their rovers as columns, one stack switch per vector step. Gymnasium
1.x's ``NEXT_STEP`` autoreset: all sub-environments reach the scenario's duration at the same
step (one duration for all); the ``step`` after that starts new episodes (seeds drawn from
the env's generator) and returns their first observations with reward 0 and
``terminated = truncated = False``, ignoring the action. Like the single env, it belongs to
the thread that calls ``reset``.

Below :data:`~amsa_phys.gym.vecsingles.SINGLES_BELOW` envs a batch's fixed cost per step
is more than the runs' own work: the envs are then single envs stepped in turn
(``gym/vecsingles.py``: each a :class:`FollowEnv`), the same episodes bit for bit.
``stepping="batch"`` or ``"single"`` chooses either path whatever the size.

``threads=N`` splits the batch's physics step (every rover's forces and integration, most of
its time from a few hundred envs up) between N threads, in chunks of at least 64 rovers: the
same episodes bit for bit, in less wall time on two free cores (the manual's Speed table).
The step times itself with and without the helpers and keeps the faster way for a while, so
on cores busy with other processes it goes on at about one thread's speed. One thread is
the default: a vector env is often one of several processes sharing the cores. The single
stepping runs in one thread.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from ..errors import ConfigError
from . import args
from .dropguard import DropGuard
from .follow import FollowEnv
from .vecepisode import VecEpisode
from .vecsingles import SINGLES_BELOW, Singles

#: the ``stepping`` argument's values
STEPPINGS = ("auto", "batch", "single")
#: the most threads the batch's physics step takes (``physics/workers.h``)
MAX_THREADS = 64

#: memory one sub-environment holds per component of its world: 1,000 envs of the default
#: scenario (8 components) took the process from 56 to 212 MB by their first steps
ENV_BYTES_PER_COMPONENT = 20_000
#: the most memory one vector env may plan to hold; beyond it, refused before building
#: anything (100,000 envs reached 13 GB and were still being built after 4 minutes)
MAX_ENV_BYTES = 2 << 30


def check_size(num_envs: int, components: int) -> None:
    """Refuse ``num_envs`` whose runs would not fit :data:`MAX_ENV_BYTES`, saying the memory
    they would need and how many fit."""
    per_env = ENV_BYTES_PER_COMPONENT * max(1, components)
    if num_envs * per_env <= MAX_ENV_BYTES:
        return
    fit = MAX_ENV_BYTES // per_env
    raise ConfigError(
        f"{num_envs:,} envs would need about {num_envs * per_env / 1e9:.1f} GB "
        f"({per_env / 1e6:.2f} MB an env of {components} components); at most {fit:,} fit "
        f"the {MAX_ENV_BYTES >> 30} GiB one vector env may hold: split them over processes",
        key="num_envs",
    )


def masked(info: dict[str, Any], n: int) -> dict[str, Any]:
    """``info`` with Gymnasium's mask beside each key (``_t``, ``_signal``, ...: which envs
    the key's values are for), as ``SyncVectorEnv`` gives them; every env reports every key
    at every step, so each mask is all True. Why: code written against one vectorization
    mode indexes ``info["_t"]``, and should not break in the other."""
    for key in list(info):
        info["_" + key] = np.ones(n, dtype=bool)
    return info


class FollowVecEnv(gymnasium.vector.VectorEnv):
    """``num_envs`` FollowEnv episodes stepped as one batch (arguments as FollowEnv's), or,
    below :data:`SINGLES_BELOW` envs or with ``stepping="single"``, as single envs in turn.

    ``threads`` (1 to :data:`MAX_THREADS`, default 1) splits the batch's physics step between
    that many threads, the same episodes bit for bit; a batch of fewer than 128 rovers (64
    envs of two) steps its physics on the calling thread alone (the module's docstring says
    more)."""

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}  # noqa: RUF012

    def __init__(
        self,
        num_envs: int = 1,
        scenario: Any = None,
        *,
        stepping: str = "auto",
        threads: int = 1,
        **kwargs: Any,
    ) -> None:
        if not isinstance(num_envs, int) or isinstance(num_envs, bool) or num_envs < 1:
            raise ConfigError(
                f"num_envs must be a whole number >= 1, got {num_envs!r}", key="num_envs"
            )
        if stepping not in STEPPINGS:
            raise ConfigError(
                f"stepping must be one of {', '.join(STEPPINGS)}, got {stepping!r}",
                key="stepping",
            )
        if (
            not isinstance(threads, int)
            or isinstance(threads, bool)
            or not 1 <= threads <= MAX_THREADS
        ):
            raise ConfigError(
                f"threads must be a whole number from 1 to {MAX_THREADS}, got {threads!r}",
                key="threads",
            )
        #: threads of the batch's physics step (the single stepping runs in one)
        self.threads = threads
        #: how the episodes step: "batch" (one batched simulation) or "single" (each env a
        #: single env, in turn); "auto" chose by the number of envs (:data:`SINGLES_BELOW`)
        self.stepping = stepping
        if stepping == "auto":
            self.stepping = "single" if num_envs < SINGLES_BELOW else "batch"
        if kwargs.get("render_mode") is not None or kwargs.get("record_trace"):
            raise ConfigError(
                "the vector env neither renders nor records traces; use FollowEnv",
                key="render_mode" if kwargs.get("render_mode") is not None else "record_trace",
            )
        self.single = FollowEnv(scenario, **kwargs)  # validates every argument, once
        if self.single._scenario.adapt:
            raise ConfigError(
                "the vector env cannot run adapt: rules (each run would switch its "
                "parameters at its own instants); use FollowEnv, or gymnasium.make_vec(..., "
                'vectorization_mode="sync")',
                key="scenario",
            )
        check_size(num_envs, len(self.single._scenario.world.leaves))
        self.num_envs = num_envs
        self.single_observation_space = self.single.observation_space
        self.single_action_space = self.single.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.metadata = {**self.metadata, "render_fps": self.single.metadata["render_fps"]}
        self._episode: VecEpisode | None = None
        #: closes the batch in progress if this env is dropped without ``close()``
        self._guard = DropGuard(self)
        #: the single envs of ``stepping="single"`` (the first is :attr:`single`)
        self._singles: Singles | None = None
        if self.stepping == "single":
            more = [FollowEnv(scenario, **kwargs) for _ in range(num_envs - 1)]
            self._singles = Singles([self.single, *more])
        self._seen = np.zeros(num_envs, dtype=np.int64)
        self._autoreset = False

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """New episodes; ``seed`` an int (env ``i`` gets ``seed + i``) or one seed each."""
        if options:
            raise ConfigError("the vector env takes no reset options", key="options")
        one_each = isinstance(seed, np.ndarray) and seed.ndim == 1  # SyncVectorEnv takes it
        if isinstance(seed, list | tuple) or one_each:
            if len(seed) != self.num_envs:
                raise ConfigError(f"expected {self.num_envs} seeds, got {len(seed)}", key="seed")
            seeds = [args.seed(s) for s in seed]
            super().reset(seed=seeds[0])
        else:
            base = args.seed(seed)
            seeds = args.seeds_from(base, self.num_envs)
            super().reset(seed=base)
        obs, info = self._start(seeds)
        return obs, masked(info, self.num_envs)

    def _start(self, seeds: list[int | None]) -> tuple[np.ndarray, dict[str, Any]]:
        drawn = [s if s is not None else int(self.np_random.integers(0, 2**31 - 1)) for s in seeds]
        self.close_extras()
        single = self.single
        self._autoreset = False
        if self._singles is not None:
            self._episode = self._singles  # type: ignore[assignment]
            return self._singles.start(drawn)
        from ..engine import publish
        from ..runs.batched import built_uncollected, fewer_collections  # imported lazily

        # a batch's build makes thousands of objects an env (built with the collector off:
        # they live as long as the episode), and asks ~18 times an env whether the compiled
        # publishing is on (the environment read once instead)
        with fewer_collections(), publish.pinned(), built_uncollected():
            self._episode = VecEpisode(
                single._scenario,
                single.path,
                drawn,
                single.observed,
                single.acted,
                threads=self.threads,
            )
            self._guard.hold(self._episode)
        self._seen = np.zeros(self.num_envs, dtype=np.int64)
        self._autoreset = False
        info = self._info()
        info["seed"] = np.array(drawn)
        return self._observations(), info

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One period of the replaced component in every run (NEXT_STEP autoreset)."""
        if self._episode is None:
            raise gymnasium.error.ResetNeeded("call reset() before step()")
        n = self.num_envs
        if self._autoreset:  # the previous step ended every episode: start new ones
            obs, info = self._start([None] * n)
            zeros = np.zeros(n, dtype=bool)
            return obs, np.zeros(n), zeros, zeros.copy(), masked(info, n)
        if self._episode.done:  # a fault in a run, or a Ctrl-C, ended the batch (step raised it)
            why = (
                "a step was interrupted"
                if getattr(self._episode, "interrupted", False)
                else ("a run faulted")
            )
            raise gymnasium.error.ResetNeeded(f"call reset() before step(): {why}")
        a = np.asarray(actions, dtype=np.float64)
        acted = self.single.acted
        if a.shape != (n, len(acted)) and a.shape != (n * len(acted),):
            # said as the single env says it, not as numpy's reshape would
            raise ValueError(f"expected actions of shape ({n}, {len(acted)}), got {a.shape}")
        a = a.reshape(n, len(acted))
        if self._singles is not None:
            obs, reward, info = self._singles.step(a)
            done = self._singles.done
            self._autoreset = done
            return obs, reward, np.zeros(n, dtype=bool), np.full(n, done), masked(info, n)
        scale = self.single.action_scale
        episode = self._episode
        episode.step(a * scale)
        q = self.single.quality
        signal = episode.signals(q.signal)  # read once: the reward's and the info's
        reward = -np.abs(signal - q.reference) / q.tolerance
        penalty = self.single.collision_penalty
        if episode.columns is not None and not episode.alone:
            # on columns no run collides before it goes alone: no new collisions, and the
            # penalty (finite, >= 0: ``args.py``) times 0 is +0.0, whose subtraction changes
            # no bit (the + 0.0 makes a -0.0 reward +0.0 either way)
            reward = reward + 0.0
        else:
            collisions = episode.collisions()
            new = collisions - self._seen
            self._seen = collisions
            reward = reward - penalty * new + 0.0
        # np.zeros and np.ones: C calls, where np.full is Python around them
        truncated = np.ones(n, dtype=bool) if episode.done else np.zeros(n, dtype=bool)
        self._autoreset = episode.done
        info = masked(self._info(signal.copy()), n)
        return self._observations(), reward, np.zeros(n, dtype=bool), truncated, info

    def _observations(self) -> np.ndarray:
        episode = self._episode
        assert episode is not None
        return self.single.observer.of_rows(episode.observed_rows())

    def _info(self, signal: np.ndarray | None = None) -> dict[str, Any]:
        episode = self._episode
        assert episode is not None
        if signal is None:
            signal = episode.signals(self.single.quality.signal)
        t = np.empty(self.num_envs)
        t.fill(float(episode.t))  # np.full's values, without its Python
        return {
            "t": t,
            "signal": signal,
            "collisions": self._seen.copy(),
        }

    def close_extras(self, **kwargs: Any) -> None:
        """Stop the episodes in progress (the batch's greenlet, or the single envs'). The env
        then holds none: a step before the next reset says to reset (it said a run had
        faulted)."""
        if self._episode is not None:
            self._episode.close()
        self._episode = None
        self._guard.hold(None)
