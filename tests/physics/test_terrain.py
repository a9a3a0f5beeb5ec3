"""Terrain: friction zones change the ground under each wheel, from the timeline too."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from rig import drive, traction_accel

import amsa_phys.physics.fleet as fleet
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario
from amsa_phys.physics.space import wheel_model
from amsa_phys.physics.templates import rover_params
from amsa_phys.physics.terrain import Terrain, Zone

G = 9.81
#: an L-shaped (concave) zone and a square over its corner, declared after it
L_SHAPE = ((0, 0), (4, 0), (4, 1), (1, 1), (1, 4), (0, 4))
SQUARE = ((0.5, 0.5), (1.5, 0.5), (1.5, 1.5), (0.5, 1.5))


def test_zone_lookup_handles_concave_polygons_and_overlaps() -> None:
    terrain = Terrain(0.8, 0.02)
    terrain.add(Zone("L", L_SHAPE, 0.3, 0.1))
    terrain.add(Zone("Ice", SQUARE, 0.05, 0.02))
    expected = {
        (3.0, 0.5): 0,  # the L's foot
        (0.5, 3.0): 0,  # its leg
        (3.0, 3.0): -1,  # the notch of the L: outside
        (1.2, 1.2): 1,  # the square, declared last, wins where both are
        (1.2, 0.8): 1,
        (-1.0, 0.5): -1,
    }
    for (x, y), zone in expected.items():
        assert terrain.locate(x, y) == zone, (x, y)
    assert terrain.ground(1) == (0.05, 0.02)
    assert terrain.ground(-1) == (0.8, 0.02)
    # the many-point lookup (the numpy path) agrees everywhere
    rng = np.random.default_rng(1)
    x, y = rng.uniform(-1, 5, 4000), rng.uniform(-1, 5, 4000)
    many = terrain.locate_many(x, y)
    assert many.tolist() == [terrain.locate(a, b) for a, b in zip(x, y, strict=True)]


def zone_world(friction: float, rolling: float) -> dict[str, Any]:
    """A zone covering the rig rover's whole course."""
    poly = [[-5, -50], [500, -50], [500, 50], [-5, 50]]
    return {
        "template": "frictionZone",
        "freq": 1,
        "params": {"friction": friction, "rollingResistance": rolling, "polygon": poly},
    }


def zoned_drive(
    tmp_path: Path, zone: dict[str, Any], *args: Any, **kwargs: Any
) -> tuple[dict[str, np.ndarray], Simulation]:
    """The rig, with ``zone`` added to its world as the component ``Mud``."""
    tr, sim = drive(tmp_path, *args, **kwargs, extra={"Mud": zone})
    return tr, sim


def test_top_speed_in_a_zone_follows_its_rolling_resistance(tmp_path: Path) -> None:
    tr, _ = zoned_drive(tmp_path, zone_world(0.8, 0.06), 100, 100, 20)
    wheel = wheel_model(rover_params(), G)
    expected = wheel.steady_speed(100, 0.06)  # 1.6 (1 - (0.06 * 147.15 + 2) / 120)
    assert abs(tr["Rover.speed"][-1] - expected) / expected < 0.001
    assert expected < wheel.steady_speed(100, 0.02) - 0.05  # the zone, not the world's ground


def test_mud_from_the_timeline_caps_the_grip(tmp_path: Path) -> None:
    """A rover far stronger than its tyres: at its traction limit on the zone's mu (its
    closed form ``rig.traction_accel``), on mu 0.8 until t = 1, when the zone turns to ice,
    on 0.1 from then on."""
    robot = {"stallForce": 2000.0, "freeSpeed": 20.0, "maxWheelTorque": 15.0}
    tr, sim = zoned_drive(
        tmp_path,
        zone_world(0.8, 0.02),
        100,
        100,
        2,
        robot=robot,
        timeline=[{"at": 1, "set": {"Mud.friction": 0.1}}],
        rate_hz=100,
    )
    t = tr["t"]
    accel = np.diff(tr["Rover.speed"]) / np.diff(t)
    before = (t[1:] > 0.2) & (t[1:] <= 1.0)
    after = t[1:] > 1.05
    assert np.abs(accel[before] - traction_accel(0.8, robot, G)).max() < 1e-6 * G
    assert np.abs(accel[after] - traction_accel(0.1, robot, G)).max() < 1e-6 * G
    # the encoders see the wheels spin up on the ice
    assert (tr["Rover.wheelSpeedL"] - tr["Rover.speed"])[-1] > 1.0
    assert sim.shared["physics"].terrain.zones[0].friction == 0.1


def test_one_wheel_in_mud_pulls_the_rover_towards_it(tmp_path: Path) -> None:
    """Driving along the edge of a zone of heavy mud on the left: the left wheel resists more,
    the rover turns left (counter-clockwise)."""
    mud = zone_world(0.8, 0.3)
    mud["params"]["polygon"] = [[-5, 0.0], [500, 0.0], [500, 50], [-5, 50]]
    tr, _ = zoned_drive(tmp_path, mud, 100, 100, 2)
    assert tr["Rover.heading"][-1] > 0.05
    assert tr["Rover.wheelSpeedL"][-1] < tr["Rover.wheelSpeedR"][-1]


def crossing_world(tmp_path: Path, rovers: int) -> Path:
    """``rovers`` rovers driving at different powers through two zones (mud, then ice)."""
    comps: dict[str, Any] = {
        "Mud": {
            "template": "frictionZone",
            "freq": 1,
            "params": {
                "friction": 0.4,
                "rollingResistance": 0.2,
                "polygon": [[3, -100], [6, -100], [6, 100], [3, 100]],
            },
        },
        "Ice": {
            "template": "frictionZone",
            "freq": 1,
            "params": {
                "friction": 0.05,
                "rollingResistance": 0.02,
                "polygon": [[5, -100], [9, -100], [9, 100], [5, 100]],
            },
        },
    }
    for i in range(rovers):
        left, right = 90 - 2 * i, 90 - i  # nearly straight, at different speeds
        comps[f"Ctl{i}"] = {
            "template": "ConstantPower",
            "freq": 10,
            "params": {"left": left, "right": right},
        }
        comps[f"Rover{i}"] = {
            "template": "controlledRobot",
            "freq": 10,
            "params": {
                "y": 2.0 * i,
                "heading": 0.1 * (i % 5),
                "maxWheelTorque": 10.0 if i % 2 else 4.0,
            },
            "inputs": {
                "powerL": f"Norm{i}.normalizedPowerL",
                "powerR": f"Norm{i}.normalizedPowerR",
            },
        }
        comps[f"Norm{i}"] = {
            "template": "NormalizePower",
            "freq": 10,
            "inputs": {"powerL": f"Ctl{i}.LeftPower", "powerR": f"Ctl{i}.RightPower"},
        }
    path = tmp_path / "cross.yaml"
    path.write_text(yaml.safe_dump({"world": {"components": comps}, "duration": 12}))
    return path


def final_states(path: Path, monkeypatch: pytest.MonkeyPatch, batch_min: int) -> list:
    monkeypatch.setattr(fleet, "BATCH_MIN", batch_min)
    sim = Simulation.from_scenario(load_scenario(path))
    sim.run()
    return [(*r.kinematics(), *r.wheel_speeds()) for r in sim.shared["physics"].rovers]


def test_zones_act_alike_on_the_float_and_the_numpy_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = crossing_world(tmp_path, 6)
    floats = final_states(path, monkeypatch, 10**9)
    arrays = final_states(path, monkeypatch, 2)
    for a, b in zip(floats, arrays, strict=True):
        assert a == pytest.approx(b, abs=1e-9)
    xs = [s[0] for s in floats]
    assert min(xs) < 9 < max(xs)  # one rover still in a zone at the end, others through both
