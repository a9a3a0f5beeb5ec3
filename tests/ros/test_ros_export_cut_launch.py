"""``export ros --duration S``, built and launched without arguments: ``run --duration S``.

The scenario has a check of a phase the cut never reaches. The package keeps the whole
scenario (its config validates) and the cut as the launch's ``duration:=`` default; the
launch's run directory is ``run --duration``'s: trace, metrics (the same checks skipped) and
``scenario.yaml``. Needs ROS 1 and catkin (``unshare -n``, ``ros_launch.py``).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest
import ros_launch
import yaml
from ros_launch import Launch, build_workspace, ros_missing

from amsa_phys.cli.main import main

pytestmark = [pytest.mark.ros, pytest.mark.build]
MISSING = ros_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

launcher = ros_launch.launcher  # the fixture
ROOT = Path(__file__).resolve().parent.parent.parent
SHORT = ROOT / "tests" / "fixtures" / "ros_short.yaml"


def test_a_cut_package_launches_as_run_duration(
    tmp_path: Path, launcher: Callable[..., Launch]
) -> None:
    data = yaml.safe_load(SHORT.read_text())
    data["world"] = str((SHORT.parent / data["world"]).resolve())
    data["expect"].append({"metric": "max_distance", "phase": 2, "below": 17})
    scenario = tmp_path / "ros_short.yaml"
    scenario.write_text(yaml.safe_dump(data, sort_keys=False))
    ws = build_workspace(tmp_path / "ws", scenario, "mdeChallenge", export_args=("--duration", "8"))
    config = ws / "src" / "mdeChallenge" / "config" / "ros_short.yaml"
    assert main(["validate", str(config)]) == 0
    out = tmp_path / "cut"
    text = launcher(ws, "ros_short.launch", f"out:={out}", "plots:=false").finish()
    assert "completed, simulated 8 s" in text, text[-3000:]
    ref = tmp_path / "ref"
    argv = ["run", str(scenario), "--headless", "--out", str(ref), "-q", "--no-plot"]
    assert main([*argv, "--duration", "8"]) == 0
    assert (out / "trace.csv").read_bytes() == (ref / "trace.csv").read_bytes()
    got, want = (json.loads((d / "metrics.json").read_text()) for d in (out, ref))
    for key in ("phases", "overall"):
        assert got[key] == want[key], key
    assert (out / "scenario.yaml").read_text() == (ref / "scenario.yaml").read_text()
