"""Contacts: a rover pushing on a wall rests at its surface; a collision is an episode.

The wall of ``physics.walls`` is a segment of radius 0.1 m on the line ``xmax``, so its
surface is at ``xmax - 0.1``; the rover's collision box is exactly its length × width (rounded
corners inside it), so its front face is at ``x + length / 2``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rig import drive

from amsa_phys.physics import space

WALL_SURFACE = 20.0 - 0.1
MDE_ROVER = {"stallForce": 45.0, "freeSpeed": 5.5, "maxWheelTorque": 4.5, "jointFriction": 0.0}


def push_on_wall(tmp_path: Path, robot: dict[str, Any]) -> tuple[dict[str, np.ndarray], Any]:
    walls = {"xmin": -50, "xmax": 20, "ymin": -50, "ymax": 50}
    return drive(tmp_path, 100, 100, 30, robot=robot, physics={"walls": walls})


@pytest.mark.parametrize("robot", [{}, MDE_ROVER], ids=["default rover", "mde rover"])
def test_a_rover_pushing_on_a_wall_rests_within_5_mm_of_it(
    tmp_path: Path, robot: dict[str, Any]
) -> None:
    tr, sim = push_on_wall(tmp_path, robot)
    front = tr["Rover.posX"] + 0.4
    assert abs(tr["Rover.speed"][-1]) < 1e-6  # at rest, the motors still pushing at full power
    assert abs(front[-1] - WALL_SURFACE) <= 0.005  # pymunk's default slop: 3.3 cm inside
    # the impact itself sinks in at most one step's travel (Chipmunk finds the overlap at the
    # end of the step: where in the step the wall is met is the luck of the step grid; the
    # MDE rover meets it at 4.8 m/s, 4.8 cm a step) plus the slop, and is pushed out
    impact = float(np.abs(tr["Rover.speed"]).max()) * 0.01
    assert (front - WALL_SURFACE).max() < impact + 0.002
    assert [e.detail for e in sim.events if e.kind == "collision"] == ["Rover-wall"]


def test_mutation_rest_check_fails_with_pymunks_default_slop(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(space, "CONTACT_SLOP_M", 0.1)
    monkeypatch.setattr(space, "CONTACT_BIAS", (1 - 0.1) ** 60)
    tr, _ = push_on_wall(tmp_path, MDE_ROVER)
    assert tr["Rover.posX"][-1] + 0.4 - WALL_SURFACE > 0.005


def corner_hits(tmp_path: Path) -> list[str]:
    """A rover driven diagonally into the corner of its arena: two wall segments touch it."""
    walls = {"xmin": -50, "xmax": 20, "ymin": -50, "ymax": 20}
    tr, sim = drive(tmp_path, 100, 100, 25, robot={"heading": 0.785398}, physics={"walls": walls})
    assert tr["Rover.posX"][-1] > 19.0
    assert tr["Rover.posY"][-1] > 19.0  # in the corner, touching both walls
    return [e.detail for e in sim.events if e.kind == "collision"]


def test_a_corner_hit_is_one_collision(tmp_path: Path) -> None:
    assert corner_hits(tmp_path) == ["Rover-wall"]


def test_mutation_corner_check_fails_counting_shape_pairs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Counting every touching pair of shapes (as pymunk's begin callback does) gives two."""
    monkeypatch.setattr(
        space.PhysicsWorld, "_pair", lambda self, arbiter: tuple(id(s) for s in arbiter.shapes)
    )
    assert len(corner_hits(tmp_path)) == 2


def test_leaving_and_coming_back_is_a_second_collision(tmp_path: Path) -> None:
    walls = {"xmin": -50, "xmax": 20, "ymin": -50, "ymax": 50}
    timeline = [
        {"at": 16, "set": {"Ctl.left": -100, "Ctl.right": -100}},  # back off for 3 s
        {"at": 19, "set": {"Ctl.left": 100, "Ctl.right": 100}},  # and drive in again
    ]
    tr, sim = drive(tmp_path, 100, 100, 30, physics={"walls": walls}, timeline=timeline)
    assert tr["Rover.posX"][tr["t"] == 19][0] < 16.0  # it really left
    hits = [(float(e.t), e.detail) for e in sim.events if e.kind == "collision"]
    assert [d for _, d in hits] == ["Rover-wall", "Rover-wall"]
    assert hits[0][0] < 16 < 19 < hits[1][0]
