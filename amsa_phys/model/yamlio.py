"""Safe YAML loading that remembers the line of every key, within limits.

PyYAML composes the file into nodes that keep their start marks; we build plain Python
values from those nodes ourselves so that every key path maps to a line, duplicate keys are
refused (naming both lines), and only the standard safe tags construct values: YAML can
never build a Python object. YAML merge keys (``<<: *base``) work as YAML defines them: the
mapping's own keys override merged ones.

Hostile files are refused fast with one line, before they cost time or memory: only
regular files are read (``/dev/zero``, ``/dev/urandom`` or a FIFO nobody writes to would
never end), at most :data:`MAX_FILE_BYTES`; at most :data:`MAX_NODES` values are built, of
which at most :data:`MAX_EXPANSION` through aliases (a "billion laughs" file is ~1 KB); keys
are always names (``1:`` is the text ``"1"``). The world builder caps the components a file
expands to (``count:`` copies included). libyaml composes when PyYAML has it (3-4x faster on
a large resolved scenario); a file it rejects is composed again by the pure-Python parser so
that the message is PyYAML's, the same with or without libyaml.
"""

from __future__ import annotations

import errno
import json
import os
import stat
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ..errors import ConfigError

KeyPath = tuple[Any, ...]

#: Largest file read (a 10,000-component resolved scenario is ~4 MB).
MAX_FILE_BYTES = 8 * 1024 * 1024
#: Values built from one document (a 10,000-component resolved scenario has ~150,000-300,000).
MAX_NODES = 500_000
#: Values built by following aliases: an anchor reused is cheap to write, costly to expand.
MAX_EXPANSION = 100_000
#: Values in one command-line value (``--set``, ``--grid``): a parameter value is small.
MAX_VALUE_NODES = 10_000
MAX_DEPTH = 64

_STR = "tag:yaml.org,2002:str"
_INT = "tag:yaml.org,2002:int"
#: the implicit tags PyYAML gives base-60 scalars (``1:30``)
_BASE_60 = frozenset({"tag:yaml.org,2002:int", "tag:yaml.org,2002:float"})
_MERGE = "tag:yaml.org,2002:merge"
_C_LOADER = getattr(yaml, "CSafeLoader", None)


@dataclass
class YamlDoc:
    """A loaded YAML file: its data and, for each key path, the line it starts on."""

    path: Path
    data: Any
    lines: dict[KeyPath, int] = field(default_factory=dict)
    #: values built (the quantity :data:`MAX_NODES` limits)
    values: int = 0

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
    def __init__(self, path: Path, max_nodes: int = MAX_NODES) -> None:
        self.path = path
        self.lines: dict[KeyPath, int] = {}
        self.constructor = yaml.SafeLoader("")  # only its scalar constructors are used
        self.scalars = self.constructor.yaml_constructors
        self.count = 0
        self.max_nodes = max_nodes
        self.built: set[int] = set()  # collections built once: building one again is an alias
        self.aliased = 0  # > 0 while building through an alias
        self.expanded = 0
        self.alias_at: KeyPath = ()
        self.merged: dict[int, set[int]] = {}  # mapping -> its key nodes that came from <<

    def fail(self, node: yaml.Node, message: str, keypath: KeyPath = ()) -> ConfigError:
        return ConfigError(
            message, file=self.path, line=node.start_mark.line + 1, key=dotted(keypath) or None
        )

    def build(self, node: yaml.Node, keypath: KeyPath) -> Any:
        self.count += 1
        if self.count > self.max_nodes:
            raise self.fail(node, f"document too large: over {self.max_nodes:,} values")
        if self.aliased:
            self.expanded += 1
            if self.expanded > MAX_EXPANSION:
                raise self.fail(
                    node,
                    f"document too large: aliases expand to over {MAX_EXPANSION:,} values "
                    "(an alias bomb?)",
                    self.alias_at,
                )
        if len(keypath) > MAX_DEPTH:
            raise self.fail(node, f"nesting deeper than {MAX_DEPTH} levels", keypath)
        self.lines.setdefault(keypath, node.start_mark.line + 1)
        if isinstance(node, yaml.ScalarNode):
            return self.scalar(node, keypath)
        again = id(node) in self.built
        self.built.add(id(node))
        if again and not self.aliased:
            self.alias_at = keypath  # where the outermost alias is used
        self.aliased += again
        try:
            if isinstance(node, yaml.MappingNode):
                return self.build_mapping(node, keypath)
            if node.tag != "tag:yaml.org,2002:seq":
                raise self.fail(node, f"tag {node.tag!r} is not allowed", keypath)
            return [self.build(child, (*keypath, i)) for i, child in enumerate(node.value)]
        finally:
            self.aliased -= again

    def scalar(self, node: yaml.ScalarNode, keypath: KeyPath) -> Any:
        tag = node.tag
        if tag == _STR:
            return node.value
        if tag in _BASE_60 and ":" in node.value:
            # YAML 1.1's base-60 numbers (``1:30`` is 90, ``0:30`` 30): YAML 1.2 has none,
            # and a user who wrote ``1:30`` meant a range or a time, never 90; kept as the
            # text written, which the parameter then refuses, saying what it was
            return node.value
        if tag not in _SAFE_SCALAR_TAGS:
            raise self.fail(node, f"tag {tag!r} is not allowed (only plain YAML values)", keypath)
        limit = sys.get_int_max_str_digits()
        if tag == _INT and limit and sum(c.isdigit() for c in node.value) > limit:
            # Python would refuse to read it, in words about its own settings
            raise self.fail(
                node,
                f"number too large (more than {limit} digits; a number must fit a float, at "
                "most about 1.8e308)",
                keypath,
            )
        try:
            return self.scalars[tag](self.constructor, node)
        except (yaml.YAMLError, ValueError, OverflowError) as exc:
            raise self.fail(node, f"bad value: {exc}", keypath) from None

    def build_mapping(self, node: yaml.MappingNode, keypath: KeyPath) -> dict[Any, Any]:
        if node.tag != "tag:yaml.org,2002:map":
            raise self.fail(node, f"tag {node.tag!r} is not allowed", keypath)
        merged = self.merged.get(id(node))
        if merged is None:  # first time: resolve YAML merge keys (<<), remember what came in
            own = {id(k) for k, _ in node.value if k.tag != _MERGE}
            try:
                self.constructor.flatten_mapping(node)
            except yaml.YAMLError as exc:
                problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
                raise self.fail(node, f"bad merge key: {problem}", keypath) from None
            merged = self.merged[id(node)] = {id(k) for k, _ in node.value if id(k) not in own}
        out: dict[Any, Any] = {}
        first_line: dict[Any, int] = {}
        from_merge: set[Any] = set()
        for key_node, value_node in node.value:
            if not isinstance(key_node, yaml.ScalarNode) or key_node.tag not in _SAFE_SCALAR_TAGS:
                raise self.fail(key_node, "mapping keys must be plain scalars", keypath)
            key = key_node.value  # a key is a name: `1`, `1.5` or `yes` as written
            line = key_node.start_mark.line + 1
            if key in out and key not in from_merge:
                raise self.fail(
                    key_node,
                    f"duplicate key {key!r} (first defined on line {first_line[key]})",
                    (*keypath, key),
                )
            # merged pairs come first; a later one (or the mapping's own) overrides them
            if id(key_node) in merged:
                from_merge.add(key)
            else:
                from_merge.discard(key)
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
    """Load ``path`` as YAML with line tracking; raise ConfigError naming file and line.

    Only a regular file of at most :data:`MAX_FILE_BYTES` is read. It is opened without
    blocking and checked through its descriptor, so a FIFO or a device swapped in after a
    check is refused too.
    """
    path = Path(path)
    return parse_yaml(read_regular_file(path, MAX_FILE_BYTES, "a YAML file"), path)


def read_regular_file(path: Path, max_bytes: int, expected: str, follow: bool = True) -> bytes:
    """The bytes of ``path`` if it is a regular file of at most ``max_bytes``; else one line.

    The one check every loader of a user's file uses (YAML, AMSA models and templates): the
    file is opened without blocking and checked through its descriptor, so a FIFO or a device
    (``/dev/zero`` never ends) is refused even if swapped in after a check, and never more
    than ``max_bytes`` are read, even from a file that grows meanwhile. ``follow=False``: a
    symbolic link is refused too (a file of a directory someone handed over, which must not
    lead out of it).
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    if not follow:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise ConfigError("file not found", file=path) from None
    except OSError as exc:
        if not follow and exc.errno == errno.ELOOP:
            raise ConfigError(
                f"is a symbolic link, expected {expected} of its own", file=path
            ) from None
        raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise ConfigError(f"is a directory, expected {expected}", file=path)
        if not stat.S_ISREG(st.st_mode):
            raise ConfigError(
                f"is not a regular file (a {_file_kind(st.st_mode)}), expected {expected}",
                file=path,
            )
        if st.st_size > max_bytes:
            raise ConfigError(_too_large(st.st_size, max_bytes), file=path)
        chunks = []
        size = 0
        while True:  # never more than the limit, even if the file grows while read
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                break
            size += len(chunk)
            if size > max_bytes:
                raise ConfigError(_too_large(size, max_bytes), file=path)
            chunks.append(chunk)
    except OSError as exc:
        raise ConfigError(f"cannot read: {exc.strerror}", file=path) from None
    finally:
        os.close(fd)
    return b"".join(chunks)


def parse_json(raw: bytes, path: Path) -> Any:
    """The JSON value in ``raw`` (a file's bytes, :func:`read_regular_file`), or one line
    naming ``path`` and what is wrong: the one parse of every JSON file amsa-phys reads back
    from a directory someone may have handed over (a run's metrics, a search's records)."""
    try:
        return json.loads(raw)
    except json.JSONDecodeError as exc:
        raise ConfigError(f"invalid JSON: {exc.msg}", file=path, line=exc.lineno) from None
    except UnicodeDecodeError:
        raise ConfigError("invalid JSON: not UTF-8 text", file=path) from None
    except RecursionError:
        raise ConfigError("invalid JSON: nested too deeply", file=path) from None


def _file_kind(mode: int) -> str:
    if stat.S_ISFIFO(mode):
        return "FIFO"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "device"
    if stat.S_ISSOCK(mode):
        return "socket"
    return "special file"


def _too_large(size: int, limit: int = MAX_FILE_BYTES) -> str:
    return f"file too large ({size / 2**20:.1f} MiB or more; the limit is {limit / 2**20:g} MiB)"


def parse_yaml(raw: bytes | str, path: str | Path, max_nodes: int = MAX_NODES) -> YamlDoc:
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
    bad = yaml.reader.Reader.NON_PRINTABLE.search(text)
    if bad is not None:
        raise ConfigError(
            f"not YAML text: control character {ord(bad.group()):#06x} is not allowed",
            file=path,
            line=text.count("\n", 0, bad.start()) + 1,
        )
    node = _compose(text, path, max_nodes)
    if node is None:
        raise ConfigError("file is empty", file=path, line=1)
    builder = _Builder(path, max_nodes)
    data = builder.build(node, ())
    return YamlDoc(path=path, data=data, lines=builder.lines, values=builder.count)


def _compose(text: str, path: Path, max_nodes: int) -> yaml.Node | None:
    """The document's node tree: libyaml if it takes the text, else PyYAML's own message.

    With libyaml, the values are counted from the parser's events first: that is ~10x
    cheaper than composing (which resolves every scalar's type in Python), so a file of too
    many values is refused in about a second rather than after composing all of it.
    """
    if _C_LOADER is not None:
        try:
            if _values_over(yaml.parse(text, Loader=_C_LOADER), max_nodes):
                raise ConfigError(f"document too large: over {max_nodes:,} values", file=path)
            return yaml.compose(text, Loader=_C_LOADER)
        except (yaml.YAMLError, RecursionError):
            pass  # composed again below, for PyYAML's message
    try:
        return yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        problem = exc.problem or exc.context or "syntax error"
        raise ConfigError(f"YAML syntax error: {problem}", file=path, line=line) from None
    except yaml.YAMLError as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ConfigError(f"YAML error: {first}", file=path) from None
    except RecursionError:
        raise ConfigError(
            f"YAML nesting too deep (over {MAX_DEPTH} levels)", file=path, line=_too_deep(text)
        ) from None


def _too_deep(text: str) -> int | None:
    """The line where ``text`` nests deeper than ``MAX_DEPTH`` (None if it does not).

    The composer recurses once per level and runs out of stack before saying where; the
    parser's event stream is flat, so it finds the line in one pass."""
    # libyaml stops at its own depth limit, at times before the events that reach ours
    for loader in (_C_LOADER, yaml.SafeLoader):
        if loader is None:
            continue
        depth = 0
        try:
            for event in yaml.parse(text, Loader=loader):
                if isinstance(event, yaml.CollectionStartEvent):
                    depth += 1
                    if depth > MAX_DEPTH:
                        return int(event.start_mark.line) + 1
                elif isinstance(event, yaml.CollectionEndEvent):
                    depth -= 1
        except yaml.YAMLError:
            continue
    return None


def _values_over(events: Any, limit: int) -> bool:
    """Whether the event stream holds more than ``limit`` values, counted as the builder
    counts them: every node but mapping keys (an alias counts once; its expansion is capped
    when built)."""
    nodes = (yaml.ScalarEvent, yaml.AliasEvent, yaml.MappingStartEvent, yaml.SequenceStartEvent)
    ends = (yaml.MappingEndEvent, yaml.SequenceEndEvent)
    expects_key: list[bool | None] = []  # per open collection: a mapping's next node is a key?
    values = 0
    for event in events:
        if isinstance(event, nodes):
            if expects_key and expects_key[-1] is not None:
                is_key = expects_key[-1]
                expects_key[-1] = not is_key
            else:
                is_key = False
            if not is_key:
                values += 1
                if values > limit:
                    return True
            if isinstance(event, yaml.MappingStartEvent):
                expects_key.append(True)
            elif isinstance(event, yaml.SequenceStartEvent):
                expects_key.append(None)
        elif isinstance(event, ends):
            expects_key.pop()
    return False


def parse_value(text: str, what: str) -> Any:
    """A command-line value (``--set``, ``--grid``) read as YAML, within small limits.

    Text that is not YAML is taken as it is (a string, judged by the parameter). ``what``
    names the option in errors (a billion-laughs value is refused, not expanded).
    """
    if not text.strip():
        return text
    try:
        return parse_yaml(text, what, max_nodes=MAX_VALUE_NODES).data
    except ConfigError as exc:
        if "syntax error" in exc.message or "YAML error" in exc.message:
            return text
        raise ConfigError(exc.message, key=what) from None
