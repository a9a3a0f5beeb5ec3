"""``amsa-phys export ros``: a catkin package from one or more scenarios of one world.

The package is named after the root component (the world's ``name``) and holds, as in the
paper's code generator: one node per Leaf (a Python script running the project's own
template class; a C++ (roscpp) twin for templates with a C++ body, e.g. NormalizePower), a
``std_msgs/Float64`` topic per Data, a ROS parameter per Parameter, a scenario node, a launch
file per scenario, ``package.xml``, ``CMakeLists.txt`` and a README. The physical Leaves
(those that share the pymunk world) step inside the simulator node, which also publishes
``/clock`` and writes the run directory. Files are written into a directory the caller
stages and renames (``runs.rundir.staged_dir``): nothing is half-written.
"""

from __future__ import annotations

import importlib.util
import re
import stat
import string
import sys
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path
from typing import Any
from xml.sax.saxutils import escape, quoteattr

import yaml

from .. import __version__
from ..engine.timing import run_phases
from ..errors import ConfigError
from ..model.scenario import Scenario
from ..model.template import BUILTINS
from ..model.world import LeafSpec, WorldSpec
from ..runs.resolve import resolved_scenario
from ..runs.rundir import unique_names
from . import names
from .graph import RosGraph, classify

FILES = Path(__file__).parent / "files"
MODES = ("lockstep", "free")
#: A catkin package name (catkin warns about capitals, as in the paper's ``mdeChallenge``).
PACKAGE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_YAML_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


class _Text(string.Template):
    delimiter = "@@"


def _fill(file: str, **values: Any) -> str:
    return _Text((FILES / file).read_text()).substitute(**{k: str(v) for k, v in values.items()})


@dataclass
class Package:
    """What was generated (for the command's report and the tests)."""

    name: str
    launch: list[str]
    nodes: list[str]
    local: list[str]
    cpp: list[str]
    files: list[str]


def cpp_bodies() -> dict[str, str]:
    """Templates with a C++ body (``files/cpp/NAME.inc``), by template name."""
    return {p.stem: p.read_text() for p in sorted((FILES / "cpp").glob("*.inc"))}


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


def generate(scenarios: list[Scenario], sources: list[str], mode: str, out: Path) -> Package:
    """Write the package for ``scenarios`` into the (staged, empty) directory ``out``."""
    if mode not in MODES:
        raise ConfigError(f"expected lockstep or free, got {mode!r}", key="--mode")
    world = check_same_world(scenarios, sources)
    pkg = world.name
    if not PACKAGE.match(pkg):
        raise ConfigError(
            f"the root component's name {pkg!r} cannot name a catkin package (a letter, then "
            "letters, digits and _): rename the world",
            file=sources[0],
        )
    names.check_world(world)
    for port, elements in world.arrays.items():  # one buffer per element, named port[i]
        raise ConfigError(
            f"{port} is an array port ({len(elements)} values): export ros publishes one "
            "std_msgs/Float64 topic per Data and cannot carry arrays (a lidar's ranges); "
            "export a world without array ports",
            file=sources[0],
        )
    for buffer in world.buffers.values():
        if not isinstance(buffer.initial, float | int) or isinstance(buffer.initial, bool):
            raise ConfigError(
                f"Data {buffer.name} is not a number (array ports cannot be exported: "
                "one std_msgs/Float64 topic per Data)",
                file=sources[0],
            )
    local = classify(world, scenarios[0].seed)
    graph = RosGraph.of(world, local)
    bodies = cpp_bodies()
    cpp = [p for p in graph.remote if world.leaves[p].template.name() in bodies]
    for path in cpp:
        _check_cpp_ports(world.leaves[path], bodies[world.leaves[path].template.name()])
    source = ", ".join(Path(s).name for s in sources)
    python = sys.executable
    files: dict[str, str] = {}
    executable: set[str] = set()

    extra = _extra_path(world)

    def node(script: str, title: str, doc: str, module: str, args: str) -> None:
        rel = f"nodes/{script}.py"
        files[rel] = _fill(
            "node.py.in",
            title=title,
            doc=doc,
            version=__version__,
            source=source,
            python=repr(python),
            module=module,
            args=args,
            extra_path=extra,
        )
        executable.add(rel)

    node(
        names.SIMULATOR,
        f"{names.SIMULATOR}: the simulator node of {pkg}.",
        _simulator_doc(graph),
        "simulator",
        "",
    )
    node(
        names.SCENARIO,
        f"{names.SCENARIO}: the scenario node of {pkg}.",
        "Applies the scenario's timeline to the parameter server at the phases' instants\n"
        "(simulated time, /clock) and announces each phase on /amsa/phase.",
        "scenario",
        "",
    )
    for path in graph.remote:
        leaf = world.leaves[path]
        node(
            names.script(path),
            f"{names.ns(path)}: ROS node of Leaf {path} (template {leaf.template.name()}, "
            f"{_hz(leaf.freq)} Hz).",
            _leaf_doc(graph, path),
            "leaf",
            repr(path),
        )
    for path in cpp:
        files[f"src/{names.script(path)}.cpp"] = _cpp_node(graph, path, pkg, source, bodies)
    if cpp:
        files[f"include/{pkg}/amsa_leaf_node.h"] = (FILES / "amsa_leaf_node.h").read_text()
    launches = []
    for scenario, fname in zip(scenarios, unique_names(s.name for s in scenarios), strict=True):
        files[f"config/{fname}.yaml"] = yaml.dump(
            resolved_scenario(scenario), Dumper=_YAML_DUMPER, sort_keys=False
        )
        files[f"config/{fname}_params.yaml"] = _params_yaml(scenario)
        files[f"launch/{fname}.launch"] = _launch(graph, pkg, fname, mode, cpp, source)
        launches.append(f"{fname}.launch")
    python_nodes = sorted(f for f in files if f.startswith("nodes/"))
    files["package.xml"] = _fill(
        "package.xml.in",
        pkg=pkg,
        version=__version__,
        source=escape(source),
        description=escape(str(world.data.get("description") or f"The {pkg} system.")),
    )
    files["CMakeLists.txt"] = _fill(
        "CMakeLists.txt.in",
        pkg=pkg,
        version=__version__,
        source=source,
        python_nodes="\n".join(f"  {f}" for f in python_nodes),
        cpp_targets=_cmake_cpp(cpp),
    )
    files["README.md"] = _readme(graph, pkg, source, launches, mode, cpp, python)
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


def _hz(freq: Fraction) -> str:
    return f"{float(freq):g}"


def _extra_path(world: WorldSpec) -> str:
    """The user templates' module directories on ``sys.path`` (built-ins need nothing).

    Every node loads the whole scenario, so every node needs every template importable.
    """
    lines = []
    for ref in sorted({leaf.template_ref for leaf in world.leaves.values()} - set(BUILTINS)):
        module = ref.partition(":")[0]
        spec = importlib.util.find_spec(module)
        if spec is None or spec.origin is None:
            continue
        root = Path(spec.origin).resolve().parent
        for _ in range(module.count(".") + (1 if spec.origin.endswith("__init__.py") else 0)):
            root = root.parent
        line = f"sys.path.insert(0, {str(root)!r})  # {ref}"
        if line not in lines:
            lines.append(line)
    if not lines:
        return ""
    head = "\n# user templates, imported from where they were found at export time\n"
    return head + "\n".join(lines) + "\n"


def _leaf_doc(graph: RosGraph, path: str) -> str:
    leaf = graph.leaf(path)
    lines = [f"Runs {leaf.template_ref} ({leaf.template.describe()})"]
    lines.append("Subscribes (std_msgs/Float64):")
    for port, buffer in leaf.inputs.items():
        lines.append(f"  {port} <- {names.topic(buffer)}")
    lines.append("Publishes (std_msgs/Float64):")
    for b in graph.outputs(path):
        lines.append(f"  {names.topic(b)}")
    if leaf.template.params:
        lines.append("Parameters (checked against the template's range on every change):")
        for p in leaf.template.params:
            rng = f" {p.range_text()}" if p.range_text() else ""
            lines.append(f"  {names.param(path, p.name)}: {p.type}{rng}")
    return "\n".join(lines)


def _simulator_doc(graph: RosGraph) -> str:
    local = ", ".join(p for p in graph.world.leaves if p in graph.local) or "none"
    return (
        "Runs the amsa-phys engine on the scenario: steps the Leaves that share the physics\n"
        f"({local}) and publishes their outputs, asks every other Leaf's node to step\n"
        "(lockstep) or listens to it (free), publishes /clock and writes the run directory\n"
        "(trace.csv, metrics.json, scenario.yaml, plots) as `amsa-phys run` does."
    )


def _check_cpp_ports(leaf: LeafSpec, body: str) -> None:
    """A C++ body names the ports it indexes: they must be the template's, in order."""
    m = re.match(r"// ports: in=(\S*) out=(\S*)", body)
    want_in = [p.name for p in leaf.template.inputs]
    want_out = [p.name for p in leaf.template.outputs]
    if m is None or m.group(1).split(",") != want_in or m.group(2).split(",") != want_out:
        raise ConfigError(
            f"the C++ body of {leaf.template.name()} does not match its ports",
            key=f"component {leaf.path}",
        )


def _cpp_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _cpp_double(value: float) -> str:
    """A double literal that reads back to exactly ``value``."""
    text = repr(float(value))
    return text if any(c in text for c in ".en") else text + ".0"


def _cpp_node(graph: RosGraph, path: str, pkg: str, source: str, bodies: dict[str, str]) -> str:
    leaf = graph.leaf(path)
    world = graph.world
    buffers = graph.input_buffers(path)
    outputs = graph.outputs(path)
    topics = [
        f"{{{_cpp_string(names.topic(b))}, {_cpp_double(world.buffers[b].initial)}, "
        f"{str(world.leaves[world.buffers[b].producer].timing.delayed).lower()}}}"
        for b in buffers
    ]
    inputs = []
    for port, buffer in leaf.inputs.items():
        index = buffers.index(buffer) if buffer in buffers else -(1 + outputs.index(buffer))
        inputs.append(f"{{{_cpp_string(port)}, {index}}}")
    outs = [
        f"{{{_cpp_string(b.rpartition('.')[2])}, {_cpp_string(names.topic(b))}, "
        f"{_cpp_double(world.buffers[b].initial)}, {graph.subscribers(b)}}}"
        for b in outputs
    ]
    params = []
    for p in leaf.template.params:
        kind = {"float": "d", "int": "i", "enum": "i", "bool": "b"}.get(p.type)
        if kind is None:
            raise ConfigError(
                f"parameter {p.name} ({p.type}) has no C++ type", key=f"component {path}"
            )
        lo = _cpp_double(p.min) if p.min is not None else "0.0"
        hi = _cpp_double(p.max) if p.max is not None else "0.0"
        params.append(
            f"{{{_cpp_string(p.name)}, '{kind}', {str(p.min is not None).lower()}, "
            f"{str(p.max is not None).lower()}, {lo}, {hi}}}"
        )
    body = bodies[leaf.template.name()].split("\n", 1)[1].rstrip()
    freq = Fraction(leaf.freq)
    sep = ",\n             "
    return _fill(
        "cpp_node.cpp.in",
        version=__version__,
        source=source,
        path=path,
        template=leaf.template.name(),
        freq=_hz(leaf.freq),
        pkg=pkg,
        freq_num=freq.numerator,
        freq_den=freq.denominator,
        topics=sep.join(topics),
        inputs=sep.join(inputs),
        outputs=sep.join(outs),
        params=sep.join(params),
        body=body,
        name=path.rpartition(".")[2],
    )


def _cmake_cpp(cpp: list[str]) -> str:
    lines = []
    for path in cpp:
        target = f"{names.script(path)}_cpp"
        lines.append(f"  add_executable({target} src/{names.script(path)}.cpp)")
        lines.append(f"  target_link_libraries({target} ${{roscpp_LIBRARIES}})")
        lines.append(
            f"  install(TARGETS {target} RUNTIME DESTINATION ${{CATKIN_PACKAGE_BIN_DESTINATION}})"
        )
    return "\n".join(lines) if lines else "  # no Leaf has a C++ body"


def _params_yaml(scenario: Scenario) -> str:
    """The ROS parameters at t = 0: the world's values with the scenario's ``set:``."""
    values = {path: dict(leaf.params) for path, leaf in scenario.world.leaves.items()}
    for change in scenario.phases[0].changes:
        values[change.leaf][change.param] = change.value
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
        f"# ROS parameters of {scenario.name} at t = 0 (the world's values and the scenario's\n"
        "# set:), loaded by the launch file; the scenario node changes them along the timeline.\n"
    )
    return head + yaml.dump(tree, Dumper=_YAML_DUMPER, sort_keys=False)


def _plain(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def _launch(graph: RosGraph, pkg: str, fname: str, mode: str, cpp: list[str], source: str) -> str:
    find = f"$(find {pkg})"
    data_topics = " ".join(graph.data_topics())
    local = ", ".join(p for p in graph.world.leaves if p in graph.local)
    lines = [
        '<?xml version="1.0"?>',
        f"<!-- Generated by amsa-phys {__version__} from {escape(source)}: scenario"
        f" {escape(fname)} of {escape(pkg)}."
        f" roslaunch {escape(pkg)} {escape(fname)}.launch [arg:=value ...] -->",
        "<launch>",
        f'  <arg name="mode" default="{mode}" doc="lockstep: reproduces amsa-phys run byte for'
        ' byte; free: every node on its own timer (not reproducible)"/>',
        '  <arg name="out" default="" doc="run directory (default: runs/NAME-STAMP in the'
        ' current directory)"/>',
        '  <arg name="force" default="false" doc="replace an out directory amsa-phys made"/>',
        '  <arg name="bag" default="" doc="record every Data topic to this .bag file'
        ' (an absolute path)"/>',
        '  <arg name="speed" default="1.0" doc="free mode: simulated seconds per wall second"/>',
        '  <arg name="duration" default="" doc="simulated seconds to run (default: the'
        " scenario's)\"/>",
        '  <arg name="plots" default="true" doc="draw distance.png and trajectory.png"/>',
        '  <arg name="timeout" default="60" doc="seconds to wait for a node before giving up"/>',
    ]
    if cpp:
        lines.append(
            '  <arg name="cpp" default="true" doc="run the Leaves with a C++ body as their'
            ' roscpp node (false: their Python twin)"/>'
        )
    lines += [
        '  <param name="/use_sim_time" value="true"/>',
        '  <group ns="amsa">',
        f'    <param name="scenario" value="{find}/config/{fname}.yaml"/>',
        '    <param name="mode" value="$(arg mode)"/>',
        '    <param name="bag" type="bool" value="$(eval arg(\'bag\') != \'\')"/>',
        '    <param name="timeout" type="double" value="$(arg timeout)"/>',
        f'    <rosparam param="local">[{local}]</rosparam>',
        "  </group>",
        f'  <rosparam command="load" file="{find}/config/{fname}_params.yaml"/>',
        "",
        f"  <!-- the physics ({escape(local) or 'no Leaf'}) and /clock;"
        " writes the run directory -->",
        f'  <node pkg="{pkg}" type="{names.SIMULATOR}.py" name="{names.SIMULATOR}"'
        ' required="true" output="screen">',
        '    <param name="out" value="$(arg out)"/>',
        '    <param name="force" type="bool" value="$(arg force)"/>',
        '    <param name="speed" type="double" value="$(arg speed)"/>',
        '    <param name="duration" type="str" value="$(arg duration)"/>',
        '    <param name="plots" type="bool" value="$(arg plots)"/>',
        "  </node>",
        f'  <node pkg="{pkg}" type="{names.SCENARIO}.py" name="{names.SCENARIO}" required="true"'
        ' output="screen"/>',
        "",
    ]
    for path in graph.remote:
        leaf = graph.leaf(path)
        parent, _, base = path.rpartition(".")
        ns = f' ns="{names.ns(parent)}"' if parent else ""
        comment = f"  <!-- {escape(path)}: {escape(leaf.template.name())}, {_hz(leaf.freq)} Hz -->"
        lines.append(comment)
        script = names.script(path)
        common = f'pkg="{pkg}" name="{base}"{ns} required="true"'
        if path in cpp:
            lines.append(f'  <node if="$(arg cpp)" {common} type="{script}_cpp"/>')
            lines.append(f'  <node unless="$(arg cpp)" {common} type="{script}.py"/>')
        else:
            lines.append(f'  <node {common} type="{script}.py"/>')
    lines += [
        "",
        "  <!-- bag:=FILE.bag records every Data topic (connected before the run starts) -->",
        '  <node if="$(eval arg(\'bag\') != \'\')" pkg="rosbag" type="record" name="amsa_bag"',
        f"        args={quoteattr('-O $(arg bag) --tcpnodelay ' + data_topics)}/>",
        "</launch>",
    ]
    return "\n".join(lines) + "\n"


def _readme(
    graph: RosGraph,
    pkg: str,
    source: str,
    launches: list[str],
    mode: str,
    cpp: list[str],
    python: str,
) -> str:
    world = graph.world
    local = [p for p in world.leaves if p in graph.local]
    rows = []
    for path, leaf in world.leaves.items():
        where = f"`{names.SIMULATOR}`" if path in graph.local else f"`{names.ns(path)}`"
        if path in cpp:
            where += " (C++, or Python with `cpp:=false`)"
        params = ", ".join(f"`{p.name}`" for p in leaf.template.params) or "-"
        rows.append(
            f"| `{path}` | {leaf.template.name()} | {_hz(leaf.freq)} | {where} | "
            f"{', '.join(f'`{names.topic(b)}`' for b in graph.outputs(path))} | {params} |"
        )
    data_names = "".join(
        f"| `{name}` | `{names.topic(buffer)}` |\n" for name, buffer in world.data_names.items()
    )
    launch = launches[0]
    text = f"""# {pkg}

A ROS 1 (catkin) package generated by amsa-phys {__version__} from {source}: the architecture
`{pkg}` as one node per Leaf component (running amsa-phys's own template class: the same
code as `amsa-phys run`), a `std_msgs/Float64` topic `/Component/output` per Data, a ROS
parameter `/Component/param` per Parameter, a scenario node (`{names.SCENARIO}`) applying
the timeline and a simulator node (`{names.SIMULATOR}`) that owns the physics, publishes
`/clock` (simulated time, `use_sim_time`) and writes the run directory.

## Build

The package must sit in a catkin workspace's `src/` (export with `-o WS/src/{pkg}`):

    cd WS && catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3

`-DPYTHON_EXECUTABLE` names a Python that has catkin's own modules (Debian's); without it
catkin picks the first `python3` on `PATH`, which fails in an activated venv.

## Run

    source WS/devel/setup.bash
    roslaunch {pkg} {launch}
    roslaunch {pkg} {launch} mode:=free speed:=2 out:=/tmp/run bag:=/tmp/run.bag

Launch files: {", ".join(f"`{x}`" for x in launches)}. Arguments: `mode` (`lockstep` or
`free`, default `{mode}`), `out` (run directory, default `runs/NAME-STAMP` in the current
directory; an existing one is replaced only with `force:=true` and only if amsa-phys made it),
`bag` (record every Data topic), `speed` (free mode), `duration` (simulated seconds, default
the scenario's), `plots`, `timeout`{", `cpp`" if cpp else ""}.
The run ends by itself (the simulator is a required node); Ctrl-C stops every node and
writes the outputs so far.

- **lockstep** (default): the simulator steps the nodes in the engine's order at the
  engine's instants (a step request carries the exact instant and how many messages each
  input topic has carried; a node steps once it has them, publishes, and answers), and the
  scenario's changes land at their exact instants. `trace.csv` and `metrics.json` are
  byte-identical to `amsa-phys run` of the same scenario and seed (except `wall_time_s`
  and `real_time_factor`).
- **free**: every node steps on its own timer at its own rate in simulated time, with
  whatever its inputs hold then, as the paper's generated nodes ran; the simulator paces
  simulated time at `speed` x the wall clock. Not reproducible: the metrics come close to
  the in-process run's, the trace does not match it. Parameters may be changed while it
  runs (`rosparam set /MyFollowerController/Kv 0.2`): each node checks the template's range.

## Which Python

The nodes import amsa-phys, so they run in the Python that exported the package:
`{python}` (override with the environment variable `AMSA_PHYS_PYTHON`). catkin's relays
start them with Debian's `python3` (which has `rospy`); each script then records where
`rospy` lives and re-executes itself with that Python, which appends ROS's Python packages
after its own.

## Nodes, topics, parameters

Physical Leaves ({", ".join(local) or "none"}) share one pymunk world, so they step inside
`{names.SIMULATOR}` and publish from there.

| Leaf | template | Hz | node | publishes | parameters |
| --- | --- | --- | --- | --- | --- |
{chr(10).join(rows)}
"""
    if data_names:
        text += (
            "\nNamed Data (the model's names):\n\n| Data | topic |\n| --- | --- |\n" + data_names
        )
    text += """
Framework topics: `/clock`, `/amsa/step/LEAF` and `/amsa/done/LEAF` (lockstep requests and
answers, `std_msgs/String`), `/amsa/phase` (the scenario node's announcements),
`/amsa/ready` (start-up handshake: ROS 1 drops what is published before a subscriber
connects, so the run starts once every publisher has all its subscribers).
"""
    return text
