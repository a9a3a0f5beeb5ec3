"""``amsa-phys export ros`` without ROS: what the package holds, and bad input.

(Building and launching it is ``test_ros.py``, which needs ROS.)
"""

from __future__ import annotations

import os
import py_compile
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.graph import RosGraph, classify

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "ros_short.yaml"
REMOTE = [
    "LeaderGPS",
    "FollowerGPS",
    "FollowerCompass",
    "MyDistanceMonitor",
    "MyFollowerController",
    "MyNormalizePower",
]


def cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_package_has_a_node_per_leaf_a_topic_per_data_a_parameter_per_parameter(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pkg = tmp_path / "src" / "mdeChallenge"
    code, out, err = cli(capsys, "export", "ros", str(SCENARIO), "-o", str(pkg), "--mode", "free")
    assert code == 0, err
    assert "physics in amsa_simulator: Leader, Follower" in out
    manifest = ET.parse(pkg / "package.xml").getroot()
    assert manifest.findtext("name") == "mdeChallenge"  # named after the root component
    launch = ET.parse(pkg / "launch" / "ros_short.launch").getroot()
    nodes = {n.get("name"): n for n in launch.iter("node")}
    assert set(nodes) == {
        "amsa_simulator",
        "amsa_scenario",
        *REMOTE,
        "amsa_bag",
        "amsa_boundary",
        "amsa_leaves",  # the C++ Leaves' container
    }
    # the simulator is told whether the boundary runs: in lockstep it waits for it to listen
    group = {p.get("name"): p.get("value") for p in launch.find("group").iter("param")}
    assert group["boundary"] == "$(arg boundary)"
    # the boundary's standard messages are for onlookers: without them the run still runs
    optional = {"amsa_bag", "amsa_boundary"}
    assert all(n.get("required") == "true" for k, n in nodes.items() if k not in optional)
    # sim:=false runs the controller side alone; here the controller reads the monitor's
    # true distance, which no robot measures: nothing of this world runs without the sim
    assert all(
        "arg('sim')" in (n.get("if") or "") or n.get("if") == "$(arg sim)"
        for k, n in nodes.items()
        if k in {"amsa_simulator", "amsa_scenario", *REMOTE}
    )
    args = {a.get("name"): a.get("default") for a in launch.iter("arg")}
    assert args["mode"] == "free"  # --mode sets the launch files' default
    assert {"out", "bag", "speed", "duration", "cpp", "force", "plots", "sim"} <= set(args)
    # the C++ route for the templates with a C++ body: one nodelet class per template in one
    # library, every C++ Leaf in the container by default, alone in a process of its own
    # with cpp_container:=false (nodelet standalone), its Python twin with cpp:=false
    leaf = [n for n in launch.iter("node") if n.get("name") == "MyNormalizePower"]
    assert [(n.get("pkg"), n.get("type"), n.get("args")) for n in leaf] == [
        ("nodelet", "nodelet", "standalone mdeChallenge/NormalizePower"),
        ("mdeChallenge", "MyNormalizePower.py", None),
    ]
    assert "not arg('cpp_container')" in leaf[0].get("if")
    assert "arg('cpp_container')" in nodes["amsa_leaves"].get("if")
    cmake = (pkg / "CMakeLists.txt").read_text()
    assert "add_library(mdeChallenge_leaves src/leaves/GPS.cpp src/leaves/Compass.cpp" in cmake
    # the container's target is the package's own (two packages can share a workspace),
    # its executable still amsa_leaves, which the launch file starts
    assert "add_executable(mdeChallenge_amsa_leaves src/amsa_leaves.cpp)" in cmake
    assert (
        "set_target_properties(mdeChallenge_amsa_leaves PROPERTIES OUTPUT_NAME amsa_leaves)"
        in cmake
    )
    plugins = ET.parse(pkg / "nodelet_plugins.xml").getroot()
    assert [c.get("name") for c in plugins.iter("class")] == [
        f"mdeChallenge/{t}"
        for t in ("GPS", "Compass", "DistanceMonitor", "FollowerController", "NormalizePower")
    ]
    assert manifest.find("export/nodelet").get("plugin") == "${prefix}/nodelet_plugins.xml"
    wired = yaml.safe_load((pkg / "config" / "amsa_leaves.yaml").read_text())
    assert [leaf["name"] for leaf in wired["amsa_leaves"]["leaves"]] == [
        "/LeaderGPS",
        "/FollowerGPS",
        "/FollowerCompass",
        "/MyDistanceMonitor",
        "/MyFollowerController",
        "/MyNormalizePower",
    ]
    # the controller's outputs: the actuator and the simulator read LeftPower (2 processes
    # apart, 2 in the container: the container and the simulator); leaderSpeed only the trace
    assert (
        "output LeftPower /MyFollowerController/LeftPower 0x0.0p+0 2 2\n"
        in (wired["MyFollowerController"]["amsa_wiring"])
    )
    # one topic per Data: the bag records every trace column's topic
    bag = next(n for n in launch.iter("node") if n.get("name") == "amsa_bag")
    scenario = load_scenario(SCENARIO)
    topics = ["/" + b.replace(".", "/") for b in scenario.world.buffers]
    assert bag.get("args").split()[3:] == topics
    # recorded by the package's own recorder, which never drops a message (bagrecord.py)
    assert (bag.get("pkg"), bag.get("type")) == ("mdeChallenge", "amsa_bag.py")
    assert "nodes/amsa_bag.py" in (pkg / "CMakeLists.txt").read_text()
    # one parameter per Parameter, at t = 0 the world's values with the scenario's set:
    params = yaml.safe_load((pkg / "config" / "ros_short_params.yaml").read_text())
    for path, leaf in scenario.world.leaves.items():
        # and a shifted timer's phase, for a C++ node in free mode (Python nodes draw it)
        timer = {"amsa_phase"} if path == "MyDistanceMonitor" else set()
        assert set(params[path]) == {p.name for p in leaf.template.params} | timer
    assert params["MyDistanceMonitor"]["amsa_phase"] == "1/8"
    assert params["MyFollowerController"]["Kv"] == 0.1
    assert params["LeaderGPS"]["lostDataGPS"] == 10
    assert params["Leader"]["x"] == 15.0
    # the nodes are Python that compiles, and run the project's classes
    for leaf in REMOTE:
        script = pkg / "nodes" / f"{leaf}.py"
        py_compile.compile(str(script), doraise=True)
        assert script.stat().st_mode & 0o111
        assert f"main({leaf!r})" in script.read_text()
    assert "roslaunch mdeChallenge ros_short.launch" in (pkg / "README.md").read_text()
    # the resolved scenario the nodes load replays the same run
    config = load_scenario(pkg / "config" / "ros_short.yaml")
    assert config.duration == scenario.duration
    assert config.timeline.starts == scenario.timeline.starts


def test_physical_leaves_are_found_by_what_they_ask_for() -> None:
    world = load_scenario(SCENARIO).world
    local = classify(world)
    assert local == ["Leader", "Follower"]
    graph = RosGraph.of(world, local, bag=True)
    # the controller's left power: read by the actuator's node, the simulator and the bag
    assert graph.subscribers("MyFollowerController.LeftPower") == 3
    # the follower's pose: read by two sensor nodes and the bag (the simulator publishes it)
    assert graph.subscribers("Follower.posX") == 3
    assert graph.subscribers("Leader.speed") == 1  # the bag only


def test_a_world_exports_with_a_launch_file_of_its_own(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pkg = tmp_path / "pkg"
    code, _, err = cli(
        capsys, "export", "ros", str(ROOT / "worlds" / "mde_challenge.yaml"), "-o", str(pkg)
    )
    assert code == 0, err
    assert (pkg / "launch" / "mdeChallenge.launch").is_file()
    config = yaml.safe_load((pkg / "config" / "mdeChallenge.yaml").read_text())
    assert config["duration"] == 3600
    assert "timeline" not in config


def test_bad_output_directory_or_world_is_one_line_and_changes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep\n")
    for extra in ([], ["--force"]):
        code, _out, err = cli(capsys, "export", "ros", str(SCENARIO), "-o", str(mine), *extra)
        assert code == 2
        assert err.count("\n") == 1
        assert "mine" in err
        assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine"]  # no staging left
    # a package amsa-phys made is replaced with --force, not without
    pkg = tmp_path / "pkg"
    assert cli(capsys, "export", "ros", str(SCENARIO), "-o", str(pkg))[0] == 0
    assert cli(capsys, "export", "ros", str(SCENARIO), "-o", str(pkg))[0] == 2
    assert cli(capsys, "export", "ros", str(SCENARIO), "-o", str(pkg), "--force")[0] == 0
    # a component name ROS cannot use
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "name: w\ncomponents:\n  _Pilot: {template: ConstantPower}\n"
        "  Motors: {template: NormalizePower,\n"
        "           inputs: {powerL: _Pilot.LeftPower, powerR: _Pilot.RightPower}}\n"
    )
    code, _, err = cli(capsys, "export", "ros", str(bad), "-o", str(tmp_path / "x"))
    assert code == 2
    assert "'_Pilot' is not a valid ROS name" in err
    assert not (tmp_path / "x").exists()
    # two scenarios of different worlds in one package
    other = tmp_path / "other.yaml"
    other.write_text(f"world: {ROOT / 'worlds' / 'platoon.yaml'}\nduration: 5\n")
    code, _, err = cli(
        capsys, "export", "ros", str(SCENARIO), str(other), "-o", str(tmp_path / "y")
    )
    assert code == 2
    assert "runs another world" in err


def test_an_array_port_is_one_multiarray_topic_with_a_legal_name(tmp_path: Path) -> None:
    """The obstacle course's lidar publishes 31 ranges as one array port: one
    ``std_msgs/Float64MultiArray`` topic ``/Scanner/ranges`` (no ``/Scanner/ranges[0]``, which
    is not a legal ROS name), read by the avoider's node and recorded by ``bag:=``."""
    out = tmp_path / "oc"
    course = ROOT / "scenarios" / "obstacle_course.yaml"
    assert main(["export", "ros", str(course), "-o", str(out)]) == 0
    launch = (out / "launch" / "obstacle_course.launch").read_text()
    assert " /Scanner/ranges " in launch
    assert "[" not in launch.partition('type="amsa_bag.py"')[2]
    wiring = (out / "config" / "amsa_leaves.yaml").read_text()
    assert "topic /Scanner/ranges 0x0.0p+0 0 31" in wiring
    assert "ranges <- /Scanner/ranges [31]" in (out / "nodes" / "Pilot.py").read_text()


def test_no_path_of_the_exporting_machine_in_any_generated_file(tmp_path: Path) -> None:
    """Issue 26: every Python node re-executed itself with the exporting venv's interpreter,
    by an absolute path: copied to a robot, nothing started. No generated file may name the
    venv, the interpreter, the project, the home directory or where the package was written."""
    out = tmp_path / "ws" / "src" / "mdeChallenge"
    assert main(["export", "ros", str(SCENARIO), "-o", str(out)]) == 0
    machine = {
        str(ROOT),
        sys.prefix,
        sys.exec_prefix,
        sys.executable,
        os.path.realpath(sys.executable),
        str(Path.home()),
        str(tmp_path),
    }
    files = [p for p in out.rglob("*") if p.is_file() and p.name != ".amsa-phys-run"]
    assert len(files) > 10
    for path in files:
        text = path.read_text()
        for where in machine:
            assert where not in text, (path.name, where)


@pytest.mark.skipif(not Path("/usr/bin/python3").exists(), reason="no system python3")
def test_a_node_without_amsa_phys_says_what_to_install(tmp_path: Path) -> None:
    """Run by a Python that lacks amsa-phys (and no AMSA_PHYS_PYTHON), a node exits with one
    line saying what to do, instead of starting anything."""
    probe = subprocess.run(
        ["/usr/bin/python3", "-c", "import amsa_phys"], capture_output=True, cwd=tmp_path
    )
    if probe.returncode == 0:
        pytest.skip("the system python3 has amsa-phys")
    out = tmp_path / "pkg"
    assert main(["export", "ros", str(SCENARIO), "-o", str(out)]) == 0
    env = {k: v for k, v in os.environ.items() if not k.startswith(("AMSA_PHYS", "PYTHON"))}
    done = subprocess.run(
        ["/usr/bin/python3", str(out / "nodes" / "MyFollowerController.py")],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
    )
    assert done.returncode == 1
    assert done.stderr.strip() == (
        "error: /usr/bin/python3 cannot import amsa_phys: install amsa-phys into it "
        "(pip install amsa-phys) or set AMSA_PHYS_PYTHON to a Python that has it"
    )


def test_a_scenario_with_adapt_rules_exports_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 27 item 5: the rules travel in the package's scenario (the simulator fires them)
    and, for sim:=false, an adapt node is launched in the simulator's place."""
    scenario = ROOT / "scenarios" / "adaptive.yaml"
    pkg = tmp_path / "pkg"
    assert main(["export", "ros", str(scenario), "-o", str(pkg)]) == 0
    config = yaml.safe_load((pkg / "config" / "adaptive.yaml").read_text())
    assert [r["set"] for r in config["adapt"]] == [
        r.changes and {c.key: c.value for c in r.changes} for r in load_scenario(scenario).adapt
    ]
    launch = ET.parse(pkg / "launch" / "adaptive.launch").getroot()
    node = next(n for n in launch.iter("node") if n.get("name") == "amsa_adapt")
    # sim:=false, or rules:=node in lockstep (the simulator asks it: test_ros_adapt.py)
    want = "$(eval not arg('sim') or (arg('rules') == 'node' and arg('mode') == 'lockstep'))"
    assert node.get("if") == want
    rules = next(a for a in launch.iter("arg") if a.get("name") == "rules")
    assert rules.get("default") == "sim"
    py_compile.compile(str(pkg / "nodes" / "amsa_adapt.py"), doraise=True)
