"""Templates installed as plugins (the ``amsa_phys.templates`` entry points) are found by
their short name without PYTHONPATH, listed with their origin, and refused when ambiguous."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from amsa_phys.model import plugins
from amsa_phys.model.template import TemplateNotFound, resolve_template

DIST = "amsa-phys-tiny-rovers-test"

PYPROJECT = f"""
[build-system]
requires = ["setuptools>=61"]
build-backend = "setuptools.build_meta"

[project]
name = "{DIST}"
version = "0.0.1"

[tool.setuptools]
py-modules = ["tiny_rovers_plugin"]

[project.entry-points."amsa_phys.templates"]
TinyCounter = "tiny_rovers_plugin:TinyCounter"
"""

MODULE = '''
from amsa_phys import Kind, Param, Port, Template


class TinyCounter(Template):
    """Counts its steps times gain (a plugin's template)."""

    kind = Kind.ENVIRONMENT
    outputs = (Port("count", initial=0.0),)
    params = (Param("gain", "float", "multiplier", 1.0, 0.0, 10.0),)

    def initialize(self, ctx):
        self.n = 0

    def do_step(self, t, inp):
        self.n += 1
        return {"count": self.n * self.p.gain}
'''


def _pip(*args: str) -> None:
    subprocess.run(
        [sys.executable, "-m", "pip", "-q", "--disable-pip-version-check", *args],
        check=True,
        capture_output=True,
    )


@pytest.fixture(scope="module")
def installed_plugin(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """The tiny plugin package pip-installed into this environment (uninstalled after)."""
    src = tmp_path_factory.mktemp("tiny")
    (src / "pyproject.toml").write_text(PYPROJECT)
    (src / "tiny_rovers_plugin.py").write_text(MODULE)
    _pip("install", "--no-deps", str(src))  # built in its own isolated environment
    try:
        yield
    finally:
        _pip("uninstall", "-y", DIST)


def _cli(cwd: Path, *args: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    return subprocess.run(
        [sys.executable, "-m", "amsa_phys", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )


@pytest.mark.build  # pip installs a plugin package
def test_an_installed_plugin_runs_by_its_short_name(installed_plugin: None, tmp_path: Path) -> None:
    scenario = tmp_path / "s.yaml"
    scenario.write_text(
        "world:\n  components:\n"
        "    C: {template: TinyCounter, freq: 2, params: {gain: 3}}\n"
        "duration: 2\n"
    )
    done = _cli(tmp_path, "run", str(scenario), "--headless", "--out", str(tmp_path / "r"), "-q")
    assert done.returncode == 0, done.stderr
    lines = (tmp_path / "r" / "trace.csv").read_text().splitlines()
    assert lines[0] == "t,C.count"
    assert float(lines[-1].split(",")[1]) == 15.0  # 5 steps (t = 0, 0.5, ..., 2) × gain 3
    # the installed module named as module:Class works the same, still without PYTHONPATH
    scenario.write_text(
        scenario.read_text().replace("TinyCounter", "tiny_rovers_plugin:TinyCounter")
    )
    done = _cli(tmp_path, "run", str(scenario), "--headless", "--out", str(tmp_path / "m"), "-q")
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "m" / "trace.csv").read_bytes() == (
        tmp_path / "r" / "trace.csv"
    ).read_bytes()


@pytest.mark.build  # pip installs a plugin package
def test_templates_lists_where_each_template_comes_from(
    installed_plugin: None, tmp_path: Path
) -> None:
    done = _cli(tmp_path, "templates")
    assert done.returncode == 0, done.stderr
    (line,) = [x for x in done.stdout.splitlines() if x.startswith("TinyCounter ")]
    assert line.endswith(f"[plugin tiny_rovers_plugin:TinyCounter from {DIST}]")
    assert "GPS (sensor): " in done.stdout
    gps = next(x for x in done.stdout.splitlines() if x.startswith("GPS ("))
    assert gps.endswith("[built-in]")


@pytest.mark.build  # pip installs a plugin package
def test_a_misspelt_plugin_name_suggests_it(installed_plugin: None, tmp_path: Path) -> None:
    scenario = tmp_path / "s.yaml"
    scenario.write_text("world:\n  components:\n    C: {template: TinyCountr}\nduration: 1\n")
    done = _cli(tmp_path, "validate", str(scenario))
    assert done.returncode == 2
    assert "unknown template 'TinyCountr' (did you mean TinyCounter?)" in done.stderr


def test_a_name_two_packages_register_is_refused_naming_both() -> None:
    two = {
        "Pid": [
            plugins.Plugin("Pid", "a_rovers:Pid", "a-rovers"),
            plugins.Plugin("Pid", "b_rovers:Pid", "b-rovers"),
        ]
    }
    with pytest.raises(LookupError) as caught:
        plugins.target_of("Pid", two)
    assert str(caught.value) == (
        "template name 'Pid' is registered by several installed packages: "
        "a-rovers (a_rovers:Pid), b-rovers (b_rovers:Pid); name one as module:Class"
    )


def test_a_built_in_name_is_never_a_plugin(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(
        plugins, "installed", lambda: {"GPS": [plugins.Plugin("GPS", "evil:GPS", "evil")]}
    )
    assert resolve_template("GPS").__module__ == "amsa_phys.sensors.gps"
    with pytest.raises(TemplateNotFound, match="unknown template 'Nope'"):
        resolve_template("Nope")


def test_a_world_naming_a_broken_plugin_gets_no_did_you_mean_of_itself(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from amsa_phys.cli.main import main

    broken = plugins.Plugin("Broken", "no_such_module_xyz:Broken", "broken-rovers")
    monkeypatch.setattr(plugins, "installed", lambda: {"Broken": [broken]})
    scenario = tmp_path / "s.yaml"
    scenario.write_text("world:\n  components:\n    C: {template: Broken}\nduration: 1\n")
    assert main(["validate", str(scenario)]) == 2
    err = capsys.readouterr().err
    assert "cannot import module 'no_such_module_xyz'" in err
    assert "did you mean" not in err


def test_a_name_nothing_registers_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from amsa_phys.cli.main import main

    scenario = tmp_path / "s.yaml"
    scenario.write_text("world:\n  components:\n    C: {template: Qwxzy}\nduration: 1\n")
    assert main(["validate", str(scenario)]) == 2
    assert capsys.readouterr().err.endswith(
        "unknown template 'Qwxzy' (no built-in template and no installed plugin has that name)\n"
    )
