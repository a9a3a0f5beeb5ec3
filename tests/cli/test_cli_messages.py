"""What the commands say: describe's values at t = 0, test and JUnit reports, plurals, --debug
and hints (issue 17 items 7, 11 and 13)."""

from __future__ import annotations

import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
SCENARIO1 = ROOT / "scenarios" / "scenario1.yaml"
FAILING = ROOT / "tests" / "fixtures" / "failing_expect.yaml"

#: a user template whose do_step fails two calls deep
BOOM = """\
from amsa_phys.model.template import Kind, Port, Template


class Boom(Template):
    kind = Kind.OBSERVER
    inputs = (Port("x"),)
    outputs = (Port("y", 0.0),)
    params = ()

    def do_step(self, t, inp):
        return {"y": helper(inp["x"])}


def helper(x):
    return x / undefined_name
"""


def test_describe_shows_the_values_in_force_at_t0_and_their_source(
    capsys: pytest.CaptureFixture[str],
) -> None:
    args = ["describe", str(SCENARIO1), "--set", "MyFollowerController.Kw=0.1"]
    assert main([*args, "--set", "physics.ground.friction=0.5"]) == 0
    lines = [line.strip() for line in capsys.readouterr().out.splitlines()]
    assert "Kv = 0.35 1/m  [0, 10]  (scenario set; world 0.05)" in lines  # not the world's 0.05
    assert "Kw = 0.1 1/rad  [0, 10]  (--set; world 0.04)" in lines
    assert "distanceRef = 15 m  [0, 1000]  (world)" in lines
    assert "Kff = 0  [0, 2]  (default)" in lines  # the paper's law: no feed-forward
    assert "MyFollowerController: FollowerController (controller) at 4 Hz, latency 0.75 s" in lines
    physics = next(line for line in lines if line.startswith("physics:"))
    assert "ground.friction 0.5 (--set)" in physics
    assert "gravity 9.81 (default)" in physics


def test_a_junit_case_is_named_with_its_bound_classed_by_path_and_records_the_value(
    tmp_path: Path,
) -> None:
    scenario = tmp_path / "two_bounds.yaml"
    scenario.write_text(
        FAILING.read_text()
        .replace("../../worlds/mde_challenge.yaml", str(WORLD))
        .replace("expect:\n", "expect:\n  - {metric: max_distance, above: 2}\n")
    )
    junit = tmp_path / "report.xml"
    assert main(["test", str(scenario), "--junit", str(junit), "-j", "1"]) == 1
    cases = list(ET.parse(junit).getroot().iter("testcase"))
    names = [c.get("name") for c in cases]
    assert len(set(names)) == len(names)  # two max_distance checks, two names
    assert "max_distance above 2" in names
    assert {c.get("classname") for c in cases} == {str(scenario)}
    passing = next(c for c in cases if c.get("name") == "max_distance above 2")
    props = {p.get("name"): p.get("value") for p in passing.iter("property")}
    assert float(props["measured"]) > 2
    assert props["bound"] == "above 2"
    assert passing.findtext("system-out", "").endswith("above 2: pass")


def test_test_on_a_folder_skips_run_directories(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    project = tmp_path / "proj"
    project.mkdir()
    text = FAILING.read_text().replace("../../worlds/mde_challenge.yaml", str(WORLD))
    (project / "s.yaml").write_text(text)
    run_dir = project / "runs" / "s-1"
    assert main(["run", str(project / "s.yaml"), "--headless", "-q", "--out", str(run_dir)]) == 1
    capsys.readouterr()
    assert main(["test", str(project), "-j", "1"]) == 1
    out, err = capsys.readouterr()
    assert out.splitlines()[-1] == "1 scenario, 3 checks: 1 passed, 2 failed"  # not 2 scenarios
    assert "skipped 1 resolved scenario in run directories" in err


def test_counts_are_singular_when_one(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scenario = tmp_path / "one.yaml"
    scenario.write_text(f"world: {WORLD}\nduration: 1\n")
    assert main(["validate", str(scenario)]) == 0
    assert capsys.readouterr().out == f"ok: {scenario} (scenario: 8 components, 1 phase, 1 s)\n"
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        f"world: {WORLD}\nduration: 1\nquality: {{signal: Leader.posX, reference: 1}}\n"
        "expect: [{metric: max_distance, phase: 1, below: 1}]\n"
    )
    assert main(["validate", str(bad)]) == 2
    assert capsys.readouterr().err.endswith(
        "expect[0].phase: phase 1 does not exist (the scenario has 1 phase, only phase 0)\n"
    )
    broken = tmp_path / "broken.yaml"
    broken.write_text("world: nowhere.yaml\nduration: 1\n")
    assert main(["test", str(broken), "-j", "1"]) == 1
    assert capsys.readouterr().out.splitlines()[-1] == (
        "1 scenario, 0 checks: 0 passed, 0 failed, 1 error"
    )


def test_a_missing_world_file_suggests_the_other_extension(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    shutil.copy(WORLD, tmp_path / "arena.yaml")
    scenario = tmp_path / "s.yaml"
    scenario.write_text("world: arena.yml\nduration: 1\n")
    assert main(["validate", str(scenario)]) == 2
    assert capsys.readouterr().err == (
        f"error: {scenario}:1: world: world file not found: {tmp_path / 'arena.yml'} "
        "(written arena.yml; did you mean arena.yaml?)\n"
    )


def test_a_world_in_a_directory_that_does_not_exist_says_so_and_what_was_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "scenarios").mkdir()
    scenario = tmp_path / "scenarios" / "s.yaml"
    scenario.write_text("world: ../wrlds/arena.yaml\nduration: 1\n")
    assert main(["validate", str(scenario)]) == 2
    assert capsys.readouterr().err == (
        f"error: {scenario}:1: world: world file not found: {tmp_path / 'wrlds' / 'arena.yaml'} "
        f"(written ../wrlds/arena.yaml; there is no directory {tmp_path / 'wrlds'})\n"
    )


@pytest.mark.parametrize("where", ["before", "after"])
def test_debug_shows_a_user_templates_traceback(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    where: str,
) -> None:
    (tmp_path / "mytpl.py").write_text(BOOM)
    monkeypatch.syspath_prepend(str(tmp_path))
    scenario = tmp_path / "w.yaml"
    scenario.write_text(
        "world: {components: {Leader: {template: freeRobot, freq: 10},\n"
        "  B: {template: 'mytpl:Boom', freq: 1, inputs: {x: Leader.posX}}}}\nduration: 3\n"
    )
    run = ["run", str(scenario), "--headless", "-q", "--no-plot"]
    fault = (
        "error: run fault at t=0.000 s in B (Boom): do_step raised "
        "NameError(\"name 'undefined_name' is not defined\")"
    )
    assert main([*run, "--out", str(tmp_path / "a")]) == 3
    assert capsys.readouterr().err == f"{fault} (amsa-phys --debug shows its traceback)\n"
    argv = ["--debug", *run] if where == "before" else [*run, "--debug"]
    assert main([*argv, "--out", str(tmp_path / "b")]) == 3
    err = capsys.readouterr().err
    assert err.startswith("Traceback (most recent call last):\n")
    assert 'mytpl.py", line 15, in helper' in err
    assert "NameError: name 'undefined_name' is not defined\n" in err
    assert err.endswith(f"{fault}\n")


def test_an_input_error_has_no_debug_hint(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(SCENARIO1), "--headless", "--set", "Leader.x=abc"]) == 2
    assert capsys.readouterr().err == "error: --set Leader.x: expected a number, got string 'abc'\n"


def test_describe_lists_a_set_key_once_with_the_value_in_force(
    capsys: pytest.CaptureFixture[str],
) -> None:
    argv = ["describe", str(SCENARIO1)]  # the file's set: gives Kv 0.35
    argv += ["--set", "MyFollowerController.Kv=0.3"]
    assert main(argv) == 0
    phase0 = next(
        line for line in capsys.readouterr().out.splitlines() if line.startswith("phase 0 ")
    )
    assert phase0.count("MyFollowerController.Kv=") == 1
    assert "MyFollowerController.Kv=0.3" in phase0


SCENARIO2 = ROOT / "scenarios" / "scenario2.yaml"  # set: gives Kv 0.35, cruisePower 9.0


def _param_line(out: str, name: str) -> str:
    return next(line.strip() for line in out.splitlines() if line.strip().startswith(f"{name} ="))


@pytest.mark.parametrize("first", [[], ["--set", "MyFollowerController.Kw=0.05"]])
def test_describe_names_a_set_that_replaces_the_files_set_as_set_with_both_values_replaced(
    capsys: pytest.CaptureFixture[str], first: list[str]
) -> None:
    argv = ["describe", str(SCENARIO2), *first, "--set", "MyFollowerController.Kv=0.2"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert _param_line(out, "Kv") == "Kv = 0.2 1/m  [0, 10]  (--set; scenario 0.35, world 0.05)"
    if first:  # given only by --set: not the file's, whatever its place in phase 0
        assert _param_line(out, "Kw") == "Kw = 0.05 1/rad  [0, 10]  (--set; world 0.04)"
    assert (
        _param_line(out, "cruisePower") == "cruisePower = 9 %  [-100, 100]  (scenario set; world 7)"
    )


def test_describe_spells_values_as_the_run_table_does(capsys: pytest.CaptureFixture[str]) -> None:
    from amsa_phys.valuetext import value_text

    assert main(["describe", str(SCENARIO2)]) == 0
    out = capsys.readouterr().out
    phase0 = next(line for line in out.splitlines() if line.startswith("phase 0 "))
    assert f"Leader.cruisePower={value_text(9.0)}," in phase0  # the file writes 9.0
    assert "cruisePower=9.0" not in out
    assert _param_line(out, "x").startswith(f"x = {value_text(15.0)} m ")


def test_a_snapshot_after_the_end_is_refused_before_anything_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(
        [
            "run",
            str(ROOT / "tests" / "fixtures" / "mde_short.yaml"),
            "--headless",
            "--duration",
            "10",
            "--snapshot",
            str(tmp_path / "s.png"),
            "--snapshot-at",
            "50",
            "--out",
            str(tmp_path / "o"),
        ]
    )
    err = capsys.readouterr().err
    assert code == 2
    assert err == (
        "error: --snapshot-at: 50 s is after the run's end (10 s); "
        "leave it out for a snapshot of the last instant\n"
    )
    assert not (tmp_path / "o").exists()
    assert not (tmp_path / "s.png").exists()


@pytest.mark.parametrize(
    ("given", "said"),
    [
        (["--fps", "10"], "error: --fps: needs --record FILE: alone it would do nothing\n"),
        (["--speedup", "4"], "error: --speedup: needs --record FILE: alone it would do nothing\n"),
        (
            ["--size", "640x360"],
            "error: --size: needs --record FILE or --snapshot FILE.png: alone it would do "
            "nothing\n",
        ),
    ],
)
def test_a_video_option_without_a_video_is_refused_before_anything_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], given: list[str], said: str
) -> None:
    scenario = str(ROOT / "tests" / "fixtures" / "mde_short.yaml")
    out = tmp_path / "o"
    code = main(["run", scenario, "--headless", "--out", str(out), *given])
    assert code == 2
    assert capsys.readouterr().err == said
    assert not out.exists()


@pytest.mark.parametrize(
    "argv",
    [
        ["export", "amsa", "w.yaml", "-o", "X"],
        ["export", "ros2", "w.yaml", "-o", "X"],
        ["export", "ros", "w.yaml", "-o", "X"],
        ["ros2", "lockstep", "PKG"],
    ],
)
def test_debug_is_taken_after_a_commands_own_subcommand(argv: list[str]) -> None:
    """``--debug`` goes before or after the command (the docs); after a nested subcommand
    too, where it was refused (``unrecognized arguments: --debug (did you mean --debug?)``).
    Given before, a nested parser does not reset it."""
    from amsa_phys.cli.main import build_parser

    parser = build_parser(only=argv[0])
    assert parser.parse_args([*argv, "--debug"]).debug is True
    assert parser.parse_args(["--debug", *argv]).debug is True
    assert parser.parse_args(argv).debug is False


#: a plugin module that leaves a file behind when imported
TELLTALE = """\
from pathlib import Path

Path(__file__).with_name("IMPORTED").write_text("x")

from amsa_phys.model.template import Kind, Template


class Evil(Template):
    kind = Kind.CONTROLLER
"""


def test_test_on_a_folder_imports_nothing_from_a_falsify_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``falsify --trials`` writes each trial's ``worst.yaml`` (with its ``expect:``) one
    folder below the output's marker. A handed-over falsify directory whose trial names a
    plugin template must not make ``test`` on the folder import it: the files of an output
    folder are data, at any depth below its marker."""
    out = tmp_path / "found"
    argv = ["falsify", str(SCENARIO1), "--range", "MyNormalizePower.motorCoef=50:100"]
    argv += ["--budget", "2", "--duration", "2", "-j", "1", "--trials", "2", "--out", str(out)]
    assert main(argv) in (0, 1)
    worst = out / "trial-001" / "worst.yaml"
    worst.write_text(worst.read_text().replace("template: controlledRobot", "template: evil:Evil"))
    assert "expect:" in worst.read_text()
    (tmp_path / "evil.py").write_text(TELLTALE)
    monkeypatch.syspath_prepend(str(tmp_path))
    capsys.readouterr()
    assert main(["test", str(out), "-j", "1"]) == 2  # no scenario test left to run
    assert not (tmp_path / "IMPORTED").exists()
    assert "skipped 2 resolved scenarios in run directories" in capsys.readouterr().err
