"""pytest plugin: scenario files with ``expect:`` become test items.

Installed with amsa-phys (entry point ``pytest11``), so ``pytest scenarios/`` in a user's
project runs each scenario and reports its failed checks. Only YAML files with a top-level
``expect:`` key are collected; a project that keeps broken YAML fixtures under its test paths
should list them in ``collect_ignore_glob`` (as this project's tests/conftest.py does).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from .suite import has_expectations, in_run_directory, run_scenario_file


class ScenarioFailed(Exception):
    """A scenario's checks failed or it could not run."""


def pytest_collect_file(parent: pytest.Collector, file_path: Path) -> pytest.File | None:
    """Collect ``*.yaml`` / ``*.yml`` scenario files that declare expectations."""
    if (
        file_path.suffix in (".yaml", ".yml")
        and has_expectations(file_path)
        and not in_run_directory(file_path)  # a run's resolved scenario, not a test
    ):
        return ScenarioFile.from_parent(parent, path=file_path)
    return None


class ScenarioFile(pytest.File):
    """A scenario file: one test item."""

    def collect(self) -> Iterator[pytest.Item]:
        """The scenario as a single item."""
        yield ScenarioItem.from_parent(self, name=self.path.stem)


class ScenarioItem(pytest.Item):
    """Runs the scenario and fails with the failed checks."""

    def runtest(self) -> None:
        """Run it."""
        result = run_scenario_file(str(self.path))
        if result.error is not None:
            raise ScenarioFailed(f"{self.path}: {result.error}")
        failed = [c.describe() for c in result.checks if not c.passed]
        if failed:
            raise ScenarioFailed("\n".join(failed))

    def repr_failure(self, excinfo: Any, style: Any = None) -> str:
        """Just the failed checks, no traceback."""
        if isinstance(excinfo.value, ScenarioFailed):
            return str(excinfo.value)
        return str(super().repr_failure(excinfo))

    def reportinfo(self) -> tuple[Path, int, str]:
        """Where the item comes from."""
        return self.path, 0, f"scenario {self.name}"
