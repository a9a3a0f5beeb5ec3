"""Rovers in every regime of the wheel model, for the tests that hold two force paths equal.

Shared by ``engine/test_fast_paths.py``, ``test_compiled_step.py`` and
``test_column_forces.py``; importable as ``regimes`` through pytest's ``pythonpath``
(pyproject.toml), like ``toys``, so no test edits ``sys.path``.
"""

from __future__ import annotations

import random

import pymunk

from amsa_phys.physics.rover import DiffDriveRover
from amsa_phys.physics.space import wheel_model
from amsa_phys.physics.templates import rover_params

#: the physics step of these tests (s)
DT = 0.01


def make_rovers(n: int, **params: float) -> tuple[pymunk.Space, list[DiffDriveRover]]:
    space = pymunk.Space()
    box = pymunk.Body(body_type=pymunk.Body.STATIC)  # a static body first: rows must map
    space.add(box, pymunk.Poly.create_box(box, (1, 1)))
    rovers = [
        DiffDriveRover(
            space,
            f"R{i}",
            mass_kg=30.0,
            length_m=0.8,
            width_m=0.6,
            track_m=0.5,
            wheel=wheel_model(rover_params(efficiency=90.0, **params), 9.81),
            x=5.0 * i,
            y=1.0,
            heading=0.3 * i,
            collision_type=1,
        )
        for i in range(n)
    ]
    return space, rovers


#: (mu, crr) under each wheel: dry ground, mud, ice, one wheel on each
GROUNDS = [((0.8, 0.02), (0.8, 0.02)), ((0.3, 0.15), (0.3, 0.15)), ((0.05, 0.02), (0.8, 0.02))]


def every_regime(n: int) -> tuple[pymunk.Space, list[DiffDriveRover], list[tuple], list]:
    """``n`` rovers in every regime of the wheel model, with their rim speeds and grounds.

    Rims spinning forwards and backwards, faster and slower than the ground, exactly at rest
    (stuck or breaking away), motors current-limited, regenerating, inside the deadband,
    tyres gripping and saturated, on dry ground, mud and ice.
    """
    space, rovers = make_rovers(n)
    rng = random.Random(4)
    rims, grounds = [], []
    for k, r in enumerate(rovers):
        kind = k % 5
        if kind == 0:  # at rest, small commands: stuck or just breaking away
            r.set_power(rng.uniform(-8, 8), rng.uniform(-8, 8))
            rims.append((0.0, 0.0))
        else:
            r.body.velocity = (rng.uniform(-3, 3), rng.uniform(-3, 3))
            r.body.angular_velocity = rng.uniform(-3, 3)
            r.set_power(rng.choice([100, -100, 0, 1.5, 37.5]), rng.uniform(-100, 100))
            spin = rng.choice([0.0, 1.0, 1.3, -2.0])  # rims locked, rolling, spinning, reversed
            rims.append((spin * rng.uniform(-3, 3), rng.uniform(-3, 3)))
        grounds.append(GROUNDS[k % len(GROUNDS)])
    return space, rovers, rims, grounds
