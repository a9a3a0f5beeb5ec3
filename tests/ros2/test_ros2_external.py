"""``ros2:`` / ``--ros2`` judged before anything starts, and ``describe --ros2``'s table.

No ROS needed: names and wiring only (``model/externals.py``, ``ros/external.py``).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from amsa_phys.errors import ConfigError
from amsa_phys.model.configure import with_ros2
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros import external

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"
LEAF = "MyFollowerController"


def _scenario(tmp_path: Path, ros2: object) -> Path:
    data = yaml.safe_load(SCENARIO.read_text())
    data["world"] = str((SCENARIO.parent / data["world"]).resolve())
    data["ros2"] = ros2
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_the_scenario_key_names_leaves_stepped_by_nodes(tmp_path: Path) -> None:
    sc = load_scenario(_scenario(tmp_path, "MyFollowerController"))
    assert sc.ros2 == ("MyFollowerController",)


@pytest.mark.parametrize(
    ("ros2", "said"),
    [
        (["MyFollowerControler"], "did you mean MyFollowerController"),
        ("MyFollowerController,,Leader", "an empty Leaf name"),
        (["MyFollowerController", "MyDistanceMonitor"], "also external"),
        # a body stays where the physics is: a node stepping it would leave it parked
        (["Leader"], "Leader shares the simulator's physics world"),
        (["MyFollowerController", "Follower"], "Follower shares the simulator's physics world"),
    ],
)
def test_a_bad_ros2_key_is_one_line_naming_file_line_and_key(
    tmp_path: Path, ros2: object, said: str
) -> None:
    path = _scenario(tmp_path, ros2)
    with pytest.raises(ConfigError) as err:
        load_scenario(path)
    text = str(err.value)
    assert said in text
    assert str(path) in text
    assert "ros2" in text
    assert "\n" not in text


def test_the_option_replaces_the_key_and_is_judged_the_same() -> None:
    sc = load_scenario(SCENARIO)
    assert with_ros2(sc, "MyFollowerController,MyFollowerController").ros2 == (
        "MyFollowerController",
    )
    with pytest.raises(ConfigError, match="--ros2"):
        with_ros2(sc, "Nobody")
    with pytest.raises(ConfigError, match="--ros2-timeout"):
        with_ros2(sc, None, -1.0)


def test_the_wiring_is_the_ros1_names_of_the_leaf() -> None:
    sc = load_scenario(SCENARIO)
    (leaf,) = external.describe(sc.world, ["MyFollowerController"])
    assert leaf.node == "/MyFollowerController"
    assert leaf.set_parameters == "/MyFollowerController/set_parameters"
    ins = {w.port: (w.topic, w.type) for w in leaf.inputs}
    assert ins["xLeader"] == ("/LeaderGPS/gpsPosX", "std_msgs/msg/Float64")
    assert [w.topic for w in leaf.outputs] == [
        "/MyFollowerController/LeftPower",
        "/MyFollowerController/RightPower",
        "/MyFollowerController/leaderSpeed",
    ]
    kv = next(p for p in leaf.params if p.name == "Kv")
    assert (kv.type, kv.lo, kv.hi) == ("double", 0.0, 10.0)


def test_describe_lists_every_topic_with_type_and_qos() -> None:
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "amsa_phys",
            "describe",
            str(SCENARIO),
            "--ros2",
            "MyFollowerController",
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    lines = [line for line in out.splitlines() if "MyFollowerController/" in line]
    assert sum(" out " in line for line in lines) == 3
    assert any("/clock" in line and "rosgraph_msgs/msg/Clock" in line for line in out.splitlines())
    assert all("RELIABLE" in line for line in lines if " out " in line)
    assert "/MyDistanceMonitor/distanceFollowerToLeader  std_msgs/msg/Float64" in out


def test_without_rclpy_a_ros2_run_is_one_line_exit_2(tmp_path: Path) -> None:
    try:
        import rclpy  # noqa: F401

        pytest.skip("rclpy is importable in this environment")
    except ImportError:
        pass
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "amsa_phys",
            "run",
            str(SCENARIO),
            "--headless",
            "--no-plot",
            "--duration",
            "1",
            "--out",
            str(tmp_path / "r"),
            "--ros2",
            "MyFollowerController",
        ],
        capture_output=True,
        text=True,
        env={"SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"},
    )
    assert res.returncode == 2
    assert res.stderr.count("\n") == 1
    assert "rclpy" in res.stderr
    assert "docs/ros2.md" in res.stderr
