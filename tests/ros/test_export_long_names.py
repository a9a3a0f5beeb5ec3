"""A name too long to name a file is refused by every export in one line, exit 2.

A Leaf's path names its node's script, a world's name the package and the AMSA files, a
scenario's name its launch or scenario file, ``--name`` the ROS 2 package: 300 characters
had failed half-way with the file system's "File name too long" and a traceback.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.model.filenames import MAX_FILE_NAME

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
LONG = "x" * 299


def _files(tmp_path: Path, case: str) -> Path:
    """A scenario (and its world) with one name 300 characters long."""
    text = WORLD.read_text()
    name = ""
    if case == "component":
        text = text.replace("MyNormalizePower", "C" + LONG)
    elif case == "world":
        text = text.replace("name: mdeChallenge", "name: m" + LONG)
    elif case == "scenario":
        name = f"name: n{LONG}\n"
    (tmp_path / "w.yaml").write_text(text)
    scenario = tmp_path / "s.yaml"
    scenario.write_text(f"world: w.yaml\nduration: 20\n{name}")
    return scenario


CASES = [
    ("ros", "component"),
    ("ros2", "component"),
    ("ros", "world"),
    ("ros2", "world"),
    ("amsa", "world"),
    ("ros2", "scenario"),
    ("ros2", "--name"),
]


@pytest.mark.parametrize(("target", "case"), CASES)
def test_a_name_too_long_for_a_file_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], target: str, case: str
) -> None:
    scenario = _files(tmp_path, case)
    extra = ["--name", "a" + LONG] if case == "--name" else []
    out = tmp_path / "out"
    assert main(["validate", str(scenario)]) == 0  # a run takes it: only files cannot
    capsys.readouterr()
    assert main(["export", target, str(scenario), "-o", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"at most {MAX_FILE_NAME} characters" in err
    assert LONG not in err  # the name is cut in the message, not repeated whole
    assert not out.exists()


@pytest.mark.parametrize("target", ["ros", "ros2", "amsa"])
def test_a_name_at_the_limit_is_exported(tmp_path: Path, target: str) -> None:
    text = WORLD.read_text().replace("name: mdeChallenge", "name: m" + "x" * (MAX_FILE_NAME - 1))
    (tmp_path / "w.yaml").write_text(text)
    scenario = tmp_path / "s.yaml"
    scenario.write_text("world: w.yaml\nduration: 20\n")
    out = tmp_path / "out"
    assert main(["export", target, str(scenario), "-o", str(out)]) == 0
    assert any(out.iterdir())
