"""Components, kinds, parameters with ranges, links and execution order of a file."""

from __future__ import annotations

import argparse

from ..model.world import WorldSpec
from ..runs.expect import describe_bound, describe_what
from .loading import load_any


def add_args(p: argparse.ArgumentParser) -> None:
    """Arguments of ``amsa-phys describe``."""
    p.add_argument("file", help="world or scenario YAML file")


def describe_world(world: WorldSpec) -> list[str]:
    """Human-readable lines describing a world."""
    lines = [
        f"world {world.name}: {len(world.leaves)} components, physics "
        f"{float(world.physics['rate']):g} Hz"
    ]
    for path in world.leaves:
        leaf = world.leaves[path]
        t = leaf.template
        lines.append(f"  {path}: {t.name()} ({t.kind.value}) at {float(leaf.freq):g} Hz")
        for p in t.params:
            value = leaf.params[p.name]
            rng = p.range_text()
            unit = f" {p.unit}" if p.unit else ""
            lines.append(f"      {p.name} = {value!r}{unit}" + (f"  {rng}" if rng else ""))
        for port, buf in leaf.inputs.items():
            lines.append(f"      <- {port}: {buf}")
        if t.outputs:  # a terrain zone publishes nothing
            lines.append("      -> " + ", ".join(p.name for p in t.outputs))
    lines.append("execution order at a shared instant: " + " -> ".join(world.order))
    if world.schedule:
        lines.append("explicit schedule: " + ", ".join(world.schedule))
    return lines


def run(args: argparse.Namespace) -> int:
    """Print the description."""
    kind, obj = load_any(args.file)
    if kind == "scenario":
        print(
            f"scenario {obj.name}: {float(obj.duration):g} s, seed {obj.seed}, "
            f"trace at {float(obj.log_rate):g} Hz"
        )
        if obj.quality:
            q = obj.quality
            print(f"quality: {q.signal} vs {q.reference:g} ± {q.tolerance:g}")
        for i, phase in enumerate(obj.phases):
            changes = ", ".join(f"{c.key}={c.value!r}" for c in phase.changes) or "-"
            print(f"phase {i} at {float(phase.at):g} s: {changes}")
        for e in obj.expect:
            print(f"expect {describe_what(e)} {describe_bound(e)}")
        world = obj.world
    else:
        world = obj
    print("\n".join(describe_world(world)))
    return 0
