"""``export ros`` with hostile names: refused in one line, or escaped in every generated file.

Issue 33's critical cases: a scenario's ``name:`` reached a YAML comment of the params file
(a newline then ``!radians`` ran code at roslaunch), and a file name reached CMake, C++ and
Python comments and docstrings (code ran at catkin_make and at node start). Names with quotes,
backslashes or control characters are now refused before anything is written; every other
name, and free text (a world's description), is escaped. Both defences are tested: the
refusal through the CLI, and the escaping with the refusal switched off, by parsing every
generated file with its own language's parser and comparing its code with the package of
a harmless name (the names may change comments and strings only, never code).
"""

from __future__ import annotations

import ast
import json
import os
import shutil
import subprocess
import sys
import threading
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from amsa_phys.cli.main import main
from amsa_phys.ros import generate

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
AMSA_PHYS = str(Path(sys.executable).with_name("amsa-phys"))

#: Refused names (quotes, backslashes, control characters): each would have run code.
REFUSED = {
    "yaml-newline": "x\npwn: !radians __import__('os').system('touch MARK')\namsa: {mode: free}",
    "cmake-newline": "x\nexecute_process(COMMAND touch MARK)\n#",
    "docstring": 'x"""\nimport os; os.system("touch MARK")\n"""',
    "backslash": "x\\",
    "quote": "it's",
    "backtick": "`touch MARK`",
    "cr": "x\rpwn: 1",
    "nel": "x\x85pwn: 1",
}
#: Names that pass and must be escaped wherever they land.
PASSED = {
    "dashdash": "a--b--",
    "subst": "$(touch MARK)",
    "cmake-var": "${CMAKE_COMMAND} @PROJECT_NAME@",
    "tag": "!radians 1",
    "rad": "rad(2*2)",
    "markup": "<!-- </launch> &amp; ]]>",
    "trigraph": "??/",
}


def _world(tmp: Path, description: str) -> Path:
    text = WORLD.read_text().replace(
        "description: Leader/follower challenge (AMSA paper, Fig. 2)",
        f"description: {json.dumps(description)}",
    )
    path = tmp / "world.yaml"
    path.write_text(text)
    return path


def _scenario(path: Path, name: str, world: Path = WORLD) -> Path:
    path.write_text(
        f"name: {json.dumps(name)}\nworld: {json.dumps(str(world))}\nduration: 2\nseed: 1\n"
        "set: {MyFollowerController.Kv: 0.2}\n"
        "timeline:\n  - {at: 1, set: {MyFollowerController.Kv: 0.1}}\n"
    )
    return path


def _export(scenario: Path, out: Path, *extra: str) -> int:
    return main(["export", "ros", str(scenario), "-o", str(out), *extra])


@pytest.mark.parametrize("name", list(REFUSED.values()), ids=list(REFUSED))
def test_a_hostile_scenario_name_is_refused_in_one_line_before_anything_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    scenario = _scenario(tmp_path / "s.yaml", name)
    before = sorted(os.listdir(tmp_path))
    assert _export(scenario, tmp_path / "pkg") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "s.yaml: name: the scenario's name" in err
    assert "may not hold quotes, backslashes or control characters" in err
    assert sorted(os.listdir(tmp_path)) == before  # not even a staged directory


@pytest.mark.parametrize("name", list(REFUSED.values()), ids=list(REFUSED))
def test_a_hostile_file_name_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    scenario = _scenario(tmp_path / (name.replace("/", "_") + ".yaml"), "fine")
    before = sorted(os.listdir(tmp_path))
    assert _export(scenario, tmp_path / "pkg") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "the file name" in err
    assert sorted(os.listdir(tmp_path)) == before


def _code_of(pkg: Path) -> dict[str, object]:
    """What every generated file means, with comments and docstrings left out."""
    out: dict[str, object] = {}
    for path in sorted(p for p in pkg.rglob("*") if p.is_file()):
        rel = str(path.relative_to(pkg))
        text = path.read_text()
        if rel.endswith((".launch", ".xml")):
            root = ET.fromstring(text)  # drops comments
            if rel == "package.xml":
                root.find("description").text = ""  # the one place free text belongs
            out[rel] = ET.tostring(root)
        elif rel.endswith(".yaml"):
            data = yaml.safe_load(text)
            if rel.endswith("_params.yaml"):
                assert set(data) == {
                    "Leader",
                    "Follower",
                    "LeaderGPS",
                    "FollowerGPS",
                    "FollowerCompass",
                    "MyDistanceMonitor",
                    "MyFollowerController",
                    "MyNormalizePower",
                }, "a name added keys to the params file"
            elif rel == "config/amsa_leaves.yaml":
                pass  # the C++ container's Leaves and wiring: no scenario name in it
            else:  # the resolved scenario: the name and description are values
                data.pop("name")
                data["world"].pop("description")
            out[rel] = data
        elif rel.endswith(".py") or rel == "nodes/run_lockstep":  # the last: a Python script
            module = ast.parse(text)
            assert isinstance(module.body[0], ast.Expr)  # the docstring, a string
            assert isinstance(module.body[0].value, ast.Constant)
            out[rel] = ast.dump(ast.Module(module.body[1:], []))
        elif rel.endswith((".txt", ".cpp", ".h")):
            marks = "#" if rel.endswith(".txt") else "//"
            out[rel] = [ln for ln in text.splitlines() if not ln.strip().startswith(marks)]
        elif rel == "README.md":
            continue
        else:
            out[rel] = text
    return out


@pytest.mark.parametrize("switch_off_refusal", [False, True], ids=["passed-names", "all-names"])
def test_every_generated_file_parses_and_names_change_no_code(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, switch_off_refusal: bool
) -> None:
    """Each hostile name as the scenario's name, the file name and the world's description:
    every file parses with its own parser, and its code equals the harmless package's."""
    payloads = dict(PASSED)
    if switch_off_refusal:  # the escapers alone must hold
        monkeypatch.setattr(generate, "check_names", lambda *_: None)
        payloads.update(REFUSED)
    marker = tmp_path / "MARK"
    base = tmp_path / "base"
    base.mkdir()
    assert _export(_scenario(base / "plain.yaml", "plain"), base / "pkg") == 0
    want = _code_of(base / "pkg")
    for i, (key, raw) in enumerate(payloads.items()):
        name = raw.replace("MARK", str(marker))
        d = tmp_path / f"case{i}"
        d.mkdir()
        world = _world(d, name)
        # the config file names come from the scenario's name: give them the harmless one's
        scenario = _scenario(d / (raw.replace("/", "_") + ".yaml"), name, world)
        assert _export(scenario, d / "pkg") == 0, key
        got = _code_of(_renamed(d / "pkg"))
        assert got.keys() == want.keys(), key
        for rel, value in want.items():
            assert got[rel] == value, (key, rel)
    assert not marker.exists()


def _renamed(pkg: Path) -> Path:
    """The package with its scenario's files named as the harmless package names them."""
    for path in list(pkg.rglob("*")):
        if path.name == "amsa_leaves.yaml":
            continue  # named by the package, not by the scenario
        if path.is_file() and path.parent.name in ("config", "launch"):
            suffix = "_params.yaml" if path.name.endswith("_params.yaml") else path.suffix
            path.rename(path.with_name("plain" + suffix))
    launch = pkg / "launch" / "plain.launch"
    root = ET.fromstring(launch.read_text())
    for elem in root.iter():
        for attr in ("value", "file"):
            if "$(find" in (elem.get(attr) or "") and "/config/" in (elem.get(attr) or ""):
                head, _, tail = elem.get(attr).rpartition("/config/")  # type: ignore[union-attr]
                if tail == "amsa_leaves.yaml":
                    continue
                elem.set(
                    attr,
                    head + "/config/plain" + ("_params.yaml" if "_params" in tail else ".yaml"),
                )
    launch.write_bytes(ET.tostring(root))
    return pkg


@pytest.mark.build  # g++ compiles the generated node
@pytest.mark.skipif(shutil.which("g++") is None, reason="g++ is not installed")
@pytest.mark.skipif(not Path("/usr/include/ros/ros.h").exists(), reason="roscpp is not installed")
@pytest.mark.skipif(
    not Path("/usr/include/nodelet/nodelet.h").exists(), reason="nodelet is not installed"
)
def test_the_cpp_node_with_hostile_names_compiles(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(generate, "check_names", lambda *_: None)
    name = REFUSED["cmake-newline"] + "??/\\"
    scenario = _scenario(tmp_path / (name.replace("/", "_") + ".yaml"), name)
    assert _export(scenario, tmp_path / "pkg") == 0
    src = tmp_path / "pkg" / "src" / "leaves" / "NormalizePower.cpp"  # its nodelet class
    done = subprocess.run(
        [
            "g++",
            "-std=c++14",
            "-fsyntax-only",
            "-I",
            str(tmp_path / "pkg" / "include"),
            # Debian keeps these headers one level down (catkin adds the directories)
            *[
                arg
                for d in ("pluginlib", "class_loader", "rcpputils", "rcutils")
                if Path("/usr/include", d).is_dir()
                for arg in ("-I", f"/usr/include/{d}")
            ],
            str(src),
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr


def test_concurrent_exports_without_force_one_wins_the_others_fail(tmp_path: Path) -> None:
    """Four exports to one new directory at once: exactly one writes it, three exit 2."""
    scenario = _scenario(tmp_path / "s.yaml", "plain")
    out = tmp_path / "pkg"
    start = threading.Barrier(4)
    codes: list[int] = []

    def one() -> None:
        start.wait()
        codes.append(
            subprocess.run(
                [AMSA_PHYS, "export", "ros", str(scenario), "-o", str(out)],
                capture_output=True,
            ).returncode
        )

    threads = [threading.Thread(target=one) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(codes) in ([0, 2, 2, 2],), codes
    assert (out / "package.xml").is_file()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_an_output_created_while_exporting_is_not_replaced(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The race itself: another export's package appears after the check, before the rename."""
    scenario = _scenario(tmp_path / "s.yaml", "plain")
    out = tmp_path / "pkg"
    real = generate.generate

    def racing(*args: object) -> object:
        package = real(*args)  # type: ignore[arg-type]
        out.mkdir()
        (out / "theirs").write_text("another export's file")
        return package

    monkeypatch.setattr(generate, "generate", racing)
    assert _export(scenario, out) == 2
    assert "was created by someone else while exporting (use --force" in capsys.readouterr().err
    assert [p.name for p in out.iterdir()] == ["theirs"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pkg", "s.yaml"]  # staged dir gone
