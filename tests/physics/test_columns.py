"""The batch's column integration (``physics/columns.py``) is Chipmunk's, bit for bit: a
body without contacts ends every step on the floats pymunk gives it, with the second-order
pose correction every Chipmunk step of a run gets (``bodyio.trapezoid``)."""

from __future__ import annotations

import numpy as np
import pymunk

from amsa_phys.physics.bodyio import trapezoid, velocities
from amsa_phys.physics.columns import _body_state, _ColumnIO


def test_column_integration_is_chipmunks_bit_for_bit() -> None:
    rng = np.random.default_rng(5)
    space = pymunk.Space()
    bodies = []
    for _ in range(20):
        body = pymunk.Body(float(rng.uniform(5, 50)), float(rng.uniform(1, 20)))
        body.position = tuple(rng.uniform(-100, 100, 2).tolist())
        body.angle = float(rng.uniform(-4, 4))
        body.velocity = tuple(rng.uniform(-5, 5, 2).tolist())
        body.angular_velocity = float(rng.uniform(-2, 2))
        space.add(body)
        bodies.append(body)
    state = np.array([_body_state(b) for b in bodies])
    io = _ColumnIO(
        state, np.array([1.0 / b.mass for b in bodies]), np.array([1.0 / b.moment for b in bodies])
    )
    for _ in range(200):
        forces = rng.normal(0.0, 60.0, (len(bodies), 3))
        for body, (fx, fy, t) in zip(bodies, forces.tolist(), strict=True):
            body.force = (fx, fy)
            body.torque = t
        before = velocities(bodies)
        space.step(0.01)
        trapezoid(bodies, before, 0.5 * 0.01)
        io.forces[:] = forces.ravel()
        io.step(0.01)
        expected = np.array([_body_state(b) for b in bodies])
        assert np.array_equal(io.state, expected)
