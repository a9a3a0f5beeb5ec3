"""The data-only reader of a run directory (``runs/rundata.py``) gives the plots and the
replay the same world the scenario loader builds, for the shipped worlds: same leaves,
parameters, absolute inputs, frequencies, buffers in world order (so the same colours) and
the same plot context. Only what is not built in is left out."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario
from amsa_phys.runs.plotjob import plot_context
from amsa_phys.runs.rundata import read_run

ROOT = Path(__file__).resolve().parent.parent.parent


@pytest.mark.parametrize("name", ["scenario2.yaml", "obstacle_course.yaml", "platoon.yaml"])
def test_the_data_reader_sees_the_loaders_world(tmp_path: Path, name: str) -> None:
    out = tmp_path / "run"
    argv = ["run", str(ROOT / "scenarios" / name), "--headless", "-q", "--no-plot"]
    assert main([*argv, "--duration", "1", "--out", str(out)]) == 0
    notes: list[str] = []
    run = read_run(out, warn=notes.append)
    loaded = load_scenario(out / "scenario.yaml").world
    assert notes == []
    assert run.world is not None
    assert list(run.world.leaves) == list(loaded.leaves)
    for path, leaf in loaded.leaves.items():
        ours = run.world.leaves[path]
        assert ours.template.name() == leaf.template.name(), path
        assert ours.params == dict(leaf.params), path
        assert ours.inputs == dict(leaf.inputs), path
        assert ours.freq == leaf.freq, path
        assert ours.kind == leaf.kind, path
    traced = set((out / "trace.csv").read_text().split("\n", 1)[0].split(","))
    assert [b for b in run.world.buffers if "[" not in b] == [
        b for b in loaded.buffers if "[" not in b
    ]
    assert {b for b in run.world.buffers if "[" in b} == {
        b for b in loaded.buffers if "[" in b and b in traced
    }
    assert run.world.physics == loaded.physics
    assert plot_context(run.world) == plot_context(loaded)  # type: ignore[arg-type]
