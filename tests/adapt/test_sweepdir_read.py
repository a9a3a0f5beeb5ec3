"""A sweep directory's recorded scenario read back by ``adapt``: a hand edit is refused with
its line and key (as ``validate`` refuses a scenario), a template that is not built in is
named where it is written, and nothing is imported."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.adapt.sweepdir import read_sweep_scenario, write_sweep_scenario
from amsa_phys.errors import ConfigError
from amsa_phys.model.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def sweepdir(tmp_path: Path) -> Path:
    scenario = load_scenario(ROOT / "scenarios" / "scenario1.yaml")
    write_sweep_scenario(tmp_path, scenario, {"grid": {"MyFollowerController.Kv": [0.1, 0.2]}})
    return tmp_path


def _line_of(path: Path, text: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if text in line)


def test_the_recorded_scenario_reads_back(sweepdir: Path) -> None:
    assert read_sweep_scenario(sweepdir).world.leaves["MyFollowerController"]


def test_a_misspelt_key_is_named_with_its_line(sweepdir: Path) -> None:
    path = sweepdir / "scenario.yaml"
    path.write_text(path.read_text().replace("\nworld:\n", "\nwrold:\n", 1))
    with pytest.raises(ConfigError) as caught:
        read_sweep_scenario(sweepdir)
    line = _line_of(path, "wrold:")
    assert str(caught.value) == f"{path}:{line}: wrold: unknown key (did you mean world?)"


def test_a_world_named_not_inlined_is_refused_at_its_key(sweepdir: Path) -> None:
    path = sweepdir / "scenario.yaml"
    data = path.read_text()
    head, _, rest = data.partition("\nworld:\n")
    body = rest.split("\nduration:", 1)[1]
    path.write_text(f"{head}\nworld: ../worlds/mde_challenge.yaml\nduration:{body}")
    with pytest.raises(ConfigError) as caught:
        read_sweep_scenario(sweepdir)
    line = _line_of(path, "world: ../worlds")
    assert str(caught.value) == (
        f"{path}:{line}: world: not a sweep's scenario: the world is not inlined"
    )


def test_a_template_not_built_in_is_named_where_it_is_written(sweepdir: Path) -> None:
    path = sweepdir / "scenario.yaml"
    text = path.read_text()
    assert "template: FollowerController" in text
    path.write_text(text.replace("template: FollowerController", "template: evil:Mod", 1))
    with pytest.raises(ConfigError) as caught:
        read_sweep_scenario(sweepdir)
    line = _line_of(path, "template: evil:Mod")
    assert str(caught.value).startswith(
        f"{path}:{line}: world.components.MyFollowerController.template: component "
        "MyFollowerController names template 'evil:Mod', not built in; not imported"
    )


def test_a_falsify_directory_is_named_for_what_it_is(tmp_path: Path) -> None:
    (tmp_path / "falsify.json").write_text("{}\n")
    with pytest.raises(ConfigError) as caught:
        read_sweep_scenario(tmp_path)
    assert "a falsify directory, not a sweep's" in str(caught.value)


def test_duration_without_validate_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``adapt DIR --duration S`` without ``--validate`` was silently ignored."""
    from amsa_phys.cli.main import main

    (tmp_path / "results.csv").write_text("run\n")
    assert main(["adapt", str(tmp_path), "-o", str(tmp_path / "r.yaml"), "--duration", "100"]) == 2
    assert capsys.readouterr().err.startswith(
        "error: --duration: sets the length of --validate's held-out sequences: give --validate"
    )
