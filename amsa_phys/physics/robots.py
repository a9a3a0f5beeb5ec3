"""The robot templates' common base and ``controlledRobot``, the rover driven by Data.

``controlledRobot`` (the Follower, kind *process*) takes its wheel powers from Data and
publishes its true pose; :class:`Robot` is what it shares with ``freeRobot``
(``freerobot.py``): the rover in the run's pymunk world, the parameters that may change mid-run
and the pose outputs. The physics advances between steps at ``physics.rate``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from ..model.template import Kind, Port, Template
from .power import POWER_NAMES, POWER_PARAMS, PowerSupply, power_on
from .rover import DiffDriveRover
from .roverparams import BODY_PARAMS, ROVER_PARAMS, WHEEL_PARAMS, check_geometry
from .space import physics_of

#: What both robots publish each step: the true pose, speeds and the rims' speeds.
POSE_OUTPUTS = (
    Port("posX", 0.0, "true x position", "m"),
    Port("posY", 0.0, "true y position", "m"),
    Port("heading", 0.0, "true heading in [-pi, pi)", "rad"),
    Port("speed", 0.0, "signed speed along the heading", "m/s"),
    Port("yawRate", 0.0, "angular velocity", "rad/s"),
    Port(
        "wheelSpeedL",
        0.0,
        "left wheel rim speed omega*r (what an encoder measures: includes tyre slip)",
        "m/s",
    ),
    Port(
        "wheelSpeedR",
        0.0,
        "right wheel rim speed omega*r (what an encoder measures: includes tyre slip)",
        "m/s",
    ),
)


_PI, _TWO_PI, _cos, _sin = math.pi, 2 * math.pi, math.cos, math.sin


class Robot(Template):
    """What both robot templates share: a rover in the run's physics world, its parameters
    (:data:`roverparams.ROVER_PARAMS`) and its true pose as outputs."""

    rover: DiffDriveRover
    fixed_once_running = frozenset(BODY_PARAMS)
    #: a rover's outputs are its body's: deterministic (``freeRobot`` draws in behaviour 4)
    uses_random = False
    #: a batch builds each run's rover from its parameters at t = 0 (the timeline may not
    #: change them during a batched run)
    batch_params_at_start = True

    @classmethod
    def check_params(cls, values: Mapping[str, Any]) -> None:
        """Refuse a geometry statics cannot stand on (``check_geometry``)."""
        check_geometry(values)

    def initialize(self, ctx: Any) -> None:
        self.physics = physics_of(ctx)
        self.rover = self.physics.add_rover(self.path, self.p)

    def on_param_change(self, name: str, value: Any) -> None:
        if name in WHEEL_PARAMS:
            self.physics.update_wheel(self.rover, self.p)
        elif name in BODY_PARAMS:
            raise ValueError(f"{name} is fixed once the run has started")

    def _pose(self) -> dict[str, float]:
        rover = self.rover
        # rover.kinematics() and rover.wheel_speeds() without their frames: the readers
        # the physics world attached (the C step's own), called straight
        source, rims = rover._source, rover._rims
        x, y, a, vx, vy, w = source() if source is not None else rover.kinematics()
        left, right = rims() if rims is not None else (0.0, 0.0)
        return {
            "posX": x,
            "posY": y,
            "heading": (a + _PI) % _TWO_PI - _PI,  # wrap_angle(a), inlined: every step
            "speed": vx * _cos(a) + vy * _sin(a),
            "yawRate": w,
            "wheelSpeedL": left,
            "wheelSpeedR": right,
        }


class ControlledRobot(Robot):
    """The controlled rover (the Follower): wheel powers in %, true pose out."""

    template_name = "controlledRobot"
    kind = Kind.PROCESS
    inputs = (
        Port("powerL", 0.0, "left wheel power", "%"),
        Port("powerR", 0.0, "right wheel power", "%"),
    )
    outputs = POSE_OUTPUTS
    params = ROVER_PARAMS + POWER_PARAMS
    fixed_once_running = frozenset(BODY_PARAMS | POWER_NAMES)
    #: the battery and windings (``power.py``), None with an ideal supply (the default)
    supply: PowerSupply | None = None

    def initialize(self, ctx: Any) -> None:
        super().initialize(ctx)
        if power_on(self.p):
            self.supply = PowerSupply(self.p)
            self._since: Fraction | None = None
            self._applied = (0.0, 0.0)

    def supplied(self, t: Fraction, left: float, right: float) -> tuple[float, float]:
        """The commanded powers as the supply and the windings leave them (``power.py``):
        first the step that ends is charged to the battery and the windings."""
        supply = self.supply
        assert supply is not None
        if self._since is not None and t > self._since:
            w = self.rover.wheel
            rims = self.rover.wheel_speeds()
            forces = (
                w.motor_force(self._applied[0], rims[0]),
                w.motor_force(self._applied[1], rims[1]),
            )
            duties = (
                abs(w.command(self._applied[0])) / 100.0,
                abs(w.command(self._applied[1])) / 100.0,
            )
            supply.update(forces, duties, w.stall_force_n, float(t - self._since))
        self._since = t
        sl, sr = left * supply.scale[0], right * supply.scale[1]
        # the driver saturates at +-100 % (rover.set_power): so does the duty drawn
        self._applied = (max(-100.0, min(100.0, sl)), max(-100.0, min(100.0, sr)))
        return self._applied

    def do_step(self, t: Fraction, inp: Mapping[str, Any]) -> Mapping[str, Any]:
        """The paper's doStep: apply the commanded powers, publish the pose."""
        if self.supply is None:
            self.rover.set_power(inp["powerL"], inp["powerR"])
        else:
            self.rover.set_power(*self.supplied(t, inp["powerL"], inp["powerR"]))
        return self._pose()

    @classmethod
    def step_many(
        cls,
        comps: Sequence[ControlledRobot],
        t: Fraction,
        inp: Mapping[str, Any],
        p: Any,
        state: dict[str, Any],
    ) -> tuple[Mapping[str, Any], None]:
        """``do_step`` for many copies at once (``engine/batch.py``).

        What the group's copies fix for the run (their world, whether any has a supply,
        their rovers' positions, the compiled pose writer) is looked up at its first step
        and kept as one tuple: a vector env steps this group at every instant.
        """
        fixed = state.get("_fixed")
        if fixed is not None:
            physics, supplied, rovers, index, poses, set_powers = fixed
        else:  # (freeRobot's batch step comes here too: it has no supply)
            if "supplied" not in state:
                state["supplied"] = any(getattr(c, "supply", None) is not None for c in comps)
            supplied = state["supplied"]
        if supplied:  # per rover, as do_step (power.py)
            left, right = np.array(inp["powerL"], dtype=float), np.array(inp["powerR"], dtype=float)
            left = np.broadcast_to(left, (len(comps),)).copy()
            right = np.broadcast_to(right, (len(comps),)).copy()
            for i, c in enumerate(comps):
                if getattr(c, "supply", None) is not None:
                    left[i], right[i] = c.supplied(t, float(left[i]), float(right[i]))
            inp = {**inp, "powerL": left, "powerR": right}
        if fixed is None:  # after the first supply step, as ever (``index_of`` starts columns)
            fixed = state["_fixed"] = _fixed(comps, state)
            physics, supplied, rovers, index, poses, set_powers = fixed
        set_powers(rovers, index, inp["powerL"], inp["powerR"])
        arrays = pose_arrays(physics) if poses is not None else None
        if arrays is not None:  # the same outputs in one C call (``_step.robot_poses``)
            kept = state.get("_poses_out")
            if kept is None or kept[0].shape[1] != len(comps):
                # the outputs' block and its rows, made once: the engine copies a group's
                # outputs into the store at once (and sends copies), so a template may reuse
                # its arrays; seven row views a step were ~1 µs
                block = np.empty((len(POSE_OUTPUTS), len(comps)))
                kept = state["_poses_out"] = (block, dict(zip(POSE_NAMES, block, strict=True)))
            poses(*arrays, index, kept[0])
            return kept[1], None
        x, y, a, vx, vy, w = physics.kinematics_array(index).T
        left, right = physics.rim_array(index).T
        return {
            "posX": x,
            "posY": y,
            "heading": (a + math.pi) % (2 * math.pi) - math.pi,
            "speed": vx * np.cos(a) + vy * np.sin(a),
            "yawRate": w,
            "wheelSpeedL": left,
            "wheelSpeedR": right,
        }, None


#: :data:`POSE_OUTPUTS`' names, in order (the rows of ``_step.robot_poses``' output)
POSE_NAMES = tuple(port.name for port in POSE_OUTPUTS)


def _robot_poses() -> Any:
    """``_step.robot_poses`` where the extension is in use, else None (numpy's path)."""
    from . import compiled

    return getattr(compiled._step, "robot_poses", None) if compiled.columns_compiled() else None


def _fixed(comps: Sequence[ControlledRobot], state: dict[str, Any]) -> tuple[Any, ...]:
    """What a robot group's step keeps for the run: ``(physics, supplied, rovers, index,
    poses, set_powers)``, also under the keys it was always kept by in ``state``."""
    physics = comps[0].physics
    if "index" not in state:
        state["index"] = physics.index_of([c.rover for c in comps])
    if "rovers" not in state:
        state["rovers"] = [c.rover for c in comps]
    if "poses" not in state:
        state["poses"] = _robot_poses()
    # a batch's columns command every run's rovers: straight to them (``PhysicsWorld``
    # hands its ``set_powers`` to its group, fixed once the batch is built)
    group = getattr(physics, "group", None)
    set_powers = physics.set_powers if group is None else group.set_powers
    return physics, state["supplied"], state["rovers"], state["index"], state["poses"], set_powers


#: ``fleet.Fleet``, imported at the first robot group's step (``pose_arrays``)
_FLEET: Any = None


def pose_arrays(physics: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """The (N, 6) state and (2, N) rims arrays a robot group's indices point into, when its
    rovers are arrays (a batch's columns, a large fleet: a ``fleet.Fleet``); else None.
    Asked at every step: a fleet may read its state into a new array."""
    global _FLEET
    if _FLEET is None:
        from .fleet import Fleet

        _FLEET = Fleet
    group = physics.group
    model = group._model if group is not None else physics._model
    if not isinstance(model, _FLEET):
        return None
    return model.state, model.rims
