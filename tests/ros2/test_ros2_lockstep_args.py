"""``ros2 lockstep`` refuses a wrong path and ``--duration`` in one line, without ROS 2.

A path that is no package is said first (not as a missing ``config/amsa.yaml``, and before a
missing rclpy: this suite's venv has none); ``--duration`` names the export that sets it.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main


def _err(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    assert main(list(argv)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    return err


@pytest.mark.parametrize("action", ["lockstep", "robot"])
def test_a_missing_package_is_said_before_a_missing_rclpy(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], action: str
) -> None:
    missing = tmp_path / "NONEXIST"
    err = _err(capsys, "ros2", action, str(missing))
    assert f"{missing}: no such directory" in err
    assert "rclpy" not in err
    assert "amsa.yaml" not in err


def test_a_file_is_not_a_package(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    file = tmp_path / "pkg.yaml"
    file.write_text("package: x\n")
    assert f"{file}: not a directory" in _err(capsys, "ros2", "lockstep", str(file))


def test_duration_is_the_exports(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    err = _err(capsys, "ros2", "lockstep", str(tmp_path), "--duration", "60")
    assert "--duration" in err
    assert "export ros2 SCENARIO --duration 60" in err
    assert "unrecognized" not in err
