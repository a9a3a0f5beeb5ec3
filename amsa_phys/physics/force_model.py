"""The force model's interface (:class:`ForceModel`) and the one place that picks a model.

A physics world hands its rovers to a *force model*, which owns their wheel state (rim
speeds), the ground terms under each wheel and the bodies' state read after each step, and
advances them one physics step at a time. Five classes implement it:

* ``fewrovers.FewRovers``: plain floats, one rover after the other (the pure path);
* ``fleet.Fleet``: the same arithmetic over arrays of many rovers (40 and more, and a
  batch's columns without the extension);
* ``compiled.CompiledFewRovers``, ``compiled.CompiledFleet``: the same APIs with the whole
  step in C (``_step.c``);
* ``compiled.ColumnForces``: the Fleet's arrays with the C force pass, for a batch's columns
  (``columns.py``), which integrates the bodies itself.

Why a declared protocol: callers (``space.py``, ``columns.py``, the robots' grouped steps)
used these methods by convention, and a sixth model would have had to find them by reading
the others. :func:`make_force_model` is the only code that chooses among them, so the rule
"C when built, array fleets from :data:`fleet.BATCH_MIN` rovers" is written once. Every
model computes a rover's forces with the same arithmetic: ``_step.c``'s ``rover_forces`` or
its pure twin ``forces.rover_step``, bit for bit; ``wheel.py`` and
``reference.reference_forces`` state the model readably and are the tests' specification.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np

from . import compiled, fleet
from .bodyio import BodyIO
from .fewrovers import FewRovers
from .rover import DiffDriveRover


@runtime_checkable
class ForceModel(Protocol):
    """What every force model offers to the physics world and the robots' grouped steps."""

    rovers: list[DiffDriveRover]
    dt: float
    #: (2, n) driver outputs (% after the deadband) when the model keeps them as an array
    #: (``PhysicsWorld.set_powers`` writes there); None when it reads the rovers' own
    drives: np.ndarray | None

    def refresh(self) -> None:
        """Re-read every rover's constants (after a parameter change: motor wear, ...)."""

    def set_ground(self, k: int, terms: list[float]) -> None:
        """Rover ``k``'s ground terms (``forces.ground_list``) from the next step on."""

    def advance(self) -> tuple[int, str] | None:
        """One physics step; the first rover beyond the safety limits and why, or None."""

    def kinematics(self, k: int) -> Sequence[float]:
        """Rover ``k``'s ``x, y, angle, vx, vy, w`` after the last step."""

    def kinematics_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 6) state of the rovers at ``index`` after the last step."""

    def rim_speeds(self, k: int) -> tuple[float, float]:
        """Rover ``k``'s left and right rim speeds (m/s) after the last step."""

    def rim_array(self, index: np.ndarray) -> np.ndarray:
        """(n, 2) rim speeds of the rovers at ``index``."""


def make_force_model(
    io: Any,
    rovers: list[DiffDriveRover],
    dt: float,
    limits: tuple[float, float],
    grounds: list[list[float]],
    *,
    columns: bool = False,
) -> ForceModel:
    """The force model for ``rovers`` read and written through ``io``.

    ``columns``: a batch's columns (``columns.py``; ``io`` integrates the bodies itself, so
    only the force pass can be compiled). Otherwise the whole step is compiled when the
    extension is built and can reach Chipmunk (``compiled.status`` says why not), and the
    array fleet (C or pure) takes over from :data:`fleet.BATCH_MIN` rovers.
    """
    if columns:
        kind: Any = compiled.ColumnForces if compiled.columns_compiled() else fleet.Fleet
        return kind(io, rovers, dt, limits, grounds)  # type: ignore[no-any-return]
    fast = isinstance(io, BodyIO) and compiled.usable(io)
    if len(rovers) >= fleet.BATCH_MIN:
        kind = compiled.CompiledFleet if fast else fleet.Fleet
    else:
        kind = compiled.CompiledFewRovers if fast else FewRovers
    return kind(io, rovers, dt, limits, grounds)  # type: ignore[no-any-return]
