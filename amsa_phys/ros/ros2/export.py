"""``amsa-phys export ros2``: an ament_python package from a scenario.

The package (``package.xml`` format 3) holds one rclpy node per Leaf that runs outside the
physics (the ROS 1 export's remote Leaves, ``graph.classify``), each running the project's own
template class (``leafnode.py``) under the names of ``ros/names.py`` and ``ros/external.py``
(the same description the ROS 1 export and ``run --ros2`` use), a ``ros__parameters`` YAML
keyed by node, a ``launch/NAME.launch.py`` (generated and parsed, not run here: no
``ros2 launch``), the resolved scenario in ``config/`` and ``config/amsa.yaml``, the list
``amsa-phys ros2 lockstep`` and ``ros2 robot`` read. The robot boundary (``robot.py``) is
the node ``amsa_boundary``: the launch file's ``sim:=false`` starts it with the controller
side (``ros/boundary.py``'s plan, ROS 1's ``sim:=false``) and nothing else. Every name
reaches a file through ``quote.py``'s escaper for that file's language; ROS names are
judged first (``names.check_world``).
"""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

from ..._version import __version__
from ...errors import ConfigError
from ...model.filenames import file_name_problem
from ...model.scenario import Scenario
from .. import names
from ..boundary import NODE as BOUNDARY
from ..boundary import plan as boundary_plan
from ..exported import KEY as CUT_KEY
from ..exported import cut_seconds, scenario_yaml
from ..external import start_values
from ..graph import RosGraph, classify
from ..quote import Code, check_name, fill, py_string, yaml_comment, yaml_dump
from .readme import readme

FILES = Path(__file__).resolve().parent.parent / "files" / "ros2"
#: A ROS 2 package name (REP 144): lower case letters, digits, underscores.
PACKAGE = re.compile(r"^[a-z][a-z0-9_]*$")
#: Python modules the package's nodes and launch file import, besides the standard library:
#: a package (which is also a Python package of that name) may not be called after one, or
#: installed beside it the one would shadow the other
SHADOWED = frozenset(
    {
        "amsa_phys",
        "rclpy",
        "launch",
        "launch_ros",
        "ament_index_python",
        "numpy",
        "pymunk",
        "yaml",
        "greenlet",
        "std_msgs",
        "sensor_msgs",
        "nav_msgs",
        "geometry_msgs",
        "builtin_interfaces",
        "rosgraph_msgs",
        "tf2_msgs",
        "rcl_interfaces",
    }
)


def shadowing(name: str) -> str | None:
    """Why a package called ``name`` would shadow a module its nodes import (None if not)."""
    if name in SHADOWED:
        return f"the nodes import the Python module {name}, which the package would shadow"
    if name in getattr(sys, "stdlib_module_names", ()):
        return f"{name} is a module of Python's standard library, which the package would shadow"
    return None


MANIFEST = "config/amsa.yaml"


@dataclass
class Package2:
    """What was generated (for the command's report and the tests)."""

    name: str
    nodes: list[str]
    local: list[str]
    files: list[str]
    #: the controller side: the nodes ``sim:=false`` / ``ros2 robot`` start on a robot
    robot: list[str]


def package_name(world_name: str) -> str:
    """``mdeChallenge`` -> ``mde_challenge`` (REP 144), or a ConfigError."""
    snake = re.sub(r"(?<=[a-z0-9])([A-Z])", r"_\1", world_name).lower()
    if (why := file_name_problem(snake, "the package name")) is not None:
        raise ConfigError(f"{why}: rename the world or give --name", key="world")
    if not PACKAGE.match(snake):
        raise ConfigError(
            f"the root component's name {world_name!r} cannot name a ROS 2 package (a letter, "
            "then letters, digits and _): rename the world",
            key="world",
        )
    if (why := shadowing(snake)) is not None:
        raise ConfigError(
            f"the root component's name {world_name!r} gives the package name {snake!r}: "
            f"{why}; rename the world or give --name",
            key="world",
        )
    return snake


def _fill(file: str, **values: Any) -> Code:
    return fill((FILES / file).read_text(), **values)


def check_package_name(name: str) -> str:
    """``export ros2 --name``: a REP 144 package name, or a ConfigError (never written
    anywhere otherwise: it names files, a Python package and XML text)."""
    if (why := file_name_problem(name, "the package name")) is not None:
        raise ConfigError(why, key="--name")
    if not PACKAGE.match(name):
        raise ConfigError(
            f"--name {name!r} cannot name a ROS 2 package: a lowercase letter, then lowercase "
            "letters, digits and _ (REP 144)"
        )
    if (why := shadowing(name)) is not None:
        raise ConfigError(f"--name {name!r}: {why}; choose another")
    return name


def generate(
    scenario: Scenario,
    source: str,
    out: Path,
    cut: Fraction | None = None,
    name: str | None = None,
) -> Package2:
    """Write the package of ``scenario`` into the (staged, empty) directory ``out``; ``cut``
    (``--duration``) is kept apart from the whole scenario, as ``exported.py`` says. ``name``:
    the package's, else the root component's in snake case (two scenarios of one world then
    share it: ``--name`` tells their packages apart in one workspace)."""
    check_name(Path(source).name, "the file name", key=source)
    check_name(scenario.name, "the scenario name", file=source, key="name")
    world = scenario.world
    names.check_world(world)
    pkg = check_package_name(name) if name is not None else package_name(world.name)
    local = classify(world, scenario.seed)
    remote = [p for p in world.leaves if p not in local]
    fname = re.sub(r"[^A-Za-z0-9_]", "_", scenario.name) or "scenario"
    if (why := file_name_problem(fname, "the scenario's name")) is not None:
        raise ConfigError(f"{why}: shorten it", file=source, key="name")
    files: dict[str, str] = {}
    src = Path(source).name
    scripts = []
    launch_nodes = []
    side = boundary_plan(RosGraph.of(world, local)).controller
    controller = set(side)
    for path in remote:
        script = names.script(path)
        leaf = world.leaves[path]
        files[f"{pkg}/{script}.py"] = _fill(
            "node.py.in",
            title=f"ROS 2 node of Leaf {path} ({leaf.template.name()}).",
            doc=(leaf.template.__doc__ or "").strip().splitlines()[0]
            if leaf.template.__doc__
            else "",
            version=__version__,
            source=src,
            pkg=pkg,
            path=path,
            scenario=f"{fname}.yaml",
        )
        scripts.append(Code(f"            {py_string(f'{script} = {pkg}.{script}:main')},"))
        ns = names.ns(path)
        launch_nodes.append(
            Code(
                f"        Node(package=PACKAGE, executable={py_string(script)}, "
                f"name={py_string(ns.rpartition('/')[2])}, "
                f"namespace={py_string(ns.rpartition('/')[0] or '/')}, "
                "parameters=[params, {'use_sim_time': True}]"
                + ("" if path in controller else ", condition=IfCondition(SIM)")
                + "),"
            )
        )
    files[f"{pkg}/{BOUNDARY}.py"] = _fill(
        "boundary.py.in", version=__version__, source=src, pkg=pkg, scenario=f"{fname}.yaml"
    )
    scripts.append(Code(f"            {py_string(f'{BOUNDARY} = {pkg}.{BOUNDARY}:main')},"))
    files[f"{pkg}/__init__.py"] = ""
    files[f"resource/{pkg}"] = ""
    files["package.xml"] = _fill(
        "package.xml.in",
        pkg=pkg,
        version=__version__,
        source=src,
        description=str(world.data.get("description") or f"The {world.name} system."),
    )
    files["setup.py"] = _fill(
        "setup.py.in", pkg=pkg, version=__version__, scripts=Code("\n".join(scripts))
    )
    files["setup.cfg"] = _fill("setup.cfg.in", pkg=pkg)
    files[f"launch/{fname}.launch.py"] = _fill(
        "launch.py.in",
        name=scenario.name,
        version=__version__,
        pkg=pkg,
        params=f"{fname}_params.yaml",
        nodes=Code("\n".join(launch_nodes)),
        boundary=BOUNDARY,
    )
    files["README.md"] = readme(
        scenario,
        pkg,
        src,
        f"{fname}.launch.py",
        f"{fname}_params.yaml",
        remote,
        local,
        side,
        None if cut is None else float(cut),
    )
    files[f"config/{fname}.yaml"] = scenario_yaml(scenario)
    files[f"config/{fname}_params.yaml"] = _params_yaml(scenario, remote)
    manifest: dict[str, Any] = {
        "package": pkg,
        "scenario": f"{fname}.yaml",
        "params": f"{fname}_params.yaml",
        "nodes": [{"leaf": p, "module": f"{pkg}/{names.script(p)}.py"} for p in remote],
        "local": list(local),
        "boundary": f"{pkg}/{BOUNDARY}.py",
    }
    if cut is not None:
        manifest[CUT_KEY] = cut_seconds(cut)
    files[MANIFEST] = yaml_dump(manifest)
    for rel, text in files.items():
        target = out / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text)
    return Package2(pkg, remote, local, sorted(files), side)


def _params_yaml(scenario: Scenario, remote: list[str]) -> str:
    """``ros__parameters`` of every node at t = 0 (the world's values, the scenario's set:),
    ``use_sim_time`` on: keyed by the node's full name."""
    values = start_values(scenario)  # as the ROS 1 export's (external.py)
    tree: dict[str, Any] = {}
    for path in remote:
        params: dict[str, Any] = {"use_sim_time": True}
        for name, value in values[path].items():
            params[name] = _plain(value)
        tree[names.ns(path)] = {"ros__parameters": params}
    head = (
        f"# ROS 2 parameters of {yaml_comment(scenario.name)} at t = 0 (the world's values and\n"
        "# the scenario's set:); amsa-phys sets them along the timeline through each node's\n"
        "# set_parameters service.\n"
    )
    return head + yaml_dump(tree)


def _plain(value: Any) -> Any:
    if isinstance(value, tuple):
        flat: list[Any] = []
        for v in value:
            flat.extend(_plain(v) if isinstance(v, tuple) else [v])
        return flat
    return value


__all__ = ["MANIFEST", "Package2", "generate", "package_name"]
