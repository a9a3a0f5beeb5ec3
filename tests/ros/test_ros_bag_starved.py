"""``bag:=`` keeps every message even when its recorder is starved, and the run's last ones.

In lockstep the simulator outruns real time; ``rosbag record`` (a queue of 100 messages per
topic) dropped messages from the middle of a run whenever it fell behind on a loaded machine.
Here the recorder is starved on purpose: stopped (SIGSTOP) as the run starts and let go
(SIGCONT) only once the run is over and the simulator says it waits for the recorder, so every
message of the run reaches it at once, and the launch must not end before it has written them.
The bag must still hold, on every Data topic, every value the trace shows, in order.
Mutation-checked: ``rosbag record`` as the launch's recorder again loses messages here; the
package's recorder with a subscriber queue (``queue_size=100``) does too; a simulator that
does not wait for the recorder at the end never says so, and the launch ends without a bag.
The package is the session's build of ``ros_short.yaml`` (``ros_short_workspace`` in
conftest.py). Skipped, with the reason, where ROS, catkin, unshare or root is missing.
"""

from __future__ import annotations

import os
import signal
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

import pytest
import ros_launch
from ros_launch import Launch, assert_bag_holds_the_trace, ros_missing

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.runtime.bagtail import WINDOW

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "ros_short.yaml"

pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(ros_missing() is not None, reason=str(ros_missing())),
]
launcher = ros_launch.launcher  # the fixture


def _process(token: str, name: str) -> int:
    """The launch's process whose command line names ROS node ``name``."""
    want = f"__name:={name}".encode()
    for pid in ros_launch._leftovers(token):
        try:
            argv = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if want in argv:
            return pid
    raise AssertionError(f"no process of node {name} in the launch")


def test_a_starved_recorder_loses_no_message(
    ros_short_workspace: Path, launcher: Callable[..., Launch], tmp_path: Path
) -> None:
    scenario = load_scenario(SCENARIO)
    world = scenario.world
    # while the recorder is stopped the run must be able to end: no topic carries a window
    # of messages (past one, the simulator waits for the recorder: bagtail.py)
    most = max(
        Fraction(leaf.freq) * Fraction(str(scenario.duration)) for leaf in world.leaves.values()
    )
    assert most < WINDOW
    reference = tmp_path / "ref"
    assert (
        main(["run", str(SCENARIO), "--headless", "--out", str(reference), "-q", "--no-plot"]) == 0
    )
    out = tmp_path / "starved"
    bag = tmp_path / "starved.bag"
    launch = launcher(
        ros_short_workspace, "ros_short.launch", f"out:={out}", "plots:=false", f"bag:={bag}"
    )
    assert launch.read_until("running ros_short"), "".join(launch.lines)[-3000:]
    recorder = _process(launch.token, "amsa_bag")
    os.kill(recorder, signal.SIGSTOP)
    try:
        # the run is over, its outputs written, and the simulator waits for the recorder
        waiting = launch.read_until("waiting for the bag recorder")
    finally:
        os.kill(recorder, signal.SIGCONT)
    assert waiting, "".join(launch.lines)[-3000:]
    text = launch.finish()
    assert "amsa_simulator: done: 1 expectation passed" in text, text[-3000:]
    assert (out / "trace.csv").read_bytes() == (reference / "trace.csv").read_bytes()
    # every Data topic holds the values the trace shows, in order (the trace samples every
    # 0.05 s, faster than any Leaf publishes); a delayed Leaf's last ones, in flight when the
    # run ends, are in the bag only
    delayed = {p for p, leaf in world.leaves.items() if leaf.timing.delayed}
    assert_bag_holds_the_trace(bag, reference / "trace.csv", delayed)
    # and the simulator saw the recorder write every message it counted before it ended
    assert "the bag is incomplete" not in text, text[-3000:]
