"""The framework's own ROS names live in one registry (``model/rosnames.py``).

A name spelled twice drifts: the C++ Leaf reads ``/amsa/seed`` while the launch file sets
another, and only a ROS run would find out. So nothing in the package but the registry may
spell one (the scan below covers every text file: Python, the C++ headers, the node and
package templates), and the generated files take them through holes filled from the
registry: a registry edited to another namespace leaves no old name in the generated C++.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from amsa_phys.model import rosnames
from amsa_phys.model.scenario import load_scenario
from amsa_phys.ros import generate

PACKAGE = Path(rosnames.__file__).resolve().parents[1]
ROOT = PACKAGE.parent
REGISTRY = Path(rosnames.__file__).resolve()
#: A framework name: the namespace at the start of a ROS name (not ``reference/amsa/``, a
#: file path, nor ``/amsa_simulator``, a node of its own).
SPELLED = re.compile(r"(?<![\w./-])/amsa\b(?![_-])")


def _texts() -> list[Path]:
    """Every file of the package a person or the generator reads as text."""
    out = []
    for path in sorted(PACKAGE.rglob("*")):
        if not path.is_file() or "__pycache__" in path.parts:
            continue
        try:
            path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue  # images, fonts
        out.append(path)
    return out


def test_no_framework_name_is_spelled_outside_the_registry() -> None:
    files = _texts()
    assert any(p.suffix == ".h" for p in files)
    assert any(p.name.endswith(".in") for p in files)
    found = [
        f"{p.relative_to(ROOT)}:{n}: {line.strip()}"
        for p in files
        if p != REGISTRY
        for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
        if SPELLED.search(line)
    ]
    assert not found, "framework names spelled outside model/rosnames.py:\n" + "\n".join(found)


def test_the_registry_is_one_namespace_of_distinct_names() -> None:
    assert rosnames.NAMESPACE == "/" + rosnames.NAMESPACE_BASE
    values = list(rosnames.FRAMEWORK.values())
    assert len(set(values)) == len(values)
    for key, value in rosnames.FRAMEWORK.items():
        assert value == rosnames.NAMESPACE or value.startswith(rosnames.NAMESPACE + "/"), key
        assert rosnames.BASE.match(key), key  # a template hole's name


def _export(out: Path) -> None:
    scenario = ROOT / "scenarios" / "scenario1.yaml"
    generate.generate([load_scenario(scenario)], [str(scenario)], "lockstep", out)


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("pkg") / "pkg"
    _export(out)
    return out


def test_every_framework_name_in_the_ros1_package_is_a_registry_name(exported: Path) -> None:
    """What the generator wrote (C++, Python nodes, launch, README) names only registry
    names, a Leaf's step/done topic being the registry's prefix and the Leaf's node."""
    leaves = [n.replace(".", "/") for n in _leaf_paths(exported)] + [rosnames.CONTAINER]
    known = set(rosnames.FRAMEWORK.values())
    known |= {f"{p}/{leaf}" for p in (rosnames.STEP, rosnames.DONE) for leaf in leaves}
    known |= {rosnames.STEP + "/LEAF", rosnames.DONE + "/LEAF", rosnames.STEP + "/Leaf"}
    known.add(rosnames.DONE + "/Leaf")
    seen = set()
    for path in exported.rglob("*"):
        if path.is_file():
            for m in re.finditer(r"(?<![\w./-])/amsa(?:/[A-Za-z_][\w]*)*", path.read_text()):
                seen.add(m.group(0))
                assert m.group(0) in known, f"{path.relative_to(exported)}: {m.group(0)}"
    # the C++ Leaf node reads the seed and answers on the container's topic
    assert {rosnames.P_SEED, rosnames.DONE_CONTAINER, rosnames.READY} <= seen


def _leaf_paths(pkg: Path) -> list[str]:
    return [p.stem.replace("__", ".") for p in (pkg / "nodes").glob("*.py")]


def test_the_launch_files_graph_parameters_are_registry_parameters(exported: Path) -> None:
    launch = ET.parse(next((exported / "launch").glob("*.launch"))).getroot()
    groups = [g for g in launch.iter("group") if g.get("ns") == rosnames.NAMESPACE_BASE]
    assert len(groups) == 1
    params = {rosnames.NAMESPACE + "/" + (e.get("name") or e.get("param") or "") for e in groups[0]}
    params |= {e.get("name") for e in launch.iter("param") if e.get("name", "").startswith("/amsa")}
    registry = {v for k, v in rosnames.FRAMEWORK.items() if k.startswith("p_")}
    assert params <= registry, params - registry
    assert {rosnames.P_SEED, rosnames.P_SIM, rosnames.P_MODE, rosnames.P_SCENARIO} <= params


def test_the_generated_cpp_takes_its_names_from_the_registry(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Edit the registry (another namespace): the C++ headers, the container and the node
    scripts' parameter read follow, and no old name is left in them."""
    for key, value in rosnames.FRAMEWORK.items():
        monkeypatch.setitem(rosnames.FRAMEWORK, key, "/elsewhere" + value[len("/amsa") :])
    out = tmp_path / "pkg"
    _export(out)
    cpp = [*(out / "include").rglob("*.h"), *(out / "src").glob("*.cpp")]
    assert cpp
    for path in cpp:
        text = path.read_text()
        assert not SPELLED.search(text), path.name
    header = next((out / "include").rglob("amsa_leaf_node.h")).read_text()
    assert '"/elsewhere/seed"' in header
    assert '"/elsewhere/done" + getName()' in header
    node = (out / "nodes" / f"{rosnames.SIMULATOR}.py").read_text()
    assert '"/elsewhere/sim"' in node
    assert not SPELLED.search(node.split('"""', 2)[2])
