"""Steps one exported node twice, the first time before anybody reads its output.

Run by ``test_ros2_first_answer.py`` with the ROS 2 venv's python, in a private network:
``late_reader_probe.py PKG``. It starts the package's ``MyDistanceMonitor`` as lockstep
does (its own trigger), waits until the node reads its inputs and trigger, then steps it
at t=0 with the leader 3 m away, *before* creating a reader of its output (as a run the
node has not discovered yet is, to that node); then creates the reader, steps it at
t=0.25 s with the leader 5 m away, and prints every distance it receives, one per line,
until the second. A node that answers before its writer has matched a reader loses the
first answer (VOLATILE): the output is then ``5.0`` alone, not ``3.0`` and ``5.0``.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import rclpy
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64

from amsa_phys.ros import names
from amsa_phys.ros.ros2 import lockstep

LEAF = "MyDistanceMonitor"
QOS = QoSProfile(
    depth=10,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
    history=HistoryPolicy.KEEP_LAST,
)


def main() -> None:
    plan = lockstep.plan(Path(sys.argv[1]))
    node_proc = subprocess.Popen(plan.commands[LEAF], stdin=subprocess.DEVNULL)
    rclpy.init()
    probe = rclpy.create_node("late_reader_probe")
    inputs = {
        port: probe.create_publisher(Float64, f"/amsa/in/{LEAF}/{port}", QOS)
        for port in ("xLeader", "yLeader", "xFollower", "yFollower")
    }
    trigger = probe.create_publisher(Clock, names.step_topic(LEAF), QOS)
    pubs = [*inputs.values(), trigger]
    try:
        while any(p.get_subscription_count() < 1 for p in pubs):  # the node is up
            rclpy.spin_once(probe, timeout_sec=0.01)
            if node_proc.poll() is not None:
                sys.exit(f"the node exited with {node_proc.returncode}")

        def step(t_ns: int, gap: float) -> None:
            for port, value in (("xLeader", gap), ("yLeader", 0.0), ("xFollower", 0.0)):
                inputs[port].publish(Float64(data=value))
            inputs["yFollower"].publish(Float64(data=0.0))
            msg = Clock()
            msg.clock.nanosec = t_ns
            trigger.publish(msg)

        step(0, 3.0)
        for p in pubs:  # the node's middleware holds the first step's messages
            p.wait_for_all_acked()
        got: list[float] = []
        probe.create_subscription(
            Float64, f"/{LEAF}/distanceFollowerToLeader", lambda m: got.append(m.data), QOS
        )
        while trigger.get_subscription_count() < 1 or not probe.count_publishers(
            f"/{LEAF}/distanceFollowerToLeader"
        ):
            rclpy.spin_once(probe, timeout_sec=0.01)
        step(250_000_000, 5.0)
        while 5.0 not in got:
            rclpy.spin_once(probe, timeout_sec=0.05)
            if node_proc.poll() is not None:
                sys.exit(f"the node exited with {node_proc.returncode}")
        for value in got:
            print(value, flush=True)
    finally:
        node_proc.terminate()
        try:
            node_proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            node_proc.kill()
        probe.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
