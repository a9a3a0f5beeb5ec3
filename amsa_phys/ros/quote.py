"""One escaper per target language of the generated ROS package, and the filler that uses them.

Every name or value that comes from a user's scenario, world, model or file name reaches a
generated file through exactly one function here (a scenario's ``name:`` with a
newline ended a YAML comment and roslaunch's rosparam loader evaluated a ``!radians`` tag; a
file name ran ``execute_process`` at ``catkin_make`` and closed a Python docstring). Escaping
is the default path, as a template engine's autoescape is: a template's hole names its
language (``@@{source:cmake_comment}``) and :func:`fill` applies that escaper; only a
:class:`Code` value (a fragment the generator built itself, from escaped parts) can go into a
``code`` hole, so a raw string cannot reach a file by forgetting a call.

Names are also refused up front (:func:`check_name`): quotes, backslashes and control
characters in a scenario's name or a file name are an error before anything is written.
The escapers still hold for everything else (a world's description, a template's docstring).
"""

from __future__ import annotations

import json
import re
import shlex
import unicodedata
from collections.abc import Callable
from typing import Any

import yaml

from ..errors import ConfigError


class Code(str):
    """A fragment the generator built from escaped parts (or constants): inserted as is."""

    __slots__ = ()


# -- refusing ---------------------------------------------------------------------------------

#: Characters a name or file name may not hold: quotes, backslash, and (below) every control,
#: format, line/paragraph separator or surrogate character.
_BAD_ASCII = set("\"'`\\")


def bad_char(text: str) -> str | None:
    """The first character of ``text`` a name may not hold, or None."""
    for ch in text:
        if ch in _BAD_ASCII or unicodedata.category(ch) in ("Cc", "Cf", "Cs", "Zl", "Zp"):
            return ch
    return None


def check_name(text: str, what: str, **where: Any) -> None:
    """Refuse a name with quotes, backslashes or control characters (one line, exit 2)."""
    ch = bad_char(text)
    if ch is not None:
        raise ConfigError(
            f"{what} {text!r} holds {ch!r}: names that go into generated code may not hold "
            "quotes, backslashes or control characters; rename it",
            **where,
        )


# -- one line of free text (comments) --------------------------------------------------------

_LINE_BREAKS = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029]")


def _one_line(text: str) -> str:
    """``text`` with every control character and line break (YAML's NEL, LS, PS too) as ``?``."""
    return _LINE_BREAKS.sub("?", str(text))


def xml_text(text: str) -> str:
    """Character data: ``&<>`` escaped; characters XML 1.0 cannot hold at all become ``?``."""
    text = re.sub(r"[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff\ud800-\udfff]", "?", str(text))
    text = text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return text.replace("\r", "&#13;")  # a parser would read a raw CR as a newline


def xml_attr(text: str) -> str:
    """An attribute value for a double-quoted attribute (the quotes are the template's).

    roslaunch evaluates ``$(...)`` inside attribute values (``$(eval ...)`` is Python) and has
    no escape for it, so a user's value holding ``$(`` is refused rather than written.
    """
    text = str(text)
    if "$(" in text:
        raise ConfigError(f"{text!r} holds '$(' which roslaunch would evaluate; rename it")
    out = xml_text(text).replace('"', "&quot;")
    return out.replace("\n", "&#10;").replace("\t", "&#9;")


def xml_comment(text: str) -> str:
    """Text inside ``<!-- -->``: one line, no ``--`` (XML forbids it), not ending with ``-``."""
    text = xml_text(_one_line(text))
    while "--" in text:
        text = text.replace("--", "- -")
    return text + " " if text.endswith("-") else text


def yaml_scalar(value: str) -> str:
    """A double-quoted YAML scalar (JSON's escapes, ASCII only: always the same string back).

    A double-quoted scalar never takes a tag (``!radians``), an anchor or a line break.
    """
    return json.dumps(str(value), ensure_ascii=True)


class _QuotingDumper(getattr(yaml, "CSafeDumper", yaml.SafeDumper)):  # type: ignore[misc]
    """PyYAML's safe dumper with every string that is not an identifier double-quoted."""


_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_./]*$")


def _represent_str(dumper: yaml.SafeDumper, text: str) -> yaml.ScalarNode:
    # an identifier stays plain (PyYAML still quotes ``true``, ``null``...): keys stay readable
    style = None if _IDENTIFIER.match(text) else '"'
    return dumper.represent_scalar("tag:yaml.org,2002:str", text, style=style)


_QuotingDumper.add_representer(str, _represent_str)


def yaml_dump(data: Any) -> str:
    """A YAML document of plain data, every string but identifiers double-quoted.

    roslaunch's rosparam loader adds implicit resolvers to PyYAML's SafeLoader: a plain
    scalar ``rad(...)`` or ``deg(...)`` becomes ``!radians``/``!degrees``, which it
    evaluates as Python. A quoted string is never resolved, so no value can become code.
    """
    return yaml.dump(data, Dumper=_QuotingDumper, sort_keys=False, allow_unicode=False)


def yaml_comment(text: str) -> str:
    """Text after ``#``: one line (YAML also breaks lines at NEL, LS and PS)."""
    return _one_line(text)


_PLAIN_CMAKE = re.compile(r"^[A-Za-z0-9_./+-]+$")


def cmake_arg(text: str) -> str:
    """A CMake argument: plain names as they are, anything else quoted with ``\\``, ``"``,
    ``$`` (no ``${...}`` expands) and ``@`` escaped."""
    text = str(text)
    if _PLAIN_CMAKE.match(text):
        return text
    for a, b in (("\\", "\\\\"), ('"', '\\"'), ("$", "\\$"), ("@", "\\@")):
        text = text.replace(a, b)
    for a, b in (("\n", "\\n"), ("\r", "\\r"), ("\t", "\\t")):
        text = text.replace(a, b)
    return '"' + _LINE_BREAKS.sub("?", text) + '"'


def cmake_comment(text: str) -> str:
    """Text after ``# `` (the template's space keeps ``#[[`` from opening a bracket comment)."""
    return _one_line(text)


def cpp_string(text: str) -> str:
    """A C++ narrow string literal (UTF-8 bytes): escapes for anything not plain ASCII.

    Octal escapes are three digits, so a following digit never joins one; ``?`` is escaped so
    no trigraph (``??/`` is a backslash) forms in any standard mode.
    """
    out = ['"']
    for byte in str(text).encode("utf-8", "surrogatepass"):
        ch = chr(byte)
        if ch in '"\\?':
            out.append("\\" + ch)
        elif 0x20 <= byte < 0x7F:
            out.append(ch)
        else:
            out.append(f"\\{byte:03o}")
    return "".join(out) + '"'


def cpp_comment(text: str) -> str:
    """Text after ``//``: one line, no backslash (a trailing one splices the next line in)."""
    return _one_line(text).replace("\\", "/").replace("??", "?_")


def py_string(text: str) -> str:
    """A Python string literal (``repr``: always reads back to ``text``)."""
    return repr(str(text))


def py_dstring(text: str) -> str:
    """A double-quoted Python string literal (reads back to ``text``): for a file whose
    house style quotes so, where :func:`py_string`'s ``repr`` would pick single quotes."""
    return '"' + py_doc(text).replace("\n", "\\n") + '"'


def py_comment(text: str) -> str:
    """Text after ``#``: one line."""
    return _one_line(text)


def py_doc(text: str) -> str:
    """Text inside a ``\"\"\"`` docstring: ``\\`` and ``\"`` escaped, newlines kept, other
    control or unprintable characters as escapes (the docstring reads back to ``text``)."""
    out = []
    for ch in str(text):
        if ch in '\\"':
            out.append("\\" + ch)
        elif ch == "\n" or ch.isprintable():
            out.append(ch)
        else:
            out.append(ch.encode("unicode_escape").decode("ascii"))
    return "".join(out)


def sh_word(text: str) -> str:
    """One POSIX shell word."""
    return shlex.quote(str(text))


def md_text(text: str) -> str:
    """Markdown text on one line: every ASCII punctuation character backslash-escaped."""
    return re.sub(r"([\\`*_\[\]<>|!])", r"\\\1", _one_line(text))


def md_code(text: str) -> str:
    """A Markdown code span (one line; a backtick, which would end it, becomes ``'``)."""
    return "`" + _one_line(text).replace("`", "'") + "`"


ESCAPERS: dict[str, Callable[[str], str]] = {
    "xml_text": xml_text,
    "xml_attr": xml_attr,
    "xml_comment": xml_comment,
    "yaml_scalar": yaml_scalar,
    "yaml_comment": yaml_comment,
    "cmake_arg": cmake_arg,
    "cmake_comment": cmake_comment,
    "cpp_string": cpp_string,
    "cpp_comment": cpp_comment,
    "py_string": py_string,
    "py_dstring": py_dstring,
    "py_comment": py_comment,
    "py_doc": py_doc,
    "sh_word": sh_word,
    "md_text": md_text,
    "md_code": md_code,
}

_HOLE = re.compile(r"@@\{(\w+):(\w+)\}")


def holes(text: str) -> set[str]:
    """The names of the holes ``text`` has (a file filled from a registry takes just these)."""
    return {m.group(1) for m in _HOLE.finditer(text)}


def fill(text: str, /, **values: Any) -> Code:
    """``template`` with every ``@@{name:kind}`` hole filled through the escaper ``kind``.

    ``kind`` ``code`` takes a :class:`Code` (or an int) only: a plain string there is a bug
    (TypeError), never written. Every value must fill a hole and every hole must get a value.
    """
    used: set[str] = set()

    def one(m: re.Match[str]) -> str:
        name, kind = m.group(1), m.group(2)
        if name not in values:
            raise KeyError(f"no value for hole {name}")
        used.add(name)
        value = values[name]
        if kind == "code":
            if isinstance(value, bool) or not isinstance(value, Code | int):
                raise TypeError(f"hole {name} takes generated code, got {type(value).__name__}")
            return str(value)
        if kind not in ESCAPERS:
            raise KeyError(f"hole {name}: unknown kind {kind}")
        return ESCAPERS[kind](str(value))

    out = _HOLE.sub(one, text)
    unused = set(values) - used
    if unused:
        raise KeyError(f"values fill no hole: {sorted(unused)}")
    return Code(out)
