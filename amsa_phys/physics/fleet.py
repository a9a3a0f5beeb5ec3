"""Many rovers of one Space as arrays: one batch read and write a step, state as an (n, 6) array.

The force arithmetic is the pure path's one copy, ``forces.rover_step``, called per rover over
the arrays' rows; what this class owns is the array bookkeeping the many-rover callers need:
drives, rims and ground terms as (2, n) and (9, n) arrays (the robots' grouped steps and a
batch's columns read and write them whole), the state as one array, one vectorised safety
check. ``compiled.CompiledFleet`` and ``compiled.ColumnForces`` keep these arrays and hand the
arithmetic to C.

Why no numpy arithmetic any more: the numpy pass was a third copy of the wheel
model that rounded differently from the C step and the float path, so every change of the
model was written three times and a batched row without the extension differed from its
single run. Without a C compiler a large fleet now costs the float path's ~5 µs a rover and
step (a 1,000-rover platoon ~5 ms a step, several times the old numpy pass): installs that
run large fleets or batched sweeps should have a compiler, which ``pip install`` uses.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .bodyio import BodyIO, substeps
from .forces import fold, outside, per_kind, rover_step, too_fast
from .rover import DiffDriveRover
from .wheel import step_constants

#: From this many rovers on, PhysicsWorld keeps the rovers as arrays (the grouped robots'
#: reads and writes and the safety check are then one array operation each).
BATCH_MIN = 40
#: Where ``forces.ground_list``'s seven terms go in :attr:`Fleet.ground`'s rows: the left and
#: right wheel of each term next to each other, so each term is one (2, n) view.
GROUND_ROWS = [0, 2, 4, 1, 3, 5, 6, 7, 8]


class Fleet:
    """All rovers of one Space as arrays, indexed like ``rovers``."""

    def __init__(
        self,
        io: BodyIO,
        rovers: list[DiffDriveRover],
        dt: float,
        limits: tuple[float, float],
        grounds: list[list[float]],
    ) -> None:
        self.io = io
        self.rovers = rovers
        self.dt = dt
        self.max_speed, self.extent, *sub = limits
        #: faster than this a step is cut into Chipmunk sub-steps (``bodyio.substeps``)
        self.sub_speed = sub[0] if sub else math.inf
        self.rows = np.array(io.rows, dtype=np.intp)
        n = len(rovers)
        self.drives = np.zeros((2, n))
        for i, r in enumerate(rovers):
            r.attach_power_slot(self.drives, i)
        self.rims = np.zeros((2, n))
        self.ground = np.zeros((len(GROUND_ROWS), n))
        if grounds:  # set_ground for every rover, in one assignment
            self.ground[GROUND_ROWS] = np.array(grounds, dtype=np.float64).T
        self._out = np.frombuffer(io.forces, dtype=np.float64).reshape(-1, 3)
        start = int(self.rows[0]) if n else 0
        consecutive = n > 0 and bool((self.rows == np.arange(start, start + n)).all())
        self._span = slice(start, start + n) if consecutive else None
        self._gather = np.zeros((n, 3))  # forces when the rovers are not consecutive bodies
        self.refresh()
        self.state = self.read()
        self._top2 = _top_speed2(self.state)

    def refresh(self) -> None:
        """Re-read every rover's constants (after a parameter change: motor wear, ...).

        Folded exactly as ``FewRovers.refresh`` folds them: both call ``forces.rover_step``.
        Lazily (:meth:`plans`): the compiled models subclassing this one never run the pure
        pass, and keep constants of their own.
        """
        self._plans: list[tuple[Any, ...]] | None = None  # folded when the pure pass needs them
        self.half_track = np.array([r.half_track for r in self.rovers], dtype=np.float64)

    def plans(self) -> list[tuple[Any, ...]]:
        """Every rover's constants for ``forces.rover_step`` (folded once per kind of rover)."""
        if self._plans is None:
            dt = self.dt
            self._plans = per_kind(
                self.rovers,
                lambda r: (
                    *fold(r, dt),
                    step_constants(r.wheel, dt, r.mass, r.moment, r.half_track),
                ),
            )
        return self._plans

    def set_ground(self, k: int, terms: list[float]) -> None:
        """Rover ``k``'s ground terms (``forces.ground_list``) from the next step on."""
        self.ground[GROUND_ROWS, k] = terms

    def kinematics(self, k: int) -> list[float]:
        """Rover ``k``'s six state floats after the last step."""
        return self.state[k].tolist()

    def kinematics_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 6) state of the rovers at ``index`` after the last step."""
        return self.state[index]

    def rim_speeds(self, k: int) -> tuple[float, float]:
        """Rover ``k``'s left and right rim speeds (m/s) after the last step."""
        return float(self.rims[0, k]), float(self.rims[1, k])

    def rim_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 2) rim speeds of the rovers at ``index``."""
        return self.rims[:, index].T

    def advance(self) -> tuple[int, str] | None:
        """One physics step: forces, pymunk's step, the new state; a safety violation or None."""
        self.apply(self.state)
        self.io.write()
        self.io.step(self.dt, substeps(self._top2, self.sub_speed))
        state = self.state = self.read()
        # the usual case in five array operations; NaN makes max() NaN, which fails
        self._top2 = top2 = _top_speed2(state)
        if top2 <= self.max_speed**2 and np.abs(state[:, :2]).max() <= self.extent:
            return None
        return self.first_violation(state, self.max_speed, self.extent)

    def read(self) -> np.ndarray:
        """(rovers, 6) array: x, y, angle, vx, vy, w now (a copy)."""
        raw = self.io.read_array()
        if self._span is not None:  # the rovers are consecutive bodies: a slice, no gather
            return raw[self._span].copy()
        return raw[self.rows]

    def apply(self, state: np.ndarray) -> None:
        """Write every rover's force and torque for this step and advance the rims: the
        pure path's per-rover arithmetic (``forces.rover_step``) over the arrays' rows."""
        dt = self.dt
        rows = state.tolist()
        drive_l, drive_r = self.drives.tolist()
        rim_l, rim_r = self.rims.tolist()
        grounds = self.ground[GROUND_ROWS].T.tolist()
        out = self._out[self._span] if self._span is not None else self._gather
        results = [
            rover_step(plan, gnd, dt, row[2], row[3], row[4], row[5], ul, ur, dl, dr)
            for plan, gnd, row, ul, ur, dl, dr in zip(
                self.plans(), grounds, rows, rim_l, rim_r, drive_l, drive_r, strict=True
            )
        ]
        if results:
            arr = np.array(results, dtype=np.float64)
            out[:, :] = arr[:, :3]
            self.rims[...] = arr[:, 3:].T
        if self._span is None:
            self._out[self.rows] = out

    def first_violation(
        self, state: np.ndarray, max_speed: float, extent: float
    ) -> tuple[int, str] | None:
        """The first rover beyond the speed limit or the world's extent, and why."""
        speed = np.hypot(state[:, 3], state[:, 4])
        bad_speed = ~(speed <= max_speed)  # NaN counts as bad
        bad_place = ~((np.abs(state[:, 0]) <= extent) & (np.abs(state[:, 1]) <= extent))
        bad = bad_speed | bad_place
        if not bad.any():
            return None
        i = int(np.argmax(bad))
        if bad_speed[i]:
            return i, too_fast(float(speed[i]), max_speed)
        return i, outside(float(state[i, 0]), float(state[i, 1]), extent)


def _top_speed2(state: np.ndarray) -> float:
    """The largest ``vx * vx + vy * vy`` of the rovers (NaN if any is NaN), 0 for none."""
    if not len(state):
        return 0.0
    vx, vy = state[:, 3], state[:, 4]
    speed2 = vx * vx
    speed2 += vy * vy
    return float(speed2.max())
