"""Every run's rovers of a batch as columns: one force pass and one integration a step.

In a batched sweep (``engine/multirun.py``) each run keeps its own :class:`PhysicsWorld`
with its own pymunk Space (its rovers, obstacles and walls), so runs can never touch: no
offsets (a far offset would change how positions round) and no collision filters (32
categories are too few for thousands of runs, and every run at the same place would make
pymunk's broadphase quadratic). What is shared is the arithmetic:

* the wheel, tyre and grip forces of all rovers of all runs are one pass: the compiled
  step's own per-rover C code (``compiled.ColumnForces``, ``_step.column_forces``) where
  the extension is built, so each rover gets the very floats its run made alone gets; the
  pure ``fleet.Fleet`` (the same per-rover arithmetic in Python, ``forces.rover_step``) under
  ``AMSA_PHYS_PURE=1`` or without the extension. Profiled on a 250-run scenario1 batch, the
  numpy pass was half of the batch's time, most of it in the rare branches' masks (some
  rover takes one at two steps in three); the C pass takes each rover's branch alone;
* every rover is integrated here, in numpy, with Chipmunk's own update for a body without
  contacts (``cpBodyUpdatePosition`` then ``cpBodyUpdateVelocity``: ``p += v dt; a += w dt;
  v += (g + f / m) dt; w += t / I dt``, then ``bodyio.trapezoid``'s second-order pose
  correction, the same operations in the same order, so the same floats: given the same
  forces, a body ends each step where its Space would put it, bit for bit;
  ``tests/physics/test_columns.py``).

With the compiled forces the integration, the contact screening below and the safety check
run in the same C call as the forces (``_step.Columns``, ``ColumnForces.columns``): the
numpy passes over 500-value columns cost more than the forces themselves (a 250-run batch's
physics step ~65 µs, now ~35). The C step performs this module's numpy operations in the same
order, so it gives the same floats and marks the same runs
(``tests/physics/test_column_step.py``); the numpy code below remains the pure path's.

Contacts are where that stops: pymunk solves a contact with 10 sequential-impulse passes,
which leave a residual that depends on the order of the contact points, and that order
depends on the history of the Space's broadphase tree. Measured on the MDE world, a
follower running into its leader: the same states and forces a step before, a Space
stepped alone and one brought up to date at the contact differ by 3e-5 m/s after that one
step; a difference of 1e-14 in the forces (numpy's arrangement of the force model against
the float path's) grows to 1e-5 in the run's metrics. So a run whose shapes come within
reach of each other (:data:`REACH_M` plus what they can cover in two steps) is marked
(:attr:`ColumnPhysics.touched`) and its row comes from the run made alone: contacts are
exactly those of a single run, because they are a single run's.

Worlds with terrain zones, lidars (a ray cast needs the Space current every step) or
changes to a rover during the run are not batched (``runs/batched.py`` says why).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import pymunk

from ..engine.tasks import in_run
from ..errors import RunFault
from .fleet import Fleet
from .force_model import make_force_model
from .forces import ground_list
from .rover import DiffDriveRover
from .space import PhysicsWorld
from .tunnelling import resolvable_speed

#: Two shapes of a run closer than this (plus two steps of their motion): the run may be
#: about to touch, and its row is made alone.
REACH_M = 0.5


class _ColumnIO:
    """What ``Fleet`` reads and writes through (``bodyio.BodyIO``'s interface), over columns.

    ``step`` integrates every body as Chipmunk integrates one without contacts, then lets
    :class:`ColumnPhysics` look for runs about to touch.
    """

    def __init__(self, state: np.ndarray, m_inv: np.ndarray, i_inv: np.ndarray) -> None:
        n = len(state)
        self.rows = list(range(n))
        self.state = state  # (n, 6): x, y, angle, vx, vy, w
        self.forces = np.zeros(3 * n)
        self._f = self.forces.reshape(n, 3)
        self.m_inv = m_inv
        self.i_inv = i_inv
        self.before = state.copy()
        self.on_step: Any = None

    def read_array(self) -> np.ndarray:
        return self.state

    def write(self) -> None:
        pass

    def step(self, dt: float, substeps: int = 1) -> None:
        """One step of every body (``substeps`` is the Space's business: a run fast enough to
        need them is made alone, :meth:`ColumnPhysics._contacts`)."""
        s = self.state
        np.copyto(self.before, s)
        # cpBodyUpdatePosition: p = p + (v + v_bias) * dt; a = a + (w + w_bias) * dt
        s[:, 0] += (s[:, 3] + 0.0) * dt
        s[:, 1] += (s[:, 4] + 0.0) * dt
        s[:, 2] += (s[:, 5] + 0.0) * dt
        # cpBodyUpdateVelocity (damping 1, gravity 0 in the plane):
        # v = v * 1 + (g + f * m_inv) * dt; w = w * 1 + t * i_inv * dt
        f = self._f
        s[:, 3] += (0.0 + f[:, 0] * self.m_inv) * dt
        s[:, 4] += (0.0 + f[:, 1] * self.m_inv) * dt
        s[:, 5] += f[:, 2] * self.i_inv * dt
        # bodyio.trapezoid: p = p + (v1 - v0) * (dt / 2), a = a + (w1 - w0) * (dt / 2)
        half = 0.5 * dt
        b = self.before
        s[:, 0] += (s[:, 3] - b[:, 3]) * half
        s[:, 1] += (s[:, 4] - b[:, 4]) * half
        s[:, 2] += (s[:, 5] - b[:, 5]) * half
        if self.on_step is not None:
            self.on_step(dt)


class ColumnPhysics:
    """The batch's physics step: every run's :class:`PhysicsWorld`, stepped as columns.

    Each run's world registers its step hook here instead of with the engine
    (:meth:`adopt`); the batch registers :meth:`step` once. The runs' Spaces hold their
    rovers where they started (they are never stepped). The robots' grouped
    ``step_many`` reaches the columns through each world's ``index_of``, ``set_powers``,
    ``kinematics_array`` and ``rim_array``, which :meth:`adopt` points here.
    """

    def __init__(self) -> None:
        self.worlds: list[PhysicsWorld] = []
        self.rovers: list[DiffDriveRover] = []
        self._model: Fleet | None = None
        self.steps = 0
        self.sim: Any = None
        #: 1 for each run whose shapes came within reach of each other (:attr:`touched`)
        self._touched = np.zeros(0, dtype=np.uint8)
        #: the whole step in C (``compiled.ColumnForces.columns``), when the forces are C's
        self._fused: Any = None
        self._powers: Any = None

    @property
    def touched(self) -> set[int]:
        """Runs whose shapes came within reach of each other: their rows are made alone."""
        return set(np.flatnonzero(self._touched).tolist())

    def adopt(self, world: PhysicsWorld, run: Any) -> None:
        """Take over ``world``'s step (its rovers and contacts stay its own); ``run`` is its
        run's view of the batch, through which the first world registers the one step of
        all. The world sends its robots' group calls here (``PhysicsWorld.group``)."""
        if not self.worlds:
            self.sim = run
            run.add_hook(world.rate, self.step, "physics")
            run.batch_hook(self.step, self.step_many)
        self.worlds.append(world)
        world.group = self

    def release(self) -> None:
        """Let the batch's worlds, rovers and force model go at the batch's end
        (``MultiRun.release``): a world and the columns name each other (``world.group``),
        and the model holds every rover, so an ended batch would wait for the cyclic
        collector. The fused C step (and its helper threads) goes with them."""
        self.worlds = []
        self.rovers = []
        self._model = None
        self._fused = None
        self._io = None
        self.sim = None

    # -- the robots' group interface (as PhysicsWorld's, over every run) -------------------
    def index_of(self, rovers: Sequence[DiffDriveRover]) -> np.ndarray:
        """Positions of ``rovers`` in the columns."""
        self._model or self._start()
        where = {id(r): k for k, r in enumerate(self.rovers)}
        return np.array([where[id(r)] for r in rovers], dtype=np.intp)

    def set_powers(
        self, rovers: Sequence[DiffDriveRover], index: np.ndarray, left: Any, right: Any
    ) -> None:
        """:meth:`PhysicsWorld.set_powers` over the columns, without its loop per rover:
        saturation at ±100 % (NaN to -100), then each driver's deadband, written into the
        force model's drives (the only reader in a batch: no window draws the rovers'
        ``power_l``). A rover's wheel (and deadband) is fixed in a batch (``batched.py``)."""
        model = self._model or self._start()
        powers = self._powers
        if powers is not None:  # the same rule in one C call (``_step.column_powers``)
            f64 = np.float64
            powers(
                np.ascontiguousarray(left, dtype=f64),
                np.ascontiguousarray(right, dtype=f64),
                np.ascontiguousarray(index, dtype=np.int64),
                self._band,
                model.drives,
            )
            return
        left = np.where(np.isnan(left), -100.0, np.clip(left, -100.0, 100.0))
        right = np.where(np.isnan(right), -100.0, np.clip(right, -100.0, 100.0))
        band = self._band[index]
        model.drives[0, index] = np.where((-band < left) & (left < band), 0.0, left)
        model.drives[1, index] = np.where((-band < right) & (right < band), 0.0, right)

    def kinematics_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 6) state of the rovers at ``index`` after the last step."""
        return (self._model or self._start()).kinematics_array(index)

    def rim_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 2) rim speeds of the rovers at ``index``."""
        return (self._model or self._start()).rim_array(index)

    # -- stepping ------------------------------------------------------------------------
    def _start(self) -> Fleet:
        """Gather every run's rovers (run by run) and their shapes' reach; start the model."""
        self.rovers = [r for w in self.worlds for r in w.rovers]
        run_of = [i for i, w in enumerate(self.worlds) for _ in w.rovers]
        self._run = np.array(run_of, dtype=np.intp)
        first = self.worlds[0]
        self.dt = first.dt
        state = np.array([_body_state(r.body) for r in self.rovers], dtype=np.float64)
        state = state.reshape(len(self.rovers), 6)
        m_inv = np.array([1.0 / r.body.mass for r in self.rovers])
        i_inv = np.array([1.0 / r.body.moment for r in self.rovers])
        io = _ColumnIO(state, m_inv, i_inv)
        io.on_step = self._contacts
        grounds = []
        for w in self.worlds:
            ground = w.terrain.ground(-1)
            grounds += [ground_list(r, ground, ground) for r in w.rovers]
        # faster than its world's resolvable speed a run's Space would take sub-steps
        # (``bodyio.substeps``), which these columns do not: such a run is made alone (with a
        # margin, so that rounding at the threshold cannot decide it)
        self._sub = np.array(
            [
                speed
                for w in self.worlds
                for speed in [resolvable_speed(w.rovers, w.space, self.dt)] * len(w.rovers)
            ]
        )
        limits = (first.max_speed, first.extent)
        # the C force model (a single run's own arithmetic) when built; the pure one otherwise
        model = make_force_model(io, self.rovers, self.dt, limits, grounds, columns=True)
        assert isinstance(model, Fleet)
        self._model = model
        self._io = io
        for k, rover in enumerate(self.rovers):
            rover.attach_state(functools.partial(model.kinematics, k))
            rover.attach_rims(functools.partial(model.rim_speeds, k))
        # reach: each rover's bounding radius; the static shapes' boxes (the same in every
        # run of a batch: one physics setting); rover pairs within each run
        self._radius = np.array(_radii(self.rovers))
        self._band = np.array([r.wheel.deadband_pct for r in self.rovers])
        #: ``_step.column_powers`` with the compiled forces (their drives are C-contiguous)
        self._powers = getattr(_compiled_step(), "column_powers", None)
        if self._powers is not None and not model.drives.flags.c_contiguous:
            self._powers = None
        statics = [s for s in first.space.shapes if s.body.body_type == pymunk.Body.STATIC]
        self._boxes = np.array([[s.bb.left, s.bb.bottom, s.bb.right, s.bb.top] for s in statics])
        pairs = [
            (a, b)
            for i in range(len(self.worlds))
            for a in np.flatnonzero(self._run == i)
            for b in np.flatnonzero(self._run == i)
            if a < b
        ]
        self._pa = np.array([p[0] for p in pairs], dtype=np.intp)
        self._pb = np.array([p[1] for p in pairs], dtype=np.intp)
        self._touched = np.zeros(len(self.worlds), dtype=np.uint8)
        if hasattr(model, "columns"):  # the compiled forces: screen, step and check in C too
            screen = {
                "run": self._run.astype(np.int64),
                "radius": self._radius,
                "sub": self._sub.astype(np.float64),
                "reach": REACH_M,
                "pairs_a": self._pa.astype(np.int64),
                "pairs_b": self._pb.astype(np.int64),
                "boxes": np.ascontiguousarray(self._boxes, dtype=np.float64).reshape(-1, 4),
                "touched": self._touched,
            }
            self._fused = model.columns(
                io.state, io._f, (m_inv, i_inv), screen, threads=self.threads
            )
        return model

    #: threads of the compiled column step (``compiled.ColumnForces.columns``); the numpy
    #: path ignores it. Each rover is computed by the same code in any thread: the same floats
    threads = 1

    #: whether a touched run's rovers stay where they were (the vector env's columns,
    #: ``gym/veccolumns.py``); a sweep lets them move (it makes the run again alone)
    FREEZE = False

    def step(self) -> None:
        """One physics step of every run (the batch's hook)."""
        model = self._model or self._start()
        if self._fused is not None:
            # _contacts, forces, integration, check: in C (frozen rows held: advance_many)
            fused = self._fused
            ok = fused.advance_many(1, True)[1] if self.FREEZE else fused.advance()
            bad = None if ok else model.first_violation(model.state, model.max_speed, model.extent)
        else:
            bad = model.advance()
        self.steps += 1
        if bad is not None:
            self._fault(bad)

    def step_many(self, count: int, seek: Callable[[int], None]) -> int:
        """Up to ``count`` physics steps in one C call, as ``count`` calls of :meth:`step`
        take them, bit for bit (``Simulation.batch_hook``: the engine hands over the runs
        of physics-only instants between two instants with components). How many were
        taken; 0 on the numpy path, which steps one by one. ``seek(k)`` puts the engine's
        clock at the ``k``-th, where a fault is reported.

        Why: a vector env's agent step is 25 physics steps; their Python layers cost more
        than a small batch's arithmetic (the vector env's fixed ~2 ms a step).
        """
        model = self._model or self._start()
        fused = self._fused
        if fused is None or not hasattr(fused, "advance_many"):
            return 0
        done, ok = fused.advance_many(count, self.FREEZE)
        self.steps += done
        if not ok:
            bad = model.first_violation(model.state, model.max_speed, model.extent)
            if bad is not None:
                seek(done - 1)
                self._fault(bad)
        return int(done)

    def _fault(self, bad: tuple[int, str]) -> None:
        """Raise the safety violation ``bad`` as its run's fault (the batch makes that run
        alone)."""
        rover = self.rovers[bad[0]]
        fault = RunFault(rover.name, self.sim.now + 1 / self.worlds[0].rate, bad[1])
        raise in_run(fault, int(self._run[bad[0]]))

    def within_reach_at_start(self) -> set[int]:
        """The runs whose first step would mark them touched: within reach at t = 0.

        Call after the batch is initialised (every run's world adopted) and before it steps.
        The first step's watch sees exactly this state, so each of these runs would be
        computed in the columns only to be thrown away and made alone: the batch makes them
        alone at once instead (``runs/batched.py``; the paper's Fig. 5 starts the follower
        1 m behind the leader, and every run of its sweeps was computed twice).
        """
        if not any(w.rovers for w in self.worlds):
            return set()  # nothing the columns step: nothing to touch
        self._model or self._start()
        return self._near(self._io.state, self.dt)

    def _contacts(self, dt: float) -> None:
        """Mark the runs whose shapes are within reach of each other before this step."""
        near = self._near(self._io.before, dt)
        if near:
            self._touched[np.fromiter(near, np.intp)] = 1

    def _near(self, state: np.ndarray, dt: float) -> set[int]:
        """Runs (of ``state``, the columns' rows) whose shapes are within reach of each other
        or of a static shape, or too fast for the columns, in a step of ``dt``."""
        out: set[int] = set()
        x, y = state[:, 0], state[:, 1]
        speed = np.hypot(state[:, 3], state[:, 4])
        reach = self._radius + REACH_M + 2.0 * dt * speed
        fast = speed > 0.99 * self._sub
        if fast.any():
            out.update(self._run[fast].tolist())
        if len(self._pa):
            pa, pb = self._pa, self._pb
            gap = np.hypot(x[pa] - x[pb], y[pa] - y[pb])
            near = gap < reach[pa] + reach[pb]
            if near.any():
                out.update(self._run[pa[near]].tolist())
        if len(self._boxes):
            b = self._boxes
            dx = np.maximum(np.maximum(b[None, :, 0] - x[:, None], 0.0), x[:, None] - b[None, :, 2])
            dy = np.maximum(np.maximum(b[None, :, 1] - y[:, None], 0.0), y[:, None] - b[None, :, 3])
            near = (np.hypot(dx, dy) < reach[:, None]).any(axis=1)
            if near.any():
                out.update(self._run[near].tolist())
        return out


def _compiled_step() -> Any:
    """The C extension when a batch's forces are compiled (not under ``AMSA_PHYS_PURE``)."""
    from . import compiled

    return compiled._step if compiled.columns_compiled() else None


def _body_state(body: pymunk.Body) -> list[float]:
    x, y = body.position
    vx, vy = body.velocity
    return [x, y, body.angle, vx, vy, body.angular_velocity]


def _radii(rovers: Sequence[DiffDriveRover]) -> list[float]:
    """:func:`_radius` of each rover's shape, computed once for each size: a rover's box is
    made from its length and width alone (``rover.py``), and reading a shape's vertices
    from pymunk was ~10 % of a batch's set-up."""
    seen: dict[tuple[float, float], float] = {}
    out = []
    for r in rovers:
        key = (r.length, r.width)
        radius = seen.get(key)
        if radius is None:
            radius = seen[key] = _radius(r.shape)
        out.append(radius)
    return out


def _radius(shape: pymunk.Shape) -> float:
    """The largest distance of ``shape`` from its body's centre (a bounding circle)."""
    if isinstance(shape, pymunk.Poly):
        return max(math.hypot(v.x, v.y) for v in shape.get_vertices()) + shape.radius
    if isinstance(shape, pymunk.Circle):
        return math.hypot(*shape.offset) + shape.radius
    return 1e9  # anything else: always within reach (stepped by its Space)
