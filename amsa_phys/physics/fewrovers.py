"""A few rovers' force model over plain floats: one batch read and write a step (the pure path).

``FewRovers`` is the pure path for fewer than ``fleet.BATCH_MIN`` rovers (and the base the
compiled ``compiled.CompiledFewRovers`` keeps its API from): it folds each rover's constants
once, reads the bodies' state in one batch call, computes each rover's forces with the one
copy of the arithmetic (``forces.rover_step``), writes them in one batch call, steps the
space and checks the safety limits. Split from ``forces.py`` so that the
arithmetic, which ``_step.c`` mirrors bit for bit, sits alone in its module.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .bodyio import FORCE, STATE, BodyIO, substeps
from .forces import fold, outside, rover_step, too_fast
from .rover import DiffDriveRover
from .wheel import step_constants


class FewRovers:
    """The force model over plain floats for rovers at body ``rows`` of a batch state.

    Constants are folded per rover once; each step reads the rovers' state in one batch call,
    computes forces (~130 float operations and seven trig calls a rover on the usual path),
    writes them in one batch call and advances the rims (``rims``: left and right rim speed of
    rover ``k`` at ``2k``, ``2k + 1``).
    """

    #: the rovers' drives are read from the rovers themselves (``force_model.ForceModel``)
    drives: np.ndarray | None = None

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
        self.rows = io.rows
        self.dt = dt
        self.max_speed, self.extent, *sub = limits
        #: faster than this a step is cut into Chipmunk sub-steps (``bodyio.substeps``)
        self.sub_speed = sub[0] if sub else math.inf
        self._max2 = self.max_speed * self.max_speed * (1 - 1e-12)  # never above hypot's test
        self._top2 = 0.0  # the fastest rover's squared speed after the last step
        #: per rover, ground terms under each wheel (``ground_list``); terrain rewrites them
        self.grounds = grounds
        self.rims = [0.0] * (2 * len(rovers))
        self.refresh()
        self.state = io.read()
        state = self.state
        for i in self._offsets:
            self._top2 = max(self._top2, state[i + 3] * state[i + 3] + state[i + 4] * state[i + 4])

    def refresh(self) -> None:
        """Re-read every rover's constants (after a parameter change: motor wear, ...)."""
        self._plan = []
        for k, (r, row) in enumerate(zip(self.rovers, self.rows, strict=True)):
            f = fold(r, self.dt)
            s = step_constants(r.wheel, self.dt, r.mass, r.moment, r.half_track)
            self._plan.append((r, row * STATE, row * FORCE, 2 * k, (*f, s), self.grounds[k]))
        self._offsets = [row * STATE for row in self.rows]

    @property
    def offsets(self) -> list[int]:
        """Where each rover's six floats start in :attr:`state`."""
        return self._offsets

    def set_ground(self, k: int, terms: list[float]) -> None:
        """Rover ``k``'s ground terms (``ground_list``) from the next step on."""
        self.grounds[k][:] = terms

    def kinematics(self, k: int) -> list[float]:
        """Rover ``k``'s six state floats after the last step."""
        i = self._offsets[k]
        return self.state[i : i + STATE]

    def kinematics_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 6) state of the rovers at ``index`` after the last step."""
        rows = np.asarray(self.rows)[index]
        return np.array(self.state).reshape(-1, STATE)[rows]

    def rim_speeds(self, k: int) -> tuple[float, float]:
        """Rover ``k``'s left and right rim speeds (m/s) after the last step."""
        return self.rims[2 * k], self.rims[2 * k + 1]

    def rim_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 2) rim speeds of the rovers at ``index``."""
        return np.array(self.rims).reshape(-1, 2)[index]

    def advance(self) -> tuple[int, str] | None:
        """One physics step: forces, pymunk's step, the new state; a safety violation or None."""
        io = self.io
        self.apply(self.state)
        io.write()
        io.step(self.dt, substeps(self._top2, self.sub_speed))
        state = self.state = io.read()
        # the safety check, inline: written so that NaN fails every comparison
        max2 = self._max2
        extent = self.extent
        top2 = 0.0
        for i in self._offsets:
            vx = state[i + 3]
            vy = state[i + 4]
            v2 = vx * vx + vy * vy
            if v2 > top2:
                top2 = v2
            if not (
                v2 <= max2 and -extent <= state[i] <= extent and -extent <= state[i + 1] <= extent
            ):
                return self.first_violation(state, self.max_speed, extent)
        self._top2 = top2
        return None

    def apply(self, state: Sequence[float]) -> None:
        """Write each rover's ``fx, fy, torque`` for this step and advance the rims."""
        forces = self.io.forces
        rims = self.rims
        dt = self.dt
        for r, i, o, j, plan, gnd in self._plan:
            fx, fy, torque, rims[j], rims[j + 1] = rover_step(
                plan,
                gnd,
                dt,
                state[i + 2],
                state[i + 3],
                state[i + 4],
                state[i + 5],
                rims[j],
                rims[j + 1],
                r.drive_l,
                r.drive_r,
            )
            forces[o] = fx
            forces[o + 1] = fy
            forces[o + 2] = torque

    def first_violation(
        self, state: Sequence[float], max_speed: float, extent: float
    ) -> tuple[int, str] | None:
        """The first rover beyond the speed limit or the world's extent, and why."""
        for k, i in enumerate(self._offsets):
            x, y, _, vx, vy, _ = state[i : i + STATE]
            speed = math.hypot(vx, vy)
            if not speed <= max_speed:  # also catches NaN
                return k, too_fast(speed, max_speed)
            if not (abs(x) <= extent and abs(y) <= extent):
                return k, outside(x, y, extent)
        return None
