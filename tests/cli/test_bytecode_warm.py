"""Under PYTHONDONTWRITEBYTECODE=1 an ``amsa-phys`` command leaves the ``.pyc`` of the
modules it imported, so the next command imports them compiled (``amsa_phys/bytecode.py``).

Each process here gets an empty cache of its own (``PYTHONPYCACHEPREFIX``), so the test
neither depends on nor changes the package's own ``__pycache__``.
"""

from __future__ import annotations

import os
import py_compile
import subprocess
import sys
from pathlib import Path

import pytest

from amsa_phys import bytecode

ROOT = Path(__file__).resolve().parent.parent.parent
PKG = ROOT / "amsa_phys"
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"


def command(tmp: Path, cache: Path, **env: str) -> subprocess.CompletedProcess[str]:
    """A short headless run, as a user starts it (``python -m amsa_phys``), verbose imports."""
    argv = [sys.executable, "-v", "-m", "amsa_phys", "run", str(SCENARIO1), "--headless"]
    argv += ["--no-plot", "-q", "--duration", "1", "--out", str(tmp / "run"), "--force"]
    full = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "PYTHONPYCACHEPREFIX": str(cache)}
    full.pop(bytecode.OPT_OUT, None)
    full.update(env)
    done = subprocess.run(argv, env=full, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return done


def package_pycs(cache: Path) -> list[Path]:
    return list((cache / PKG.relative_to(PKG.anchor)).rglob("*.pyc"))


def compiled_from_cache(stderr: str) -> set[str]:
    """The package's modules a ``python -v`` process loaded from a ``.pyc``."""
    prefix = "# code object from "
    return {
        line
        for line in stderr.splitlines()
        if line.startswith(prefix) and "/amsa_phys/" in line and line.endswith(".pyc'")
    }


def test_a_command_leaves_the_bytecode_the_next_one_imports(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    first = command(tmp_path, cache)
    assert not compiled_from_cache(first.stderr)  # nothing to read yet: all from source
    written = package_pycs(cache)
    assert len(written) > 50  # the run imports most of the engine, physics and model
    second = command(tmp_path, cache)
    loaded = compiled_from_cache(second.stderr)
    # every module of the package the second run imported came from the bytecode
    assert len(loaded) == len(written)


def test_the_opt_out_writes_nothing(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    command(tmp_path, cache, **{bytecode.OPT_OUT: "1"})
    assert package_pycs(cache) == []


def test_where_python_writes_bytecode_itself_the_package_does_not(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    monkeypatch.delenv(bytecode.OPT_OUT, raising=False)
    assert not bytecode.wanted()
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    assert bytecode.wanted() == (PKG.stat().st_uid == os.getuid())


def test_an_edited_source_makes_its_bytecode_stale(tmp_path: Path) -> None:
    source = tmp_path / "mod.py"
    source.write_text("x = 1\n")
    cache = tmp_path / "mod.pyc"
    py_compile.compile(str(source), cfile=str(cache), doraise=True)
    assert bytecode._fresh(str(source), str(cache))
    source.write_text("x = 22\n")  # another size (and maybe the same second)
    assert not bytecode._fresh(str(source), str(cache))
    os.utime(source, (1_000_000, 1_000_000))  # same size, another mtime
    py_compile.compile(str(source), cfile=str(cache), doraise=True)
    os.utime(source, (2_000_000, 2_000_000))
    assert not bytecode._fresh(str(source), str(cache))
    assert not bytecode._fresh(str(source), str(tmp_path / "missing.pyc"))
