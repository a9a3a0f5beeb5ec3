"""The standard-message mapping: definitions, geodesy, roles read from declarations, CDR."""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path
from typing import Any, ClassVar

import pytest
from mcap_ros2._dynamic import serialize_dynamic
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

import amsa_phys as ap
from amsa_phys.bag.writer import scalar_cdr
from amsa_phys.model.template import Kind, Port, Template
from amsa_phys.model.world import load_world
from amsa_phys.stdmsgs import (
    Context,
    build,
    enu_to_geodetic,
    find_sources,
    geodetic_to_enu,
    msgdef,
    quaternion_yaw,
    schema_name,
    variance,
    yaw_quaternion,
)
from amsa_phys.stdmsgs.defs import FIELDS
from amsa_phys.stdmsgs.names import ros_path

ROOT = Path(__file__).resolve().parents[2]
STANDARD = [n for n in FIELDS if not n.startswith("amsa_msgs/")]
HUMBLE = get_typestore(Stores.ROS2_HUMBLE)


@pytest.mark.parametrize("name", STANDARD)
def test_definitions_are_ros2_humbles(name: str) -> None:
    """Every standard type's text is the one rosbags generates from ROS 2's own interfaces."""
    reference, _ = HUMBLE.generate_msgdef(schema_name(name), ros_version=2)
    assert msgdef(name) == reference


@pytest.mark.parametrize("name", ["amsa_msgs/Scalar", "amsa_msgs/Event"])
def test_own_types_parse_as_ros2_definitions(name: str) -> None:
    types = get_types_from_msg(FIELDS[name], schema_name(name))
    fields = [f[0] for f in types[schema_name(name)][1]]
    assert fields[0] == "header"


def test_scalar_cdr_is_the_librarys_and_decodes() -> None:
    """The hand-packed scalar equals mcap-ros2-support's encoding and rosbags reads it."""
    name = schema_name("amsa_msgs/Scalar")
    encode = serialize_dynamic(name, msgdef("amsa_msgs/Scalar"))[name]
    for ns, value in [(0, 0.0), (1_250_000_000, -3.5), (10**13 + 7, 1e-300), (3, math.pi)]:
        msg = {"header": {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}, "frame_id": ""}}
        assert scalar_cdr(ns, value) == encode({**msg, "data": value})
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(FIELDS["amsa_msgs/Scalar"], name))
    decoded = store.deserialize_cdr(scalar_cdr(2_500_000_001, 42.25), name)
    assert (decoded.header.stamp.sec, decoded.header.stamp.nanosec) == (2, 500_000_001)
    assert decoded.data == 42.25


def test_geodetic_round_trip_and_scale() -> None:
    origin = (43.5616, 1.4683)
    for x, y in [(0.0, 0.0), (123.4, -56.7), (-1000.0, 2500.0)]:
        lat, lon = enu_to_geodetic(x, y, origin)
        back = geodetic_to_enu(lat, lon, origin)
        assert back == pytest.approx((x, y), abs=1e-6)
    # 1 km north is 1000 m / (length of a degree of latitude), the textbook series for
    # WGS 84: 111132.954 - 559.822 cos 2φ + 1.175 cos 4φ metres per degree
    phi = math.radians(origin[0])
    per_degree = 111132.954 - 559.822 * math.cos(2 * phi) + 1.175 * math.cos(4 * phi)
    lat, lon = enu_to_geodetic(0.0, 1000.0, origin)
    assert lat - origin[0] == pytest.approx(1000.0 / per_degree, rel=1e-6)
    assert lon == origin[1]
    # east: a degree of longitude is shorter by cos(latitude) (prime vertical radius)
    lat, lon = enu_to_geodetic(1000.0, 0.0, origin)
    assert (lon - origin[1]) * math.cos(phi) * 111320 == pytest.approx(1000.0, rel=3e-3)


@pytest.mark.parametrize("yaw", [0.0, 1.0, -2.5, math.pi - 1e-9])
def test_yaw_quaternion_round_trip(yaw: float) -> None:
    q = yaw_quaternion(yaw)
    assert q["x"] ** 2 + q["y"] ** 2 + q["z"] ** 2 + q["w"] ** 2 == pytest.approx(1.0)
    assert quaternion_yaw(q) == pytest.approx(yaw)


def test_mde_world_topics_and_frames() -> None:
    """The MDE challenge: both robots' poses, the follower's wheel commands, two fixes, the
    compass, on the documented topics, each sensor placed on the robot it measures."""
    got = {
        (s.role.name, s.leaf, s.topic, s.frame_id)
        for s in find_sources(load_world(ROOT / "worlds/mde_challenge.yaml"))
    }
    assert got == {
        ("Pose", "Leader", "/Leader/ground_truth/odom", "map"),
        ("Pose", "Follower", "/Follower/ground_truth/odom", "map"),
        ("WheelCommand", "Follower", "/Follower/wheel_cmd", "Follower/base_link"),
        ("NavSatFix", "LeaderGPS", "/Leader/LeaderGPS/fix", "Leader/base_link"),
        ("NavSatFix", "FollowerGPS", "/Follower/FollowerGPS/fix", "Follower/base_link"),
        ("Heading", "FollowerCompass", "/Follower/FollowerCompass/heading", "Follower/base_link"),
    }


def test_obstacle_course_has_every_sensor_type() -> None:
    sources = find_sources(load_world(ROOT / "worlds/obstacle_course.yaml"))
    msgs = {s.role.name: s.role.msg for s in sources}
    assert msgs["LaserScan"] == "sensor_msgs/LaserScan"
    assert msgs["Imu"] == "sensor_msgs/Imu"
    assert msgs["Odometry"] == "nav_msgs/Odometry"
    scan = next(s for s in sources if s.role.name == "LaserScan")
    assert scan.topic == "/Rover/Scanner/scan"
    assert len(scan.buffers["ranges"]) == 31  # one buffer per beam, in order
    assert scan.buffers["ranges"][3] == "Scanner.ranges[3]"


# -- user templates: the mapping reads declarations, not template names -------------------
class Receiver(Template):
    """A GPS by another name with the built-in port names."""

    kind = Kind.SENSOR
    inputs = (Port("posX"), Port("posY"))
    outputs = (Port("gpsPosX"), Port("gpsPosY"))


class Renamed(Template):
    """A GPS whose ports are named otherwise, and says which field each is."""

    kind = Kind.SENSOR
    inputs = (Port("posX"), Port("posY"))
    outputs = (Port("east"), Port("north"))
    standard_messages: ClassVar[dict[str, dict[str, str]]] = {
        "NavSatFix": {"x": "east", "y": "north"}
    }


class OptedOut(Template):
    """The built-in port names, but declares it fills no standard message."""

    kind = Kind.SENSOR
    inputs = (Port("posX"), Port("posY"))
    outputs = (Port("gpsPosX"), Port("gpsPosY"))
    standard_messages: ClassVar[dict[str, dict[str, str]]] = {}


class Tracker(Template):
    """The GPS's ports on an observer: a kind NavSatFix does not come from."""

    kind = Kind.OBSERVER
    inputs = (Port("posX"), Port("posY"))
    outputs = (Port("gpsPosX"), Port("gpsPosY"))


def _world(**sensors: str) -> Any:
    comps: dict[str, Any] = {"Bot": {"template": "freeRobot", "freq": 10}}
    for name, template in sensors.items():
        comps[name] = {
            "template": f"test_stdmsgs:{template}",
            "freq": 5,
            "inputs": {"posX": "Bot.posX", "posY": "Bot.posY"},
        }
    return ap.load({"world": {"name": "w", "components": comps}, "duration": 1}).world


def test_roles_come_from_declarations_not_names() -> None:
    world = _world(A="Receiver", B="Renamed", C="OptedOut", D="Tracker")
    fixes = {s.leaf: s for s in find_sources(world) if s.role.name == "NavSatFix"}
    assert sorted(fixes) == ["A", "B"]
    assert fixes["A"].buffers == {"x": "A.gpsPosX", "y": "A.gpsPosY"}
    assert fixes["B"].buffers == {"x": "B.east", "y": "B.north"}
    assert fixes["B"].topic == "/Bot/B/fix"
    assert fixes["B"].frame_id == "Bot/base_link"


def test_variance_from_the_noise_model() -> None:
    p = {"stddev": 0.5, "bias_mean": 0.3, "bias_stddev": 0.4, "precision": 0.1}
    assert variance(p, "", 0.0) == pytest.approx(0.25 + 0.09 + 0.16 + 0.01 / 12)
    gm = {"stddev": 0.0, "dynamic_bias_stddev": 0.2, "dynamic_bias_correlation_time": 50.0}
    assert variance(gm, "", 7.0) == pytest.approx(0.04 * 25)  # stationary: σ²T/2
    walk = {"stddev": 0.0, "dynamic_bias_stddev": 0.2, "dynamic_bias_correlation_time": 0.0}
    assert variance(walk, "", 9.0) == pytest.approx(0.04 * 9)  # a random walk grows as t
    assert variance({"gyro_stddev": 0.1}, "gyro_", 1.0) == pytest.approx(0.01)
    assert variance({"x": 1}, "", 1.0) is None


def test_navsatfix_message() -> None:
    world = load_world(ROOT / "worlds/mde_challenge.yaml")
    src = next(s for s in find_sources(world) if s.leaf == "FollowerGPS")
    ctx = Context((3, 250_000_000), 3.25, 0.25, (43.0, 1.0))
    values = {"FollowerGPS.gpsPosX": 10.0, "FollowerGPS.gpsPosY": -20.0}
    msg = build(src, values, {"stddev": 2.0}, ctx)
    assert msg["header"] == {
        "stamp": {"sec": 3, "nanosec": 250_000_000},
        "frame_id": "Follower/base_link",
    }
    assert geodetic_to_enu(msg["latitude"], msg["longitude"], (43.0, 1.0)) == pytest.approx(
        (10.0, -20.0)
    )
    assert msg["position_covariance"] == [4.0, 0, 0, 0, 4.0, 0, 0, 0, 0]
    assert msg["position_covariance_type"] == 2  # DIAGONAL_KNOWN
    assert msg["status"] == {"status": 0, "service": 1}  # STATUS_FIX, SERVICE_GPS


def test_ros_names() -> None:
    assert ros_path("Team.Car3.GPS") == "Team/Car3/GPS"
    assert ros_path("Lidar.ranges[12]") == "Lidar/ranges_12"
    assert ros_path("a.3d") == "a/_3d"


def test_fraction_free_context() -> None:
    """A builder's context holds plain numbers (the stamp is integers)."""
    ctx = Context((1, 2), float(Fraction(1, 3)), 0.1, (0.0, 0.0))
    assert isinstance(ctx.t_s, float)


def _sample(name: str) -> dict[str, Any]:
    """A message of every type amsa-phys writes, with odd values (strings of several
    lengths, empty and full sequences, negative and tiny numbers) to exercise alignment."""
    h = {"stamp": {"sec": 12, "nanosec": 345}, "frame_id": "Car3/Robot/base_link"}
    vec = {"x": 1.5, "y": -2.25, "z": 1e-300}
    quat = {"x": 0.0, "y": 0.0, "z": 0.5, "w": 0.8660254037844386}
    cov36 = [float(i) for i in range(36)]
    samples: dict[str, dict[str, Any]] = {
        "sensor_msgs/NavSatFix": {
            "header": h,
            "status": {"status": -1, "service": 1},
            "latitude": 43.5,
            "longitude": -1.25,
            "altitude": 0.0,
            "position_covariance": [0.1 * i for i in range(9)],
            "position_covariance_type": 2,
        },
        "sensor_msgs/Imu": {
            "header": h,
            "orientation": quat,
            "orientation_covariance": [-1.0, *[0.0] * 8],
            "angular_velocity": vec,
            "angular_velocity_covariance": [0.0] * 9,
            "linear_acceleration": vec,
            "linear_acceleration_covariance": [0.5] * 9,
        },
        "nav_msgs/Odometry": {
            "header": h,
            "child_frame_id": "a",
            "pose": {"pose": {"position": vec, "orientation": quat}, "covariance": cov36},
            "twist": {"twist": {"linear": vec, "angular": vec}, "covariance": cov36},
        },
        "sensor_msgs/LaserScan": {
            "header": {**h, "frame_id": "ab"},
            "angle_min": -1.5,
            "angle_max": 1.5,
            "angle_increment": 0.1,
            "time_increment": 0.0,
            "scan_time": 0.2,
            "range_min": 0.1,
            "range_max": 20.0,
            "ranges": [1.0, 2.5, 20.0, 0.123456789],
            "intensities": [],
        },
        "sensor_msgs/JointState": {
            "header": h,
            "name": ["left_wheel_joint", "right_wheel_joint", "x"],
            "position": [],
            "velocity": [1.0],
            "effort": [-35.5, 40.0, 0.0],
        },
        "tf2_msgs/TFMessage": {
            "transforms": [
                {
                    "header": h,
                    "child_frame_id": f"r{i}/base_link",
                    "transform": {"translation": vec, "rotation": quat},
                }
                for i in range(3)
            ]
        },
        "amsa_msgs/Event": {"header": h, "kind": "phase", "detail": "phase 1: Kv=0.15 é"},
        "amsa_msgs/Scalar": {"header": {**h, "frame_id": ""}, "data": -0.0},
    }
    return samples[name]


WRITTEN = [
    "sensor_msgs/NavSatFix",
    "sensor_msgs/Imu",
    "nav_msgs/Odometry",
    "sensor_msgs/LaserScan",
    "sensor_msgs/JointState",
    "tf2_msgs/TFMessage",
    "amsa_msgs/Event",
    "amsa_msgs/Scalar",
]


@pytest.mark.parametrize("name", WRITTEN)
def test_cdr_encoder_is_byte_for_byte_the_librarys(name: str) -> None:
    """amsa-phys's compiled CDR encoder against mcap-ros2-support's, on every type written."""
    from amsa_phys.bag.cdr import encoder

    msg = _sample(name)
    reference = serialize_dynamic(schema_name(name), msgdef(name))[schema_name(name)]
    assert encoder(name)(msg) == reference(msg)


def test_cdr_encoder_refuses_a_wrong_fixed_array() -> None:
    from amsa_phys.bag.cdr import encoder

    msg = _sample("sensor_msgs/NavSatFix")
    msg["position_covariance"] = [0.0] * 8
    with pytest.raises(ValueError, match="expected 9 elements, got 8"):
        encoder("sensor_msgs/NavSatFix")(msg)
