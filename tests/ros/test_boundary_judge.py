"""``ros/boundary.py``'s ``judge``: what a robot's driver may send, said in one short reason.

The one mapping both boundary nodes use (ROS 1's ``sim:=false``, ROS 2's ``amsa_boundary``);
no ROS needed: it reads fields, which the messages of both share.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from types import SimpleNamespace

import pytest

from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.boundary import Refused, judge, plan, read_fields
from amsa_phys.ros.graph import RosGraph, classify
from amsa_phys.stdmsgs import DEFAULT_ORIGIN, enu_to_geodetic, yaw_quaternion

ROOT = Path(__file__).resolve().parent.parent.parent


def _source(scenario: str, role: str):  # type: ignore[no-untyped-def]
    world = load_scenario(ROOT / "scenarios" / scenario).world
    inbound = plan(RosGraph.of(world, classify(world))).inbound
    return next(s for s in inbound if s.role.name == role)


def _imu(yaw: float = 0.5, **cov: list[float]) -> SimpleNamespace:
    zeros = [0.0] * 9
    return SimpleNamespace(
        header=SimpleNamespace(frame_id="Rover/base_link"),
        orientation=SimpleNamespace(**yaw_quaternion(yaw)),
        orientation_covariance=cov.get("orientation", zeros),
        angular_velocity=SimpleNamespace(x=0.0, y=0.0, z=0.25),
        angular_velocity_covariance=cov.get("angular_velocity", zeros),
        linear_acceleration=SimpleNamespace(x=0.5, y=-0.1, z=9.8),
        linear_acceleration_covariance=cov.get("linear_acceleration", zeros),
    )


def test_a_good_message_reads_as_the_leafs_outputs() -> None:
    assert judge(_source("obstacle_course.yaml", "Imu"), _imu(), DEFAULT_ORIGIN) == {
        "gyro_z": 0.25,
        "accel_x": 0.5,
        "accel_y": -0.1,
    }
    got = judge(_source("obstacle_course.yaml", "Heading"), _imu(0.7), DEFAULT_ORIGIN)
    assert got is not None
    assert got["yaw"] == pytest.approx(0.7, abs=1e-12)


@pytest.mark.parametrize(
    ("role", "cov", "why"),
    [
        ("Heading", "orientation", "orientation not provided (orientation_covariance[0] = -1)"),
        (
            "Imu",
            "angular_velocity",
            "angular velocity not provided (angular_velocity_covariance[0] = -1)",
        ),
        (
            "Imu",
            "linear_acceleration",
            "linear acceleration not provided (linear_acceleration_covariance[0] = -1)",
        ),
    ],
)
def test_a_quantity_the_driver_does_not_provide_is_refused(role: str, cov: str, why: str) -> None:
    src = _source("obstacle_course.yaml", role)
    with pytest.raises(Refused, match="^" + re.escape(why) + "$"):
        judge(src, _imu(**{cov: [-1.0] + [0.0] * 8}), DEFAULT_ORIGIN)
    assert read_fields(src, _imu(**{cov: [-1.0] + [0.0] * 8}), DEFAULT_ORIGIN) is None


def test_an_unset_quaternion_is_no_heading() -> None:
    src = _source("obstacle_course.yaml", "Heading")
    msg = _imu()
    msg.orientation = SimpleNamespace(x=0.0, y=0.0, z=0.0, w=0.0)
    with pytest.raises(Refused, match="orientation is not a rotation"):
        judge(src, msg, DEFAULT_ORIGIN)


def test_the_frame_is_checked_only_when_asked() -> None:
    src = _source("paper_fig6_sensed.yaml", "NavSatFix")
    lat, lon = enu_to_geodetic(3.0, 4.0, DEFAULT_ORIGIN)
    fix = SimpleNamespace(
        header=SimpleNamespace(frame_id="gps_link"),
        status=SimpleNamespace(status=0),
        latitude=lat,
        longitude=lon,
    )
    assert judge(src, fix, DEFAULT_ORIGIN) is not None
    with pytest.raises(Refused, match=f"frame_id 'gps_link', expected '{src.frame_id}'"):
        judge(src, fix, DEFAULT_ORIGIN, frame=src.frame_id)
    fix.header.frame_id = src.frame_id
    got = judge(src, fix, DEFAULT_ORIGIN, frame=src.frame_id)
    assert got is not None
    assert (got["x"], got["y"]) == (pytest.approx(3.0), pytest.approx(4.0))


def test_a_lost_fix_is_no_fault_and_a_nan_one_is() -> None:
    src = _source("paper_fig6_sensed.yaml", "NavSatFix")
    lost = SimpleNamespace(status=SimpleNamespace(status=-1), latitude=math.nan, longitude=0.0)
    assert judge(src, lost, DEFAULT_ORIGIN) is None
    bad = SimpleNamespace(status=SimpleNamespace(status=0), latitude=math.nan, longitude=0.0)
    with pytest.raises(Refused, match=r"^latitude is nan$"):
        judge(src, bad, DEFAULT_ORIGIN)


def test_an_empty_scan_is_refused() -> None:
    src = _source("obstacle_course.yaml", "LaserScan")
    scan = SimpleNamespace(
        ranges=[], angle_min=-1.0, angle_increment=0.1, range_min=0.1, range_max=10.0
    )
    with pytest.raises(Refused, match=r"^no ranges$"):
        judge(src, scan, DEFAULT_ORIGIN)
