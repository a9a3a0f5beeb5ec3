"""``amsa_phys/Follow-v0``: an agent in place of a scenario's controller.

The agent *is* the component: its observation is what the component reads (its connected
inputs, in the template's port order), its action is what it publishes, and it acts at the
component's own frequency, where the component would run in each instant; the engine runs
everything in between (``gym/episode.py``). Reward per step, from the scenario's quality
signal ``s`` (reference ``r``, tolerance ``tol``) at the agent's next instant::

    reward = -|s - r| / tol - collision_penalty * (new collisions during the step)

so a step inside the tolerance band costs at most 1 and a perfect follower earns 0.
"""

from __future__ import annotations

import dataclasses
import operator
import os
from collections.abc import Mapping, Sequence
from fractions import Fraction
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.utils import EzPickle

from ..api.memory import check_trace_memory
from ..api.source import Source, load
from ..engine import publish
from ..engine.tracemem import TraceMemory
from ..errors import ConfigError
from ..model.scenario import Scenario
from ..model.suggest import did_you_mean
from ..model.template import Kind
from . import args
from .dropguard import DropGuard
from .episode import Episode
from .observe import Observer

#: the usual action's dtype: ``is`` against it is a third of ``==`` (a byte-swapped float64
#: array fails it and takes the general path, converted as before)
_F64 = np.dtype(np.float64)

#: ``gymnasium.make("amsa_phys/Follow-v0")`` with no scenario: the paper's degraded context
DEFAULT_SCENARIO = Path(__file__).with_name("data") / "follow.yaml"


class FollowEnv(gymnasium.Env[np.ndarray, np.ndarray], EzPickle):
    """A scenario as a Gymnasium environment whose agent replaces one component.

    Args:
        scenario: a scenario file or mapping (as ``amsa_phys.run`` takes); default the
            packaged ``gym/data/follow.yaml`` (the paper's degraded context, 120 s).
        observation: ``"relative"`` (default: robot-relative, normalised to [-1, 1],
            ``gym/observe.py``) or ``"absolute"`` (the raw inputs, unbounded).
        controller: the Leaf the agent replaces (default: the scenario's only controller).
        actions: the outputs the agent sets (default: those another component reads).
        action_scale: an action ``a`` in [-1, 1] publishes ``a * action_scale`` (default 100:
            the MDE controllers' outputs are percent of power). Not clipped: the actuator
            downstream clamps, as it clamps the replaced controller.
        collision_penalty: subtracted from the reward per new collision.
        duration, set, log_rate, base_dir: as for ``amsa_phys.run`` (the CLI's options).
        render_mode: ``None``, ``"rgb_array"`` or ``"human"`` (a window, paced to
            ``render_fps``); render_size: (width, height) in pixels.
        record_trace: keep the episode's trace in memory (:meth:`trace`), as ``run`` does.

    Pickling (``EzPickle``) keeps the constructor's arguments and the registry's ``spec``,
    not the episode in progress: an unpickled environment is a fresh one, to ``reset()``
    before stepping.
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array", "human"], "render_fps": 4}  # noqa: RUF012

    def __init__(
        self,
        scenario: Source | None = None,
        *,
        observation: str = "relative",
        controller: str | None = None,
        actions: Sequence[str] | None = None,
        action_scale: float = 100.0,
        collision_penalty: float = 10.0,
        duration: float | Fraction | None = None,
        set: Mapping[str, Any] | None = None,  # the CLI's --set, by its name
        log_rate: float | None = None,
        base_dir: str | os.PathLike[str] | None = None,
        render_mode: str | None = None,
        render_size: tuple[int, int] = (640, 360),
        record_trace: bool = False,
        threads: int | None = None,
    ) -> None:
        if threads is not None:  # the vector env's, not ours: said, not a bare TypeError
            raise ConfigError(
                "threads is the vector env's argument (gymnasium.make_vec(..., "
                'vectorization_mode="vector_entry_point", threads=N)); a single env, and '
                "each env of a sync vector env, runs in the thread that steps it",
                key="threads",
            )
        EzPickle.__init__(
            self,
            scenario,
            observation=observation,
            controller=controller,
            actions=actions,
            action_scale=action_scale,
            collision_penalty=collision_penalty,
            duration=duration,
            set=set,
            log_rate=log_rate,
            base_dir=base_dir,
            render_mode=render_mode,
            render_size=render_size,
            record_trace=record_trace,
        )
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ConfigError(
                f"unknown render mode {render_mode!r}; amsa_phys/Follow-v0 renders "
                "'rgb_array' or 'human'",
                key="render_mode",
            )
        if scenario is None:
            scenario = DEFAULT_SCENARIO
        controller = args.component(controller)
        actions = args.names(actions, "actions")
        size = args.render_size(render_size)
        record_trace = args.flag(record_trace, "record_trace")
        self.action_scale = args.finite_number(action_scale, "action_scale", positive=True)
        self.collision_penalty = args.finite_number(
            collision_penalty, "collision_penalty", positive=False
        )
        self._source = scenario
        self._options = {"duration": duration, "set": set, "log_rate": log_rate}
        self._base_dir = base_dir
        self._scenario = self._load({})
        world = self._scenario.world
        if self._scenario.quality is None:
            raise ConfigError(
                "the scenario has no quality: section; the reward is computed from it",
                key="scenario",
            )
        self.quality = self._scenario.quality
        #: the reward's terms, looked up once (step reads them every period)
        self._signal = self.quality.signal
        self._reference = self.quality.reference
        self._tolerance = self.quality.tolerance
        self.path = controller if controller is not None else _default_controller(self._scenario)
        if self.path not in world.leaves:
            hint = did_you_mean(self.path, world.leaves)
            if not hint:  # nothing close: the ones an agent usually replaces
                kinds = [p for p, lf in world.leaves.items() if lf.kind is Kind.CONTROLLER]
                shown = ", ".join(kinds[:5]) + (", ..." if len(kinds) > 5 else "")
                hint = f" (the world's controllers: {shown})" if kinds else ""
            raise ConfigError(f"unknown component {self.path!r}{hint}", key="controller")
        leaf = world.leaves[self.path]
        ports = [p for p in leaf.template.inputs if p.name in leaf.inputs]
        arrays = [p.name for p in ports if p.array]
        if arrays:  # an observation is a flat vector of the inputs' numbers, one each
            raise ConfigError(
                f"{self.path} reads the array input {arrays[0]!r} (a lidar's ranges): the "
                "agent observes one number per input; replace a component that reads numbers",
                key="controller",
            )
        self.observed = [p.name for p in ports]
        if not self.observed:
            raise ConfigError(
                f"{self.path} reads no input: the agent would observe nothing", key="controller"
            )
        outputs = [p.name for p in leaf.template.outputs]
        self.acted = list(actions) if actions is not None else _read_outputs(world, self.path)
        for name in self.acted:
            if name not in outputs:
                raise ConfigError(
                    f"{self.path} has no output {name!r}" + did_you_mean(name, outputs),
                    key="actions",
                )
        if not self.acted:
            raise ConfigError(f"{self.path} has no output to act on", key="actions")
        self.period = 1 / leaf.freq
        self.metadata = {**self.metadata, "render_fps": float(leaf.freq)}
        self.observer = Observer(ports, observation)
        self.observation_space = spaces.Box(self.observer.low, self.observer.high, dtype=np.float64)
        self.action_space = spaces.Box(-1.0, 1.0, (len(self.acted),), np.float64)
        self._action_shape = (len(self.acted),)
        #: the two outputs of the usual controller (left and right power), published as a
        #: dict display: a comprehension over zip cost ~0.4 us a step
        self._pair = tuple(self.acted) if len(self.acted) == 2 else None
        #: the inputs in port order as one C call (a tuple; a 1-tuple for one input)
        self._pick = (
            operator.itemgetter(*self.observed)
            if len(self.observed) > 1
            else lambda inp, name=self.observed[0]: (inp[name],)
        )
        self.render_mode = render_mode
        self.render_size = size
        self.record_trace = record_trace
        self._episode: Episode | None = None
        #: closes the episode in progress if this env is dropped without ``close()``
        self._guard = DropGuard(self)
        self._memory: TraceMemory | None = None
        self._frames: Any = None
        self._collisions = 0
        self._seen_events = 0
        self._data: Any = None  # the episode's store (``step`` reads the signal there)
        self._signal_at = 0

    # -- Gymnasium API ---------------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode: the scenario from t = 0 with scenario seed ``seed``.

        Without ``seed`` the scenario seed is drawn from the environment's generator (seeded
        by the last ``reset(seed=...)``). ``options={"set": {"Comp.param": v}}`` changes
        parameters at t = 0 for this episode (on top of the constructor's ``set``).
        """
        seed = args.seed(seed)
        extra = args.reset_set(options)
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(0, 2**31 - 1))
        scenario = self._scenario
        if extra:
            scenario = self._load(extra)
        scenario = dataclasses.replace(scenario, seed=episode_seed)
        if self.record_trace:  # warn above 1 GB, refuse above the machine's memory
            check_trace_memory(scenario, list(scenario.world.buffers))
        # The garbage collector kept out of a reset (a few per cent of the CPU): the new
        # episode is built with the youngest generation collected less often (the vector
        # env's batches do the same), and the episode ending is closed (``Episode.close``
        # frees it by reference counting) only once the new one is built, so the collector's
        # count of new objects ends where it began. No collection then moves the new
        # episode's objects to an older generation, whose growth is what sets off the full
        # collections that walk every object of the process.
        from ..runs.batched import fewer_collections  # the sweep's module, imported lazily

        ended, self._episode = self._episode, None
        self._close_frames()
        # the pure path's switch read once for the whole build, not at each of its ~30 asks
        with fewer_collections(), publish.pinned():
            try:
                memory = TraceMemory(list(scenario.world.buffers)) if self.record_trace else None
                self._memory = memory
                trace = memory.write if memory is not None else None
                # a picture samples the log (``view/scene.py``); the agent's step reads the store
                keep_log = self.render_mode is not None
                self._episode = Episode(scenario, self.path, trace, keep_log=keep_log)
                self._guard.hold(self._episode)
            finally:
                if ended is not None:
                    ended.close()
        sim = self._episode.sim
        self._data, self._signal_at = sim.data, sim.at(self._signal)
        self._collisions = 0
        self._seen_events = 0
        if self.render_mode == "rgb_array":
            from .render import FrameSource

            self._frames = FrameSource(self._episode.sim, self.quality, self.render_size)
        elif self.render_mode == "human":
            from .human import HumanView

            fps = float(self.metadata["render_fps"])
            self._frames = HumanView(self._episode.sim, self.quality, self.render_size, fps)
            self._frames.show([f"agent: {self.path}"])
        info = self._info()
        info["seed"] = episode_seed
        return self._observation(), info

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Publish ``action * action_scale`` as the component's outputs; run one period.

        The per-step path is lean on purpose (it was a third of an env-step): the
        usual action (a float64 array of the right shape) skips the conversion, the quality
        signal is read once for the reward and the info, and the observation is built from
        the inputs the episode already holds.
        """
        episode = self._episode
        if episode is None or episode.done:
            if episode is None:  # never reset (an unpickled env too): no episode has ended
                raise gymnasium.error.ResetNeeded("call reset() before step()")
            why = episode.ended_by or "the episode has ended"
            raise gymnasium.error.ResetNeeded(f"call reset() before step(): {why}")
        if (
            type(action) is np.ndarray
            and action.dtype is _F64
            and action.shape == self._action_shape
        ):
            values = action.tolist()
        else:
            a = np.asarray(action, dtype=np.float64).reshape(-1)
            if a.shape != self._action_shape:
                raise ValueError(f"expected an action of shape ({len(self.acted)},), got {a.shape}")
            values = a.tolist()
        scale = self.action_scale
        pair = self._pair
        if pair is not None:
            v0, v1 = values
            episode.step({pair[0]: v0 * scale, pair[1]: v1 * scale})
        else:  # the shape was checked: strict=False skips zip's own length check
            episode.step({name: v * scale for name, v in zip(self.acted, values, strict=False)})
        if self._frames is not None:
            self._frames.sample()
            if self.render_mode == "human":
                self._frames.show([f"agent: {self.path}"])
        sim = episode.sim
        new = 0
        if len(sim.events) > self._seen_events:
            events = sim.events
            new = sum(1 for e in events[self._seen_events :] if e.kind == "collision")
            self._seen_events = len(events)
            self._collisions += new
        signal = self._data[self._signal_at]  # sim.read(signal), its position looked up once
        reward = -abs(signal - self._reference) / self._tolerance
        reward -= self.collision_penalty * new
        reward += 0.0  # -0.0 (no error at all) reads as 0.0
        done = episode.done
        if done and self._memory is not None:
            self._memory.close()
        t = episode.t  # float(t), without Fraction.__float__'s calls (``episode._exchange``)
        info = {
            "t": t._numerator / t._denominator,
            "signal": signal,
            "collisions": self._collisions,
        }
        if done:
            return self._observation(), reward, False, done, info
        inputs = episode.inputs  # ``_observation`` inlined: the usual step
        obs = self.observer.of_values(self._pick(inputs))
        return obs, reward, False, done, info

    def render(self) -> np.ndarray | None:  # type: ignore[override]
        """The current picture (``render_mode="rgb_array"``), ``(height, width, 3)`` uint8."""
        if self._frames is None or self._episode is None or self.render_mode != "rgb_array":
            return None  # "human" draws at every step (Gymnasium's convention)
        status = [f"agent: {self.path}"]
        return self._frames.draw(status)  # type: ignore[no-any-return]

    def close(self) -> None:
        """End the episode in progress and the window, if any (safe to call twice)."""
        if self._episode is not None:
            self._episode.close()
        self._guard.hold(None)
        self._close_frames()

    def _close_frames(self) -> None:
        if self._frames is not None and hasattr(self._frames, "close"):
            self._frames.close()
        self._frames = None

    def __getstate__(self) -> dict[str, Any]:
        """The constructor's arguments (``EzPickle``) and the registry's ``spec``."""
        return {**EzPickle.__getstate__(self), "spec": self.spec}

    def __setstate__(self, state: dict[str, Any]) -> None:
        """A fresh env from the arguments, keeping ``spec``: ``gymnasium.make`` set it on
        this instance, not in the arguments, and a worker's ``env.spec.id`` must still be
        ``amsa_phys/Follow-v0`` (plain attribute pickling, as CartPole's, keeps it too)."""
        spec = state.pop("spec", None)
        EzPickle.__setstate__(self, state)
        self.spec = spec

    # -- extras ----------------------------------------------------------------------------
    @property
    def t(self) -> float:
        """Simulated time of the agent's current instant (the duration once ended)."""
        return float(self._episode.t) if self._episode is not None else 0.0

    def trace(self) -> np.ndarray:
        """The episode's trace so far (``record_trace=True``), as ``amsa_phys.Run.trace``."""
        if self._memory is None:
            raise RuntimeError("make the environment with record_trace=True to keep the trace")
        return self._memory.structured()

    # -- helpers ---------------------------------------------------------------------------
    def _load(self, extra_set: Mapping[str, Any]) -> Scenario:
        opts = self._options
        return load(
            self._source,
            duration=opts["duration"],
            set=_merged(opts["set"], extra_set),
            log_rate=opts["log_rate"],
            base_dir=self._base_dir,
        )

    def _observation(self) -> np.ndarray:
        episode = self._episode
        assert episode is not None
        if episode.done:  # the end: what the component would read now
            leaf = episode.sim.world.leaves[self.path]
            values = episode.sim.read_many([leaf.inputs[p] for p in self.observed]).tolist()
        else:
            inputs = episode.inputs
            values = [inputs[p] for p in self.observed]
        return self.observer.of_values(values)

    def _info(self) -> dict[str, Any]:
        episode = self._episode
        assert episode is not None
        return {
            "t": float(episode.t),
            "signal": float(episode.sim.read(self.quality.signal)),
            "collisions": self._collisions,
        }


def _merged(given: Any, extra: Mapping[str, Any]) -> Any:
    """The constructor's ``set`` with a reset's on top (a wrong ``set`` is left for
    ``load`` to refuse, naming it ``--set`` as ``amsa_phys.run`` does)."""
    if given is None:
        return dict(extra)
    return {**given, **extra} if isinstance(given, Mapping) else given


def _default_controller(scenario: Scenario) -> str:
    controllers = [p for p, leaf in scenario.world.leaves.items() if leaf.kind is Kind.CONTROLLER]
    if len(controllers) == 1:
        return controllers[0]
    if not controllers:
        raise ConfigError(
            "the world has no controller; name the component the agent replaces",
            key="controller",
        )
    shown = ", ".join(controllers[:5]) + (", ..." if len(controllers) > 5 else "")
    raise ConfigError(
        f"the world has {len(controllers)} controllers ({shown}); choose one", key="controller"
    )


def _read_outputs(world: Any, path: str) -> list[str]:
    """The outputs of ``path`` that another component reads, in port order."""
    read = {
        buf for other, leaf in world.leaves.items() if other != path for buf in leaf.inputs.values()
    }
    outputs = [p.name for p in world.leaves[path].template.outputs]
    return [name for name in outputs if f"{path}.{name}" in read]
