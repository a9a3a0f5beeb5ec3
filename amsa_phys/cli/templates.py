"""List the template library: kind, ports and parameters of every built-in and plugin
template.

Each line ends with where the template comes from (built-in, or the installed plugin package).
"""

from __future__ import annotations

import argparse

from ..errors import ConfigError, one_line
from ..model import plugins as plugin_registry
from ..model.suggest import did_you_mean
from ..model.template import BUILTINS, TemplateNotFound, known_names, resolve_template


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys templates``."""
    p.add_argument(
        "name",
        nargs="?",
        help="show one template (built-in name, installed plugin's name or module:Class)",
    )


def origin(name: str) -> str:
    """Where template ``name`` comes from, as the listing shows it."""
    if name in BUILTINS:
        return "built-in"
    if ":" in name:
        return f"module {name.partition(':')[0]}"
    found = plugin_registry.installed().get(name, [])
    return ", ".join(f"plugin {p.target} from {p.distribution}" for p in found) or "unknown"


def run(args: argparse.Namespace) -> int:
    """Print each template (built-ins, then installed plugins), saying where it comes from."""
    plugins = plugin_registry.installed()
    names = [args.name] if args.name else [*BUILTINS, *(n for n in plugins if n not in BUILTINS)]
    for name in names:
        try:
            t = resolve_template(name)
        except TemplateNotFound as exc:
            if not args.name:  # one broken plugin does not hide the rest of the library
                print(one_line(f"{name} (not loadable: {exc}) [{origin(name)}]"))
                continue
            if name in plugins:  # the name is right: its package is what fails, say which
                raise ConfigError(f"{origin(name)}: {exc}", key="templates") from None
            hint = did_you_mean(name, known_names()) if ":" not in name else ""
            extra = [n for n in plugins if n not in BUILTINS]
            known = "" if hint else f"; built-in: {', '.join(BUILTINS)}"
            if not hint:
                known += f"; plugins: {', '.join(extra) if extra else 'none installed'}"
            raise ConfigError(f"{exc}{hint}{known}", key="templates") from None
        # the name a world writes (a plugin's registered name, not its class's name)
        print(one_line(f"{name} ({t.kind.value}): {t.describe()} [{origin(name)}]"))
        for direction, ports in (("in ", t.inputs), ("out", t.outputs)):
            for port in ports:
                # an array port: out ranges[beams] (one Data per element), in ranges[]
                shape = f"[{port.size}]" if port.array else ""
                print(
                    one_line(
                        f"    {direction} {port.name}{shape}"
                        + (f" [{port.unit}]" if port.unit else "")
                        + (f"  {port.description}" if port.description else "")
                    )
                )
        for p in t.params:
            unit = f" {p.unit}" if p.unit else ""
            rng = f" {p.range_text()}" if p.range_text() else ""
            aliases = t.aliases_of(p.name)
            also = f" (also {', '.join(aliases)})" if aliases else ""
            print(
                one_line(
                    f"    param {p.name}{also}: {p.type} = {p.default!r}{unit}{rng}  "
                    f"{p.description}"
                )
            )
    if not args.name:
        for name in (n for n in plugins if n in BUILTINS):
            who = ", ".join(p.distribution for p in plugins[name])
            print(f"note: plugin name {name!r} from {who} is a built-in's: use module:Class")
        for line in LEAF_KEYS:
            print(line)
    return 0


#: What every Leaf takes in a world besides its template's parameters (README, "World").
LEAF_KEYS = (
    "every Leaf (components.NAME in a world; also Leaf.KEY in a scenario's set: or --set):",
    "    freq: Hz = 10  the rate of its doStep",
    "    latency: s = 0  its outputs reach their readers this long after its step",
    "    jitter: s = 0  each publication delayed by a further uniform draw in [0, jitter)",
    "    phase: s or random = 0  its timer ticks at phase + k / freq (world timing: "
    "{free_running: true} draws one for every Leaf without its own)",
)
