"""The run's pymunk world: ground, walls, obstacles, rovers, collisions, the physics hook.

One ``PhysicsWorld`` per run, created by the first robot template that asks for it
(``ctx.shared("physics", ...)``) and stepped by an engine hook at ``physics.rate`` Hz after
the components due at the same instant. The Space is rebuilt for every run and uses one
thread, so a run is deterministic. Top-down: no gravity in the plane; the ground acts only
through the wheel model (normal load ``m g / 2`` per wheel).
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Sequence
from fractions import Fraction
from typing import Any

import numpy as np
import pymunk

from ..errors import RunFault
from . import fleet
from .bodyio import BodyIO
from .forces import FewRovers
from .rover import DiffDriveRover
from .wheel import WheelModel

ROVER = 1
OBSTACLE = 2


class PhysicsWorld:
    """Owns the pymunk Space for one run."""

    def __init__(self, settings: dict[str, Any], sim: Any) -> None:
        self.settings = settings
        self.sim = sim
        self.rate = Fraction(str(settings["rate"]))
        self.dt = float(1 / self.rate)
        self.gravity = float(settings["gravity"])
        self.ground_friction = float(settings["ground"]["friction"])
        self.rolling_resistance = float(settings["ground"]["rolling_resistance"])
        self.max_speed = float(settings["max_speed"])
        self.extent = float(settings["extent"])
        self.space = pymunk.Space(threaded=False)
        self.space.gravity = (0.0, 0.0)
        self.space.iterations = 10
        self.rovers: list[DiffDriveRover] = []
        self._owner: dict[int, str] = {}
        self.collisions = 0
        self._model: FewRovers | fleet.Fleet | None = None
        self._add_obstacles(settings.get("obstacles") or [], settings.get("walls"))
        self.space.on_collision(ROVER, ROVER, begin=self._on_collision)
        self.space.on_collision(ROVER, OBSTACLE, begin=self._on_collision)
        sim.add_hook(self.rate, self.step, "physics")

    def _add_obstacles(self, obstacles: list[dict[str, Any]], walls: dict[str, Any] | None) -> None:
        static = self.space.static_body
        shapes: list[pymunk.Shape] = []
        for i, ob in enumerate(obstacles):
            kind = ob["type"]
            if kind == "box":
                body = pymunk.Body(body_type=pymunk.Body.STATIC)
                body.position = (ob["x"], ob["y"])
                body.angle = float(ob.get("angle", 0.0))
                shape = pymunk.Poly.create_box(body, (ob["width"], ob["height"]))
                self.space.add(body)
            elif kind == "circle":
                shape = pymunk.Circle(static, ob["radius"], (ob["x"], ob["y"]))
            else:
                pts = ob["points"]
                radius = float(ob.get("thickness", 0.1)) / 2
                for a, b in itertools.pairwise(pts):
                    seg = pymunk.Segment(static, tuple(a), tuple(b), radius)
                    self._owner[id(seg)] = f"obstacle[{i}]"
                    shapes.append(seg)
                continue
            self._owner[id(shape)] = f"obstacle[{i}]"
            shapes.append(shape)
        if walls:
            x0, x1, y0, y1 = walls["xmin"], walls["xmax"], walls["ymin"], walls["ymax"]
            corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]
            for a, b in itertools.pairwise(corners):
                seg = pymunk.Segment(static, a, b, 0.1)
                self._owner[id(seg)] = "wall"
                shapes.append(seg)
        for shape in shapes:
            shape.friction = 0.6
            shape.elasticity = 0.1
            shape.collision_type = OBSTACLE
        if shapes:
            self.space.add(*shapes)

    def add_rover(self, name: str, p: Any) -> DiffDriveRover:
        """Add a rover whose template parameters are ``p`` (see templates.RoverParams)."""
        wheel, lateral_limit = self._wheel_model(p)
        rover = DiffDriveRover(
            self.space,
            name,
            mass_kg=p.mass,
            length_m=p.length,
            width_m=p.width,
            track_m=p.track,
            wheel=wheel,
            lateral_limit_n=lateral_limit,
            x=p.x,
            y=p.y,
            heading=p.heading,
            collision_type=ROVER,
        )
        self._owner[id(rover.shape)] = name
        self.rovers.append(rover)
        self._model = None  # the batch layout changed
        return rover

    def _wheel_model(self, p: Any) -> tuple[WheelModel, float]:
        """A rover's wheel model and lateral grip limit from its template parameters.

        Both scale with the normal load per wheel (``m g / 2``) and the ground's friction.
        """
        load = p.mass * self.gravity / 2
        mu = self.ground_friction
        wheel = WheelModel(
            stall_force_n=p.stallForce,
            free_speed_mps=p.freeSpeed,
            efficiency=p.efficiency / 100.0,
            traction_limit_n=mu * p.tractionCoef * load,
            rolling_force_n=self.rolling_resistance * p.rollingCoef * load,
        )
        return wheel, mu * p.lateralCoef * 2 * load

    def update_wheel(self, rover: DiffDriveRover, p: Any) -> None:
        """Rebuild a rover's wheel model after a parameter change (motor wear, ...)."""
        rover.wheel, rover.lateral_limit = self._wheel_model(p)
        if self._model is not None:
            self._model.refresh()

    def step(self) -> None:
        """Advance the world by one physics step (the engine's hook).

        One batch write, one C step and one batch read of body state (``bodyio.py``); the
        state read after a step is the next step's input, since only the physics step moves
        bodies.
        """
        bad = (self._model or self._start()).advance()
        if bad is not None:
            raise RunFault(self.rovers[bad[0]].name, self.sim.now + 1 / self.rate, bad[1])

    def _start(self) -> FewRovers | fleet.Fleet:
        """Choose the force model for this many rovers and read the initial state."""
        io = BodyIO(self.space, [r.body for r in self.rovers])
        limits = (self.max_speed, self.extent)
        if len(self.rovers) >= fleet.BATCH_MIN:
            model: FewRovers | fleet.Fleet = fleet.Fleet(io, self.rovers, self.dt, limits)
        else:
            model = FewRovers(io, self.rovers, self.dt, limits)
        self._model = model
        for k, rover in enumerate(self.rovers):
            rover.attach_state(functools.partial(self._kinematics, k))
        return model

    def index_of(self, rovers: Sequence[DiffDriveRover]) -> np.ndarray:
        """Positions of ``rovers`` in this world (for :meth:`kinematics_array`)."""
        where = {id(r): k for k, r in enumerate(self.rovers)}
        return np.array([where[id(r)] for r in rovers], dtype=np.intp)

    def set_powers(
        self,
        rovers: Sequence[DiffDriveRover],
        index: np.ndarray,
        left: np.ndarray,
        right: np.ndarray,
    ) -> None:
        """Command many rovers at once, as ``rover.set_power`` would one by one.

        The grouped controlled robots of a platoon (``step_many``) command 200 rovers at
        4 Hz; one by one that is ~0.8 µs a rover. Saturation is the motor driver's (±100 %,
        NaN to -100 as :func:`rover._saturate`); the rovers' ``power_l``/``power_r`` (which the
        per-rover force model and the renderer read) and the batch model's arrays both follow.
        """
        left = np.where(np.isnan(left), -100.0, np.clip(left, -100.0, 100.0))
        right = np.where(np.isnan(right), -100.0, np.clip(right, -100.0, 100.0))
        for rover, lp, rp in zip(rovers, left.tolist(), right.tolist(), strict=True):
            rover.power_l = lp
            rover.power_r = rp
        model = self._model
        if isinstance(model, fleet.Fleet):
            model.powers[0, index] = left
            model.powers[1, index] = right

    def kinematics_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 6) ``x, y, angle, vx, vy, w`` of the rovers at ``index`` after the last step."""
        return (self._model or self._start()).kinematics_array(index)

    def _kinematics(self, k: int) -> Sequence[float]:
        """Rover ``k``'s ``x, y, angle, vx, vy, w`` after the last step."""
        return (self._model or self._start()).kinematics(k)

    def _on_collision(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
        a, b = arbiter.shapes
        names = sorted((self._owner.get(id(a), "?"), self._owner.get(id(b), "?")))
        self.collisions += 1
        self.sim.record_event("collision", f"{names[0]}-{names[1]}")


def physics_of(ctx: Any) -> PhysicsWorld:
    """The run's PhysicsWorld, created on first use from the world's ``physics:`` settings."""
    return ctx.shared("physics", lambda sim: PhysicsWorld(sim.world.physics, sim))
