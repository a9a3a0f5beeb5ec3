"""Reading an AMSA model (``.amsacore``: XMI of the metamodel ``amsaCore.ecore``).

The metamodel (``shared/reference/amsa/amsaCore.ecore``): an ``AMSAFramework`` holds one
``rootComponent`` (a CompositeComponent); a Composite holds ``data`` (Data) and
``components``; a LeafComponent has ``outputs``, ``inputs`` (each with a ``source``),
``parameters`` (name, value as a string), a ``leafTemplate`` (a reference into the template
file) and ``freq`` (EDouble, default 10). An input's source is a Data, whose source is an
output (or another Data, or a Composite's port, followed the same way).

References are EMF fragment paths (``//@rootComponent/@components.7/@outputs.0``, optionally
after ``file#``) or ``xmi:id`` values; a reference that names nothing is an error with the
line it is on. amsa-phys's own extras (physics settings, exact frequencies, user template
modules) travel in an ``xmi:Extension extender="amsa-phys"`` element, which EMF ignores.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..model.schema import NAME
from .xmlsafe import Element, parse_file

AMSA_NS = "http://com.merconcept/AMSA"
XMI_NS = "http://www.omg.org/XMI"
XSI_NS = "http://www.w3.org/2001/XMLSchema-instance"
XSI_TYPE = f"{{{XSI_NS}}}type"
XMI_ID = f"{{{XMI_NS}}}id"
EXTENDER = "amsa-phys"
_NAME = re.compile(NAME)


@dataclass
class LeafNode:
    """A LeafComponent of the model."""

    path: str
    elem: Element
    template: str  # the template's name (the href's fragment)
    template_href: str
    freq: str | None
    priority: int
    #: name -> (value, or None if the model leaves it empty; line)
    params: dict[str, tuple[str | None, int]]
    #: input port -> (buffer "Producer.output", line)
    inputs: dict[str, tuple[str, int]]
    outputs: list[str]


@dataclass
class CompositeNode:
    """A CompositeComponent (the root is the system)."""

    path: str
    name: str
    elem: Element
    auto_scheduling: bool
    children: list[LeafNode | CompositeNode] = field(default_factory=list)


@dataclass
class Model:
    """What an ``.amsacore`` file says, references resolved."""

    path: Path
    root: CompositeNode
    leaves: dict[str, LeafNode]
    #: Data name ("name", or "Composite.name" inside a Composite) -> (buffer, line)
    data: dict[str, tuple[str, int]]
    templates_href: str | None
    extension: dict[str, Any]


def read_model(path: Path) -> Model:
    """Parse and resolve an AMSA model file; a one-line ConfigError on anything wrong."""
    root = parse_file(path, "AMSA XMI", _check_root)
    return _Reader(path, root).read()


def _check_root(root: Element) -> str | None:
    """Judged on the root's start tag, before the rest of the file is parsed."""
    if root.tag != f"{{{AMSA_NS}}}AMSAFramework":
        return (
            f"is not an AMSA model: the root element is {_show(root.tag)}, expected "
            f"AMSA:AMSAFramework of namespace {AMSA_NS}"
        )
    return None


def _show(tag: str) -> str:
    uri, _, local = tag.rpartition("}")
    return f"{local} (namespace {uri.lstrip('{')})" if uri else local


class _Reader:
    def __init__(self, path: Path, root: Element) -> None:
        self.path = path
        self.root = root
        self.ids: dict[str, Element] = {}
        self.parent: dict[int, Element] = {}
        self.owner: dict[int, str] = {}  # element -> path of the component it is
        #: element -> its children by feature (tag), built once per element a path walks
        #: through: resolving N references is linear, not N x the children of the root
        self.features: dict[int, dict[str, list[Element]]] = {}
        self._index(root)

    def _index(self, elem: Element) -> None:
        for child in elem.children:
            self.parent[id(child)] = elem
            ident = child.get(XMI_ID)
            if ident:
                self.ids[ident] = child
            self._index(child)

    def error(self, elem: Element | None, message: str) -> ConfigError:
        return ConfigError(message, file=self.path, line=elem.line if elem else None)

    def read(self) -> Model:
        tops = [c for c in self.root.children if c.local == "rootComponent"]
        if len(tops) != 1:
            raise self.error(self.root, f"has {len(tops)} rootComponent elements, expected 1")
        top = tops[0]
        leaves: dict[str, LeafNode] = {}
        data_elems: list[tuple[str, Element]] = []
        root = self._composite(top, "", leaves, data_elems)
        for leaf in leaves.values():
            for port, (ref, line) in list(leaf.inputs.items()):
                elem = self._input_elem(leaf, port)
                leaf.inputs[port] = (self._buffer(elem, ref), line)
        data = {}
        for name, elem in data_elems:
            if name in data:
                raise self.error(elem, f"Data {name!r} is declared twice")
            source = elem.get("source")
            if not source:
                raise self.error(elem, f"Data {name!r} has no source (no producer)")
            data[name] = (self._buffer(elem, source), elem.line)
        href = None
        for c in self.root.children:
            if c.local == "templatesContainers" and c.get("href"):
                href = c.get("href")
                break
        return Model(self.path, root, leaves, data, href, self._extension())

    def _input_elem(self, leaf: LeafNode, port: str) -> Element:
        return next(c for c in leaf.elem.children if c.local == "inputs" and c.get("name") == port)

    def _name(self, elem: Element, what: str) -> str:
        """The element's name: one a world file can hold (the importer writes it as a key)."""
        name = elem.get("name")
        if not name:
            raise self.error(elem, f"{what} without a name")
        if not _NAME.match(name):
            raise self.error(
                elem,
                f"{what} is named {name!r}: amsa-phys names are a letter or _, then letters, "
                "digits and _; rename it in the model",
            )
        return name

    def _composite(
        self,
        elem: Element,
        prefix: str,
        leaves: dict[str, LeafNode],
        data_elems: list[tuple[str, Element]],
    ) -> CompositeNode:
        name = self._name(elem, "a Composite")
        path = "" if elem.local == "rootComponent" else (f"{prefix}.{name}" if prefix else name)
        auto = elem.get("autoScheduling", "true") != "false"
        node = CompositeNode(path, name, elem, auto)
        self.owner[id(elem)] = path
        for child in elem.children:
            if child.local == "data":
                dname = self._name(child, "a Data")
                data_elems.append((f"{path}.{dname}" if path else dname, child))
            elif child.local == "components":
                kind = child.qname(child.get(XSI_TYPE) or "")
                if kind == f"{{{AMSA_NS}}}LeafComponent":
                    leaf = self._leaf(child, path)
                    if leaf.path in leaves:
                        raise self.error(child, f"component {leaf.path} is defined twice")
                    leaves[leaf.path] = leaf
                    node.children.append(leaf)
                elif kind == f"{{{AMSA_NS}}}CompositeComponent":
                    node.children.append(self._composite(child, path, leaves, data_elems))
                else:
                    raise self.error(
                        child,
                        f"component of unknown type {child.get(XSI_TYPE)!r} (expected "
                        "AMSA:LeafComponent or AMSA:CompositeComponent)",
                    )
        return node

    def _leaf(self, elem: Element, prefix: str) -> LeafNode:
        name = self._name(elem, "a LeafComponent")
        path = f"{prefix}.{name}" if prefix else name
        self.owner[id(elem)] = path
        refs = [c for c in elem.children if c.local == "leafTemplate"]
        if len(refs) != 1 or not refs[0].get("href"):
            raise self.error(elem, f"component {path} has no leafTemplate reference")
        href = refs[0].get("href") or ""
        template = href.rpartition("#")[2].lstrip("/")
        if not template:
            raise self.error(refs[0], f"component {path}: leafTemplate {href!r} names no template")
        params: dict[str, tuple[str | None, int]] = {}
        inputs: dict[str, tuple[str, int]] = {}
        outputs: list[str] = []
        for child in elem.children:
            if child.local == "parameters":
                pname = self._name(child, "a parameter")
                if pname in params:
                    raise self.error(child, f"{path}.{pname} is given twice")
                value = child.get("value")
                params[pname] = (value if value not in (None, "") else None, child.line)
            elif child.local == "inputs":
                port = self._name(child, "an input")
                source = child.get("source")
                if not source:
                    raise self.error(child, f"{path}: input {port} is not connected (no source)")
                inputs[port] = (source, child.line)
            elif child.local == "outputs":
                outputs.append(self._name(child, "an output"))
        priority_text = elem.get("schedulingPriority", "0") or "0"
        try:
            priority = int(priority_text)
        except ValueError:
            raise self.error(
                elem, f"{path}: schedulingPriority {priority_text!r} is not an integer"
            ) from None
        return LeafNode(
            path, elem, template, href, elem.get("freq"), priority, params, inputs, outputs
        )

    def _feature(self, elem: Element) -> dict[str, list[Element]]:
        table = self.features.get(id(elem))
        if table is None:
            table = {}
            for child in elem.children:
                table.setdefault(child.local, []).append(child)
            self.features[id(elem)] = table
        return table

    def resolve(self, ref: str, at: Element) -> Element:
        """The element a reference names, or a ConfigError naming the dangling reference."""
        target = ref.strip()
        file_part, sep, fragment = target.partition("#")
        if sep and file_part and Path(file_part).name != self.path.name:
            raise self.error(
                at, f"reference {ref!r} points into another file (only one model file is read)"
            )
        if sep:
            target = fragment
        if not target.startswith("//"):
            found = self.ids.get(target)
            if found is None:
                raise self.error(at, f"dangling reference {ref!r}: no element has this xmi:id")
            return found
        elem = self.root
        for segment in target[2:].split("/"):
            feature, _, index_text = segment.lstrip("@").partition(".")
            try:
                index = int(index_text) if index_text else 0
            except ValueError:
                raise self.error(
                    at, f"dangling reference {ref!r}: bad index {index_text!r}"
                ) from None
            matches = self._feature(elem).get(feature, [])
            if index >= len(matches) or index < 0:
                raise self.error(
                    at,
                    f"dangling reference {ref!r}: there is no {feature} number {index} "
                    f"(found {len(matches)})",
                )
            elem = matches[index]
        return elem

    def _buffer(self, at: Element, ref: str) -> str:
        """Follow a source chain (Data -> ... -> a Leaf's output) to ``Producer.output``."""
        seen: set[int] = set()
        elem = self.resolve(ref, at)
        while True:
            if id(elem) in seen:
                raise self.error(at, f"reference {ref!r} goes round a loop of Data")
            seen.add(id(elem))
            parent = self.parent.get(id(elem))
            if elem.local == "outputs" and parent is not None and id(parent) in self.owner:
                kind = parent.qname(parent.get(XSI_TYPE) or "")
                if kind == f"{{{AMSA_NS}}}LeafComponent":
                    return f"{self.owner[id(parent)]}.{elem.get('name')}"
            source = elem.get("source")
            if elem.local in ("data", "inputs", "outputs") and source:
                elem = self.resolve(source, elem)
                continue
            raise self.error(
                at,
                f"reference {ref!r} leads to a {elem.local} element with no producer "
                "(expected a Leaf's output, or a Data fed by one)",
            )

    def _extension(self) -> dict[str, Any]:
        """amsa-phys's extras from ``xmi:Extension extender="amsa-phys"`` (empty if none)."""
        out: dict[str, Any] = {}
        for ext in self.root.children:
            if ext.tag != f"{{{XMI_NS}}}Extension" or ext.get("extender") != EXTENDER:
                continue
            for item in ext.children:
                try:
                    if item.local == "world":
                        out["world"] = json.loads(item.get("json") or "{}")
                    elif item.local == "template":
                        out.setdefault("templates", {})[item.get("name")] = item.get(
                            "implementation"
                        )
                    elif item.local == "frequency":
                        out.setdefault("frequencies", {})[item.get("component")] = item.get("hz")
                    elif item.local == "unnamedData":
                        out["unnamed"] = (item.get("names") or "").split()
                except json.JSONDecodeError as exc:
                    raise self.error(
                        item, f"amsa-phys extension is not valid JSON: {exc}"
                    ) from None
                except RecursionError:
                    raise self.error(
                        item, "amsa-phys extension is not valid JSON: nested too deeply"
                    ) from None
        return out
