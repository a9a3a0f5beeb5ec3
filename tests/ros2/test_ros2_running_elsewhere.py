"""A node that runs but is wired to other topics is told apart from a node not running.

The user's node ``/MyFollowerController`` is on the graph but publishes its outputs on
relative names (``/LeftPower``, a common slip: ``create_publisher(..., "LeftPower")``). The
start fault must not send them looking for the node (``is the node running?``) but say
what it publishes instead. The start wait (``external.START_TIMEOUT_S``, 60 s) is made 15 s
for the test: long enough for the node to be seen, short enough to wait for. In ``unshare
-n`` with the ROS 2 venv (``ros2net.py``).
"""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest
from ros2net import NODE, PY, ROOT, in_private_network, ros2_missing

pytestmark = pytest.mark.ros2
MISSING = ros2_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

ENV = {"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"}
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"


def test_a_running_node_on_other_topics_is_told_what_it_publishes(tmp_path: Path) -> None:
    argv = ["run", str(SCENARIO), "--headless", "--no-plot", "-q", "--duration", "1"]
    argv += ["--out", str(tmp_path / "r"), "--ros2", "MyFollowerController"]
    code = (
        "import sys, amsa_phys.ros.external as e; e.START_TIMEOUT_S = 15.0; "
        "from amsa_phys.cli.main import main; sys.exit(main(sys.argv[1:]))"
    )
    err = tmp_path / "err"
    node = " ".join(shlex.quote(str(a)) for a in [PY, NODE, "--mode", "relative"])
    script = tmp_path / "netns.sh"
    script.write_text(
        "ip link set lo up\n"
        f"{node} > {tmp_path / 'node.log'} 2>&1 & NODE=$!\n"
        f"{PY} -c '{code}' {' '.join(argv)} 2> {err}; rc=$?\n"
        "kill -INT $NODE; wait $NODE\nexit $rc\n"
    )
    rc, left = in_private_network(script, ENV, tmp_path / "log")
    lines = err.read_text().splitlines()
    assert rc == 2, lines
    assert left == []
    assert lines[-1] == (
        "error: run fault at t=0.000 s in ROS 2 node /MyFollowerController: no publisher on "
        "/MyFollowerController/LeftPower within 15 s: the node /MyFollowerController is "
        "running but publishes /LeftPower, /RightPower, /leaderSpeed "
        "(describe --ros2 lists the topics to use)"
    ), lines
