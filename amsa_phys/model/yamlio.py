"""Safe YAML loading that remembers the line of every key.

PyYAML composes the file into nodes that keep their start marks; we build plain Python
values from those nodes ourselves so that every key path maps to a line, duplicate keys are
refused (naming both lines), and only the standard safe tags construct values: YAML can
never build a Python object.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ..errors import ConfigError

KeyPath = tuple[Any, ...]

#: Upper bound on nodes built, so alias bombs ("billion laughs") fail fast and clearly.
MAX_NODES = 200_000
MAX_DEPTH = 64


@dataclass
class YamlDoc:
    """A loaded YAML file: its data and, for each key path, the line it starts on."""

    path: Path
    data: Any
    lines: dict[KeyPath, int] = field(default_factory=dict)

    def line(self, keypath: KeyPath) -> int | None:
        """Line of ``keypath``, or of its longest prefix that has one (1-based)."""
        keypath = tuple(keypath)
        while keypath:
            if keypath in self.lines:
                return self.lines[keypath]
            keypath = keypath[:-1]
        return self.lines.get((), None)

    def error(self, keypath: KeyPath, message: str) -> ConfigError:
        """A ConfigError located at ``keypath`` in this file."""
        return ConfigError(message, file=self.path, line=self.line(keypath), key=dotted(keypath))


def dotted(keypath: KeyPath) -> str:
    """``("components", "GPS", "params")`` -> ``components.GPS.params``; indexes as ``[i]``."""
    out = ""
    for part in keypath:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


class _Builder:
    def __init__(self, path: Path) -> None:
        self.path = path
        self.lines: dict[KeyPath, int] = {}
        self.constructor = yaml.SafeLoader("")  # only its scalar constructors are used
        self.count = 0

    def fail(self, node: yaml.Node, message: str, keypath: KeyPath = ()) -> ConfigError:
        return ConfigError(
            message, file=self.path, line=node.start_mark.line + 1, key=dotted(keypath) or None
        )

    def build(self, node: yaml.Node, keypath: KeyPath) -> Any:
        self.count += 1
        if self.count > MAX_NODES:
            raise self.fail(node, f"document too large (over {MAX_NODES} values; alias bomb?)")
        if len(keypath) > MAX_DEPTH:
            raise self.fail(node, f"nesting deeper than {MAX_DEPTH} levels", keypath)
        self.lines.setdefault(keypath, node.start_mark.line + 1)
        if isinstance(node, yaml.MappingNode):
            return self.build_mapping(node, keypath)
        if isinstance(node, yaml.SequenceNode):
            if node.tag != "tag:yaml.org,2002:seq":
                raise self.fail(node, f"tag {node.tag!r} is not allowed", keypath)
            return [self.build(child, (*keypath, i)) for i, child in enumerate(node.value)]
        if node.tag not in _SAFE_SCALAR_TAGS:
            raise self.fail(
                node, f"tag {node.tag!r} is not allowed (only plain YAML values)", keypath
            )
        try:
            return self.constructor.construct_object(node, deep=True)
        except (yaml.YAMLError, ValueError, OverflowError) as exc:
            raise self.fail(node, f"bad value: {exc}", keypath) from None

    def build_mapping(self, node: yaml.MappingNode, keypath: KeyPath) -> dict[Any, Any]:
        if node.tag != "tag:yaml.org,2002:map":
            raise self.fail(node, f"tag {node.tag!r} is not allowed", keypath)
        try:
            self.constructor.flatten_mapping(node)  # resolves YAML merge keys (<<)
        except yaml.YAMLError as exc:
            raise self.fail(node, f"bad merge key: {exc}", keypath) from None
        out: dict[Any, Any] = {}
        first_line: dict[Any, int] = {}
        for key_node, value_node in node.value:
            if not isinstance(key_node, yaml.ScalarNode) or key_node.tag not in _SAFE_SCALAR_TAGS:
                raise self.fail(key_node, "mapping keys must be plain scalars", keypath)
            key = self.constructor.construct_object(key_node)
            if isinstance(key, float | bool) or key is None:
                key = key_node.value  # a key like `1.5` or `yes` is a name, not a number
            line = key_node.start_mark.line + 1
            if key in out:
                raise self.fail(
                    key_node,
                    f"duplicate key {key!r} (first defined on line {first_line[key]})",
                    (*keypath, key),
                )
            first_line[key] = line
            self.lines[(*keypath, key)] = line
            out[key] = self.build(value_node, (*keypath, key))
            self.lines[(*keypath, key)] = line
        return out


_SAFE_SCALAR_TAGS = {
    "tag:yaml.org,2002:str",
    "tag:yaml.org,2002:int",
    "tag:yaml.org,2002:float",
    "tag:yaml.org,2002:bool",
    "tag:yaml.org,2002:null",
}


def load_yaml(path: str | Path) -> YamlDoc:
    """Load ``path`` as YAML with line tracking; raise ConfigError naming file and line."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise ConfigError("file not found", file=path) from None
    except IsADirectoryError:
        raise ConfigError("is a directory, expected a YAML file", file=path) from None
    except OSError as exc:
        raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None
    return parse_yaml(raw, path)


def parse_yaml(raw: bytes | str, path: str | Path) -> YamlDoc:
    """Parse YAML text (see :func:`load_yaml`)."""
    path = Path(path)
    if isinstance(raw, bytes):
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ConfigError(f"not UTF-8 text (byte {exc.start})", file=path) from None
    else:
        text = raw
    if "\x00" in text:
        raise ConfigError("binary data, expected YAML text", file=path)
    try:
        node = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        problem = exc.problem or exc.context or "syntax error"
        raise ConfigError(f"YAML syntax error: {problem}", file=path, line=line) from None
    except yaml.reader.ReaderError as exc:
        line = text.count("\n", 0, exc.position) + 1
        char = exc.character if isinstance(exc.character, str) else chr(exc.character)
        raise ConfigError(
            f"not YAML text: control character {ord(char):#06x} is not allowed",
            file=path,
            line=line,
        ) from None
    except yaml.YAMLError as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ConfigError(f"YAML error: {first}", file=path) from None
    except RecursionError:
        raise ConfigError("YAML nesting too deep", file=path) from None
    if node is None:
        raise ConfigError("file is empty", file=path, line=1)
    builder = _Builder(path)
    data = builder.build(node, ())
    return YamlDoc(path=path, data=data, lines=builder.lines)
