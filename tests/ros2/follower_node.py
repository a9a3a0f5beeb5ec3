"""A user's follower controller as a plain rclpy node: the paper's law, written by hand.

Not generated and not importing amsa-phys: this is what a user brings. It declares the
controller's parameters, subscribes to ``/clock`` and the six inputs, and once it holds one
new message of each since its last step, computes the law and publishes its three outputs
(the lockstep contract of ``docs/ros2.md``); when ``/clock`` goes back, a new run starts
and it forgets what it estimated. At exit it prints how many runs and steps it served.

``--mode`` makes it misbehave for the fault tests: ``sign`` (the turning term's sign wrong),
``never`` (never answers), ``late`` (answers the 20th step after 3 s), ``nan``, ``wrongtype``
(publishes LeftPower as Float32), ``besteffort`` (publishes LeftPower BEST_EFFORT: a QoS the
contract's RELIABLE subscription never matches), ``die`` (exits at the 20th step), ``refuse``
(refuses Kv below 0.1), ``undeclared`` (never declares Kw), ``relative`` (publishes its outputs
on relative names, ``LeftPower``: ``/LeftPower``, not the node's own), ``mute`` (its
``set_parameters`` service never answers: the callback blocks).
"""

from __future__ import annotations

import argparse
import math
import signal
import sys
import threading
import time
from collections import deque
from fractions import Fraction

import rclpy
from rcl_interfaces.msg import SetParametersResult
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float32, Float64

INPUTS = {
    "xLeader": "/LeaderGPS/gpsPosX",
    "yLeader": "/LeaderGPS/gpsPosY",
    "xFollower": "/FollowerGPS/gpsPosX",
    "yFollower": "/FollowerGPS/gpsPosY",
    "headingFollower": "/FollowerCompass/compassHeading",
    "distanceLeaderFollower": "/MyDistanceMonitor/distanceFollowerToLeader",
}
PARAMS = {
    "Kv": 0.1,
    "Kw": 0.04,
    "distanceRef": 15.0,
    "Kff": 0.0,
    "maxSpeed": 5.5,
    "frictionPower": 6.5,
    "speedWindow": 3.0,
}
QOS = QoSProfile(
    depth=10,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
    history=HistoryPolicy.KEEP_LAST,
)


class Follower(Node):
    def __init__(self, mode: str) -> None:
        super().__init__("MyFollowerController")
        self.mode = mode
        for name, default in PARAMS.items():
            if not (mode == "undeclared" and name == "Kw"):
                self.declare_parameter(name, default)
        self.add_on_set_parameters_callback(self.on_params)
        self.fresh: dict[str, float] = {}
        self.t: Fraction | None = None
        self.last_t: Fraction | None = None
        self.runs = 1
        self.steps = 0
        self.fixes: deque[tuple[float, float, float]] = deque()
        self.v_leader = 0.0
        self.create_subscription(Clock, "/clock", self.on_clock, QOS)
        for port, topic in INPUTS.items():
            self.create_subscription(Float64, topic, lambda m, p=port: self.on_input(p, m), QOS)
        left_type = Float32 if mode == "wrongtype" else Float64
        left_qos = QOS
        if mode == "besteffort":
            left_qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
        at = "" if mode == "relative" else "/MyFollowerController/"
        self.left = self.create_publisher(left_type, f"{at}LeftPower", left_qos)
        self.right = self.create_publisher(Float64, f"{at}RightPower", QOS)
        self.speed = self.create_publisher(Float64, f"{at}leaderSpeed", QOS)

    def on_params(self, params: list) -> SetParametersResult:
        while self.mode == "mute":  # the test kills the node
            time.sleep(1.0)
        for p in params:
            if self.mode == "refuse" and p.name == "Kv" and p.value < 0.1:
                return SetParametersResult(successful=False, reason="Kv below 0.1")
        return SetParametersResult(successful=True)

    def p(self, name: str) -> float:
        return self.get_parameter(name).value

    def on_clock(self, msg: Clock) -> None:
        t = Fraction(msg.clock.sec) + Fraction(msg.clock.nanosec, 10**9)
        if self.last_t is not None and t < self.last_t:  # a new run: time went back
            self.fixes.clear()
            self.v_leader = 0.0
            self.runs += 1
        self.t = self.last_t = t
        self.maybe_step()

    def on_input(self, port: str, msg: Float64) -> None:
        self.fresh[port] = msg.data
        self.maybe_step()

    def maybe_step(self) -> None:
        if self.t is None or len(self.fresh) < len(INPUTS):
            return
        t, inp = self.t, self.fresh
        self.t, self.fresh = None, {}
        self.steps += 1
        if self.mode == "never":
            return
        if self.mode == "die" and self.steps == 20:
            sys.exit(0)
        if self.mode == "late" and self.steps == 20:
            time.sleep(8.0)  # well past the run's 3 s timeout
        left, right, speed = self.law(float(t), inp)
        if self.mode == "nan" and self.steps == 20:
            left = math.nan
        if self.steps == 1 and self.mode not in ("wrongtype", "besteffort"):
            self.wait_matched()
        self.left.publish(Float32(data=left) if self.mode == "wrongtype" else Float64(data=left))
        self.right.publish(Float64(data=right))
        self.speed.publish(Float64(data=speed))

    def wait_matched(self) -> None:
        """The first answer waits for amsa-phys's subscribers (docs/ros2.md, "Hold your
        first answer until it has a reader"): a VOLATILE publisher drops a message for a
        subscriber it has not matched yet. (wrongtype and besteffort never match.)"""
        pubs = (self.left, self.right, self.speed)
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline and any(p.get_subscription_count() < 1 for p in pubs):
            time.sleep(0.005)

    def law(self, t: float, inp: dict[str, float]) -> tuple[float, float, float]:
        """The paper's proportional follower law (Kv on distance, Kw on bearing)."""
        if inp["distanceLeaderFollower"] <= 0.0:
            return 0.0, 0.0, self.v_leader
        xl, yl = inp["xLeader"], inp["yLeader"]
        self.update_speed(t, xl, yl)
        alpha = math.atan2(yl - inp["yFollower"], xl - inp["xFollower"]) - inp["headingFollower"]
        alpha = (alpha + math.pi) % (2 * math.pi) - math.pi
        e = inp["distanceLeaderFollower"] - self.p("distanceRef")
        ff = (
            self.p("frictionPower") + 100.0 * self.v_leader / self.p("maxSpeed")
            if self.v_leader > 0
            else 0.0
        )
        forward = (100.0 * self.p("Kv") * e + self.p("Kff") * ff) * math.cos(alpha)
        turn = 100.0 * self.p("Kw") * alpha
        if self.mode == "sign":
            turn = -turn  # the bug: steers away from the leader
        return forward - turn, forward + turn, self.v_leader

    def update_speed(self, t: float, x: float, y: float) -> None:
        """Leader speed: least-squares slope of the recent new GPS fixes."""
        fixes = self.fixes
        if fixes and fixes[-1][1] == x and fixes[-1][2] == y:
            return
        if fixes:
            lt, lx, ly = fixes[-1]
            if math.hypot(x - lx, y - ly) > 2 * self.p("maxSpeed") * max(t - lt, 0.25):
                fixes.clear()
        fixes.append((t, x, y))
        while fixes and fixes[0][0] < t - self.p("speedWindow"):
            fixes.popleft()
        n = len(fixes)
        if n < 2:
            return
        st = sx = sy = 0.0
        for ft, fx, fy in fixes:
            st += ft
            sx += fx
            sy += fy
        mt, mx, my = st / n, sx / n, sy / n
        stt = stx = sty = 0.0
        for ft, fx, fy in fixes:
            d = ft - mt
            stt += d * d
            stx += d * (fx - mx)
            sty += d * (fy - my)
        if stt <= 0:
            return
        self.v_leader = math.hypot(stx / stt, sty / stt)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--mode", default="ok")
    args = ap.parse_args()
    # stopped by SIGTERM or SIGINT through Python's own handlers, not rclpy's: rclpy's handler
    # once left this node deadlocked in spin() after a SIGTERM (every thread in a futex wait),
    # and the harness waited for it for ever
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    stop = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *_: stop.set())
    node = Follower(args.mode)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.1)  # returns often enough to see the flag
    finally:  # what the falsify test accounts for
        print(f"FOLLOWER runs={node.runs} steps={node.steps}", flush=True)
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
