"""``amsa-phys templates`` with plugins: a plugin is shown under the name a world writes,
and a registered plugin that fails to load is named as such (no "did you mean" itself)."""

from __future__ import annotations

from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.model import plugins

MODULE = '''
from amsa_phys import Kind, Port, Template


class PDThing(Template):
    """A controller whose class name differs from its registered name."""

    kind = Kind.CONTROLLER
    outputs = (Port("LeftPower", 0.0),)

    def initialize(self, ctx):
        pass

    def do_step(self, t, inp):
        return {"LeftPower": 0.0}
'''


@pytest.fixture
def registry(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Two registered plugins: ``ShortPid`` (loads, class PDThing) and ``Broken`` (no module)."""
    (tmp_path / "tpl_cli_plugin.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    found = {
        "Broken": [plugins.Plugin("Broken", "tpl_cli_plugin_gone:X", "my-rovers")],
        "ShortPid": [plugins.Plugin("ShortPid", "tpl_cli_plugin:PDThing", "my-rovers")],
    }
    monkeypatch.setattr(plugins, "installed", lambda: found)


def test_a_plugin_is_listed_under_its_registered_name(
    registry: None, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["templates"]) == 0
    out = capsys.readouterr().out.splitlines()
    (line,) = [x for x in out if "tpl_cli_plugin:PDThing" in x]
    assert line.startswith("ShortPid (controller): ")
    assert not any(x.startswith("PDThing ") for x in out)
    # and the name shown is one the command (and a world) accepts
    assert main(["templates", "ShortPid"]) == 0
    assert capsys.readouterr().out.startswith("ShortPid (controller): ")


def test_a_broken_plugin_asked_by_name_says_which_package_fails(
    registry: None, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["templates", "Broken"]) == 2
    err = capsys.readouterr().err
    assert "plugin tpl_cli_plugin_gone:X from my-rovers: cannot import module" in err
    assert "did you mean" not in err


def test_an_unknown_name_says_no_plugin_is_installed(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(plugins, "installed", lambda: {})
    assert main(["templates", "PidFollower"]) == 2
    assert "; plugins: none installed" in capsys.readouterr().err
