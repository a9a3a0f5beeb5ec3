"""An AMSA model (``.amsacore`` + ``.amsatemplate``) as an amsa-phys world file.

Everything the model says is kept: the component tree, templates, frequencies, parameter
values, links and the names of its Data (``data:``). What it leaves empty is never guessed
silently: an empty parameter takes the template's default, a missing frequency the
metamodel's 10 Hz, a dataflow loop under automatic scheduling gets an order — each marked
by a comment in the world file and reported as one warning line, so a scenario can supply
the real value (``set: {MyFollowerController.Kv: 0.35, MyNormalizePower.freq: 4}``).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ..errors import ConfigError, one_line
from ..model.dataflow import execution_order
from ..model.template import BUILTINS, Kind, Template, TemplateNotFound, resolve_template
from ..model.world import DEFAULT_FREQ_HZ
from .amsacore import CompositeNode, LeafNode, Model, read_model
from .amsatemplate import COMPATIBLE, TemplateDecl, read_templates

#: Automatic scheduling of a loop: in dataflow order, cut where the actuator feeds the process
#: (the process applies the power commanded a period earlier, then its sensors, observers,
#: controllers and actuators run on its new state). The loop's further delay is each
#: component's ``latency`` (``model/timing.py``), which an AMSA model has no place for.
AUTO_ORDER = (Kind.PROCESS, Kind.SENSOR, Kind.OBSERVER, Kind.CONTROLLER, Kind.ACTUATOR)


@dataclass
class Warning_:
    """A value the model leaves empty (or doubtful), and what the world uses instead."""

    file: Path
    line: int | None
    message: str

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}" if self.line else str(self.file)
        return f"{where}: {self.message}"


@dataclass
class Imported:
    """The world's text (with comments), warnings to print, the template file read (an input)."""

    name: str
    text: str
    warnings: list[Warning_] = field(default_factory=list)
    templates: Path | None = None


def import_model(
    model_path: Path, templates_path: Path | None = None, modules: Sequence[str] = ()
) -> Imported:
    """Read an AMSA model and write it as a world (text); see the module docstring.

    A model may say that a template is implemented by a user's Python module
    (``mypkg.rovers:Tracked``). Import never imports code a file names: such a module is
    imported only if the user names it in ``modules`` (``--template-module``).
    """
    model = read_model(model_path)
    tpath = templates_path or _templates_file(model)
    return _Importer(model, tpath, read_templates(tpath), set(modules)).run()


def _templates_file(model: Model) -> Path:
    """The template file the model names, which must sit next to it.

    The model is data from elsewhere: a name with a directory part (``/etc/passwd``,
    ``../secret``) or a link that leads out of the model's folder is refused, so a model can
    make import read no file but its own sibling (``--templates FILE`` reads any file the
    user names)."""
    hrefs = [model.templates_href] + [leaf.template_href for leaf in model.leaves.values()]
    for href in hrefs:
        name = (href or "").partition("#")[0]
        if name:
            return _sibling(model, name)
    raise ConfigError("names no template file; give --templates FILE", file=model.path)


def _sibling(model: Model, name: str) -> Path:
    """``name`` in the model's folder, or a one-line ConfigError (never the file's text)."""
    folder = model.path.parent
    plain = Path(name).name == name and "\\" not in name and name not in (".", "..")
    if not plain:
        raise ConfigError(
            "the model names a template file outside its folder; only a file next to the "
            "model is read: give --templates FILE",
            file=model.path,
        )
    path = folder / name
    if not path.is_file():
        raise ConfigError(
            f"the model's templates {name!r} are not next to it; give --templates FILE",
            file=model.path,
        )
    if path.resolve().parent != folder.resolve():
        raise ConfigError(
            f"the model's templates {name!r} link to a file outside its folder; only a file "
            "next to the model is read: give --templates FILE",
            file=model.path,
        )
    return path


class _Importer:
    def __init__(
        self, model: Model, tpath: Path, decls: dict[str, TemplateDecl], modules: set[str]
    ) -> None:
        self.model = model
        self.modules = modules
        self.tpath = tpath
        self.decls = decls
        self.warnings: list[Warning_] = []
        self.notes: dict[str, list[str]] = {}  # leaf path -> comment per key ("params.Kv")
        self.classes: dict[str, type[Template]] = {}
        self.refs: dict[str, str] = {}

    def warn(self, line: int | None, message: str) -> None:
        self.warnings.append(Warning_(self.model.path, line, message))

    def err(self, line: int | None, message: str) -> ConfigError:
        return ConfigError(message, file=self.model.path, line=line)

    def run(self) -> Imported:
        leaves = self.model.leaves
        if not leaves:
            raise self.err(self.model.root.elem.line, "has no LeafComponent")
        bodies = {path: self._leaf(leaf) for path, leaf in leaves.items()}
        self._check_poses(bodies)
        schedule = self._schedule(bodies)
        text = self._text(bodies, schedule)
        return Imported(self.model.root.name, text, self.warnings, self.tpath)

    # -- templates -------------------------------------------------------------------------
    def _template(self, leaf: LeafNode) -> type[Template]:
        name = leaf.template
        if name in self.classes:
            return self.classes[name]
        decl = self.decls.get(name)
        if decl is None:
            known = ", ".join(sorted(self.decls)) or "none"
            raise self.err(
                leaf.elem.line,
                f"{leaf.path}: unknown template {name!r} ({self.tpath} declares {known})",
            )
        ref = self.model.extension.get("templates", {}).get(name) or name
        if ref not in BUILTINS and ":" not in ref:
            raise ConfigError(
                f"template {name} has no amsa-phys implementation (built-in templates: "
                f"{', '.join(BUILTINS)})",
                file=self.tpath,
                line=decl.line,
            )
        module = ref.partition(":")[0]
        if ref not in BUILTINS and module not in self.modules:
            raise self.err(
                leaf.elem.line,
                f"template {name} is implemented by {ref!r}, Python code the model names: "
                "import never imports a module a file names; if you trust it, give "
                f"--template-module {module}",
            )
        try:
            cls = resolve_template(ref)
        except TemplateNotFound as exc:
            raise ConfigError(f"template {name}: {exc}", file=self.tpath, line=decl.line) from None
        self._check_decl(decl, cls)
        self.classes[name] = cls
        self.refs[name] = ref
        return cls

    def _check_decl(self, decl: TemplateDecl, cls: type[Template]) -> None:
        """The template file's interface must be one amsa-phys's template provides."""
        for what, names, ports in (
            ("input", decl.inputs, cls.inputs),
            ("output", decl.outputs, cls.outputs),
        ):
            have = [p.name for p in ports]
            for n in names:
                if n not in have:
                    raise ConfigError(
                        f"template {decl.name}: amsa-phys's {cls.name()} has no {what} {n!r} "
                        f"(its {what}s: {', '.join(have) or 'none'})",
                        file=self.tpath,
                        line=decl.line,
                    )
        params = {p.name: p for p in cls.params}
        for p in decl.params:
            if p.name not in params:
                raise ConfigError(
                    f"template {decl.name}: amsa-phys's {cls.name()} has no parameter {p.name!r}",
                    file=self.tpath,
                    line=p.line,
                )
            ours = params[p.name].type
            if ours not in COMPATIBLE.get(p.type, {ours}):
                self.warnings.append(
                    Warning_(
                        self.tpath,
                        p.line,
                        f"{decl.name}.{p.name} is declared {p.type}, amsa-phys's is {ours}; "
                        "values are read as amsa-phys's type",
                    )
                )

    # -- one leaf --------------------------------------------------------------------------
    def _leaf(self, leaf: LeafNode) -> dict[str, Any]:
        cls = self._template(leaf)
        notes = self.notes.setdefault(leaf.path, [])
        for out in leaf.outputs:
            if out not in {p.name for p in cls.outputs}:
                raise self.err(
                    leaf.elem.line, f"{leaf.path}: template {cls.name()} has no output {out!r}"
                )
        body: dict[str, Any] = {"template": self.refs[leaf.template]}
        if leaf.freq is None:
            body["freq"] = DEFAULT_FREQ_HZ
            notes.append(f"freq: not in the model: the AMSA default {DEFAULT_FREQ_HZ} Hz")
            self.warn(
                leaf.elem.line,
                f"{leaf.path} has no frequency: the AMSA metamodel's default "
                f"{DEFAULT_FREQ_HZ} Hz is used (set {leaf.path}.freq in a scenario's set:)",
            )
        else:
            body["freq"] = self._freq(leaf)
        declared = {p.name: p for p in cls.params}
        params: dict[str, Any] = {}
        for name, (raw, line) in leaf.params.items():
            param = declared.get(name)
            if param is None:
                raise self.err(
                    line,
                    f"{leaf.path}: unknown parameter {name!r} of template {cls.name()} "
                    f"(its parameters: {', '.join(declared) or 'none'})",
                )
            if raw is None:
                params[name] = param.default
                notes.append(f"params.{name}: empty in the model: template default")
                self.warn(
                    line,
                    f"{leaf.path}.{name} is empty in the model: the template default "
                    f"{_scalar(param.default)} is used (supply it in a scenario's set:)",
                )
                continue
            value = _read_value(raw, param.type)
            try:
                params[name] = param.coerce(value)
            except ValueError as exc:
                raise self.err(line, f"{leaf.path}.{name}: {exc}") from None
            number = params[name]
            default = param.default
            if (
                not self.model.extension  # amsa-phys wrote the file: values are exact
                and param.type in ("int", "float")
                and number == 0
                and isinstance(default, int | float)
                and default != 0
            ):
                notes.append(f"params.{name}: 0 in the model (template default {_scalar(default)})")
                self.warn(
                    line,
                    f"{leaf.path}.{name} is 0 in the model, the template default is "
                    f"{_scalar(default)} (an unset placeholder?): kept as 0; supply it in a "
                    "scenario's set:",
                )
        try:
            cls.check_params({**{n: p.default for n, p in declared.items()}, **params})
        except ValueError as exc:
            raise self.err(leaf.elem.line, f"{leaf.path}: {exc}") from None
        if params:
            body["params"] = params
        inputs: dict[str, str] = {}
        for port, (buffer, line) in leaf.inputs.items():
            if port not in {p.name for p in cls.inputs}:
                raise self.err(line, f"{leaf.path}: template {cls.name()} has no input {port!r}")
            producer, _, output = buffer.rpartition(".")
            prod = self.model.leaves[producer]
            prod_cls = self._template(prod)
            if output not in {p.name for p in prod_cls.outputs}:
                raise self.err(
                    line,
                    f"{leaf.path}.{port}: {producer} ({prod_cls.name()}) has no output {output!r}",
                )
            inputs[port] = buffer
        missing = [p.name for p in cls.inputs if p.name not in inputs]
        if missing:
            raise self.err(
                leaf.elem.line,
                f"{leaf.path}: input {missing[0]!r} of template {cls.name()} is not connected",
            )
        if inputs:
            body["inputs"] = inputs
        return body

    def _freq(self, leaf: LeafNode) -> int | float:
        raw = leaf.freq or ""
        try:
            value = float(raw)
        except ValueError:
            raise self.err(leaf.elem.line, f"{leaf.path}: freq {raw!r} is not a number") from None
        if not math.isfinite(value) or value <= 0:
            raise self.err(leaf.elem.line, f"{leaf.path}: freq must be > 0, got {raw}")
        return int(value) if value.is_integer() else value

    def _check_poses(self, bodies: dict[str, dict[str, Any]]) -> None:
        """Rovers that would all start at the same place (the model has no initial pose)."""
        starts: dict[tuple[float, float], list[str]] = {}
        for path, body in bodies.items():
            cls = self.classes[self.model.leaves[path].template]
            names = {p.name for p in cls.params}
            if {"x", "y"} <= names:
                params = body.get("params", {})
                x = params.get("x", cls.param("x").default)
                y = params.get("y", cls.param("y").default)
                starts.setdefault((x, y), []).append(path)
        for (x, y), paths in starts.items():
            if len(paths) > 1 and not self.model.extension:
                self.warn(
                    None,
                    f"{', '.join(paths)} start at the same place ({x:g}, {y:g}): the model has "
                    "no initial pose; set their x and y in a scenario's set:",
                )

    # -- order -----------------------------------------------------------------------------
    def _schedule(self, bodies: dict[str, dict[str, Any]]) -> list[str]:
        """An explicit order where the model asks for one or its dataflow needs one."""
        leaves = self.model.leaves
        listed = [p for p in leaves if leaves[p].priority != 0]
        manual = not self.model.root.auto_scheduling or any(
            not c.auto_scheduling for c in _composites(self.model.root)
        )
        position = {p: i for i, p in enumerate(leaves)}
        if manual and listed:
            return sorted(listed, key=lambda p: (-leaves[p].priority, position[p]))

        class _Spec:
            def __init__(self, inputs: dict[str, str]) -> None:
                self.inputs = inputs

        specs = {p: _Spec(b.get("inputs", {})) for p, b in bodies.items()}

        def fail(_: tuple[Any, ...], message: str) -> ConfigError:
            return ConfigError(message)

        try:
            execution_order(specs, [], fail)
            return []
        except ConfigError as exc:
            loop = exc.message.split(";")[0]
        kinds = {p: self.classes[leaves[p].template].kind for p in leaves}
        order = sorted(
            (p for p in leaves if kinds[p] in AUTO_ORDER),
            key=lambda p: (AUTO_ORDER.index(kinds[p]), position[p]),
        )
        words = ", ".join(k.value for k in AUTO_ORDER)
        self.warn(
            self.model.root.elem.line,
            f"the model leaves the order to automatic scheduling but its {loop}: scheduled "
            f"in dataflow order ({words}), the process applying what was commanded a period "
            f"earlier; any further delay is a component's latency, which the model has no "
            f"place for (set it in a scenario's set:): [{', '.join(order)}]",
        )
        self.notes.setdefault("", []).append(
            "schedule: not in the model (automatic scheduling with a dataflow loop): "
            f"dataflow order, {words}; the model has no latency (set a component's "
            "latency in a scenario's set:)"
        )
        return order

    # -- text ------------------------------------------------------------------------------
    def _text(self, bodies: dict[str, dict[str, Any]], schedule: list[str]) -> str:
        model = self.model
        ext_world = model.extension.get("world", {})
        lines = [
            f"# {one_line(model.root.name)}: imported by `amsa-phys import` from",
            f"# {one_line(model.path.name)} (templates: {one_line(self.tpath.name)}).",
        ]
        if self.warnings:
            lines.append("# Values the model leaves empty (each marked below and reported as a")
            lines.append("# warning); supply the real ones in a scenario's set:")
            for w in self.warnings:
                lines.append(f"#   - {one_line(w.message)}")
        lines.append(
            "# Parameters the AMSA templates do not declare (a rover's mass, initial pose, ...)"
        )
        lines.append("# take their amsa-phys defaults: `amsa-phys templates NAME` lists them.")
        lines.append(f"name: {_scalar(model.root.name)}")
        description = ext_world.get("description") or f"imported from {model.path.name}"
        lines.append(f"description: {_scalar(description)}")
        if "physics" in ext_world:
            lines.append("physics:")
            dumped = yaml.safe_dump(ext_world["physics"], sort_keys=False, default_flow_style=None)
            lines += ["  " + ln for ln in dumped.rstrip("\n").splitlines()]
        else:
            lines.append("# physics: not in the AMSA model; amsa-phys's defaults apply")
        if "timing" in ext_world:
            lines.append(f"timing: {_scalar(ext_world['timing'])}")
        unnamed = set(model.extension.get("unnamed", []))
        named = {n: b for n, (b, _) in model.data.items() if n not in unnamed}
        if named:
            lines.append("data:                     # the model's Data, by name")
            for name, buffer in named.items():  # names checked by amsacore: NAME(.NAME)*
                lines.append(f"  {name}: {_scalar(buffer)}")
        lines.append("components:")
        lines += self._components(model.root, bodies, 1)
        if schedule:
            note = "  # " + self.notes[""][0] if self.notes.get("") else ""
            lines.append(f"schedule: [{', '.join(schedule)}]{note}")
        return "\n".join(lines) + "\n"

    def _components(
        self, node: CompositeNode, bodies: dict[str, dict[str, Any]], depth: int
    ) -> list[str]:
        pad = "  " * depth
        out: list[str] = []
        for child in node.children:
            name = child.path.rpartition(".")[2]
            if isinstance(child, CompositeNode):
                out.append(f"{pad}{name}:")
                out.append(f"{pad}  components:")
                out += self._components(child, bodies, depth + 2)
                continue
            body = bodies[child.path]
            notes = {n.split(":")[0]: n.split(": ", 1)[1] for n in self.notes.get(child.path, [])}
            out.append(f"{pad}{name}:")
            out.append(f"{pad}  template: {_scalar(body['template'])}")
            out.append(_commented(f"{pad}  freq: {_scalar(body['freq'])}", notes.get("freq")))
            timing = self.model.extension.get("world", {}).get("leafTiming", {})
            for key, value in timing.get(child.path, {}).items():  # amsa-phys's own
                out.append(f"{pad}  {key}: {_scalar(str(value))}")
            if "params" in body:
                out.append(f"{pad}  params:")
                for k, v in body["params"].items():
                    out.append(_commented(f"{pad}    {k}: {_scalar(v)}", notes.get(f"params.{k}")))
            if "inputs" in body:
                out.append(f"{pad}  inputs:")
                for k, v in body["inputs"].items():
                    out.append(f"{pad}    {k}: {_scalar(v)}")
        return out


def _composites(node: CompositeNode) -> list[CompositeNode]:
    out = [node]
    for child in node.children:
        if isinstance(child, CompositeNode):
            out += _composites(child)
    return out


def _commented(line: str, note: str | None) -> str:
    return f"{line}  # {one_line(note)}" if note else line


_PLAIN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_PLAIN_WORDS = {"true", "false", "yes", "no", "on", "off", "null", "y", "n", "~"}


def _scalar(value: Any) -> str:
    """``value`` as one line of YAML flow text (exact floats: PyYAML writes their repr).

    Numbers and plain names (the bulk of a model) are written directly; anything else goes
    through PyYAML's safe dumper, which quotes and escapes what needs it (a newline in a
    name cannot add a key). One dumper per value costs ~50 us: a 2,000-component model has
    ~50,000 values.
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float) and "e" not in (text := repr(value)) and "." in text:
        return text  # (YAML 1.1 reads 1e+20 as text: PyYAML's dumper writes 1.0e+20)
    if isinstance(value, str) and _PLAIN.match(value) and value.lower() not in _PLAIN_WORDS:
        return value
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=True)  # double-quoted: one line, no tag
    if isinstance(value, tuple):
        value = [list(v) if isinstance(v, tuple) else v for v in value]
    text = yaml.safe_dump(value, default_flow_style=True, width=1 << 20)
    return text.removesuffix("\n").removesuffix("\n...").strip()


def _read_value(raw: str, kind: str) -> Any:
    """A parameter's value string as the value its amsa-phys type expects."""
    if kind == "str":
        return raw
    try:
        value = yaml.safe_load(raw)
    except yaml.YAMLError:
        return raw
    if kind == "float" and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return value
