"""What ``export ros`` generates for the C++ nodes, checked without building them.

The lockstep tests (tests/ros/test_ros_nodes.py) need ROS; these say, anywhere, that every
C++ body names its template's ports, that a body reads its inputs in the template's order
whatever order the world lists them in, that a Leaf with an optional input left unlinked
runs its Python twin, and that the launch file gives the C++ sensors the scenario's seed.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.model.template import resolve_template
from amsa_phys.ros.cppnode import cpp_bodies, has_cpp

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "tests" / "fixtures" / "ros_nodes.yaml"


@pytest.mark.parametrize("name", sorted(t.name() for t in cpp_bodies()))
def test_every_body_names_its_templates_ports(name: str) -> None:
    template = resolve_template(name)
    m = re.match(r"// ports: in=(\S*) out=(\S*)", cpp_bodies()[template])
    assert m is not None
    assert [n for n in m.group(1).split(",") if n] == [p.name for p in template.inputs]
    assert m.group(2).split(",") == [p.name for p in template.outputs]


@pytest.fixture(scope="module")
def package(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("pkg") / "rosNodes"
    assert main(["export", "ros", str(SCENARIO), "-o", str(out)]) == 0
    return out


def test_inputs_follow_the_templates_order_not_the_worlds(package: Path) -> None:
    # CartGoal lists {posY: Cart.posY, posX: Cart.posX}: subscribed in that order (topic 0 is
    # /Cart/posY), but the body's in[0] must be posX, i.e. topic 1
    wired = yaml.safe_load((package / "config" / "amsa_leaves.yaml").read_text())
    lines = wired["CartGoal"]["amsa_wiring"].splitlines()
    assert [line.split()[1] for line in lines if line.startswith("topic ")] == [
        "/Cart/posY",
        "/Cart/posX",
    ]
    assert [line for line in lines if line.startswith("input ")] == ["input posX 1", "input posY 0"]


def test_the_launch_file_sets_the_scenarios_seed(package: Path) -> None:
    launch = (package / "launch" / "ros_nodes.launch").read_text()
    seed = load_scenario(SCENARIO).seed
    assert f'<param name="seed" type="str" value="{seed}"/>' in launch


def test_an_imu_without_the_pose_stays_in_python() -> None:
    world = load_scenario(SCENARIO).world
    imu = world.leaves["CartIMU"]
    assert has_cpp(imu, cpp_bodies())
    imu.inputs.pop("heading")  # the 2019 wiring: speed and yaw rate only (optional pose)
    try:
        assert not has_cpp(imu, cpp_bodies())
    finally:
        imu.inputs["heading"] = "Cart.heading"
