"""What ``amsa-phys adapt`` writes follows the project's rule for outputs.

An output that is one of its inputs (the sweep's ``results.csv`` or ``scenario.yaml``, the
``--scenario`` file) is refused even with ``--force``: writing it would lose the sweep.
``--results`` replaces an existing file only with ``--force``, as ``-o`` does.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from refusal import assert_one_line_refusal
from sweepfiles import two_context_sweep

from amsa_phys.cli.main import main

TABLE = {("healthy", 0.2): 0.5, ("healthy", 0.35): 0.9, ("worn", 0.2): 0.9, ("worn", 0.35): 0.5}


def _sweep(tmp_path: Path) -> tuple[Path, Path]:
    return two_context_sweep(tmp_path, TABLE)


@pytest.mark.parametrize("name", ["results.csv", "sweep.yaml"])
def test_an_output_that_is_an_input_is_refused_even_with_force(
    tmp_path: Path, capsys, name: str
) -> None:
    scenario, sweep = _sweep(tmp_path)
    target = sweep / name if name == "results.csv" else scenario
    before = target.read_bytes()
    argv = ["adapt", str(sweep), "--scenario", str(scenario), "-o", str(target), "--force"]
    code = main([*argv, "--margin", "inf", "--min-gain", "0"])
    assert_one_line_refusal(code, capsys.readouterr().err, "is an input of this command", "error:")
    assert target.read_bytes() == before
    # the sweep still reads: adapt on it again writes its rules
    argv = ["adapt", str(sweep), "--scenario", str(scenario), "-o", str(tmp_path / "r.yaml")]
    assert main([*argv, "--margin", "inf", "--min-gain", "0"]) == 0


def test_the_world_of_the_scenario_given_is_an_input_too(tmp_path: Path, capsys) -> None:
    """``--scenario S.yaml``: the world file S names is read too, so ``-o`` naming it is
    refused even with ``--force`` (only S itself was protected)."""
    scenario, sweep = _sweep(tmp_path)
    doc = yaml.safe_load(scenario.read_text())
    world = tmp_path / "world.yaml"
    world.write_bytes(Path(doc["world"]).read_bytes())
    doc["world"] = str(world)
    scenario.write_text(yaml.safe_dump(doc))
    before = world.read_bytes()
    argv = ["adapt", str(sweep), "--scenario", str(scenario), "-o", str(world), "--force"]
    code = main([*argv, "--margin", "inf", "--min-gain", "0"])
    assert_one_line_refusal(code, capsys.readouterr().err, "is an input of this command", "error:")
    assert world.read_bytes() == before


def test_the_recorded_scenario_is_an_input_too(tmp_path: Path, capsys) -> None:
    scenario, sweep = _sweep(tmp_path)
    recorded = sweep / "scenario.yaml"
    recorded.write_bytes(scenario.read_bytes())
    argv = ["adapt", str(sweep), "-o", str(recorded), "--force"]
    assert_one_line_refusal(main(argv), capsys.readouterr().err, "is an input", "error:")
    assert recorded.read_bytes() == scenario.read_bytes()


def test_results_replaces_an_existing_file_only_with_force(tmp_path: Path, capsys) -> None:
    scenario, sweep = _sweep(tmp_path)
    kept = tmp_path / "prec.json"
    kept.write_text('{"mine": true}\n')
    argv = ["adapt", str(sweep), "--scenario", str(scenario), "-o", str(tmp_path / "r.yaml")]
    argv += ["--validate", "--sequences", "1", "--seeds", "1", "--duration", "60"]
    code = main([*argv, "--results", str(kept)])
    assert_one_line_refusal(code, capsys.readouterr().err, "use --force", "error:")
    assert kept.read_text() == '{"mine": true}\n'
    assert not (tmp_path / "r.yaml").exists()  # refused before any work


def test_results_and_rules_cannot_be_one_file(tmp_path: Path, capsys) -> None:
    scenario, sweep = _sweep(tmp_path)
    rules = tmp_path / "r.yaml"
    argv = ["adapt", str(sweep), "--scenario", str(scenario), "-o", str(rules), "--force"]
    argv += ["--validate", "--sequences", "1", "--seeds", "1", "--duration", "60"]
    code = main([*argv, "--results", str(rules)])
    assert_one_line_refusal(code, capsys.readouterr().err, "names the rules file", "error:")
    assert not rules.exists()
