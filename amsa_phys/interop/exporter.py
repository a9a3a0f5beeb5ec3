"""An amsa-phys world as the original AMSA files: ``NAME.amsacore`` (XMI) + ``NAME.amsatemplate``.

Every Leaf is written with its frequency, every parameter value (not only those the paper's
templates declare) and every output of its template; every Data buffer that is read or named
becomes a ``data`` element (named as in the world's ``data:``, otherwise ``Producer_output``),
in the Composite of its name. An explicit ``schedule:`` becomes ``autoScheduling="false"`` on
the root with ``schedulingPriority`` n..1 on the listed Leaves (the importer reads it back in
that order). What the metamodel has no place for — physics settings, the description, user
template modules, which Data names were invented — goes into an ``xmi:Extension`` that EMF
ignores and ``amsa-phys import`` reads, so importing the files gives the same world back.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any
from xml.sax.saxutils import quoteattr

from ..model.filenames import file_name_problem
from ..model.template import BUILTINS, Template
from ..model.timing import LeafTiming
from ..model.world import CompositeSpec, LeafSpec, WorldSpec
from .amsacore import AMSA_NS, EXTENDER, XMI_NS, XSI_NS
from .amsatemplate import template_text


@dataclass
class Exported:
    """The two files' names and texts."""

    core_name: str
    core_text: str
    template_name: str
    template_text: str


def export_world(world: WorldSpec) -> Exported:
    """The ``.amsacore`` and ``.amsatemplate`` texts of ``world``; ``ValueError`` if the
    world's name cannot name them."""
    name = world.name
    if (why := file_name_problem(name, "the world's name")) is not None:
        raise ValueError(f"{why}: shorten it")
    tfile = f"{name}.amsatemplate"
    templates = _templates(world)
    writer = _Writer(world, tfile)
    return Exported(f"{name}.amsacore", writer.text(templates), tfile, template_text(templates))


def _templates(world: WorldSpec) -> list[type[Template]]:
    out: dict[str, type[Template]] = {}
    for leaf in world.leaves.values():
        name = leaf.template.name()
        other = out.get(name)
        if other is not None and other is not leaf.template:
            raise ValueError(f"two different templates are both called {name!r}")
        out[name] = leaf.template
    return list(out.values())


def _value_text(value: Any) -> str:
    """A parameter value as the model's string (floats exact: their repr)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, tuple):
        return json.dumps([list(v) if isinstance(v, tuple) else v for v in value])
    return str(value)


class _Writer:
    def __init__(self, world: WorldSpec, tfile: str) -> None:
        self.world = world
        self.tfile = tfile
        self.frag: dict[str, str] = {}  # component path -> fragment path
        self.data: dict[str, list[tuple[str, str]]] = {}  # composite path -> [(name, buffer)]
        self.data_frag: dict[str, str] = {}  # buffer -> fragment of its data element
        self.unnamed: list[str] = []
        self._place_data()

    def _place_data(self) -> None:
        named = {buffer: name for name, buffer in self.world.data_names.items()}
        used = {b for leaf in self.world.leaves.values() for b in leaf.inputs.values()}
        taken = set(self.world.data_names)
        for buffer in self.world.buffers:
            if buffer not in used and buffer not in named:
                continue
            if buffer in named:
                full = named[buffer]
            else:
                base = buffer.replace(".", "_")
                full, n = base, 1
                while full in taken:
                    n += 1
                    full = f"{base}_{n}"
                taken.add(full)
                self.unnamed.append(full)
            scope, _, short = full.rpartition(".")
            self.data.setdefault(scope, []).append((short, buffer))

    def text(self, templates: list[type[Template]]) -> str:
        lines = ['<?xml version="1.0" encoding="UTF-8"?>']
        count = len(self.world.leaves) + len(_composites(self.world.root))
        lines.append(
            f'<AMSA:AMSAFramework xmi:version="2.0" xmlns:xmi="{XMI_NS}" '
            f'xmlns:xsi="{XSI_NS}" xmlns:AMSA="{AMSA_NS}" instancesCount="{count}">'
        )
        self._fragments(self.world.root, "//@rootComponent")
        auto = "" if not self.world.schedule else ' autoScheduling="false"'
        lines.append(f"  <rootComponent name={quoteattr(self.world.name)}{auto}>")
        lines += self._composite_body(self.world.root, 2)
        lines.append("  </rootComponent>")
        lines.append(f'  <templatesContainers href="{self.tfile}#/"/>')
        lines += self._extension(templates)
        lines.append("</AMSA:AMSAFramework>")
        return "\n".join(lines) + "\n"

    def _fragments(self, node: CompositeSpec, frag: str) -> None:
        """Fragment paths of every component and data element, in document order."""
        for i, (_, buffer) in enumerate(self.data.get(node.path, [])):
            self.data_frag[buffer] = f"{frag}/@data.{i}"
        for i, child in enumerate(node.children):
            cfrag = f"{frag}/@components.{i}"
            self.frag[child.path] = cfrag
            if isinstance(child, CompositeSpec):
                self._fragments(child, cfrag)

    def _output_frag(self, buffer: str) -> str:
        producer, _, port = buffer.rpartition(".")
        leaf = self.world.leaves[producer]
        index = [p.name for p in leaf.template.outputs].index(port)
        return f"{self.frag[producer]}/@outputs.{index}"

    def _composite_body(self, node: CompositeSpec, depth: int) -> list[str]:
        pad = "  " * depth
        out = []
        for short, buffer in self.data.get(node.path, []):
            source = quoteattr(self._output_frag(buffer))
            out.append(f"{pad}<data name={quoteattr(short)} source={source}/>")
        for child in node.children:
            name = child.path.rpartition(".")[2]
            if isinstance(child, CompositeSpec):
                out.append(
                    f'{pad}<components xsi:type="AMSA:CompositeComponent" name={quoteattr(name)}>'
                )
                out += self._composite_body(child, depth + 1)
                out.append(f"{pad}</components>")
            else:
                out += self._leaf(child, name, pad)
        return out

    def _leaf(self, leaf: LeafSpec, name: str, pad: str) -> list[str]:
        freq = float(leaf.freq)
        attrs = f'name={quoteattr(name)} freq="{freq!r}"'
        if leaf.path in self.world.schedule:
            prio = len(self.world.schedule) - self.world.schedule.index(leaf.path)
            attrs += f' schedulingPriority="{prio}"'
        out = [f'{pad}<components xsi:type="AMSA:LeafComponent" {attrs}>']
        for port in leaf.template.outputs:
            out.append(f"{pad}  <outputs name={quoteattr(port.name)}/>")
        for port, buffer in leaf.inputs.items():
            source = quoteattr(self.data_frag[buffer])
            out.append(f"{pad}  <inputs name={quoteattr(port)} source={source}/>")
        href = f"{self.tfile}#{leaf.template.name()}"
        out.append(f"{pad}  <leafTemplate href={quoteattr(href)}/>")
        for pname, value in leaf.params.items():
            text = quoteattr(_value_text(value))
            out.append(f"{pad}  <parameters name={quoteattr(pname)} value={text}/>")
        out.append(f"{pad}</components>")
        return out

    def _extension(self, templates: list[type[Template]]) -> list[str]:
        world: dict[str, Any] = {"physics": self.world.physics}
        description = self.world.data.get("description")
        if description:
            world["description"] = description
        if world["physics"].get("walls") is None:
            world["physics"] = {k: v for k, v in world["physics"].items() if k != "walls"}
        if self.world.timing:
            world["timing"] = self.world.timing
        timing = {path: _timing(leaf.timing) for path, leaf in self.world.leaves.items()}
        timing = {path: t for path, t in timing.items() if t}
        if timing:  # the loop timing (model/timing.py): the metamodel has no place for it
            world["leafTiming"] = timing
        out = [f'  <xmi:Extension extender="{EXTENDER}">']
        out.append(f"    <world json={quoteattr(json.dumps(world, sort_keys=True))}/>")
        for cls in templates:
            ref = next(
                (leaf.template_ref for leaf in self.world.leaves.values() if leaf.template is cls),
                cls.name(),
            )
            if ref not in BUILTINS:
                out.append(
                    f"    <template name={quoteattr(cls.name())} implementation={quoteattr(ref)}/>"
                )
        if self.unnamed:
            out.append(f"    <unnamedData names={quoteattr(' '.join(self.unnamed))}/>")
        out.append("  </xmi:Extension>")
        return out


def _timing(t: LeafTiming) -> dict[str, str]:
    """A Leaf's latency, jitter and phase as exact texts (``"3/4"``, ``"random"``)."""
    out = {}
    for key in ("latency", "jitter", "phase"):
        value = getattr(t, key)
        if value is None or (key != "phase" and not value):
            continue
        out[key] = str(value)
    return out


def _composites(node: CompositeSpec) -> list[CompositeSpec]:
    out = [node]
    for child in node.children:
        if isinstance(child, CompositeSpec):
            out += _composites(child)
    return out
