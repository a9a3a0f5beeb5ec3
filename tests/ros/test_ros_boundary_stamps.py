"""The boundary node's standard messages in lockstep carry the instant their values were made.

Issue 26: the ``amsa_boundary`` node stamped each NavSatFix, Imu, Odometry and tf with the
latest ``/clock``, which the simulator publishes only where a node steps (4 Hz in the 30 s
scenario1 of ``tests/fixtures/ros_short.yaml``): the 10 Hz Leader's ground truth and tf came
up to 0.25 s late with repeated stamps (tf warns of repeated data), and a race between the
``/clock`` and data connections could stamp a message with another instant. Here a lockstep
launch records the boundary's output with the package's recorder (``bag:=``'s: ``rosbag
record`` dropped messages when starved), and every message is looked up in the in-process
MCAP bag of the same scenario and seed (``amsa-phys run --bag``, whose
stamps are each Leaf's step time): the message with that stamp on that topic must hold the
same values, and stamps strictly increase per topic (per robot frame on ``/tf``).
Mutation-checked: the boundary stamping with ``rospy.Time.now()`` again (``/clock``) fails
it. Both bags are read with ``rosbags``. The package is the session's build of
``ros_short.yaml`` (``ros_short_workspace`` in conftest.py, shared with test_ros.py): the
test's launch file is removed after it, its outputs are in its own directory. Skipped, with
the reason, where ROS, catkin, unshare or root is missing.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import ros_launch
from ros_launch import Launch, package_edit, ros_missing
from rosbags.highlevel import AnyReader

import amsa_phys as ap
from amsa_phys.model.scenario import load_scenario
from amsa_phys.stdmsgs import find_sources

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "ros_short.yaml"
PKG = "mdeChallenge"
#: the standard types the boundary publishes (``/tf_static`` is latched once, at 0)
STANDARD = {
    "sensor_msgs/msg/NavSatFix",
    "sensor_msgs/msg/Imu",
    "nav_msgs/msg/Odometry",
    "sensor_msgs/msg/LaserScan",
    "sensor_msgs/msg/JointState",
    "tf2_msgs/msg/TFMessage",
}

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture

#: the simulator's launch-prefix: it starts once the recorder is connected to every topic
#: the boundary publishes (else a lockstep run, shorter than a second of wall time, may be
#: over before the recorder's connections are)
WAIT_RECORDER = """
import os, sys, time, xmlrpc.client
topics = set(sys.argv[1 : sys.argv.index("--")])
command = sys.argv[sys.argv.index("--") + 1 :]
master = xmlrpc.client.ServerProxy(os.environ["ROS_MASTER_URI"])
deadline = time.monotonic() + 60
while time.monotonic() < deadline:
    code, _, uri = master.lookupNode("/wait_recorder", "/stamps_bag")
    if code == 1:
        _, _, bus = xmlrpc.client.ServerProxy(uri).getBusInfo("/wait_recorder")
        if topics <= {c[4] for c in bus if c[2] == "i" and c[5]}:
            break
    time.sleep(0.05)  # polling the recorder's connections (the event waited for)
os.execv(command[0], command)
"""

Keyed = dict[tuple[str, str], dict[int, tuple[Any, ...]]]


def _values(msg: Any) -> tuple[Any, ...]:
    """What a message says, beside its stamp (the fields the Leaf's values set)."""
    name = type(msg).__name__.rpartition("__")[2]
    if name == "NavSatFix":
        return (msg.latitude, msg.longitude, msg.status.status)
    if name == "Imu":
        o, w, a = msg.orientation, msg.angular_velocity, msg.linear_acceleration
        return (o.z, o.w, w.z, a.x, a.y)
    if name == "Odometry":
        p = msg.pose.pose
        return (p.position.x, p.position.y, p.orientation.z, p.orientation.w)
    if name == "JointState":
        return tuple(msg.effort)
    if name == "LaserScan":
        return tuple(msg.ranges)
    raise AssertionError(f"unexpected message type {name}")


def _pose(tf: Any) -> tuple[float, ...]:
    return (tf.translation.x, tf.translation.y, tf.rotation.z, tf.rotation.w)


def _read(bag: Path) -> Keyed:
    """(topic, frame) -> {stamp in ns: values}; fails on a repeated or decreasing stamp."""
    out: Keyed = {}
    last: dict[tuple[str, str], int] = {}
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.msgtype in STANDARD and c.topic != "/tf_static"]
        for conn, _, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            if conn.msgtype == "tf2_msgs/msg/TFMessage":
                items = [
                    (tf.child_frame_id, tf.header.stamp, _pose(tf.transform))
                    for tf in msg.transforms
                ]
            else:
                items = [("", msg.header.stamp, _values(msg))]
            for frame, stamp, values in items:
                key, ns = (conn.topic, frame), stamp.sec * 1_000_000_000 + stamp.nanosec
                assert ns > last.get(key, -1), f"{key}: stamp {ns} after {last.get(key)}"
                last[key] = ns
                out.setdefault(key, {})[ns] = values
    return out


def test_lockstep_boundary_stamps_are_the_instants_of_their_values(
    ros_short_workspace: Path, tmp_path: Path, launcher: Callable[..., Launch]
) -> None:
    ref = tmp_path / "ref"
    ref.mkdir()
    ap.run(SCENARIO, bag=ref / "run.mcap")
    expected = _read(ref / "run.mcap")
    topics = sorted({topic for topic, _ in expected} | {"/tf"})
    ws = ros_short_workspace
    recorded = tmp_path / "boundary.bag"
    launch_dir = ws / "src" / PKG / "launch"
    (tmp_path / "wait_recorder.py").write_text(WAIT_RECORDER)
    original = (launch_dir / "ros_short.launch").read_text()
    simulator = 'type="amsa_simulator.py" name="amsa_simulator"'
    assert original.count(simulator) == 1
    prefix = f"/usr/bin/python3 {tmp_path / 'wait_recorder.py'} {' '.join(topics)} --"
    launch = original.replace(simulator, f'{simulator} launch-prefix="{prefix}"').replace(
        "</launch>",
        f'  <node pkg="{PKG}" type="amsa_bag.py" name="stamps_bag"'
        f' args="-O {recorded} {" ".join(topics)}"/>\n</launch>',
    )
    # in lockstep the boundary runs when asked
    args = (f"out:={tmp_path / 'lockstep'}", "plots:=false", "boundary:=true")
    with package_edit(launch_dir / "stamps.launch", launch):
        text = launcher(ws, "stamps.launch", *args).finish()
    assert "completed" in text, text[-3000:]
    # with the boundary, lockstep awaits every instant: pipelined, the simulator outran the
    # boundary node's publishers and their queues dropped messages
    assert "running ros_short (lockstep)" in text, text[-3000:]
    got = _read(recorded)
    assert set(got) == set(expected), (sorted(got), sorted(expected))
    # a jittery Leaf's message in the in-process bag holds the values visible at the trace
    # instant after the latency (the bag's own approximation; the jitter varies the delivery):
    # there only the stamps are compared. The boundary's values are those made at the step
    world = load_scenario(SCENARIO).world
    leaf_of = {src.topic: src.leaf for src in find_sources(world)}
    jittery = {p for p, leaf in world.leaves.items() if leaf.timing.jitter > 0}
    assert jittery == {"FollowerGPS"}
    for key, messages in got.items():
        want = expected[key]
        if leaf_of.get(key[0]) in jittery:  # its last steps, still in flight, are not in the bag
            late = [ns for ns in messages if ns > max(want)]
            assert len(late) <= 2, (key, late)  # 0.2 s of jitter at 4 Hz
            messages = {ns: v for ns, v in messages.items() if ns <= max(want)}
        # from its first message on, the boundary published every one the bag holds (it
        # may connect to the simulator after the first instants of a run this short)
        assert sorted(messages) == [ns for ns in want if ns >= min(messages)], key
        assert len(messages) >= len(want) // 2, (key, len(messages), len(want))
        for ns, values in messages.items():
            assert ns in want, f"{key}: a message stamped {ns} ns, no step of its Leaf then"
            if leaf_of.get(key[0]) not in jittery:
                assert values == want[ns], f"{key} at {ns} ns: {values} != {want[ns]}"
