"""A run directory is data: no command that reads one (or a sweep directory) imports a module
its files name.

Each case puts a marker module on ``sys.path`` and in the working directory; the run's
``scenario.yaml`` names it as a template (``evilmod:Evil``). Importing it would create a
marker file. Every reader -- ``plot``, ``view``'s loader, ``python -m amsa_phys plot``,
``plot --paper fig5`` on a run directory, ``adapt`` over a sweep with kept runs -- must leave
no marker, name the module in one warning line, and still draw from the run's own files.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from amsa_phys.cli.main import main
from amsa_phys.runs.rundata import NOT_IMPORTED, read_run

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"
ADAPT_FIXTURE = ROOT / "tests" / "fixtures" / "adapt"
EVIL = (
    "from pathlib import Path\n"
    "Path(__file__).with_name('MARKER').write_text('imported')\n"
    "from amsa_phys import Template\n"
    "class Evil(Template):\n"
    "    pass\n"
)
#: the quality signal's producer: its template is replaced by the marker module's
REPLACED = "MyDistanceMonitor"


@pytest.fixture(scope="module")
def clean_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("made") / "run"
    argv = ["run", str(SCENARIO), "--headless", "-q", "--no-plot", "--duration", "4"]
    assert main([*argv, "--out", str(out)]) == 0
    return out


@pytest.fixture
def evil_run(clean_run: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    """A copy of the run naming ``evilmod:Evil``; the module on sys.path and in the cwd."""
    home = tmp_path / "home"
    home.mkdir()
    (home / "evilmod.py").write_text(EVIL)
    run = home / "r"
    shutil.copytree(clean_run, run)
    text = (run / "scenario.yaml").read_text()
    head, sep, rest = text.partition(f"    {REPLACED}:\n      template: ")
    assert sep, "the fixture's world changed: pick another leaf"
    rest = rest.split("\n", 1)[1]
    (run / "scenario.yaml").write_text(f"{head}{sep}evilmod:Evil\n{rest}")
    monkeypatch.syspath_prepend(str(home))
    monkeypatch.chdir(home)
    sys.modules.pop("evilmod", None)
    return home, run


def _no_marker(home: Path) -> None:
    assert not (home / "MARKER").exists(), "a module the run directory names was imported"
    assert "evilmod" not in sys.modules


def test_plot_draws_the_run_without_importing_what_it_names(
    evil_run: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    home, run = evil_run
    assert main(["plot", str(run)]) == 0
    _no_marker(home)
    err = capsys.readouterr().err
    assert f"names module evilmod; {NOT_IMPORTED}" in err
    assert err.count("evilmod") == 1, err  # one line, said once
    # the run's own files still give the picture: the traced signal of the unknown leaf
    assert (run / "distance.png").stat().st_size > 0
    assert (run / "trajectory.png").stat().st_size > 0


def test_view_loads_the_run_without_importing_what_it_names(
    evil_run: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    from amsa_phys.cli.view import load_run

    home, run = evil_run
    scene = load_run(run)
    _no_marker(home)
    assert f"names module evilmod; {NOT_IMPORTED}" in capsys.readouterr().err
    # the replay still has the world's rovers and the quality signal the trace holds
    assert scene.rover_names == ["Leader", "Follower"]
    frame = scene.frame(scene.rows - 1)
    assert frame.metrics.value is not None
    assert frame.metrics.value == pytest.approx(
        float(scene.data[-1, scene.col[f"{REPLACED}.distanceFollowerToLeader"]])
    )


def test_paper_figure_from_a_run_directory_imports_nothing(
    evil_run: tuple[Path, Path], tmp_path: Path
) -> None:
    home, run = evil_run
    out = tmp_path / "fig5.png"
    assert main(["plot", "--paper", "fig5", str(run), "-o", str(out)]) == 0
    _no_marker(home)
    assert out.stat().st_size > 0


def test_python_m_plot_in_the_modules_folder_imports_nothing(
    evil_run: tuple[Path, Path],
) -> None:
    home, _run = evil_run
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(home)}
    done = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "plot", "r"],
        cwd=home,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert not (home / "MARKER").exists()
    assert f"names module evilmod; {NOT_IMPORTED}" in done.stderr
    assert "Traceback" not in done.stderr


def test_a_stdlib_module_named_by_a_run_is_not_imported_either(
    evil_run: tuple[Path, Path],
) -> None:
    """``template: this:Zen``: importing ``this`` prints the Zen of Python."""
    _home, run = evil_run
    text = (run / "scenario.yaml").read_text().replace("evilmod:Evil", "this:Zen")
    (run / "scenario.yaml").write_text(text)
    done = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "plot", str(run)],
        env={**os.environ, "MPLBACKEND": "Agg"},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert "Beautiful is better than ugly" not in done.stdout + done.stderr
    assert f"names module this; {NOT_IMPORTED}" in done.stderr


def test_an_unknown_plugin_name_is_not_loaded(evil_run: tuple[Path, Path]) -> None:
    _home, run = evil_run
    text = (run / "scenario.yaml").read_text().replace("evilmod:Evil", "someplugin")
    (run / "scenario.yaml").write_text(text)
    notes: list[str] = []
    loaded = read_run(run, warn=notes.append)
    assert loaded.world is not None
    assert loaded.world.leaves[REPLACED].template.builtin is False
    assert len(notes) == 1
    assert "names template someplugin (not built in)" in notes[0]


def test_adapt_over_a_sweep_with_a_kept_run_naming_a_module_imports_nothing(
    evil_run: tuple[Path, Path], tmp_path: Path
) -> None:
    home, run = evil_run
    sweep = tmp_path / "sweep"
    shutil.copytree(ADAPT_FIXTURE, sweep)
    shutil.copytree(run, sweep / "runs" / "r0")
    rules = tmp_path / "rules.yaml"
    argv = ["adapt", str(sweep), "--scenario", str(ADAPT_FIXTURE / "sweep.yaml")]
    assert main([*argv, "-o", str(rules)]) == 0
    _no_marker(home)


def test_a_not_imported_rovers_parameters_keep_only_numbers(
    evil_run: tuple[Path, Path],
) -> None:
    """Nothing judges a not-imported template's parameters: text or a list where the replay
    reads a body's size is left out (the default size drawn), never a ValueError."""
    from amsa_phys.cli.view import load_run

    _home, run = evil_run
    text = (run / "scenario.yaml").read_text()
    head, sep, rest = text.partition("    Follower:\n      template: controlledRobot\n")
    assert sep
    _params, _, tail = rest.partition("      inputs:\n")
    bad = (
        "      freq: 4\n      params:\n"
        "        length: abc\n        width: [1, 2]\n        track: 0.7\n"
    )
    (run / "scenario.yaml").write_text(
        f"{head}    Follower:\n      template: evilmod:Bot\n{bad}      inputs:\n{tail}"
    )
    notes: list[str] = []
    assert read_run(run, warn=notes.append).world.leaves["Follower"].params == {"track": 0.7}
    scene = load_run(run)
    follower = next(r for r in scene.frame(scene.rows - 1).rovers if r.name == "Follower")
    assert (follower.length, follower.width, follower.track) == (0.8, 0.6, 0.7)


def test_monitor_judges_a_formula_on_the_run_without_importing_what_it_names(
    evil_run: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """``monitor RUNDIR FORMULA`` reads the trace's columns only: the module the run's
    scenario names is neither imported nor needed to judge a formula over its signals."""
    home, run = evil_run
    formula = f"always(abs({REPLACED}.distanceFollowerToLeader) >= 0)"
    assert main(["monitor", str(run), formula, "--json"]) == 0
    _no_marker(home)
    out = capsys.readouterr().out
    assert '"robustness"' in out
