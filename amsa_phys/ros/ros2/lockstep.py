"""``amsa-phys ros2 lockstep PKG --out RUNDIR``: an exported package's nodes in the loop.

Starts every node of the package (``config/amsa.yaml``) as a process of this Python, with
its ``ros__parameters`` file and each input remapped to the topic amsa-phys delivers it on
(``names.input_topic``), then runs the package's scenario with those Leaves stepped by their
nodes (``bridge.py``) and writes the run directory as ``amsa-phys run`` does: the same
``trace.csv``, byte for byte. No ``ros2 launch``: the wheels this is tested with have none.
Every node is stopped when the run ends, however it ends; a node that dies is the run's fault.
"""

from __future__ import annotations

import dataclasses
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from ...errors import ConfigError
from ...model.scenario import Scenario, load_scenario
from ...model.yamlio import load_yaml
from .. import external, names
from ..exported import KEY as CUT_KEY
from ..exported import cut_of
from .export import MANIFEST
from .insim import ExternalSimulation

STOP_WAIT_S = 10.0  # a node gets this long to leave after SIGINT, then it is killed


@dataclasses.dataclass
class Plan:
    """The package's scenario and how each node is started."""

    scenario: Scenario
    commands: dict[str, list[str]]


@dataclasses.dataclass
class Package:
    """An exported package as its manifest says: the scenario, parameters and node scripts."""

    scenario: Scenario
    params: Path
    #: each Leaf's node script, in the manifest's order
    scripts: dict[str, Path]
    #: the Leaves of the simulator (``local``), and the boundary node's script
    local: list[str]
    boundary: Path | None


def read_package(pkg: Path) -> Package:
    """Read the package's manifest and scenario (one line naming the file if either is bad)."""
    if not pkg.is_dir():
        what = "not a directory" if pkg.exists() else "no such directory"
        raise ConfigError(
            f"{what} (a package made by amsa-phys export ros2 SCENARIO -o DIR)", file=pkg
        )
    manifest = pkg / MANIFEST
    if not manifest.is_file():
        raise ConfigError(
            "not an amsa-phys ROS 2 package (export one with amsa-phys export ros2)",
            file=manifest,
        )
    doc = load_yaml(manifest)
    data = doc.data
    if not isinstance(data, dict) or not isinstance(data.get("nodes"), list):
        raise doc.error((), "expected package, scenario, params and nodes")
    for key in ("scenario", "params"):
        if not isinstance(data.get(key), str) or "/" in data[key] or data[key].startswith("."):
            raise doc.error((key,), "expected a file name in config/")
    duration = data.get(CUT_KEY)
    if duration is not None and (
        isinstance(duration, bool) or not isinstance(duration, int | float)
    ):
        raise doc.error((CUT_KEY,), "expected seconds (export ros2 --duration)")
    if duration is not None:
        try:
            cut_of(float(duration), CUT_KEY)
        except ConfigError as exc:
            raise doc.error((CUT_KEY,), exc.message) from None
    # the whole scenario cut as `run --duration` cuts it: its checks skipped as there
    seconds = None if duration is None else float(duration)
    scenario = load_scenario(pkg / "config" / data["scenario"], duration=seconds)

    def script(value: Any, where: tuple[Any, ...]) -> Path:
        path = (pkg / value).resolve() if isinstance(value, str) else None
        if path is None or pkg.resolve() not in path.parents or not path.is_file():
            raise doc.error(where, "expected a file of the package")
        return path

    scripts: dict[str, Path] = {}
    for i, node in enumerate(data["nodes"]):
        leaf = node.get("leaf") if isinstance(node, dict) else None
        module = node.get("module") if isinstance(node, dict) else None
        if leaf not in scenario.world.leaves or not isinstance(module, str):
            raise doc.error(("nodes", i), "expected a Leaf of the package's world and its module")
        scripts[leaf] = script(module, ("nodes", i, "module"))
    local = data.get("local", [])
    if not isinstance(local, list) or any(p not in scenario.world.leaves for p in local):
        raise doc.error(("local",), "expected the Leaves of the package's world in the simulator")
    boundary = script(data["boundary"], ("boundary",)) if "boundary" in data else None
    return Package(scenario, pkg / "config" / data["params"], scripts, local, boundary)


def plan(pkg: Path, timeout_s: float | None = None) -> Plan:
    """Read the package; each node's command for lockstep (inputs remapped, own trigger)."""
    package = read_package(pkg)
    scenario = package.scenario
    leaves = list(package.scripts)
    commands: dict[str, list[str]] = {}
    described = external.describe(scenario.world, leaves, private_inputs=True)
    for wiring in described:
        remaps = []
        for w in wiring.inputs:
            remaps += ["-r", f"{names.topic(w.buffer)}:={w.topic}"]
        commands[wiring.path] = [
            sys.executable,
            str(package.scripts[wiring.path]),
            "--amsa-step",
            "--ros-args",
            "--params-file",
            str(package.params),
            *remaps,
        ]
    scenario = dataclasses.replace(scenario, ros2=tuple(leaves))
    if timeout_s is not None:
        scenario = dataclasses.replace(scenario, ros2_timeout=float(timeout_s))
    return Plan(scenario, commands)


@contextmanager
def nodes_running(commands: dict[str, list[str]]) -> Iterator[dict[str, subprocess.Popen[Any]]]:
    """Every node started; every one stopped (SIGINT, then SIGKILL) when the block ends."""
    procs: dict[str, subprocess.Popen[Any]] = {}
    try:
        for path, cmd in commands.items():
            procs[path] = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, env=os.environ.copy())
        yield procs
    finally:
        for proc in procs.values():
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
        for proc in procs.values():
            try:
                proc.wait(timeout=STOP_WAIT_S)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def simulation(plan: Plan, procs: dict[str, subprocess.Popen[Any]]) -> Any:
    """The factory ``run_scenario`` calls: the bridge, watching the node processes."""

    def dead() -> tuple[str, str] | None:
        for path, proc in procs.items():
            if proc.poll() is not None:
                return path, f"the node of {path} exited with status {proc.returncode}"
        return None

    def make(scenario: Scenario, trace: Any) -> ExternalSimulation:
        return ExternalSimulation(
            scenario, scenario.ros2_timeout, private_inputs=True, watch=dead, trace=trace
        )

    return make
