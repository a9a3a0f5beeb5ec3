"""The exported ROS 2 package says in its README how to run it, and what each node is.

A user opening the package folder finds how to run it (``ros2 lockstep .``, colcon and
``ros2 launch``), whether it has a controller side for a robot, every node with the topics
it subscribes to and publishes (the same wiring ``describe --ros2`` shows), and every
parameter with its type and range. No rclpy needed.
"""

from __future__ import annotations

import re
from pathlib import Path

from ros2net import ROOT, amsa

from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros import external


def export(tmp_path: Path, name: str, *args: str) -> str:
    out = tmp_path / name
    amsa("export", "ros2", str(ROOT / "scenarios" / f"{name}.yaml"), "-o", str(out), *args)
    return (out / "README.md").read_text()


def rows(text: str, header: str) -> dict[str, list[str]]:
    """A Markdown table after ``header``: first cell -> the cells."""
    part = text[text.index(header) :]
    out = {}
    for line in part.splitlines()[1:]:
        if not line.startswith("| `"):
            if out:
                break
            continue
        cells = [c.strip() for c in line.strip("|").split(" | ")]
        out[cells[0].strip("`")] = cells
    return out


def test_every_node_is_listed_with_its_topics_and_parameters(tmp_path: Path) -> None:
    text = export(tmp_path, "paper_fig6_sensed")
    scenario = load_scenario(ROOT / "scenarios" / "paper_fig6_sensed.yaml")
    nodes = rows(text, "## Nodes")
    params = rows(text, "## Parameters")
    remote = [p for p in scenario.world.leaves if p not in ("Leader", "Follower")]
    wiring = external.describe(scenario.world, remote)
    assert sorted(nodes) == sorted(w.node for w in wiring)
    for w in wiring:
        subs = re.findall(r"`([^`]+)`", nodes[w.node][3])
        pubs = re.findall(r"`([^`]+)`", nodes[w.node][4])
        assert subs == [i.topic for i in w.inputs], w.node
        assert pubs == [o.topic for o in w.outputs], w.node
        listed = re.findall(r"`(\w+)` \(", params[w.node][1])
        assert listed == [p.name for p in w.params], w.node
    assert "`Kv` (double, [0, 10])" in params["/MyFollowerController"][1]
    # the commands a user copies
    assert "amsa-phys ros2 lockstep . --out RUNDIR" in text
    assert "ros2 launch mde_challenge_sensed paper_fig6_sensed.launch.py" in text
    # this package has a controller side: the robot section names it
    robot = text[text.index("## On a robot") : text.index("## Nodes")]
    assert "amsa-phys ros2 robot ." in robot
    for leaf in ("MyGpsDistance", "MyFollowerController", "MyNormalizePower"):
        assert f"`{leaf}`" in robot


def test_a_package_without_a_controller_side_says_so(tmp_path: Path) -> None:
    text = export(tmp_path, "scenario1", "--duration", "50", "--name", "s1")
    robot = text[text.index("## On a robot") : text.index("## Nodes")]
    assert "No node of this package can run on a robot" in robot
    assert "ros2 robot" not in robot
    assert text.startswith("# s1\n")
    assert "(cut at 50 s, as `run --duration` cuts it)" in text
