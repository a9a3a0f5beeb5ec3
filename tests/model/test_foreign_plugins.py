"""A user's template plugin installed beside the project changes no test's message.

The suite's conftest hides the ``amsa_phys.templates`` entry points of every distribution but
the project's and its own test plugin's; here a foreign one (``PidFollower``, the plugin
template a user's package registers) is made visible on ``sys.path`` as an installed
distribution's metadata, and the messages stay the ones the tests expect.
"""

from __future__ import annotations

from importlib.metadata import entry_points
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.model import plugins


def _install_foreign(root: Path) -> None:
    """``pid-rovers``'s metadata, as pip would leave it in site-packages."""
    info = root / "pid_rovers-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: pid-rovers\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(
        "[amsa_phys.templates]\nPidFollower = pid_rovers:PidFollower\n"
    )


def test_a_foreign_plugin_changes_no_message(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    _install_foreign(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    assert "PidFollower" in {ep.name for ep in entry_points(group=plugins.GROUP)}  # installed
    assert "PidFollower" not in plugins.installed()
    assert main(["templates", "Follower"]) == 2
    err = capsys.readouterr().err
    assert "(did you mean FollowerController?)" in err
    assert "PidFollower" not in err
