"""The manual builds without a warning, and its CLI reference is the parsers' own."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

from amsa_phys.cli import reference

ROOT = Path(__file__).resolve().parents[2]


def test_cli_reference_is_up_to_date() -> None:
    page = ROOT / "docs" / "reference" / "cli.md"
    assert page.read_text() == reference.render(), (
        "docs/reference/cli.md is out of date: python -m amsa_phys.cli.reference "
        "docs/reference/cli.md"
    )


def test_cli_reference_lists_every_command_and_option() -> None:
    text = reference.render()
    assert "### `amsa-phys sweep`" in text
    assert "| `--executor {batch,local,dask}` |" in text
    assert "#### `amsa-phys export ros`" in text  # a command's own subcommands too
    assert "| `--debug` |" in text.split("### ")[0]  # once, at the top
    assert "| `--debug` |" not in text.split("### `amsa-phys run`")[1]


def test_the_manual_builds_strictly(tmp_path: Path) -> None:
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d", str(tmp_path / "site")],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    api = (tmp_path / "site" / "reference" / "api" / "index.html").read_text()
    assert "do_step" in api  # mkdocstrings read the Template's docstrings
    # the docstrings' Sphinx roles are links, not ":class:" printed before the name
    assert not re.search(r":(meth|func|class|attr|data):<code>", api)
    assert '<a href="#amsa_phys.errors.ConfigError"><code>ConfigError</code></a>' in api
    assert (tmp_path / "site" / "assets" / "paper_fig5.png").is_file()
    assert not (tmp_path / "site" / "hooks.py").exists()


def test_every_object_the_api_page_documents_is_a_name_of_ap() -> None:
    """The page says `import amsa_phys as ap` gives every name on it (headings show the short
    name): each ``::: module.Name`` but the received InitContext and the errors module."""
    import amsa_phys as ap

    page = (ROOT / "docs" / "reference" / "api.md").read_text()
    names = re.findall(r"^::: ([\w.]+)$", page, flags=re.M)
    assert "amsa_phys.api.result.run" in names
    short = [n.rpartition(".")[2] for n in names if n != "amsa_phys.errors"]
    missing = [n for n in short if n != "InitContext" and not hasattr(ap, n)]
    assert not missing, f"not importable as ap.NAME: {missing}"
