"""The two physical robot templates of the MDE challenge: ``freeRobot`` and ``controlledRobot``.

Both are differential-drive rovers in the run's pymunk world. ``controlledRobot`` (the
Follower, kind *process*) takes its wheel powers from Data; ``freeRobot`` (the Leader, kind
*environment*) drives itself by a behaviour (paper: "the leader may have different
behaviors"). At every step a robot publishes its true pose and applies the current power;
the physics advances between steps at ``physics.rate``.

This module is where the template registry (``amsa_phys.physics.templates:FreeRobot``), the
README and user code find them; each concept lives in a room of its own: the
parameter table in ``roverparams.py``, the common base and ``controlledRobot`` in
``robots.py``, ``freeRobot``'s behaviours in ``freerobot.py``.
"""

from __future__ import annotations

from .freerobot import BEHAVIORS, FreeRobot
from .robots import POSE_OUTPUTS, ControlledRobot, Robot
from .roverparams import BODY_PARAMS, ROVER_PARAMS, WHEEL_PARAMS, check_geometry, rover_params

__all__ = [
    "BEHAVIORS",
    "BODY_PARAMS",
    "POSE_OUTPUTS",
    "ROVER_PARAMS",
    "WHEEL_PARAMS",
    "ControlledRobot",
    "FreeRobot",
    "Robot",
    "check_geometry",
    "rover_params",
]
