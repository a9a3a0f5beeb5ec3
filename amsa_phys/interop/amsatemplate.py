"""The AMSA template files (``.amsatemplate``, the original tool's Xtext syntax), read and written.

The syntax, as the MDE challenge's file uses it::

    Template GPS {
        input posX, posY
        output gpsPosX, gpsPosY
        parameter {
            int lostDataGPS;
        }
    }

``input``, ``output`` and ``parameter`` are optional and come in that order; a parameter is
``TYPE NAME;`` (an optional ``= VALUE`` default is accepted). ``//`` and ``/* */`` comments are
skipped, as Xtext's default terminals do. A template file declares interfaces only: the
behaviour is an amsa-phys template of the same name (``amsa-phys templates``).
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ConfigError
from ..model.template import Template
from ..model.yamlio import read_regular_file

#: The parameter types of an amsa-phys template, as a template file spells them.
TYPE_WORDS = {
    "float": "double",
    "int": "int",
    "enum": "int",
    "bool": "boolean",
    "str": "string",
    "points": "string",
}
#: Type words of a template file and the amsa-phys types each may stand for.
COMPATIBLE = {
    "double": {"float"},
    "float": {"float"},
    "int": {"int", "enum"},
    "long": {"int", "enum"},
    "boolean": {"bool"},
    "bool": {"bool"},
    "string": {"str", "points", "enum"},
    "String": {"str", "points", "enum"},
}

_TOKEN = re.compile(
    r"""(?P<ws>\s+)|(?P<comment>//[^\n]*|/\*.*?\*/)|(?P<id>\^?[A-Za-z_][A-Za-z0-9_]*)
    |(?P<number>-?[0-9]+(\.[0-9]*)?([eE][-+]?[0-9]+)?)|(?P<string>"(\\.|[^"\\])*"|'(\\.|[^'\\])*')
    |(?P<punct>[{},;=])""",
    re.VERBOSE | re.DOTALL,
)
MAX_BYTES = 5_000_000


@dataclass
class ParamDecl:
    """``TYPE NAME [= VALUE];`` in a template's ``parameter`` block."""

    type: str
    name: str
    default: str | None
    line: int


@dataclass
class TemplateDecl:
    """One ``Template NAME { ... }``."""

    name: str
    line: int
    inputs: list[str] = field(default_factory=list)
    outputs: list[str] = field(default_factory=list)
    params: list[ParamDecl] = field(default_factory=list)


def read_templates(path: Path) -> dict[str, TemplateDecl]:
    """Every template declared in ``path``, by name; a one-line ConfigError if malformed."""
    data = read_regular_file(path, MAX_BYTES, "an AMSA template file")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise ConfigError("is not a UTF-8 text file (expected AMSA templates)", file=path) from None
    return parse_templates(text, path)


#: How a message names a token it did not expect: by its kind, never its text, since the file
#: may be one a model named that is no template file at all (its words are not for the
#: terminal). Punctuation is the grammar's own.
_KINDS = {"id": "a name", "number": "a number", "string": "a string", "eof": "the end of the file"}


def _found(kind: str, value: str) -> str:
    """What an unexpected token is, without its text (``'{'`` for the grammar's punctuation)."""
    return repr(value) if kind == "punct" else _KINDS.get(kind, "something else")


def _tokens(text: str, path: Path) -> Iterator[tuple[str, str, int]]:
    pos = 0
    line = 1
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None:
            column = pos - (text.rfind("\n", 0, pos) + 1) + 1
            raise ConfigError(
                f"column {column}: a character AMSA template syntax does not have",
                file=path,
                line=line,
            )
        kind = m.lastgroup or ""
        value = m.group()
        if kind not in ("ws", "comment"):
            yield kind, value, line
        line += value.count("\n")
        pos = m.end()


def parse_templates(text: str, path: Path) -> dict[str, TemplateDecl]:
    """Parse template-file text (``path`` names it in messages)."""
    toks = list(_tokens(text, path))
    i = 0
    out: dict[str, TemplateDecl] = {}

    def peek() -> tuple[str, str, int]:
        return toks[i] if i < len(toks) else ("eof", "", toks[-1][2] if toks else 1)

    def expect(value: str | None = None, kind: str | None = None) -> tuple[str, str, int]:
        nonlocal i
        k, v, line = peek()
        if (value is not None and v != value) or (kind is not None and k != kind):
            want = repr(value) if value is not None else "a name"
            raise ConfigError(f"expected {want}, found {_found(k, v)}", file=path, line=line)
        i += 1
        return k, v, line

    def names() -> list[str]:
        found = [expect(kind="id")[1].lstrip("^")]
        while peek()[1] == ",":
            expect(",")
            found.append(expect(kind="id")[1].lstrip("^"))
        return found

    if not toks:
        raise ConfigError("declares no template (expected AMSA template syntax)", file=path)
    while i < len(toks):
        kind, word, line = peek()
        if word != "Template":
            raise ConfigError(
                f"expected 'Template', found {_found(kind, word)} (is this an AMSA template file?)",
                file=path,
                line=line,
            )
        expect("Template")
        _, name, line = expect(kind="id")
        name = name.lstrip("^")
        if name in out:
            raise ConfigError(
                f"template {name} is declared twice (first on line {out[name].line})",
                file=path,
                line=line,
            )
        decl = TemplateDecl(name, line)
        expect("{")
        if peek()[1] == "input":
            expect("input")
            decl.inputs = names()
        if peek()[1] == "output":
            expect("output")
            decl.outputs = names()
        if peek()[1] == "parameter":
            expect("parameter")
            expect("{")
            while peek()[1] != "}":
                _, ptype, pline = expect(kind="id")
                _, pname, _ = expect(kind="id")
                default = None
                if peek()[1] == "=":
                    expect("=")
                    k, default, _ = peek()
                    if k not in ("number", "string", "id"):
                        raise ConfigError(
                            f"expected a value, found {_found(k, default)}", file=path, line=pline
                        )
                    expect()
                expect(";")
                decl.params.append(ParamDecl(ptype, pname.lstrip("^"), default, pline))
            expect("}")
        expect("}")
        out[name] = decl
    return out


def template_text(templates: Sequence[type[Template]]) -> str:
    """The template file declaring ``templates`` (every port and parameter of each)."""
    blocks = []
    for cls in templates:
        lines = [f"// {cls.name()} ({cls.kind.value}): {cls.describe()}".rstrip(": ")]
        lines.append(f"Template {cls.name()} {{")
        if cls.inputs:
            lines.append("\tinput " + ", ".join(p.name for p in cls.inputs))
        if cls.outputs:
            lines.append("\toutput " + ", ".join(p.name for p in cls.outputs))
        if cls.params:
            lines.append("\tparameter {")
            for p in cls.params:
                unit = f" [{p.unit}]" if p.unit else ""
                rng = f" {p.range_text()}" if p.range_text() else ""
                lines.append(f"\t\t{TYPE_WORDS[p.type]} {p.name};  // {p.description}{unit}{rng}")
            lines.append("\t}")
        lines.append("}")
        blocks.append("\n".join(lines))
    return "\n\n".join(blocks) + "\n"
