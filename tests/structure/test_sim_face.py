"""Code outside the engine touches a running simulation only through ``engine/face.py``.

A scan of every module outside ``engine/`` for attribute reads (and writes) on what holds a
simulation: a name ``sim`` / ``simulation`` (``_sim``, ``self.sim``, ``link.sim`` alike) or
a parameter annotated with the engine's ``Simulation`` / ``MultiRun`` or a face. Each name
read must be declared by a face: a reader that reaches the loop's own state (``sim.store``,
``sim._tick``, ``sim.log``) fails here, so the loop can change its insides freely. And no
class outside the engine overrides a private method of ``Simulation``: a runtime plugs in
(``engine/plugs.py``) instead. Each check is also run on a module with one bad line added
(the mutation check).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from amsa_phys.engine.face import FACES, BatchDriver, ServiceHost, SimDriver, SimView, declared
from amsa_phys.engine.multirun import MultiRun
from amsa_phys.engine.runner import Simulation
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
PKG = ROOT / "amsa_phys"
OUTSIDE = sorted(p for p in PKG.rglob("*.py") if p.relative_to(PKG).parts[0] != "engine")
#: what a simulation is held by, by convention across the package
HOLDERS = {"sim", "simulation", "_sim", "_simulation"}
#: the types whose holders are checked wherever they are named
TYPES = {"Simulation", "MultiRun", *(f.__name__ for f in FACES)}
ALLOWED = frozenset().union(*(declared(f) for f in FACES))
ENGINE_CLASSES = {"Simulation", "MultiRun"}


def _annotated(tree: ast.AST) -> set[str]:
    """Parameters annotated with a simulation's type (``sim: Simulation | None`` too)."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.arg) and node.annotation is not None:
            named = {n.id for n in ast.walk(node.annotation) if isinstance(n, ast.Name)}
            named |= {n.attr for n in ast.walk(node.annotation) if isinstance(n, ast.Attribute)}
            text = ast.unparse(node.annotation)
            if named & TYPES or any(t in text for t in TYPES):
                out.add(node.arg)
    return out


def _holds_sim(node: ast.AST, annotated: set[str]) -> bool:
    if isinstance(node, ast.Name):
        return node.id in HOLDERS or node.id in annotated
    return isinstance(node, ast.Attribute) and node.attr in HOLDERS


def off_face(source: str, where: str) -> list[str]:
    """Each read or write of a simulation's attribute no face declares, as ``file:line``."""
    tree = ast.parse(source)
    annotated = _annotated(tree)
    return [
        f"{where}:{node.lineno}: .{node.attr}"
        for node in ast.walk(tree)
        if isinstance(node, ast.Attribute)
        and _holds_sim(node.value, annotated)
        and node.attr not in ALLOWED
    ]


def private_overrides(source: str, where: str) -> list[str]:
    """Methods with a private name in a class deriving from the engine's ``Simulation``."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.ClassDef):
            continue
        bases = {ast.unparse(b).rpartition(".")[2] for b in node.bases}
        if not bases & ENGINE_CLASSES:
            continue
        for item in node.body:
            if isinstance(item, ast.FunctionDef | ast.AsyncFunctionDef):
                name = item.name
                if name.startswith("_") and not (name.startswith("__") and name.endswith("__")):
                    out.append(f"{where}:{item.lineno}: {node.name}.{name}")
    return out


@pytest.mark.parametrize("path", OUTSIDE, ids=[str(p.relative_to(PKG)) for p in OUTSIDE])
def test_outside_the_engine_a_run_is_read_through_its_faces(path: Path) -> None:
    where = str(path.relative_to(PKG))
    source = path.read_text()
    assert off_face(source, where) == []
    assert private_overrides(source, where) == []


def test_the_scan_sees_what_readers_do() -> None:
    """The readers of the package are found (the scan is not vacuous), in every shape."""
    seen = set()
    for path in OUTSIDE:
        tree = ast.parse(path.read_text())
        held = _annotated(tree)
        seen |= {
            node.attr
            for node in ast.walk(tree)
            if isinstance(node, ast.Attribute) and _holds_sim(node.value, held)
        }
    assert {"now", "world", "events", "add_log_listener", "advance"} <= seen


@pytest.mark.parametrize(
    "line",
    [
        "sim._tick",  # the loop's own clock
        "self.sim.store.data",  # the buffer store, not the face's data
        "x = simulation.log.quality_waits",
        "link.sim._pending_live.append(c)",
        "def f(run: Simulation) -> None:\n    run.deliveries",  # held under another name
        "def f(run: SimView | None) -> None:\n    run.shared",
    ],
)
def test_a_read_off_the_face_fails(line: str) -> None:
    view = PKG / "view" / "scene.py"
    source = view.read_text() + "\n\n" + line + "\n"
    assert off_face(view.read_text(), "scene.py") == []
    assert len(off_face(source, "scene.py")) == 1


def test_a_private_override_fails() -> None:
    rossim = PKG / "ros" / "runtime" / "rossim.py"
    bad = (
        "\n\nclass Sneaky(Simulation):\n"
        "    def _apply_adapt(self) -> None:\n        pass\n"
        "    def __init__(self) -> None:\n        pass\n"
    )
    assert private_overrides(rossim.read_text(), "rossim.py") == []
    found = private_overrides(rossim.read_text() + bad, "rossim.py")
    assert [f.rpartition(" ")[2] for f in found] == ["Sneaky._apply_adapt"]


def test_the_engine_satisfies_every_face_it_claims() -> None:
    """Every name a face declares is there on a Simulation (and a batch), initialized."""
    scenario = load_scenario(ROOT / "scenarios" / "scenario1.yaml", duration=1)
    sim = Simulation.from_scenario(scenario)
    sim.initialize()
    for face in (SimView, SimDriver, ServiceHost):
        assert isinstance(sim, face)
        assert [n for n in declared(face) if not hasattr(sim, n)] == []
    batch = MultiRun([scenario, scenario])
    batch.initialize()
    assert isinstance(batch, BatchDriver)
    assert [n for n in declared(BatchDriver) if not hasattr(batch, n)] == []


def test_the_faces_hide_the_loop() -> None:
    """The faces are narrow: none of the loop's own state is on them."""
    sim = Simulation.from_scenario(load_scenario(ROOT / "scenarios" / "scenario1.yaml"))
    inside = {"store", "log", "shared", "deliveries", "plugs", "values", "change_log"}
    assert inside <= set(vars(sim))  # they exist ...
    assert not inside & ALLOWED  # ... and no face declares them
    sim.initialize()  # the physics world is made as its Leaves initialize
    assert sim.service("physics") is sim.shared["physics"]
    assert sim.service("nothing") is None
