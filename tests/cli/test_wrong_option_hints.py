"""Two mistakes a new user makes, each answered with what to do instead.

A scenario given where a world is expected said "world: unknown key" (the reverse case
already explained itself); ``--grid Ctrl.Kv=0.1:0.3`` said "expected a number" with no hint
that ranges are ``--range``'s.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "amsa_phys", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_a_scenario_named_as_a_world_says_so(tmp_path: Path) -> None:
    scenario = tmp_path / "s.yaml"
    scenario.write_text(f"world: {ROOT}/scenarios/scenario1.yaml\nduration: 10\n")
    done = _cli("run", str(scenario), "--headless", "--out", "r", cwd=tmp_path)
    assert done.returncode == 2
    (line,) = done.stderr.strip().splitlines()
    assert "scenario1.yaml:4: world: this is a scenario file" in line
    assert "'../worlds/mde_challenge.yaml'" in line  # the world it names: what to give instead


def test_a_range_given_to_grid_points_to_range(tmp_path: Path) -> None:
    done = _cli(
        "sweep",
        str(ROOT / "scenarios" / "scenario1.yaml"),
        "--grid",
        "MyFollowerController.Kv=0.1:0.3",
        "--out",
        "sw",
        cwd=tmp_path,
    )
    assert done.returncode == 2
    (line,) = done.stderr.strip().splitlines()
    assert "expected a number" in line
    assert "--range MyFollowerController.Kv=0.1:0.3:5" in line
    assert not (tmp_path / "sw").exists()


def test_a_word_given_to_grid_gets_no_range_hint(tmp_path: Path) -> None:
    done = _cli(
        "sweep",
        str(ROOT / "scenarios" / "scenario1.yaml"),
        "--grid",
        "MyFollowerController.Kv=0.1,abc",
        "--out",
        "sw",
        cwd=tmp_path,
    )
    assert done.returncode == 2
    assert "--range" not in done.stderr
