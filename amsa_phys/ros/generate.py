"""``amsa-phys export ros``: a catkin package from one or more scenarios of one world.

The package is named after the root component (the world's ``name``) and holds, as in the
paper's code generator: one node per Leaf (a Python script running the project's own
template class; a C++ (roscpp) twin for templates with a C++ body, e.g. NormalizePower), a
``std_msgs/Float64`` topic per Data (an array port, a lidar's ranges: one
``std_msgs/Float64MultiArray`` topic of the port's fixed length), a ROS parameter per
Parameter, a scenario node, a launch file per scenario, ``package.xml``, ``CMakeLists.txt``
and a README. The physical Leaves (those that share the pymunk world) step inside the
simulator node, which also publishes
``/clock`` and writes the run directory. Files are written into a directory the caller
stages and renames (``runs.rundir.staged_dir``): nothing is half-written.

One module per target file (``launchxml``, ``cppnode``, ``readme``; the node scripts,
``package.xml`` and ``CMakeLists.txt`` from ``files/*.in``), and every name reaches a file
through :mod:`.quote`'s escaper for that file's language. Names that would need
escaping in code (quotes, backslashes, control characters) are refused first, in one line,
by :func:`check_names`.
"""

from __future__ import annotations

import re
import stat
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any

from .._version import __version__
from ..engine.timing import run_phases
from ..errors import ConfigError
from ..model.filenames import file_name_problem
from ..model.rosnames import FRAMEWORK, PHASE
from ..model.scenario import Scenario
from ..model.world import WorldSpec
from ..runs.resolve import resolved_scenario
from ..runs.rundir import unique_names
from . import boundary, names
from .cppnode import (
    check_cpp_ports,
    cmake_targets,
    cpp_bodies,
    cpp_leaf,
    cpp_templates,
    has_cpp,
    hz,
    leaves_yaml,
    manifest_export,
    plugins_xml,
)
from .exported import cut_text, scenario_yaml
from .external import start_values
from .graph import RosGraph, classify
from .launchxml import launch_xml
from .quote import (
    Code,
    check_name,
    cmake_arg,
    fill,
    holes,
    py_string,
    yaml_comment,
    yaml_dump,
)
from .readme import readme

FILES = Path(__file__).parent / "files"
MODES = ("lockstep", "free")
#: A catkin package name (catkin warns about capitals, as in the paper's ``mdeChallenge``).
PACKAGE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


def _fill(file: str, **values: Any) -> Code:
    """``files/FILE`` with its holes filled: the caller's values, and for every hole named
    after a framework name (``@@{p_seed:cpp_string}``) that name from the one registry."""
    text = (FILES / file).read_text()
    used = holes(text)
    return fill(text, **{k: v for k, v in FRAMEWORK.items() if k in used}, **values)


@dataclass
class Package:
    """What was generated (for the command's report and the tests)."""

    name: str
    launch: list[str]
    nodes: list[str]
    local: list[str]
    cpp: list[str]
    files: list[str]


def check_names(scenarios: list[Scenario], sources: list[str]) -> None:
    """Refuse, in one line, a scenario name or file name that generated code would have to
    escape (quotes, backslashes, control characters): before anything is written."""
    for scenario, source in zip(scenarios, sources, strict=True):
        check_name(Path(source).name, "the file name", key=source)
        check_name(scenario.name, "the scenario's name", file=source, key="name")


def check_same_world(scenarios: list[Scenario], sources: list[str]) -> WorldSpec:
    """All scenarios must run the same world (one package = one architecture)."""
    first = resolved_scenario(scenarios[0])["world"]
    for scenario, source in zip(scenarios[1:], sources[1:], strict=True):
        if resolved_scenario(scenario)["world"] != first:
            raise ConfigError(
                f"runs another world than {sources[0]} (one package holds one world; "
                "export the other scenarios separately)",
                file=source,
            )
    return scenarios[0].world


def generate(
    scenarios: list[Scenario],
    sources: list[str],
    mode: str,
    out: Path,
    cut: Fraction | None = None,
) -> Package:
    """Write the package for ``scenarios`` into the (staged, empty) directory ``out``; ``cut``
    (``--duration``) becomes each launch file's ``duration:=`` default, the scenario files
    stay whole (``exported.py``)."""
    if mode not in MODES:
        raise ConfigError(f"expected lockstep or free, got {mode!r}", key="--mode")
    check_names(scenarios, sources)
    world = check_same_world(scenarios, sources)
    pkg = world.name
    if not PACKAGE.match(pkg):
        raise ConfigError(
            f"the root component's name {pkg!r} cannot name a catkin package (a letter, then "
            "letters, digits and _): rename the world",
            file=sources[0],
        )
    if (why := file_name_problem(pkg, "the root component's name")) is not None:
        raise ConfigError(f"{why}: rename the world", file=sources[0])
    names.check_world(world)
    arrays = {e for elements in world.arrays.values() for e in elements}
    for buffer in world.buffers.values():
        if buffer.name in arrays:  # an array port's element: the port's topic carries it
            continue
        if not isinstance(buffer.initial, float | int) or isinstance(buffer.initial, bool):
            raise ConfigError(
                f"Data {buffer.name} is not a number (a topic carries a std_msgs/Float64, or an "
                "array port's std_msgs/Float64MultiArray)",
                file=sources[0],
            )
    local = classify(world, scenarios[0].seed)
    graph = RosGraph.of(world, local)
    bodies = cpp_bodies()
    cpp = [p for p in graph.remote if has_cpp(world.leaves[p], bodies)]
    for path in cpp:
        check_cpp_ports(world.leaves[path], bodies[world.leaves[path].template])
    source = ", ".join(Path(s).name for s in sources)
    files: dict[str, str] = {}
    executable: set[str] = set()

    def node(script: str, title: str, doc: str, module: str, args: Code) -> None:
        rel = f"nodes/{script}.py"
        files[rel] = _fill(
            "node.py.in",
            title=title,
            doc=doc,
            version=__version__,
            source=source,
            module=Code(module),
            args=args,
            # amsa-phys missing: the simulator alone says so (every node would, the same)
            quiet=Code("False" if script == names.SIMULATOR else "True"),
        )
        executable.add(rel)

    node(
        names.SIMULATOR,
        f"{names.SIMULATOR}: the simulator node of {pkg}.",
        _simulator_doc(graph),
        "simmain",
        Code(""),
    )
    # rosrun PKG run_lockstep SCENARIO.launch: roslaunch, then the run's verdict as exit code
    files[f"nodes/{names.RUN_LOCKSTEP}"] = _fill(
        "node.py.in",
        title=f"{names.RUN_LOCKSTEP}: launch a scenario of {pkg}, exit with its verdict.",
        doc="rosrun PKG run_lockstep SCENARIO.launch [arg:=value ...]: runs roslaunch, then\n"
        "judges the run directory's expectations as amsa-phys run does. Exit 0: every check\n"
        "passed; 1: a check failed; 2: the run faulted or did not start; 130: interrupted.",
        version=__version__,
        source=source,
        module=Code("runcheck"),
        args=Code(py_string(pkg)),
        quiet=Code("False"),
    )
    executable.add(f"nodes/{names.RUN_LOCKSTEP}")
    node(
        names.SCENARIO,
        f"{names.SCENARIO}: the scenario node of {pkg}.",
        "Applies the scenario's timeline to the parameter server at the phases' instants\n"
        f"(simulated time, /clock) and announces each phase on {PHASE}.",
        "scenario",
        Code(""),
    )
    node(
        boundary.NODE,
        f"{boundary.NODE}: the robot boundary of {pkg}.",
        "Publishes the standard messages (NavSatFix, Imu, Odometry, LaserScan, /tf,\n"
        "JointState wheel commands) from the data topics; with sim:=false, turns the robot\n"
        "drivers' messages into the data topics the controller side reads.",
        "boundary",
        Code(""),
    )
    node(
        names.BAG,
        f"{names.BAG}: the bag:= recorder of {pkg}.",
        "Records the topics it is given (-O FILE.bag TOPIC...) to a ROS 1 bag without a\n"
        "queue: it never drops a message (a recorder behind slows the publishers instead).",
        "bagrecord",
        Code(""),
    )
    adapt = any(s.adapt for s in scenarios)
    if adapt:
        node(
            "amsa_adapt",
            f"amsa_adapt: the adapt: rules of {pkg} on a robot (sim:=false).",
            "Reads the estimators' topics and sets the rules' parameters on the parameter\n"
            "server when a rule fires (with the simulator, the rules fire inside it).",
            "adapt",
            Code(""),
        )
    for path in graph.remote:
        leaf = world.leaves[path]
        node(
            names.script(path),
            f"{names.ns(path)}: ROS node of Leaf {path} (template {leaf.template.name()}, "
            f"{hz(leaf.freq)} Hz).",
            _leaf_doc(graph, path),
            "leaf",
            Code(py_string(path)),
        )
    for tname, paths in cpp_templates(graph, cpp).items():
        files[f"src/leaves/{tname}.cpp"] = cpp_leaf(graph, tname, paths, pkg, source, bodies)
    if cpp:
        files[f"src/{names.CONTAINER}.cpp"] = _fill("amsa_leaves.cpp")
        files["nodelet_plugins.xml"] = plugins_xml(graph, pkg, cpp)
        files[f"config/{names.CONTAINER}.yaml"] = leaves_yaml(
            graph, pkg, cpp, boundary.plan(graph).controller
        )
        files[f"include/{pkg}/amsa_leaf_node.h"] = _fill(
            "amsa_leaf_node.h",
            seed_missing=FRAMEWORK["p_seed"]
            + " is not on the parameter server (a string of digits)",
        )
        files[f"include/{pkg}/amsa_pymath.h"] = (FILES / "amsa_pymath.h").read_text()
        for header in (
            "amsa_noise.h",
            "amsa_rng.h",
            "amsa_ziggurat.h",
            "amsa_window.h",
            "amsa_container.h",
            "amsa_wiring.h",
            "amsa_exit.h",
        ):
            files[f"include/{pkg}/{header}"] = _fill(header)
    launches = []
    for scenario, fname in zip(scenarios, unique_names(s.name for s in scenarios), strict=True):
        files[f"config/{fname}.yaml"] = scenario_yaml(scenario)
        files[f"config/{fname}_params.yaml"] = _params_yaml(scenario)
        files[f"launch/{fname}.launch"] = launch_xml(
            graph,
            pkg,
            fname,
            mode,
            cpp,
            source,
            adapt=bool(scenario.adapt),
            seed=scenario.seed,
            duration=cut_text(cut),
        )
        launches.append(f"{fname}.launch")
    python_nodes = sorted(f for f in files if f.startswith("nodes/"))
    files["package.xml"] = _fill(
        "package.xml.in",
        pkg=pkg,
        version=__version__,
        source=source,
        description=str(world.data.get("description") or f"The {pkg} system."),
        export=manifest_export(cpp),
    )
    files["CMakeLists.txt"] = _fill(
        "CMakeLists.txt.in",
        pkg=pkg,
        version=__version__,
        source=source,
        python_nodes=Code("\n".join(f"  {cmake_arg(f)}" for f in python_nodes)),
        cpp_targets=cmake_targets(graph, pkg, cpp),
    )
    files["README.md"] = readme(graph, pkg, source, launches, mode, cpp)
    for rel, text in files.items():
        target = out / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text)
        if rel in executable:
            target.chmod(target.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    return Package(
        pkg,
        launches,
        [names.SIMULATOR, names.SCENARIO, *graph.remote],
        sorted(local, key=list(world.leaves).index),
        cpp,
        sorted(files),
    )


def _leaf_doc(graph: RosGraph, path: str) -> str:
    leaf = graph.leaf(path)
    lines = [f"Runs {leaf.template_ref} ({leaf.template.describe()})"]
    lines.append("Subscribes (std_msgs/Float64; [N]: Float64MultiArray of N values):")
    for port, buffer in leaf.inputs.items():
        lines.append(f"  {port} <- {names.topic(buffer)}{_size(graph, buffer)}")
    lines.append("Publishes:")
    for b in graph.outputs(path):
        lines.append(f"  {names.topic(b)}{_size(graph, b)}")
    if leaf.template.params:
        lines.append("Parameters (checked against the template's range on every change):")
        for p in leaf.template.params:
            rng = f" {p.range_text()}" if p.range_text() else ""
            lines.append(f"  {names.param(path, p.name)}: {p.type}{rng}")
    return "\n".join(lines)


def _size(graph: RosGraph, data: str) -> str:
    return f" [{graph.size(data)}]" if graph.is_array(data) else ""


def _simulator_doc(graph: RosGraph) -> str:
    local = ", ".join(p for p in graph.world.leaves if p in graph.local) or "none"
    return (
        "Runs the amsa-phys engine on the scenario: steps the Leaves that share the physics\n"
        f"({local}) and publishes their outputs, asks every other Leaf's node to step\n"
        "(lockstep) or listens to it (free), publishes /clock and writes the run directory\n"
        "(trace.csv, metrics.json, scenario.yaml, plots) as `amsa-phys run` does."
    )


def _params_yaml(scenario: Scenario) -> str:
    """The ROS parameters at t = 0: the world's values with the scenario's ``set:``."""
    values = start_values(scenario)  # as the ROS 2 export's (external.py)
    phases = run_phases(scenario.world, scenario.seed)
    tree: dict[str, Any] = {}
    for path, params in values.items():
        node = tree
        for part in path.split("."):
            node = node.setdefault(part, {})
        for name, value in params.items():
            node[name] = _plain(value)
        if phases[path]:  # the timer's phase, for a C++ node in free mode ("NUM/DEN" s)
            node["amsa_phase"] = f"{phases[path].numerator}/{phases[path].denominator}"
    head = (
        f"# ROS parameters of {yaml_comment(scenario.name)} at t = 0 (the world's values and\n"
        "# the scenario's set:), loaded by the launch file; the scenario node changes them\n"
        "# along the timeline.\n"
    )
    return head + yaml_dump(tree)


def _plain(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value
