"""What a robotics tool reads from a bag beyond the values: gravity, frames, covariances, time.

Read back with ``rosbags`` (the library ROS 2 users reach for, independent of the writer's
``mcap`` stack). Each property is one a consumer relies on without looking at the data:

* REP 145: a level IMU at rest reads +g on z (a filter subtracts it; without it, the robot
  seems to fall at 1 g);
* REP 105: per robot, ``map`` -> ``odom`` -> ``base_link`` (rviz, Foxglove and the
  navigation stack look for ``odom``), composing to the true pose;
* wheel odometry states the covariance of its noise model, the error it really shows;
* every stamp is simulated time from 0, the bag says so, and stamps equal log times.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

import amsa_phys as ap
from amsa_phys.stdmsgs import GRAVITY, quaternion_yaw

ROOT = Path(__file__).resolve().parents[2]
OBSTACLES = ROOT / "scenarios" / "obstacle_course.yaml"
NS = 1_000_000_000


def _read(bag: Path) -> dict[str, list[tuple[int, Any]]]:
    """topic -> [(log time, message)] in log order."""
    out: dict[str, list[tuple[int, Any]]] = {}
    with AnyReader([bag]) as reader:
        for conn, t, raw in reader.messages():
            out.setdefault(conn.topic, []).append((t, reader.deserialize(raw, conn.msgtype)))
    return out


@pytest.fixture(scope="module")
def obstacle_bag(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[tuple[int, Any]]]:
    bag = tmp_path_factory.mktemp("frames") / "obs.mcap"
    ap.run(OBSTACLES, duration=10, bag=bag)
    return _read(bag)


def test_the_imu_reads_gravity_upwards(obstacle_bag: dict[str, list[tuple[int, Any]]]) -> None:
    imus = [m for _, m in obstacle_bag["/Rover/Imu/imu"]]
    assert imus
    assert all(m.linear_acceleration.z == GRAVITY for m in imus)
    assert pytest.approx(9.81, abs=0.01) == GRAVITY


def test_tf_is_map_odom_base_link_and_composes_to_the_truth(
    obstacle_bag: dict[str, list[tuple[int, Any]]],
) -> None:
    static = obstacle_bag["/tf_static"]
    assert len(static) == 1
    assert static[0][0] == 0
    fixed = {tf.child_frame_id: tf for tf in static[0][1].transforms}
    assert set(fixed) == {"Rover/odom", "Parked/odom"}  # every robot of the world
    for tf in fixed.values():
        assert tf.header.frame_id == "map"
        tr, rot = tf.transform.translation, tf.transform.rotation
        assert (tr.x, tr.y, tr.z, rot.x, rot.y, rot.z, rot.w) == (0, 0, 0, 0, 0, 0, 1)
    truth = {t: m for t, m in obstacle_bag["/Rover/ground_truth/odom"]}
    assert all(m.header.frame_id == "map" for m in truth.values())
    moving = [
        (t, tf)
        for t, msg in obstacle_bag["/tf"]
        for tf in msg.transforms
        if tf.child_frame_id == "Rover/base_link"
    ]
    assert len(moving) == len(truth)
    for t, tf in moving:
        assert tf.header.frame_id == "Rover/odom"
        # map -> odom is the identity, so odom -> base_link is the pose in map
        pose = truth[t].pose.pose
        assert tf.transform.translation.x == pose.position.x
        assert tf.transform.translation.y == pose.position.y
        assert tf.transform.rotation.z == pose.orientation.z
    # the wheel odometry's estimate is in the odom frame too
    odo = [m for _, m in obstacle_bag["/Rover/Odometry/odom"]]
    assert odo
    assert all(m.header.frame_id == "Rover/odom" for m in odo)


def test_stamps_are_simulated_time_from_zero(
    obstacle_bag: dict[str, list[tuple[int, Any]]], tmp_path: Path
) -> None:
    for topic, msgs in obstacle_bag.items():
        for t, m in msgs:
            header = m.transforms[0].header if topic.startswith("/tf") else m.header
            if topic == "/amsa/events":
                continue  # an event keeps its own instant inside the trace row that wrote it
            assert header.stamp.sec * NS + header.stamp.nanosec <= t, topic
    first = min(t for msgs in obstacle_bag.values() for t, _ in msgs)
    assert first == 0
    from mcap.reader import make_reader

    bag = tmp_path / "meta.mcap"
    ap.run(OBSTACLES, duration=1, bag=bag)
    with bag.open("rb") as f:
        meta = {m.name: m.metadata for m in make_reader(f).iter_metadata()}
    assert meta["amsa-phys"]["time"].startswith("simulated")


#: One rover driving straight with noisy wheel encoders read at its own rate.
ODOMETRY_WORLD = {
    "world": {
        "components": {
            "Rover": {"template": "freeRobot", "freq": 20, "params": {"behavior": 1}},
            "Odometry": {
                "template": "WheelOdometry",
                "freq": 20,
                "params": {"stddev": 0.05},
                "inputs": {"wheelSpeedL": "Rover.wheelSpeedL", "wheelSpeedR": "Rover.wheelSpeedR"},
            },
        }
    },
    "duration": 30,
    "seed": 1,
}


def test_wheel_odometry_states_the_yaw_variance_it_shows(tmp_path: Path) -> None:
    """Over seeds, the odometry's yaw error at 30 s has the variance its message states
    (its position error along the track, on a straight line, too); the yaw variance grows
    linearly in time, a random walk."""
    bag = tmp_path / "odo.mcap"
    ap.run(ODOMETRY_WORLD, bag=bag)
    odo = _read(bag)["/Rover/Odometry/odom"]
    stated = {t: m.pose.covariance for t, m in odo}
    cov_end = stated[30 * NS]
    cov_half = stated[15 * NS]
    assert cov_end[35] == pytest.approx(2 * cov_half[35])
    assert cov_end[0] > 0
    assert cov_end[7] > 0
    yaw_err, x_err, y_err = [], [], []
    for seed in range(60):
        trace = ap.run(ODOMETRY_WORLD, seed=seed).trace
        yaw = trace["Odometry.odomHeading"][-1] - trace["Rover.heading"][-1]
        yaw_err.append(math.remainder(yaw, 2 * math.pi))
        x_err.append(trace["Odometry.odomX"][-1] - trace["Rover.posX"][-1])
        y_err.append(trace["Odometry.odomY"][-1] - trace["Rover.posY"][-1])
    ratio_yaw = float(np.var(yaw_err)) / cov_end[35]
    ratio_x = float(np.var(x_err)) / cov_end[0]
    ratio_y = float(np.var(y_err)) / cov_end[7]
    # 60 samples: a variance within about ±40 % of the truth (chi-square, 99 %)
    assert 0.6 < ratio_yaw < 1.6, ratio_yaw
    assert 0.6 < ratio_x < 1.6, ratio_x
    assert 0.6 < ratio_y < 1.6, ratio_y
    assert quaternion_yaw(odo[-1][1].pose.pose.orientation) == pytest.approx(
        ap.run(ODOMETRY_WORLD).trace["Odometry.odomHeading"][-1]
    )
