"""A file another file names is read only where it should be, and never shown.

``import`` reads the template file the model names only next to the model (a plain name, no
directory part, no link out of the folder), and a template file that does not parse is
described, not quoted: a model naming ``/etc/passwd`` had its first word printed. A
scenario's ``world:`` or ``adapt:`` may name any YAML file: its shape errors name its keys
and the kind of a wrong value, never the value.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
SECRET = "hunter2SecretPassword"
TEMPLATES = "mdeChallenge.amsatemplate"


@pytest.fixture
def exported(tmp_path: Path) -> Path:
    """``export amsa`` of the MDE world, in ``tmp_path / "am"``."""
    out = tmp_path / "am"
    assert main(["export", "amsa", str(WORLD), "-o", str(out)]) == 0
    return out


def _model_naming(folder: Path, href: str) -> Path:
    """A copy of the exported model whose templates are ``href``."""
    text = (folder / "mdeChallenge.amsacore").read_text()
    assert f"{TEMPLATES}#" in text
    model = folder / "t.amsacore"
    model.write_text(text.replace(f"{TEMPLATES}#", f"{href}#"))
    return model


def _import(model: Path, capsys: pytest.CaptureFixture[str]) -> str:
    capsys.readouterr()
    out = model.parent / "t.yaml"
    assert main(["import", str(model), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert not out.exists()
    return err


@pytest.mark.parametrize("where", ["absolute", "parent", "subfolder"])
def test_a_template_file_away_from_the_model_is_not_read(
    tmp_path: Path, exported: Path, capsys: pytest.CaptureFixture[str], where: str
) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text(f"{SECRET}\n")
    (exported / "sub").mkdir()
    (exported / "sub" / "secret.txt").write_text(f"{SECRET}\n")
    href = {"absolute": str(secret), "parent": "../secret.txt", "subfolder": "sub/secret.txt"}
    err = _import(_model_naming(exported, href[where]), capsys)
    assert "outside its folder" in err
    assert SECRET not in err


def test_a_link_out_of_the_folder_is_not_read(
    tmp_path: Path, exported: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text(f"{SECRET}\n")
    (exported / "link.amsatemplate").symlink_to(secret)
    err = _import(_model_naming(exported, "link.amsatemplate"), capsys)
    assert "outside its folder" in err
    assert SECRET not in err


def test_a_link_within_the_folder_is_read(
    exported: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (exported / "link.amsatemplate").symlink_to(exported / TEMPLATES)
    model = _model_naming(exported, "link.amsatemplate")
    assert main(["import", str(model), "-o", str(exported / "t.yaml")]) == 0


@pytest.mark.parametrize(
    ("text", "words"),
    [
        (f"{SECRET}\n", "t.amsatemplate:1: expected 'Template', found a name"),
        (f"Template A {{ {SECRET} }}\n", "t.amsatemplate:1: expected '}', found a name"),
        (f'Template A {{ "{SECRET}" }}\n', "t.amsatemplate:1: expected '}', found a string"),
        (f"Template A {{\n{SECRET}@\n", "t.amsatemplate:2: column 22: a character"),
        (
            f'Template A {{ parameter {{ int x = {{ "{SECRET}"',
            "t.amsatemplate:1: expected a value, found '{'",
        ),
        ("Template A {", "t.amsatemplate:1: expected '}', found the end of the file"),
    ],
)
def test_a_template_file_that_does_not_parse_is_described_not_quoted(
    exported: Path, capsys: pytest.CaptureFixture[str], text: str, words: str
) -> None:
    (exported / "t.amsatemplate").write_text(text)
    err = _import(_model_naming(exported, "t.amsatemplate"), capsys)
    assert words in err
    assert SECRET not in err


@pytest.mark.parametrize(
    "body",
    [
        f"name: {SECRET}\ncomponents: {SECRET}\n",
        f"name: [{SECRET}]\ncomponents: {{}}\n",
        f"name: n\ncomponents: {{A: {SECRET}}}\n",
        f"name: n\ncomponents: {{A: {{template: freeRobot, freq: {SECRET}}}}}\n",
        f"name: n\ncomponents: {{A: {{template: freeRobot, freq: -1{SECRET.count('x')}}}}}\n",
        f"name: n\ncomponents: {{}}\nphysics: {{rate: 1e-{len(SECRET)}}}\n",
    ],
)
def test_a_world_a_scenario_names_is_not_quoted(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], body: str
) -> None:
    (tmp_path / "w.yaml").write_text(body)
    scenario = tmp_path / "s.yaml"
    scenario.write_text("world: w.yaml\nduration: 10\n")
    assert main(["validate", str(scenario)]) == 2
    err = capsys.readouterr().err
    assert "w.yaml:" in err
    assert SECRET not in err
    assert f"1e-{len(SECRET)}" not in err
    assert "-10" not in err


def test_an_adapt_file_a_scenario_names_is_not_quoted(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "r.yaml").write_text(f"adapt: {SECRET}\n")
    scenario = tmp_path / "s.yaml"
    scenario.write_text(f"world: {WORLD}\nduration: 10\nadapt: r.yaml\n")
    assert main(["validate", str(scenario)]) == 2
    err = capsys.readouterr().err
    assert "r.yaml:1: adapt: expected" in err
    assert SECRET not in err
