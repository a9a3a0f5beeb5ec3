"""``metrics.json`` records which code made the run: the version and the physics step.

Two runs that disagree are first asked "same amsa-phys, same physics step?": the compiled
step and the pure-Python one are built to agree bit for bit, but which one ran depends on
the install (a C compiler), ``AMSA_PHYS_PURE`` and pymunk, none of which is in the scenario.
"""

from __future__ import annotations

import json
from importlib.metadata import version
from pathlib import Path

import pytest

import amsa_phys as ap
from amsa_phys.cli.main import main
from amsa_phys.physics.step_path import PURE_ENV, describe

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO2 = ROOT / "scenarios" / "scenario2.yaml"  # the MDE world: physics at 100 Hz


def test_cli_run_records_the_version_and_the_compiled_step(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv(PURE_ENV, raising=False)
    out = tmp_path / "run"
    argv = ["run", str(SCENARIO2), "--headless", "-q", "--no-plot", "--duration", "5"]
    assert main([*argv, "--out", str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["amsa_phys_version"] == ap.__version__ == version("amsa-phys")
    compiled, why = describe()  # what `amsa-phys --version` says this install runs
    physics = metrics["physics"]
    assert physics["rate_hz"] == 100  # the world's physics.rate
    assert physics["dt_s"] == 0.01
    assert physics["steps"] == 500  # 5 s at 100 Hz
    assert physics["step"] == why
    if compiled:
        assert (physics["step"], physics["force_model"]) == ("compiled (C)", "CompiledFewRovers")
    # rovers at 0.5 m long are cut into sub-steps only past 30 m/s (none in this run)
    assert physics["substep_speed_m_s"] == 30.0


def test_the_pure_python_step_is_recorded_with_why(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(PURE_ENV, "1")
    pure = ap.run(SCENARIO2, duration=5)
    assert pure.metrics["physics"]["step"] == f"pure Python ({PURE_ENV} is set)"
    assert pure.metrics["physics"]["force_model"] == "FewRovers"
    monkeypatch.delenv(PURE_ENV)
    other = ap.run(SCENARIO2, duration=5)
    assert other.metrics["physics"]["step"] == describe()[1]
    assert other.trace.tobytes() == pure.trace.tobytes()  # the record, not the result, differs


def test_a_world_without_physics_records_none(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(ROOT / "tests"))
    world = {"components": {"K": {"template": "toys:Source", "freq": 4}}}
    run = ap.run({"world": world, "duration": 1, "quality": {"signal": "K.count", "reference": 0}})
    assert run.metrics["amsa_phys_version"] == ap.__version__
    assert run.metrics["physics"] is None
