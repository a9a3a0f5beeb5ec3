"""Which Leaves of a world form which standard ROS messages, read from template declarations.

A *role* is a standard message that a template can fill: its fields, and the port each
field comes from by default (the built-in templates' port names: ``gpsPosX``, ``gyroZ``,
``odomX``...). A Leaf fills a role when its template's kind is one the role allows and it
declares every required port, so a user template with the same ports gets the same message
without amsa-phys knowing its name. A template whose ports are named otherwise says so in a
class attribute, ``standard_messages = {"NavSatFix": {"x": "east", "y": "north"}}``
(role -> field -> its port); a template that declares the attribute fills only the roles it
lists (``{}``: none).

Each message is placed by following the Leaf's input links: a GPS whose ``posX`` reads
``Leader.posX`` belongs to the robot ``Leader`` (a Leaf filling the ``Pose`` role), so its
fix goes on ``/Leader/LeaderGPS/fix`` in frame ``Leader/base_link``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from ..model.template import Kind
from ..model.world import LeafSpec, WorldSpec
from .names import ros_path, unique

_ROBOT = frozenset({Kind.PROCESS, Kind.ENVIRONMENT})
_SENSOR = frozenset({Kind.SENSOR})

#: The world's fixed frame (REP 105's ``map``): x east, y north, the plane's own axes.
WORLD_FRAME = "map"


@dataclass(frozen=True)
class Role:
    """A standard message a Leaf can fill, and from which of its ports."""

    name: str
    msg: str  # ``pkg/Type``
    suffix: str  # last part of the topic name
    kinds: frozenset[Kind]
    outputs: Mapping[str, str] = field(default_factory=dict)  # field -> output port
    inputs: Mapping[str, str] = field(default_factory=dict)  # field -> input port it reads
    optional: frozenset[str] = frozenset()  # fields that may be missing


ROLES: tuple[Role, ...] = (
    Role("NavSatFix", "sensor_msgs/NavSatFix", "fix", _SENSOR, {"x": "gpsPosX", "y": "gpsPosY"}),
    Role("Heading", "sensor_msgs/Imu", "heading", _SENSOR, {"yaw": "compassHeading"}),
    Role(
        "Imu",
        "sensor_msgs/Imu",
        "imu",
        _SENSOR,
        {"gyro_z": "gyroZ", "accel_x": "accelX", "accel_y": "accelY"},
    ),
    Role(
        "Odometry",
        "nav_msgs/Odometry",
        "odom",
        _SENSOR,
        {"x": "odomX", "y": "odomY", "yaw": "odomHeading"},
    ),
    Role("LaserScan", "sensor_msgs/LaserScan", "scan", _SENSOR, {"ranges": "ranges"}),
    Role(
        "Pose",
        "nav_msgs/Odometry",
        "ground_truth/odom",
        _ROBOT,
        {"x": "posX", "y": "posY", "yaw": "heading", "speed": "speed", "yaw_rate": "yawRate"},
        optional=frozenset({"speed", "yaw_rate"}),
    ),
    Role(
        "WheelCommand",
        "sensor_msgs/JointState",
        "wheel_cmd",
        _ROBOT,
        inputs={"left": "powerL", "right": "powerR"},
    ),
)
ROLE_BY_NAME = {r.name: r for r in ROLES}


@dataclass(frozen=True)
class Source:
    """One stream of standard messages in a run: a role filled by a Leaf.

    ``buffers`` maps each field to the Data buffer it reads (an array field: the element
    buffers, in order). Messages follow ``leaf``'s own instants.
    """

    role: Role
    leaf: str
    buffers: Mapping[str, str | tuple[str, ...]]
    robot: str | None
    topic: str
    frame_id: str
    child_frame_id: str = ""


def _declared(leaf: LeafSpec) -> Mapping[str, Mapping[str, str]] | None:
    """The template's own ``standard_messages`` (None: matched by the default port names)."""
    return getattr(leaf.template, "standard_messages", None)


def _fields(leaf: LeafSpec, role: Role, world: WorldSpec) -> dict[str, str | tuple[str, ...]]:
    """Field -> buffer(s) if ``leaf`` fills ``role``, else an empty dict."""
    declared = _declared(leaf)
    if declared is not None and role.name not in declared:
        return {}
    if declared is None and leaf.kind not in role.kinds:
        return {}
    given = dict((declared or {}).get(role.name, {}))
    outs = {p.name: p for p in leaf.template.outputs}
    found: dict[str, str | tuple[str, ...]] = {}
    for fname, default in role.outputs.items():
        port = outs.get(given.get(fname, default))
        if port is None:
            if fname in role.optional:
                continue
            return {}
        name = f"{leaf.path}.{port.name}"
        found[fname] = tuple(world.arrays.get(name, ())) if port.array else name
    for fname, default in role.inputs.items():
        buf = leaf.inputs.get(given.get(fname, default))
        if buf is None:
            return {}
        found[fname] = buf
    return found


def _producer(world: WorldSpec, buffer: str) -> str | None:
    spec = world.buffers.get(buffer)
    return spec.producer if spec is not None else None


def find_sources(world: WorldSpec) -> list[Source]:
    """Every standard-message stream of ``world``, in execution order, with unique topics.

    Topic rule: a robot's own streams are ``/<robot>/<suffix>``; a sensor on a robot (its
    inputs read the robot's outputs) is ``/<robot>/<sensor>/<suffix>`` with the sensor's
    name (its full path if two sensors of one robot share a name); any other Leaf is
    ``/<leaf path>/<suffix>``. Paths keep their spelling, dots become ``/``.
    """
    leaves = world.leaves
    robots = {p for p in world.order if _fields(leaves[p], ROLE_BY_NAME["Pose"], world)}
    found: list[tuple[Role, LeafSpec, dict[str, str | tuple[str, ...]], str | None]] = []
    for path in world.order:
        leaf = leaves[path]
        for role in ROLES:
            fields = _fields(leaf, role, world)
            if not fields:
                continue
            robot = path if path in robots else None
            if robot is None:
                for buf in leaf.inputs.values():
                    producer = _producer(world, buf)
                    if producer in robots:
                        robot = producer
                        break
            found.append((role, leaf, fields, robot))
    last = [leaf.path.rsplit(".", 1)[-1] for _, leaf, _, _ in found]
    taken: set[str] = set()
    sources = []
    for (role, leaf, fields, robot), short in zip(found, last, strict=True):
        if robot == leaf.path:
            topic = f"/{ros_path(robot)}/{role.suffix}"
        elif robot is not None:
            shared = sum(
                1
                for (r2, l2, _, rb2), s2 in zip(found, last, strict=True)
                if rb2 == robot and s2 == short and r2 == role and l2 is not leaf
            )
            name = ros_path(leaf.path) if shared else ros_path(short)
            topic = f"/{ros_path(robot)}/{name}/{role.suffix}"
        else:
            topic = f"/{ros_path(leaf.path)}/{role.suffix}"
        topic = unique(topic, taken)
        base = f"{ros_path(robot)}/base_link" if robot else f"{ros_path(leaf.path)}/base_link"
        if role.name == "Pose":  # the truth, in the world's frame
            frame, child = WORLD_FRAME, base
        elif role.name == "Odometry":  # dead reckoning, in the robot's odom frame (REP 105)
            frame, child = f"{ros_path(robot or leaf.path)}/odom", base
        else:
            frame, child = base, ""
        sources.append(Source(role, leaf.path, fields, robot, topic, frame, child))
    return sources
