"""Parse XML safely into small elements that remember their line.

The standard library's expat is used directly (no ``defusedxml`` dependency): an AMSA model
is plain XMI, which never has a document type declaration, so any ``<!DOCTYPE`` is refused
before a single entity can be declared — no internal entity expansion ("billion laughs"), no
external entity or DTD is ever fetched (expat does not fetch them, and the refusal comes
first). That is stricter than ``defusedxml``'s default, which lets a DTD without entities
through. Files are also capped in size, and elements in depth.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from ..errors import ConfigError

#: Largest model file read (the MDE challenge's is 5 kB).
MAX_BYTES = 20_000_000
MAX_DEPTH = 200


@dataclass
class Element:
    """One XML element: namespace-resolved tag and attribute names (``{uri}local``)."""

    tag: str
    attrib: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)
    #: prefix -> namespace URI in force at this element (to read ``xsi:type`` values)
    nsmap: dict[str, str] = field(default_factory=dict)

    @property
    def local(self) -> str:
        """The tag without its namespace."""
        return self.tag.rpartition("}")[2]

    def get(self, name: str, default: str | None = None) -> str | None:
        """An attribute by local name (no namespace) or ``{uri}name``."""
        return self.attrib.get(name, default)

    def qname(self, value: str) -> str:
        """A QName attribute value (``AMSA:LeafComponent``) as ``{uri}local``."""
        prefix, sep, local = value.rpartition(":")
        uri = self.nsmap.get(prefix if sep else "", "")
        return f"{{{uri}}}{local}" if uri else local


class _Refused(Exception):
    pass


def parse_file(path: Path, what: str = "XML") -> Element:
    """The root element of ``path``; a one-line ConfigError if it is not safe, well-formed XML."""
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None
    if size > MAX_BYTES:
        raise ConfigError(f"is {size} bytes; a model file is at most {MAX_BYTES}", file=path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None
    return parse_bytes(data, path, what)


def parse_bytes(data: bytes, path: Path, what: str = "XML") -> Element:
    """Parse ``data`` (from ``path``, for messages)."""
    parser = expat.ParserCreate(namespace_separator="}")
    stack: list[Element] = []
    root: list[Element] = []
    scopes: list[dict[str, str]] = [{}]
    pending: dict[str, str] = {}

    def start_ns(prefix: str | None, uri: str) -> None:
        pending[prefix or ""] = uri

    def start(tag: str, attrs: dict[str, str]) -> None:
        if len(stack) >= MAX_DEPTH:
            raise _Refused(f"elements nested deeper than {MAX_DEPTH}")
        nsmap = {**scopes[-1], **pending}
        pending.clear()
        scopes.append(nsmap)
        elem = Element(_brace(tag), {_brace(k): v for k, v in attrs.items()}, 0, nsmap=nsmap)
        elem.line = parser.CurrentLineNumber
        if stack:
            stack[-1].children.append(elem)
        else:
            root.append(elem)
        stack.append(elem)

    def end(tag: str) -> None:
        stack.pop()
        scopes.pop()

    def refuse_doctype(*_: object) -> None:
        raise _Refused("has a DOCTYPE declaration (refused: AMSA XMI never has one)")

    def refuse_entity(*_: object) -> None:
        raise _Refused("declares an entity (refused)")

    parser.StartNamespaceDeclHandler = start_ns
    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.StartDoctypeDeclHandler = refuse_doctype
    parser.EntityDeclHandler = refuse_entity
    parser.UnparsedEntityDeclHandler = refuse_entity
    parser.ExternalEntityRefHandler = refuse_entity  # type: ignore[assignment]
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    try:
        parser.Parse(data, True)
    except _Refused as exc:
        raise ConfigError(str(exc), file=path, line=parser.CurrentLineNumber) from None
    except expat.ExpatError as exc:
        raise ConfigError(
            f"is not well-formed {what}: {expat.ErrorString(exc.code)}", file=path, line=exc.lineno
        ) from None
    if not root:
        raise ConfigError(f"is not {what}: no element", file=path)
    return root[0]


def _brace(name: str) -> str:
    """expat's ``uri}local`` as ElementTree's ``{uri}local``; unqualified names unchanged."""
    return "{" + name if "}" in name else name
