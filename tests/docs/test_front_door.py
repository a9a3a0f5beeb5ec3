"""The README's first examples show the normal case: no warning, every check evaluated.

A new user copies the first command and the first Python snippet. A command that prints a
warning, or a snippet that prints ``checks passed: True`` with every check skipped (a run too
short for the phases its checks judge), teaches them that warnings and skips are normal.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()
FENCE = re.compile(r"^```(\w+)\n(.*?)^```$", re.M | re.S)


def _first_blocks() -> tuple[str, str]:
    """(first console command, first python block) of the README's "Four ways in"."""
    section = README.split("## Four ways in", 1)[1]
    blocks = FENCE.findall(section)
    console = next(body for lang, body in blocks if lang == "console")
    python = next(body for lang, body in blocks if lang == "python")
    first = next(line[2:] for line in console.splitlines() if line.startswith("$ "))
    return first, python


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    for tree in ("scenarios", "worlds"):
        shutil.copytree(ROOT / tree, tmp_path / tree)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_the_first_command_runs_clean(work: Path) -> None:
    command, _ = _first_blocks()
    argv = shlex.split(command)
    assert argv[0] == "amsa-phys"
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    done = subprocess.run(
        [sys.executable, "-m", "amsa_phys", *argv[1:]],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    assert "warning" not in out.lower(), out
    assert "FAIL" not in out, out
    assert "skipped" not in out, out


def test_the_first_python_example_evaluates_its_checks(work: Path) -> None:
    _, code = _first_blocks()
    namespace: dict[str, object] = {}
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        exec(compile(code, "README.md", "exec"), namespace)  # our own README's example
    run = namespace["run"]
    checks = run.checks  # type: ignore[attr-defined]
    assert checks, "the example's scenario has checks"
    assert not [c for c in checks if c.skipped], printed.getvalue()
    assert run.passed  # type: ignore[attr-defined]
