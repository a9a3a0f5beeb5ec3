"""Headless everywhere. The toy templates in tests/toys.py are importable as ``toys`` (and
the golden helpers as ``regenerate``) through pytest's ``pythonpath`` setting in
pyproject.toml, not through sys.path edits here."""

import os
from collections.abc import Iterator
from pathlib import Path

import pytest

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("MPLBACKEND", "Agg")

ROOT = Path(__file__).resolve().parent.parent

# broken and deliberately failing scenario files are inputs of tests, not tests themselves
collect_ignore_glob = ["fixtures/*", "golden/*.yaml"]


@pytest.fixture(autouse=True)
def _no_leftover_long_runs() -> Iterator[None]:
    """A test that fails mid-way must not leave its 100 000 s run burning a core."""
    yield
    from longrun import stop_leftovers

    stop_leftovers()


def pytest_addoption(parser: pytest.Parser) -> None:
    """``--runslow``: also run the tests marked slow (or set AMSA_RUNSLOW=1)."""
    parser.addoption("--runslow", action="store_true", help="run tests marked slow")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Skip ``@pytest.mark.slow`` tests unless asked for."""
    if config.getoption("--runslow") or os.environ.get("AMSA_RUNSLOW") == "1":
        return
    skip = pytest.mark.skip(reason="slow: run with --runslow or AMSA_RUNSLOW=1")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
