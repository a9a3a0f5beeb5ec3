"""A small vector env's episodes: each env a single env, stepped in turn, no batch at all.

Why: a batched simulation (``gym/vecepisode.py``) pays a fixed price per vector step, the
numpy calls of every component group whatever the number of runs (~0.35 ms on 2 shared
cores), against ~50 µs an env-step for the single env on the compiled few-rover step. Below
:data:`SINGLES_BELOW` envs the batch would be slower than Gymnasium's own ``SyncVectorEnv``
over the single env; the vector env then holds that many :class:`FollowEnv` and steps them
one after the other, gathering their results into arrays (what ``SyncVectorEnv`` does,
without its per-env bookkeeping of infos and copies). Each sub-env *is* the single env, so
its episode is the single env's by construction, contacts included.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any

import numpy as np

from .follow import FollowEnv

#: Fewer envs than this step as single envs; this many or more as one batch. Measured on
#: 2 shared cores (random actions, CPU time, both paths in the same sitting, medians of 3,
#: load ~10): batch / single envs 0.80 at 5 envs, 0.93 at 6, 1.06 at 7, 1.15 at 8
#: (``FollowVecEnv(n, stepping=...)`` timed as ``benchmarks/bench_speed.py`` times it; the
#: batch's compiled GPS and compass bodies moved it down from 8). A faster single env
#: moves the crossing up, a cheaper batch step down: re-measure both paths before changing
#: it.
SINGLES_BELOW = 7


class Singles:
    """``envs`` (made with the vector env's arguments) as the episodes of one vector step.

    After :meth:`start` and each :meth:`step` every env is paused at the agent's next
    instant, or all have ended (:attr:`done`: one duration for all). A fault in one env's
    step ends them all (as a batch's fault does): the vector env then needs a reset.
    """

    def __init__(self, envs: Sequence[FollowEnv]) -> None:
        self.envs = list(envs)
        self.n = len(self.envs)
        self.done = False
        #: whether a Ctrl-C ended the episodes (the next step says so, not "a run faulted")
        self.interrupted = False
        self._thread = threading.get_ident()
        #: no column physics, and no run ever goes alone (each already is)
        self.columns = None
        self.solo: set[int] = set()

    def start(self, seeds: Sequence[int]) -> tuple[np.ndarray, dict[str, Any]]:
        """New episodes, env ``i`` with scenario seed ``seeds[i]``: first observations and
        the vector env's info (``t``, ``signal``, ``collisions``, ``seed``)."""
        self.done = False
        self.interrupted = False
        self._thread = threading.get_ident()
        try:
            results = [env.reset(seed=int(s)) for env, s in zip(self.envs, seeds, strict=True)]
        except BaseException:
            self.done = True
            raise
        obs = np.stack([o for o, _ in results])
        return obs, self._gather([i for _, i in results])

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
        """Step env ``i`` with ``actions[i]`` (unscaled, as the single env takes it):
        observations, rewards and the vector env's info."""
        if self.done:
            raise RuntimeError("the episode has ended")
        if threading.get_ident() != self._thread:  # refused before any env steps
            raise RuntimeError(
                "step() must be called from the thread that called reset() (the envs' "
                "episodes belong to it)"
            )
        n = self.n
        obs: np.ndarray | None = None
        rewards, t, signal = np.empty(n), np.empty(n), np.empty(n)
        collisions = np.empty(n, dtype=np.int64)
        try:
            for i, (env, a) in enumerate(zip(self.envs, actions, strict=True)):
                o, r, _, truncated, info = env.step(a)
                if obs is None:  # fresh arrays each step: the caller may keep the last ones
                    obs = np.empty((n, len(o)))
                obs[i] = o
                rewards[i] = r
                t[i] = info["t"]
                signal[i] = info["signal"]
                collisions[i] = info["collisions"]
        except BaseException as exc:
            self.done = True
            self.interrupted = isinstance(exc, KeyboardInterrupt)
            raise
        self.done = truncated
        assert obs is not None
        return obs, rewards, {"t": t, "signal": signal, "collisions": collisions}

    @staticmethod
    def _gather(infos: Sequence[dict[str, Any]]) -> dict[str, Any]:
        """The envs' infos as the vector env's: one array per key."""
        out = {
            "t": np.array([i["t"] for i in infos], dtype=np.float64),
            "signal": np.array([i["signal"] for i in infos], dtype=np.float64),
            "collisions": np.array([i["collisions"] for i in infos], dtype=np.int64),
        }
        if "seed" in infos[0]:
            out["seed"] = np.array([i["seed"] for i in infos])
        return out

    def close(self) -> None:
        """End every env's episode (safe to call twice)."""
        self.done = True
        for env in self.envs:
            env.close()
