"""A C++ body is the twin of one shipped template class, not of a name.

``export ros`` runs a Leaf as a C++ node when its template has a body in ``files/cpp/``. A
user's own template that happens to be called ``GPS`` (or a subclass of the shipped GPS that
steps otherwise) must keep its own Python step under ROS: given the shipped GPS's C++ body,
the lockstep run would silently compute the built-in's outputs instead of the user's.
Checked on the generated package, without building it.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros.cppnode import cpp_bodies, has_cpp
from amsa_phys.sensors.gps import GPS

ROOT = Path(__file__).resolve().parents[2]

USER_TEMPLATES = ROOT / "tests" / "fixtures" / "usertemplates"  # usergps.py


def _scenario(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, template: str) -> Path:
    """scenario1 with FollowerGPS made of ``template`` (a user module on sys.path)."""
    monkeypatch.syspath_prepend(str(USER_TEMPLATES))
    world = (ROOT / "worlds" / "mde_challenge.yaml").read_text()
    head, sep, tail = world.partition("  FollowerGPS:\n    template: GPS\n")
    assert sep
    (tmp_path / "world.yaml").write_text(f"{head}  FollowerGPS:\n    template: {template}\n{tail}")
    scenario = (ROOT / "scenarios" / "scenario1.yaml").read_text()
    scenario = scenario.replace("world: ../worlds/mde_challenge.yaml", "world: world.yaml")
    path = tmp_path / "s.yaml"
    path.write_text(scenario)
    return path


def _cpp_leaves(tmp_path: Path, scenario: Path) -> list[str]:
    out = tmp_path / "pkg"
    assert main(["export", "ros", str(scenario), "-o", str(out)]) == 0
    wired = yaml.safe_load((out / "config" / "amsa_leaves.yaml").read_text())
    return [leaf["name"] for leaf in wired["amsa_leaves"]["leaves"]]


@pytest.mark.parametrize("template", ["usergps:GPS", "usergps:BiasedGPS"])
def test_a_users_gps_keeps_its_own_step_under_ros(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, template: str
) -> None:
    scenario = _scenario(tmp_path, monkeypatch, template)
    world = load_scenario(scenario).world
    user = world.leaves["FollowerGPS"]
    assert user.template is not GPS
    assert not has_cpp(user, cpp_bodies())
    assert has_cpp(world.leaves["LeaderGPS"], cpp_bodies())  # the shipped one still is C++
    leaves = _cpp_leaves(tmp_path, scenario)
    assert "/LeaderGPS" in leaves
    assert "/FollowerGPS" not in leaves


def test_the_bodies_are_keyed_by_the_shipped_classes() -> None:
    bodies = cpp_bodies()
    assert GPS in bodies
    assert all(isinstance(k, type) for k in bodies)
