"""The run's pymunk world: ground and terrain, walls, obstacles, rovers, collisions, the hook.

One ``PhysicsWorld`` per run, created by the first robot or zone template that asks for it
(``ctx.shared("physics", ...)``) and stepped by an engine hook at ``physics.rate`` Hz after
the components due at the same instant. The Space is rebuilt for every run and uses one
thread, so a run is deterministic. Top-down: no gravity in the plane but a grade zone's pull
along its slope; the ground acts only through the wheel model (normal load ``m g / 2`` per
wheel, times ``cos(angle)`` on a slope), with the friction and rolling resistance of the
terrain under each wheel (``terrain.py``). A step faster than :func:`resolvable_speed` is cut
into Chipmunk sub-steps (no tunnelling).

Contacts: pymunk lets shapes overlap by ``collision_slop`` before it pushes them apart (0.1 m
by default: a rover resting 3 cm inside a wall); here the slop is :data:`CONTACT_SLOP_M` and
the bias removes half of any deeper overlap every 1/60 s, so a rover pushing on a wall rests
within a few millimetres of it. A *collision* is a contact episode between two objects (a
rover and a rover, a wall, an obstacle): it starts when the first of their shape pairs
touches and ends when all have been apart for :data:`EPISODE_GAP_S` (a corner touching two
wall segments, or a bounce, is one collision).
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Callable, Sequence
from fractions import Fraction
from typing import Any

import numpy as np
import pymunk

from ..errors import RunFault
from . import fleet
from .bodyio import BodyIO
from .force_model import ForceModel, make_force_model
from .forces import ground_list, per_kind
from .rover import DiffDriveRover, PendingPowers
from .terrain import Terrain
from .tunnelling import resolvable_speed
from .wheel import WheelModel
from .worldrelease import release_world

ROVER = 1
OBSTACLE = 2
#: Overlap pymunk tolerates before pushing shapes apart (m).
CONTACT_SLOP_M = 0.002
#: Share of an overlap (beyond the slop) left after 1/60 s: half is removed.
CONTACT_BIAS = 0.5**60
#: Two objects apart for less than this are still in the same collision episode (s).
EPISODE_GAP_S = 0.5
#: From this many rovers on, the collision index is a spatial hash, not the bounding-box tree.
SPATIAL_HASH_MIN = 100
#: Spatial hash cell size, in rover lengths (Chipmunk's advice: about the size of a shape).
HASH_CELL_LENGTHS = 2.0


class PhysicsWorld:
    """Owns the pymunk Space for one run."""

    def __init__(self, settings: dict[str, Any], sim: Any) -> None:
        self.settings = settings
        self.sim = sim
        self.rate = Fraction(str(settings["rate"]))
        self.dt = float(1 / self.rate)
        self.gravity = float(settings["gravity"])
        ground = settings["ground"]
        self.terrain = Terrain(
            float(ground["friction"]), float(ground["rolling_resistance"]), self.gravity
        )
        self.max_speed = float(settings["max_speed"])
        self.extent = float(settings["extent"])
        self.space = pymunk.Space(threaded=False)
        self.space.gravity = (0.0, 0.0)
        self.space.iterations = 10
        self.space.collision_slop = CONTACT_SLOP_M
        self.space.collision_bias = CONTACT_BIAS
        self.rovers: list[DiffDriveRover] = []
        #: commands of :meth:`set_powers` not yet written onto the rovers (``rover.py``)
        self._pending = PendingPowers(self.rovers)
        self._band: np.ndarray | None = None  # each rover's deadband (``set_powers``)
        self._owner: dict[int, str] = {}
        self.collisions = 0
        self._touching: dict[tuple[str, str], int] = {}
        self._apart_since: dict[tuple[str, str], float] = {}
        self._steps = 0
        #: while :meth:`step_many` batches steps: how to move the clock to one of them
        self._seek: Callable[[int], None] | None = None
        self._model: ForceModel | None = None
        #: the batch's column physics stepping this world (``columns.py``), or None
        self.group: Any = None
        self._where: list[tuple[int, int, int, int] | None] = []
        self._add_obstacles(settings.get("obstacles") or [], settings.get("walls"))
        columns = getattr(sim, "column_physics", None)  # a batch's run declares its columns
        #: the collision-type pairs whose handlers are this world's (``release_run``)
        self._handled: tuple[tuple[int, int], ...] = ()
        if columns is not None:
            # a batch's Spaces are never stepped (``columns.py``: a run that comes within
            # reach of a contact is made alone), so they need no handlers: two handlers
            # set, and two reset at the release, were ~2 % of a batched run's CPU
            columns.adopt(self, sim)
        else:
            self._handled = ((ROVER, ROVER), (ROVER, OBSTACLE))
            for a, b in self._handled:
                self.space.on_collision(a, b, begin=self._on_collision, separate=self._on_separate)
            sim.add_hook(self.rate, self.step, "physics")
            batch = getattr(sim, "batch_hook", None)  # a Simulation's (engine/runner.py)
            if batch is not None:
                batch(self.step, self.step_many)

    def release_run(self) -> None:
        """Let the run go at its end (``Simulation.release``; ``worldrelease.py`` says why)."""
        release_world(self, self._handled)

    def _add_obstacles(self, obstacles: list[dict[str, Any]], walls: dict[str, Any] | None) -> None:
        if not obstacles and not walls:
            return  # pymunk makes its static body on first use: ~4 us a run of a batch
        static = self.space.static_body  # first, as it always was: the Space's body order
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
        """Add a rover whose template parameters are ``p`` (see templates.RoverParams).

        A batch's rover (its world adopted by the columns) stays out of the Space: that Space
        is never stepped, and nothing queries its rovers (a GNSS receiver's sky ignores every
        rover), while adding the body and shape, and removing them when the Space is freed,
        were ~5 % of a batched run's CPU."""
        rover = DiffDriveRover(
            self.space if self.group is None else None,
            name,
            mass_kg=p.mass,
            length_m=p.length,
            width_m=p.width,
            track_m=p.track,
            wheel=self._wheel_model(p),
            x=p.x,
            y=p.y,
            heading=p.heading,
            collision_type=ROVER,
        )
        self._owner[id(rover.shape)] = name
        self.rovers.append(rover)
        rover.attach_pending(self._pending, len(self.rovers) - 1)
        self._band = None
        if self._model is not None:  # the batch layout changed: read through the next model
            for k, other in enumerate(self.rovers[:-1]):
                other.attach_state(functools.partial(self._kinematics, k))
        self._model = None
        return rover

    def _wheel_model(self, p: Any) -> WheelModel:
        return wheel_model(p, self.gravity)

    def update_wheel(self, rover: DiffDriveRover, p: Any) -> None:
        """Rebuild a rover's wheel model after a parameter change (motor wear, ...)."""
        rover.wheel = self._wheel_model(p)
        rover.update_drive()  # the deadband may have changed
        self._band = None
        if self._model is not None:
            self._model.refresh()
            self._where = [None] * len(self.rovers)  # grip and resistance changed too
            self._update_grounds()

    def _update_grounds(self) -> None:
        """Recompute the ground terms of every wheel whose zone (or whose zone's values) changed.

        The left wheel's contact point is at ``+track/2`` across the heading. Called every
        step when the world has zones (a few µs a rover), never otherwise.
        """
        model = self._model
        assert model is not None
        terrain = self.terrain
        n = len(self.rovers)
        if isinstance(model, fleet.Fleet):
            x, y, a = model.state[:, 0], model.state[:, 1], model.state[:, 2]
            hx = -np.sin(a) * model.half_track
            hy = np.cos(a) * model.half_track
            where = terrain.locate_many(
                np.concatenate([x + hx, x - hx]), np.concatenate([y + hy, y - hy])
            )
            left, right = where[:n].tolist(), where[n:].tolist()
            under = terrain.locate_grades(x, y).tolist() if terrain.grades else [-1] * n
        else:
            state = model.state
            left, right, under = [], [], []
            for k, rover in enumerate(self.rovers):
                i = model.offsets[k]
                x, y, a = state[i], state[i + 1], state[i + 2]
                hx = -math.sin(a) * rover.half_track
                hy = math.cos(a) * rover.half_track
                left.append(terrain.locate(x + hx, y + hy))
                right.append(terrain.locate(x - hx, y - hy))
                under.append(terrain.locate_grade(x, y))
        version = terrain.version
        for k, rover in enumerate(self.rovers):
            key = (left[k], right[k], under[k], version)
            if key != self._where[k]:
                self._where[k] = key
                model.set_ground(
                    k,
                    ground_list(
                        rover,
                        terrain.ground(left[k]),
                        terrain.ground(right[k]),
                        terrain.slope(under[k]),
                    ),
                )

    def step(self) -> None:
        """Advance the world by one physics step (the engine's hook).

        One batch write, one C step and one batch read of body state (``bodyio.py``); the
        state read after a step is the next step's input, since only the physics step moves
        bodies.
        """
        model = self._model or self._start()
        if self.terrain.zones or self.terrain.grades:
            self._update_grounds()
        bad = model.advance()
        self._steps += 1
        if bad is not None:
            raise RunFault(self.rovers[bad[0]].name, self.sim.now + 1 / self.rate, bad[1])

    def step_many(self, count: int, seek: Callable[[int], None]) -> int:
        """Up to ``count`` consecutive physics steps in one call, when nothing but the step
        can happen between them (the engine's runs of physics-only instants): how many were
        taken, as many :meth:`step` calls would have taken them, bit for bit. 0 when they
        must go one by one: a force model without a batched step, terrain zones (their
        ground is looked up every step) or the first step (pymunk checks new bodies).
        ``seek(k)`` moves the engine's clock to the ``k``-th of these instants: where a
        collision callback records its event (and ends the batch after its step, so the
        checks below follow that step as they follow a single one) and where a fault is
        reported.

        Why: at 100 Hz the step's two Python layers and the engine's loop around them were
        ~0.3 us of each ~1.1 us step.
        """
        model: Any = self._model or self._start()
        space = self.space
        advance = getattr(model, "advance_many", None)
        if advance is None or self.terrain.zones or self.terrain.grades or space._bodies_to_check:
            return 0
        space._locked = True
        self._seek = seek
        try:
            done, bad = advance(count)
        except BaseException:
            seek(model.batch_index())
            raise
        finally:
            self._seek = None
            space._locked = False
        if space._add_later or space._remove_later or space._post_step_callbacks:
            raise RuntimeError("a collision callback changed the space during a step")
        if space._removed_shapes:
            space._removed_shapes.clear()
        self._steps += done
        if bad >= 0:  # as model.advance() reports it
            violation = model.first_violation(model.state, model.max_speed, model.extent)
            if violation is not None:
                seek(done - 1)
                raise RunFault(
                    self.rovers[violation[0]].name, self.sim.now + 1 / self.rate, violation[1]
                )
        return done  # type: ignore[no-any-return]

    def _start(self) -> ForceModel:
        """Choose the force model for this many rovers and read the initial state."""
        self._choose_index()
        io = BodyIO(self.space, [r.body for r in self.rovers])
        limits = (self.max_speed, self.extent, resolvable_speed(self.rovers, self.space, self.dt))
        ground = self.terrain.ground(-1)
        # each its own list (a few-rover model edits them in place), computed once per kind
        grounds = [list(g) for g in per_kind(self.rovers, lambda r: ground_list(r, ground, ground))]
        model = make_force_model(io, self.rovers, self.dt, limits, grounds)
        self._model = model
        self._where = [(-1, -1, -1, -1)] * len(self.rovers)
        # each rover reads its state straight from the model (the C step's own readers when
        # it has them): a robot reads both at every step, and each Python layer between
        # was ~0.1 us of it
        readers = getattr(model, "readers", None)
        for k, rover in enumerate(self.rovers):
            if readers is not None:
                state, rims = readers(k)
            else:
                state = functools.partial(model.kinematics, k)
                rims = functools.partial(model.rim_speeds, k)
            rover.attach_state(state)
            rover.attach_rims(rims)
        return model

    def _choose_index(self) -> None:
        """A spatial hash for wide worlds, Chipmunk's default bounding-box tree otherwise.

        The tree's cost per step grows with its depth (at 1,000 rovers it was 45 % of the
        loop); the hash's stays flat per shape, but it costs more than the tree for a few
        shapes. Contacts are the same either way (the tests hold them to it): the index only
        finds candidate pairs, the narrow phase decides.
        """
        n = len(self.rovers)
        if n >= SPATIAL_HASH_MIN:
            size = max(max(r.length, r.width) for r in self.rovers)
            self.space.use_spatial_hash(HASH_CELL_LENGTHS * size, 10 * len(self.space.shapes))

    def index_of(self, rovers: Sequence[DiffDriveRover]) -> np.ndarray:
        """Positions of ``rovers`` in this world (for :meth:`kinematics_array`)."""
        if self.group is not None:
            return self.group.index_of(rovers)  # type: ignore[no-any-return]
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
        NaN to -100 as :func:`rover._saturate`) and the deadband each driver's, as numpy over
        the group (the same floats: the comparisons are the scalar code's). The force model's
        drive array gets them now; the rovers' ``power_l`` ... ``drive_r`` (read by the
        renderer and the pure force model) through :class:`rover.PendingPowers` when read.
        """
        if self.group is not None:  # a batch's columns: no window reads power_l there
            self.group.set_powers(rovers, index, left, right)
            return
        left = np.where(np.isnan(left), -100.0, np.clip(left, -100.0, 100.0))
        right = np.where(np.isnan(right), -100.0, np.clip(right, -100.0, 100.0))
        if self._band is None:
            self._band = np.array([r.wheel.deadband_pct for r in self.rovers], dtype=np.float64)
        band = self._band[index]
        drive_l = np.where((-band < left) & (left < band), 0.0, left)
        drive_r = np.where((-band < right) & (right < band), 0.0, right)
        self._pending.put(index, left, right, drive_l, drive_r)
        drives = self._model.drives if self._model is not None else None
        if drives is not None:
            drives[0, index] = drive_l
            drives[1, index] = drive_r

    def kinematics_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 6) ``x, y, angle, vx, vy, w`` of the rovers at ``index`` after the last step."""
        if self.group is not None:
            return self.group.kinematics_array(index)  # type: ignore[no-any-return]
        return (self._model or self._start()).kinematics_array(index)

    def rim_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 2) left and right rim speeds of the rovers at ``index`` after the last step."""
        if self.group is not None:
            return self.group.rim_array(index)  # type: ignore[no-any-return]
        return (self._model or self._start()).rim_array(index)

    def _kinematics(self, k: int) -> Sequence[float]:
        """Rover ``k``'s ``x, y, angle, vx, vy, w`` after the last step."""
        return (self._model or self._start()).kinematics(k)

    def _pair(self, arbiter: pymunk.Arbiter) -> tuple[str, str]:
        a, b = arbiter.shapes
        names = sorted((self._owner.get(id(a), "?"), self._owner.get(id(b), "?")))
        return names[0], names[1]

    def _on_collision(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
        """A shape pair starts touching: a new collision unless its objects touch already
        (another shape pair) or were apart for less than :data:`EPISODE_GAP_S`."""
        steps = self._in_step()
        pair = self._pair(arbiter)
        count = self._touching.get(pair, 0)
        self._touching[pair] = count + 1
        if count:
            return
        apart = self._apart_since.get(pair)
        if apart is not None and (steps - apart) * self.dt < EPISODE_GAP_S:
            return
        self.collisions += 1
        self.sim.record_event("collision", f"{pair[0]}-{pair[1]}")

    def _on_separate(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
        """A shape pair stops touching; the episode may end when its objects' last does."""
        steps = self._in_step()
        pair = self._pair(arbiter)
        count = self._touching.get(pair, 0) - 1
        if count > 0:
            self._touching[pair] = count
        else:
            self._touching.pop(pair, None)
            self._apart_since[pair] = steps

    def _in_step(self) -> int:
        """Steps completed before the one under way (a collision callback's step). In a
        batch (:meth:`step_many`) the engine's clock is moved to that step first, so the
        callback's event has its step's time, and the batch ends after it."""
        if self._seek is None:
            return self._steps
        model: Any = self._model
        k = model.batch_index()
        self._seek(k)
        model.stop_batch()
        return self._steps + k


def wheel_model(p: Any, gravity: float) -> WheelModel:
    """A rover's wheel model from its template parameters (``templates.ROVER_PARAMS``).

    Torques become forces at the ground (divided by the wheel radius) and the wheel's
    inertia a mass at the rim (``J / r^2``). The normal load is shared by statics between the
    two drive wheels (axle ``axleOffset`` ahead of the centre of mass) and the caster
    (``casterOffset``): moments about the centre of mass give each drive wheel
    ``m g (-x_c) / (2 (x_a - x_c))`` at rest on the flat, the caster the rest.
    """
    r = p.wheelRadius
    x_a, x_c = p.axleOffset, p.casterOffset
    span = x_a - x_c
    return WheelModel(
        stall_force_n=p.stallForce,
        free_speed_mps=p.freeSpeed,
        efficiency=p.efficiency / 100.0,
        max_force_n=p.maxWheelTorque / r,
        deadband_pct=p.deadband,
        joint_friction_n=p.jointFriction / r,
        brake_force_n=p.brakeTorque / r,
        rim_mass_kg=p.wheelInertia / (r * r),
        load_n=p.mass * gravity * -x_c / (2 * span),
        slip_long=p.slipComplianceLongitudinal,
        slip_lat=p.slipComplianceLateral,
        traction_coef=p.tractionCoef,
        lateral_coef=p.lateralCoef,
        rolling_coef=p.rollingCoef,
        patch_radius_m=p.patchRadius,
        com_height_m=p.comHeight,
        wheelbase_m=span,
        half_weight_n=p.mass * gravity / 2,
        gravity=gravity,
    )


def physics_of(ctx: Any) -> PhysicsWorld:
    """The run's PhysicsWorld, created on first use from the world's ``physics:`` settings."""
    return ctx.shared("physics", lambda sim: PhysicsWorld(sim.world.physics, sim))
