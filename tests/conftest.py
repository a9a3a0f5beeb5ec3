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

# the markers of slow kinds and the CPU budget of the quick tier (tests/tiers.py); SIGINT at
# its default for tests that interrupt (tests/sigint.py); the session's catkin builds in the
# background (tests/ros_prebuild.py)
pytest_plugins = ["tiers", "sigint", "pytester", "ros_prebuild"]

#: the distributions whose ``amsa_phys.templates`` entry points a test may see: the project
#: and the plugin tests/model/test_plugins.py installs. A user's plugin installed in the same
#: environment must not change what a test sees (a "did you mean" naming it)
OWN_DISTRIBUTIONS = frozenset({"amsa-phys", "amsa-phys-tiny-rovers-test"})


@pytest.fixture(autouse=True)
def _no_foreign_plugins(monkeypatch: pytest.MonkeyPatch) -> None:
    """Template plugins of other installed packages are invisible to the tests (in-process)."""
    from amsa_phys.model import plugins

    real = plugins.installed

    def own() -> dict[str, list[plugins.Plugin]]:
        found = {
            name: [p for p in registered if p.distribution in OWN_DISTRIBUTIONS]
            for name, registered in real().items()
        }
        return {name: registered for name, registered in found.items() if registered}

    monkeypatch.setattr(plugins, "installed", own)


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
    """Skip ``@pytest.mark.slow`` tests unless asked for (``--runslow``, AMSA_RUNSLOW=1).

    Which tests share a worker under ``pytest -n 2 --dist loadgroup`` is tests/tiers.py's.
    """
    if config.getoption("--runslow") or os.environ.get("AMSA_RUNSLOW") == "1":
        return
    skip = pytest.mark.skip(reason="slow: run with --runslow or AMSA_RUNSLOW=1")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)
