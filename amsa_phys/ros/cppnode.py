"""The C++ (roscpp) Leaves: one nodelet class per template with a C++ body, their wiring,
the plugin list and the CMake targets (a library of the classes, the ``amsa_leaves`` container).

Every name reaches the C++ and CMake text through :mod:`.quote` (``cpp_string``,
``cpp_comment``, ``cmake_arg``); numbers are written so they read back exactly.
"""

from __future__ import annotations

import re
from dataclasses import replace
from fractions import Fraction
from pathlib import Path
from typing import Any

from .._version import __version__
from ..errors import ConfigError
from ..model.template import Template, resolve_template
from ..model.world import LeafSpec
from . import names
from .graph import RosGraph
from .quote import Code, cmake_arg, cpp_string, fill, yaml_comment, yaml_dump

FILES = Path(__file__).parent / "files"


def cpp_bodies() -> dict[type[Template], str]:
    """The shipped templates with a C++ body (``files/cpp/NAME.inc``), by class.

    A body is the C++ twin of one class's step, so it is keyed by that class, never by a
    name: a user's own template that happens to be called ``GPS``, or a subclass of the
    shipped GPS (which may step otherwise), has no body and runs its own Python step.
    """
    return {resolve_template(p.stem): p.read_text() for p in sorted((FILES / "cpp").glob("*.inc"))}


def _names(text: str) -> list[str]:
    """``a,b`` as ``["a", "b"]``, and an empty list as ``[]`` (ConstantPower has no inputs)."""
    return [n for n in text.split(",") if n]


def has_cpp(leaf: LeafSpec, bodies: dict[str, str]) -> bool:
    """Whether ``leaf`` runs as a C++ node: its template has a body and every input port is
    linked (the body indexes ``in[]`` by the template's ports; an optional port left
    unlinked, as an IMU without the pose, would shift them: such a Leaf stays in Python)."""
    ports = [p.name for p in leaf.template.inputs]
    return leaf.template in bodies and all(p in leaf.inputs for p in ports)


def check_cpp_ports(leaf: LeafSpec, body: str) -> None:
    """A C++ body names the ports it indexes: they must be the template's, in order."""
    m = re.match(r"// ports: in=(\S*) out=(\S*)", body)
    want_in = [p.name for p in leaf.template.inputs]
    want_out = [p.name for p in leaf.template.outputs]
    if m is None or _names(m.group(1)) != want_in or _names(m.group(2)) != want_out:
        raise ConfigError(
            f"the C++ body of {leaf.template.name()} does not match its ports",
            key=f"component {leaf.path}",
        )


def cpp_double(value: float) -> str:
    """A double literal that reads back to exactly ``value``."""
    text = repr(float(value))
    return text if any(c in text for c in ".en") else text + ".0"


def _first(initial: float | tuple[float, ...]) -> float:
    """A Data's initial value; an array port's elements all start at its port's initial."""
    return initial[0] if isinstance(initial, tuple) else initial


def _size(graph: RosGraph, data: str) -> str:
    """`` N`` for an array port's topic (its length), nothing for a number."""
    return f" {graph.size(data)}" if graph.is_array(data) else ""


def hz(freq: Fraction) -> str:
    """A frequency as people read it (``4``, ``0.5``)."""
    return f"{float(freq):g}"


def namespace(pkg: str) -> str:
    """The C++ namespace of the package's Leaf classes (``amsa_PKG``: a plugin class's name
    must be unique among every library a nodelet manager loads)."""
    return f"amsa_{pkg}"


def plugin(pkg: str, tname: str) -> str:
    """The nodelet class name of a template's C++ Leaf: ``PKG/TEMPLATE``."""
    return f"{pkg}/{tname}"


def cpp_templates(graph: RosGraph, cpp: list[str]) -> dict[str, list[str]]:
    """The templates of the C++ Leaves, each with its Leaves (world order)."""
    out: dict[str, list[str]] = {}
    for path in cpp:
        out.setdefault(graph.leaf(path).template.name(), []).append(path)
    return out


def _param_specs(leaf: LeafSpec) -> list[str]:
    params = []
    for p in leaf.template.params:
        kind = {"float": "d", "int": "i", "enum": "i", "bool": "b"}.get(p.type)
        if kind is None:
            raise ConfigError(
                f"parameter {p.name} ({p.type}) has no C++ type", key=f"component {leaf.path}"
            )
        lo = cpp_double(p.min) if p.min is not None else "0.0"
        hi = cpp_double(p.max) if p.max is not None else "0.0"
        params.append(
            f"{{{cpp_string(p.name)}, '{kind}', {str(p.min is not None).lower()}, "
            f"{str(p.max is not None).lower()}, {lo}, {hi}}}"
        )
    return params


def cpp_leaf(
    graph: RosGraph,
    tname: str,
    paths: list[str],
    pkg: str,
    source: str,
    bodies: dict[type[Template], str],
) -> str:
    """``src/leaves/TEMPLATE.cpp``: the template's nodelet class, compiled once for all of
    its Leaves (``paths``); each Leaf's wiring is a parameter (:func:`wiring`)."""
    leaf = graph.leaf(paths[0])
    body = bodies[leaf.template].split("\n", 1)[1].rstrip()
    sep = ",\n                        "
    return fill(
        (FILES / "cpp_leaf.cpp.in").read_text(),
        version=__version__,
        source=source,
        tname=tname,
        cls=Code(tname),  # a shipped template's name (only they have C++ bodies): an identifier
        plugin=plugin(pkg, tname),
        leaves=", ".join(paths),
        header=f"{pkg}/amsa_leaf_node.h",  # pkg is [A-Za-z][A-Za-z0-9_]*: nothing to escape
        noise_header=f"{pkg}/amsa_noise.h",
        rng_header=f"{pkg}/amsa_rng.h",
        window_header=f"{pkg}/amsa_window.h",
        namespace=Code(namespace(pkg)),  # pkg is [A-Za-z][A-Za-z0-9_]*
        in_ports=Code(", ".join(cpp_string(p.name) for p in leaf.template.inputs)),
        out_ports=Code(", ".join(cpp_string(p.name) for p in leaf.template.outputs)),
        params=Code(sep.join(_param_specs(leaf))),
        body=Code(body),  # a file of amsa-phys's own (files/cpp/), not the user's
    )


def wiring(graph: RosGraph, path: str, cpp: list[str]) -> str:
    """A C++ Leaf's ``~amsa_wiring`` (format in ``files/amsa_wiring.h``): its path, rate,
    input topics (initial value, delayed producer), the template's ports mapped to them and
    its outputs; numbers as hex floats, which C's ``strtod`` reads back exactly."""
    leaf = graph.leaf(path)
    world = graph.world
    buffers = graph.input_buffers(path)
    outputs = graph.outputs(path)
    freq = Fraction(leaf.freq)
    lines = [f"path {path}", f"freq {freq.numerator} {freq.denominator}"]
    for b in buffers:  # an array port's topic: its length last (a Float64MultiArray)
        delayed = int(world.leaves[graph.producer(b)].timing.delayed)
        initial = float(_first(graph.initial(b))).hex()
        lines.append(f"topic {names.topic(b)} {initial} {delayed}{_size(graph, b)}")
    for port in [p.name for p in leaf.template.inputs]:  # the body's order, not the YAML's
        buffer = leaf.inputs[port]
        index = buffers.index(buffer) if buffer in buffers else -(1 + outputs.index(buffer))
        lines.append(f"input {port} {index}")
    # subscribers (processes) with every Leaf a process of its own, and with the C++ Leaves
    # in the container (ROS 1 subscribes a process once per topic)
    alone = replace(graph, shared=frozenset())
    together = replace(graph, shared=frozenset(cpp))
    for b in outputs:
        initial = float(_first(graph.initial(b))).hex()
        lines.append(
            f"output {b.rpartition('.')[2]} {names.topic(b)} {initial} "
            f"{alone.subscribers(b)} {together.subscribers(b)}{_size(graph, b)}"
        )
    return "\n".join(lines) + "\n"


def leaves_yaml(graph: RosGraph, pkg: str, cpp: list[str], side: list[str]) -> str:
    """``config/amsa_leaves.yaml``: the container's list of C++ Leaves (``/amsa_leaves/leaves``)
    and each Leaf's wiring (``/LEAF/amsa_wiring``), loaded by the launch files with cpp:=true."""
    tree: dict[str, Any] = {
        names.CONTAINER: {
            "leaves": [
                {
                    "name": names.ns(path),
                    "type": plugin(pkg, graph.leaf(path).template.name()),
                    "controller_side": path in side,
                }
                for path in cpp
            ]
        }
    }
    for path in cpp:
        node = tree
        for part in path.split("."):
            node = node.setdefault(part, {})
        node["amsa_wiring"] = wiring(graph, path, cpp)
    head = (
        f"# The C++ Leaves of {yaml_comment(pkg)}: the list amsa_leaves loads into one process,\n"
        "# and each Leaf's wiring (format: include/PKG/amsa_wiring.h). Generated by amsa-phys.\n"
    )
    return head + yaml_dump(tree)


def plugins_xml(graph: RosGraph, pkg: str, cpp: list[str]) -> str:
    """``nodelet_plugins.xml``: one nodelet class per template, in the package's library."""
    lines = [
        fill('<library path="lib/lib@@{lib:xml_attr}">', lib=library(pkg)),
    ]
    for tname in cpp_templates(graph, cpp):
        lines.append(
            fill(
                '  <class name="@@{name:xml_attr}" type="@@{type:xml_attr}"'
                ' base_class_type="nodelet::Nodelet">\n'
                "    <description>Leaf template @@{tname:xml_text} (amsa-phys): doStep in"
                " C++</description>\n  </class>",
                name=plugin(pkg, tname),
                type=f"{namespace(pkg)}::{tname}",
                tname=tname,
            )
        )
    lines.append("</library>")
    return "\n".join(lines) + "\n"


def library(pkg: str) -> str:
    """The CMake target (and library name) of the package's nodelet classes."""
    return f"{pkg}_leaves"


def cmake_targets(graph: RosGraph, pkg: str, cpp: list[str]) -> Code:
    """The C++ block of CMakeLists.txt: the nodelet library (one source file per template)
    and the ``amsa_leaves`` container."""
    if not cpp:
        return Code("  # no Leaf has a C++ body")
    lib = cmake_arg(library(pkg))
    sources = " ".join(cmake_arg(f"src/leaves/{t}.cpp") for t in cpp_templates(graph, cpp))
    # the container's target is named after the package (CMake target names are global to
    # a catkin workspace: two exported packages side by side would both define amsa_leaves);
    # the executable is still devel/lib/PKG/amsa_leaves, what the launch files start
    exe = cmake_arg(f"{pkg}_{names.CONTAINER}")
    lines = [
        f"  add_library({lib} {sources})",
        f"  target_link_libraries({lib} ${{roscpp_LIBRARIES}} ${{nodelet_LIBRARIES}})",
        f"  add_executable({exe} src/{names.CONTAINER}.cpp)",
        f"  set_target_properties({exe} PROPERTIES OUTPUT_NAME {names.CONTAINER})",
        f"  target_link_libraries({exe} ${{roscpp_LIBRARIES}} ${{nodelet_LIBRARIES}})",
        # amsa_leaves.cpp is the same in every package: it finds amsa_exit.h by this path
        # (pkg is [A-Za-z][A-Za-z0-9_]*: cmake_arg leaves it unquoted, to append)
        f"  target_include_directories({exe} PRIVATE"
        f" ${{CMAKE_CURRENT_SOURCE_DIR}}/{cmake_arg(f'include/{pkg}')})",
        f"  install(TARGETS {lib} LIBRARY DESTINATION ${{CATKIN_PACKAGE_LIB_DESTINATION}})",
        f"  install(TARGETS {exe} RUNTIME DESTINATION ${{CATKIN_PACKAGE_BIN_DESTINATION}})",
        "  install(FILES nodelet_plugins.xml DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})",
    ]
    return Code("\n".join(lines))


def manifest_export(cpp: list[str]) -> Code:
    """package.xml's ``<export>``: the nodelet plugins, so a manager finds the classes."""
    if not cpp:
        return Code("")
    return Code('  <export>\n    <nodelet plugin="${prefix}/nodelet_plugins.xml"/>\n  </export>\n')
