"""Parse XML safely into small elements that remember their line.

The standard library's expat is used directly (no ``defusedxml`` dependency): an AMSA model
is plain XMI, which never has a document type declaration, so any ``<!DOCTYPE`` is refused
before a single entity can be declared — no internal entity expansion ("billion laughs"), no
external entity or DTD is ever fetched (expat does not fetch them, and the refusal comes
first). That is stricter than ``defusedxml``'s default, which lets a DTD without entities
through. Files are also capped in size, and elements in depth.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from ..errors import ConfigError
from ..model.yamlio import read_regular_file

#: Largest model file read (the MDE challenge's is 5 kB).
MAX_BYTES = 20_000_000
MAX_DEPTH = 200
#: Elements built from one file. amsa-phys writes ~20 a Leaf (the 62-Leaf platoon: 1,431), so
#: this is a ~1,500-Leaf model; importing the largest takes ~4 s on a loaded 2-core machine,
#: most of it loading the world it makes (README "Hostile input"): under the issue's 5 s.
MAX_ELEMENTS = 30_000
#: Namespace declarations in one file (AMSA XMI declares 3-4 on its root).
MAX_NAMESPACES = 64
#: Attributes on one element (an AMSA element has at most ~6).
MAX_ATTRIBUTES = 64
#: Read and parsed in pieces of this size: a wrong root is refused after the first piece.
CHUNK = 1 << 16


@dataclass(slots=True)
class Element:
    """One XML element: namespace-resolved tag and attribute names (``{uri}local``)."""

    tag: str
    attrib: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)
    #: prefix -> namespace URI in force at this element (to read ``xsi:type`` values); shared
    #: with the parent when the element declares no namespace of its own
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


RootCheck = Callable[[Element], "str | None"]


def parse_file(path: Path, what: str = "XML", root: RootCheck | None = None) -> Element:
    """The root element of ``path``; a one-line ConfigError if it is not safe, well-formed XML.

    Only a regular file is read (the YAML loader's check: no device, no FIFO), at most
    :data:`MAX_BYTES`. ``root`` judges the root element as soon as its start tag is parsed (a
    message refuses the file): a file of another kind costs one piece, not a whole tree.
    """
    data = read_regular_file(path, MAX_BYTES, f"{_article(what)} file")
    return parse_bytes(data, path, what, root)


def parse_bytes(
    data: bytes, path: Path, what: str = "XML", root: RootCheck | None = None
) -> Element:
    """Parse ``data`` (from ``path``, for messages) incrementally, within the limits above."""
    parser = expat.ParserCreate(namespace_separator="}")
    stack: list[Element] = []
    found: list[Element] = []
    scopes: list[dict[str, str]] = [{}]
    pending: dict[str, str] = {}
    count = [0, 0]  # elements, namespace declarations

    def start_ns(prefix: str | None, uri: str) -> None:
        count[1] += 1
        if count[1] > MAX_NAMESPACES:
            raise _Refused(f"declares more than {MAX_NAMESPACES} namespaces")
        pending[prefix or ""] = uri

    def start(tag: str, attrs: dict[str, str]) -> None:
        if len(stack) >= MAX_DEPTH:
            raise _Refused(f"elements nested deeper than {MAX_DEPTH}")
        count[0] += 1
        if count[0] > MAX_ELEMENTS:
            raise _Refused(f"has more than {MAX_ELEMENTS} elements")
        if len(attrs) > MAX_ATTRIBUTES:
            raise _Refused(f"an element has more than {MAX_ATTRIBUTES} attributes")
        if pending:
            nsmap = {**scopes[-1], **pending}
            pending.clear()
        else:
            nsmap = scopes[-1]  # shared: no copy per element
        scopes.append(nsmap)
        elem = Element(_brace(tag), {_brace(k): v for k, v in attrs.items()}, 0, nsmap=nsmap)
        elem.line = parser.CurrentLineNumber
        if stack:
            stack[-1].children.append(elem)
        else:
            refused = root(elem) if root is not None else None
            if refused:
                raise _Refused(refused)
            found.append(elem)
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
    view = memoryview(data)
    try:
        for at in range(0, len(data), CHUNK):
            parser.Parse(bytes(view[at : at + CHUNK]), False)
        parser.Parse(b"", True)
    except _Refused as exc:
        raise ConfigError(str(exc), file=path, line=parser.CurrentLineNumber) from None
    except expat.ExpatError as exc:
        raise ConfigError(
            f"is not well-formed {what}: {expat.ErrorString(exc.code)}", file=path, line=exc.lineno
        ) from None
    if not found:
        raise ConfigError(f"is not {what}: no element", file=path)
    return found[0]


def _article(what: str) -> str:
    return ("an " if what[:1] in "AEIOU" else "a ") + what


def _brace(name: str) -> str:
    """expat's ``uri}local`` as ElementTree's ``{uri}local``; unqualified names unchanged."""
    return "{" + name if "}" in name else name
