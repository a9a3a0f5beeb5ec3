"""``import -o WORLD.yaml`` follows the output-file rule (``runs/outfile.py``) and its writer.

The world was written under ``.NAME.tmp-PID`` with a plain ``open``: a link planted at that
guessable name was written through (a file outside the output's folder replaced by the
world) and then renamed into place as ``WORLD.yaml``. The template file a model names was
not counted as an input, so ``-o`` naming it with ``--force`` replaced what had been read.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
import yaml

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The MDE challenge as AMSA files (``mdeChallenge.amsacore`` and ``.amsatemplate``)."""
    out = tmp_path_factory.mktemp("amsa") / "files"
    assert main(["export", "amsa", str(WORLD), "-o", str(out)]) == 0
    return out


def test_a_link_planted_at_a_temporary_name_is_not_written_through(
    exported: Path, tmp_path: Path
) -> None:
    """Links at every name the writer could choose (this process's ``.w.yaml.tmp-PID``, the
    writer's ``w.yaml.tmp``): the victim outside keeps its text, the world is a real file."""
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    for name in (f".w.yaml.tmp-{os.getpid()}", "w.yaml.tmp"):
        (out_dir / name).symlink_to(victim)
    assert (
        main(["import", str(exported / "mdeChallenge.amsacore"), "-o", str(out_dir / "w.yaml")])
        == 0
    )
    assert victim.read_text() == "precious\n"
    assert not (out_dir / "w.yaml").is_symlink()
    assert "components:" in (out_dir / "w.yaml").read_text()


def test_the_template_file_the_model_names_is_an_input(
    exported: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``-o`` naming the model's sibling template file is refused, even with ``--force``."""
    model = exported / "mdeChallenge.amsacore"
    templates = exported / "mdeChallenge.amsatemplate"
    before = templates.read_bytes()
    code = main(["import", str(model), "-o", str(templates), "--force"])
    assert code == 2
    err = capsys.readouterr().err
    assert "is an input of this command" in err
    assert err.count("\n") == 1
    assert templates.read_bytes() == before


def test_a_model_file_name_reaches_the_world_only_as_a_comment(
    exported: Path, tmp_path: Path
) -> None:
    """The model's file name is in the world's first comment: a name holding a newline and
    ``name: pwned`` wrote YAML into the world (YAML of the file name's own)."""

    model = tmp_path / "m\nname: pwned\n#\u2028x: 1\n.amsacore"
    model.write_bytes((exported / "mdeChallenge.amsacore").read_bytes())
    (tmp_path / "mdeChallenge.amsatemplate").write_bytes(
        (exported / "mdeChallenge.amsatemplate").read_bytes()
    )
    out = tmp_path / "w.yaml"
    assert main(["import", str(model), "-o", str(out)]) == 0
    text = out.read_text()
    assert yaml.safe_load(text)["name"] == "mdeChallenge"
    assert "x" not in yaml.safe_load(text)
    assert text.splitlines()[1].startswith("# m\\nname: pwned\\n#\\u2028x: 1\\n.amsacore")
