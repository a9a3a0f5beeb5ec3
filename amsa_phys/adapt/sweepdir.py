"""The scenario a sweep directory records, written by ``sweep`` and read back as data.

``amsa-phys adapt SWEEPDIR`` needs the scenario the sweep ran (its ``sweep.contexts``, its
world's estimators and parameter values). The sweep writes it beside ``results.csv`` as
``scenario.yaml``: the resolved scenario (world inlined, every parameter written out) plus
its ``sweep:`` section. A sweep directory is data that users share, so reading it never
imports a module it names: a world whose templates are not all built in is refused, with
the way to go on (``--scenario`` with the scenario's own file, which the user runs).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from ..atomic import write_atomic
from ..errors import ConfigError, one_line
from ..model import schema
from ..model.scenario import Scenario, load_scenario
from ..model.template import BUILTINS
from ..model.yamlio import load_yaml
from ..runs.resolve import resolved_scenario

#: The file a sweep directory records its scenario in.
NAME = "scenario.yaml"


def write_sweep_scenario(out: Path, scenario: Scenario, sweep: dict[str, Any]) -> None:
    """Record ``scenario`` (resolved) and its ``sweep`` section in the sweep directory."""
    data = resolved_scenario(scenario)
    data.pop("adapt", None)  # the sweep's runs are compared without rules of their own
    data["sweep"] = sweep
    head = "# the scenario this sweep ran (resolved), read back by `amsa-phys adapt`\n"
    write_atomic(out / NAME, head + yaml.safe_dump(data, sort_keys=False, allow_unicode=False))


#: What ``adapt`` (which takes ``--scenario``) says to do when the directory cannot answer
ADAPT_INSTEAD = "give the scenario the sweep ran with --scenario"


def read_sweep_scenario(sweepdir: Path, instead: str = ADAPT_INSTEAD) -> Scenario:
    """The scenario ``sweepdir`` records, loaded without importing any module it names.

    ``instead``: what the command's user can do when the directory cannot answer (``tune
    --contexts`` has no ``--scenario``: its messages offered one)."""
    path = Path(sweepdir) / NAME
    if not path.is_file() and (Path(sweepdir) / "falsify.json").is_file():
        raise ConfigError(
            "a falsify directory, not a sweep's: give a sweep over the contexts "
            "(amsa-phys sweep SCENARIO --out DIR, its sweep: contexts)",
            file=sweepdir,
        )
    # one that is there but is not a file (a FIFO, a device, a link to none) is named as
    # such by the loader below: "records none" sent the user looking for a missing file
    if not (path.exists() or path.is_symlink()):
        raise ConfigError(
            f"records no {NAME} (not a sweep directory, or made before sweeps recorded "
            f"their scenario?); {instead}",
            file=sweepdir,
        )
    doc = load_yaml(path)
    if not isinstance(doc.data, dict):
        raise doc.error((), "not a sweep's scenario: expected a mapping")
    # every key first (a hand edit's ``wrold:`` named with its line), as the loader would
    schema.validate(doc.data, schema.SCENARIO, doc)
    world = doc.data["world"]
    if not isinstance(world, dict):
        raise doc.error(("world",), "not a sweep's scenario: the world is not inlined")
    for name, template, keys in _templates(world.get("components"), ("world", "components")):
        if template not in BUILTINS:
            raise doc.error(
                (*keys, "template"),
                f"component {one_line(name)} names template {one_line(str(template))!r}, not "
                f"built in; not imported: a sweep directory is data ({instead})",
            )
    return load_scenario(path)


def _templates(
    components: Any, keys: tuple[Any, ...], prefix: str = ""
) -> list[tuple[str, Any, tuple[Any, ...]]]:
    """Every (component path, template, key path) of a world's ``components`` (Composites
    walked), ``keys`` the key path of ``components`` in the file."""
    out: list[tuple[str, Any, tuple[Any, ...]]] = []
    if not isinstance(components, dict):
        return out
    for name, body in components.items():
        path = f"{prefix}{name}"
        if not isinstance(body, dict):
            continue
        if "components" in body:
            out += _templates(body["components"], (*keys, name, "components"), f"{path}.")
        if "template" in body:
            out.append((path, body["template"], (*keys, name)))
    return out
