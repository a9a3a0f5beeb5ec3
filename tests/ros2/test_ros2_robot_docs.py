"""The docs' table of the robot boundary's topics is the code's (``robotplan.markdown``).

No ROS needed: the table comes from the shared description (``ros/boundary.py``'s plan and
``stdmsgs``' streams), so renaming a topic or changing a QoS without the docs fails here.
"""

from __future__ import annotations

from pathlib import Path

from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.graph import classify
from amsa_phys.ros.ros2.robotplan import markdown, robot_of

ROOT = Path(__file__).resolve().parents[2]
MARK = "<!-- robot-table: paper_fig6_sensed "


def test_the_docs_table_of_the_robot_topics_is_the_codes() -> None:
    scenario = load_scenario(ROOT / "scenarios" / "paper_fig6_sensed.yaml")
    want = markdown(robot_of(scenario, classify(scenario.world, scenario.seed)))
    lines = (ROOT / "docs" / "ros2.md").read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(MARK)) + 1
    got = lines[start : start + len(want) + 1]
    assert got[: len(want)] == want
    assert not got[len(want)].startswith("|")  # nothing more in the table
