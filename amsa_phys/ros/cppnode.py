"""The C++ (roscpp) node of a Leaf whose template has a C++ body, and its CMake targets.

Every name reaches the C++ and CMake text through :mod:`.quote` (``cpp_string``,
``cpp_comment``, ``cmake_arg``); numbers are written so they read back exactly.
"""

from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path

from .. import __version__
from ..errors import ConfigError
from ..model.world import LeafSpec
from . import names
from .graph import RosGraph
from .quote import Code, cmake_arg, cpp_string, fill

FILES = Path(__file__).parent / "files"


def cpp_bodies() -> dict[str, str]:
    """Templates with a C++ body (``files/cpp/NAME.inc``), by template name."""
    return {p.stem: p.read_text() for p in sorted((FILES / "cpp").glob("*.inc"))}


def _names(text: str) -> list[str]:
    """``a,b`` as ``["a", "b"]``, and an empty list as ``[]`` (ConstantPower has no inputs)."""
    return [n for n in text.split(",") if n]


def has_cpp(leaf: LeafSpec, bodies: dict[str, str]) -> bool:
    """Whether ``leaf`` runs as a C++ node: its template has a body and every input port is
    linked (the body indexes ``in[]`` by the template's ports; an optional port left
    unlinked, as an IMU without the pose, would shift them: such a Leaf stays in Python)."""
    ports = [p.name for p in leaf.template.inputs]
    return leaf.template.name() in bodies and all(p in leaf.inputs for p in ports)


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
    """``, N`` for an array port (``Topic.size``/``OutputPort.size``), nothing for a number."""
    return f", {graph.size(data)}" if graph.is_array(data) else ""


def hz(freq: Fraction) -> str:
    """A frequency as people read it (``4``, ``0.5``)."""
    return f"{float(freq):g}"


def cpp_node(graph: RosGraph, path: str, pkg: str, source: str, bodies: dict[str, str]) -> str:
    """``src/PATH.cpp``: the Leaf's roscpp node around its template's C++ body."""
    leaf = graph.leaf(path)
    world = graph.world
    buffers = graph.input_buffers(path)
    outputs = graph.outputs(path)
    topics = [
        f"{{{cpp_string(names.topic(b))}, {cpp_double(_first(graph.initial(b)))}, "
        f"{str(world.leaves[graph.producer(b)].timing.delayed).lower()}{_size(graph, b)}}}"
        for b in buffers
    ]
    inputs = []
    for port in [p.name for p in leaf.template.inputs]:  # the body's order, not the YAML's
        buffer = leaf.inputs[port]
        index = buffers.index(buffer) if buffer in buffers else -(1 + outputs.index(buffer))
        inputs.append(f"{{{cpp_string(port)}, {index}}}")
    outs = [
        f"{{{cpp_string(b.rpartition('.')[2])}, {cpp_string(names.topic(b))}, "
        f"{cpp_double(_first(graph.initial(b)))}, {graph.subscribers(b)}{_size(graph, b)}}}"
        for b in outputs
    ]
    params = []
    for p in leaf.template.params:
        kind = {"float": "d", "int": "i", "enum": "i", "bool": "b"}.get(p.type)
        if kind is None:
            raise ConfigError(
                f"parameter {p.name} ({p.type}) has no C++ type", key=f"component {path}"
            )
        lo = cpp_double(p.min) if p.min is not None else "0.0"
        hi = cpp_double(p.max) if p.max is not None else "0.0"
        params.append(
            f"{{{cpp_string(p.name)}, '{kind}', {str(p.min is not None).lower()}, "
            f"{str(p.max is not None).lower()}, {lo}, {hi}}}"
        )
    body = bodies[leaf.template.name()].split("\n", 1)[1].rstrip()
    freq = Fraction(leaf.freq)
    sep = ",\n             "
    return fill(
        (FILES / "cpp_node.cpp.in").read_text(),
        version=__version__,
        source=source,
        path=path,
        path_literal=path,
        tname=leaf.template.name(),
        freq=hz(leaf.freq),
        header=f"{pkg}/amsa_leaf_node.h",  # pkg is [A-Za-z][A-Za-z0-9_]*: nothing to escape
        noise_header=f"{pkg}/amsa_noise.h",
        rng_header=f"{pkg}/amsa_rng.h",
        window_header=f"{pkg}/amsa_window.h",
        path_key=path,
        freq_num=freq.numerator,
        freq_den=freq.denominator,
        topics=Code(sep.join(topics)),
        inputs=Code(sep.join(inputs)),
        outputs=Code(sep.join(outs)),
        params=Code(sep.join(params)),
        body=Code(body),  # a file of amsa-phys's own (files/cpp/), not the user's
        name=path.rpartition(".")[2],
    )


def cmake_targets(cpp: list[str]) -> Code:
    """The ``add_executable`` block of the C++ nodes (CMakeLists.txt)."""
    lines = []
    for path in cpp:
        target = cmake_arg(f"{names.script(path)}_cpp")
        lines.append(f"  add_executable({target} {cmake_arg(f'src/{names.script(path)}.cpp')})")
        lines.append(f"  target_link_libraries({target} ${{roscpp_LIBRARIES}})")
        lines.append(
            f"  install(TARGETS {target} RUNTIME DESTINATION ${{CATKIN_PACKAGE_BIN_DESTINATION}})"
        )
    return Code("\n".join(lines) if lines else "  # no Leaf has a C++ body")
