"""The manual builds without a warning, and its CLI reference is the parsers' own."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

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


@pytest.mark.docs
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


def _assets_command() -> Any:
    """The docs' own script (``docs/make_assets.py``), loaded by its path."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_assets", ROOT / "docs" / "make_assets.py")
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_picture_is_shown_and_made_by_the_assets_command() -> None:
    """Each picture in assets/ has a recipe in docs/make_assets.py, and each is shown by the
    README or a page of the manual (no stale picture, no picture without its command)."""
    recipes = set(_assets_command().RECIPES)
    on_disk = {p.name for p in (ROOT / "assets").glob("*.png")}
    pages = [ROOT / "README.md", *(ROOT / "docs").rglob("*.md")]
    shown = {m for p in pages for m in re.findall(r"\]\(assets/([\w.-]+\.png)\)", p.read_text())}
    assert on_disk == recipes, (
        f"pictures without a recipe or recipes without a picture: {on_disk ^ recipes}"
    )
    assert shown == recipes, f"shown but not made, or made but not shown: {shown ^ recipes}"


@pytest.mark.docs
def test_the_assets_command_lists_and_makes_a_picture(tmp_path: Path) -> None:
    script = [sys.executable, str(ROOT / "docs" / "make_assets.py")]
    listed = subprocess.run([*script, "--list"], capture_output=True, text=True, check=True)
    lines = listed.stdout.splitlines()
    assert len(lines) == len(_assets_command().RECIPES)
    assert (
        "mde_architecture.png: amsa-phys graph worlds/mde_challenge.yaml"
        " -o assets/mde_architecture.png" in lines
    )
    done = subprocess.run(
        [*script, "mde_architecture.png", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    made = (tmp_path / "mde_architecture.png").read_bytes()
    assert made.startswith(b"\x89PNG\r\n\x1a\n")
    assert (
        made == (ROOT / "assets" / "mde_architecture.png").read_bytes()
    )  # the recipe is the shipped picture's
    assert [p.name for p in tmp_path.iterdir()] == ["mde_architecture.png"]  # nothing staged left
    bad = subprocess.run([*script, "nope.png"], capture_output=True, text=True, check=False)
    assert bad.returncode == 2
    assert "unknown picture nope.png" in bad.stderr


def _manual_text() -> list[str]:
    """The hand-written documentation, line by line: README and docs/ but the generated CLI
    reference (which lists everything by construction). The drafts of docs/_incoming/ count:
    a branch documents its keys there until the lead folds them into their page."""
    pages = [ROOT / "README.md", *(ROOT / "docs").rglob("*.md")]
    keep = [p for p in pages if p.name != "cli.md"]
    return [line for p in keep for line in p.read_text().splitlines()]


def _schema_keys(node: Any, out: set[str]) -> set[str]:
    if isinstance(node, dict):
        for key, value in node.items():
            if key == "properties":
                out.update(value)
            _schema_keys(value, out)
    elif isinstance(node, list):
        for value in node:
            _schema_keys(value, out)
    return out


def test_every_yaml_key_is_documented_in_the_manual() -> None:
    """Every key a world or a scenario may hold is written in code style somewhere in the
    README or the manual (its table: docs/scenarios.md), so a new key cannot land undocumented."""
    from amsa_phys.model import schema

    keys = _schema_keys(schema.WORLD, set()) | _schema_keys(schema.SCENARIO, set())
    assert {"physics", "timeline", "trace_columns", "free_running", "new_phase"} <= keys
    code = " ".join(c for line in _manual_text() for c in re.findall(r"`([^`]+)`", line))
    missing = sorted(k for k in keys if not re.search(rf"(?<!\w){re.escape(k)}(?!\w)", code))
    assert not missing, f"YAML keys the manual never names: {missing}"


def test_every_command_and_option_is_documented_in_the_manual() -> None:
    """Every subcommand appears as `amsa-phys NAME` and every option (by one of its spellings)
    in the hand-written pages, not only in the generated reference."""
    import argparse

    from amsa_phys.cli.main import build_parser

    text = "\n".join(_manual_text())
    missing = []

    def walk(parser: argparse.ArgumentParser, prefix: str) -> None:
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    if f"{prefix} {name}" not in text:
                        missing.append(f"{prefix} {name}")
                    walk(sub, f"{prefix} {name}")
            elif action.option_strings and action.dest not in ("help",):
                spelt = [
                    o for o in action.option_strings if re.search(rf"{re.escape(o)}(?![\w-])", text)
                ]
                if not spelt:
                    missing.append(f"{prefix} {'/'.join(action.option_strings)}")

    walk(build_parser(), "amsa-phys")
    assert len(missing) < 1, f"commands or options the manual never names: {missing}"
