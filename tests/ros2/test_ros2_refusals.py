"""Naming a body as a ROS 2 node is refused before anything runs or prints, with the Leaf
to name instead.

A robotics user's first guess for "my robot's controller" is the robot itself
(``--ros2 Follower``); the refusal names the Leaves that feed it. ``describe`` refuses it
before printing the scenario's summary (a summary then an error read as a half success).
No rclpy needed: the refusal comes first.
"""

from __future__ import annotations

from ros2net import ROOT, amsa

SCENARIO = str(ROOT / "scenarios" / "scenario1.yaml")
HINT = "(its commands come from MyNormalizePower)"


def test_run_refuses_a_body_and_names_what_feeds_it() -> None:
    res = amsa("run", SCENARIO, "--headless", "--ros2", "Follower", check=False)
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1
    assert "Follower shares the simulator's physics world" in lines[0]
    assert lines[0].endswith(HINT), lines


def test_describe_refuses_before_printing_anything() -> None:
    res = amsa("describe", SCENARIO, "--ros2", "Follower", check=False)
    assert res.returncode == 2
    assert res.stdout == ""
    assert res.stderr.strip().endswith(HINT), res.stderr
