"""Every broken file in tests/fixtures/bad gives exit 2 and its one-line message."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from amsa_phys.cli.main import main

BAD = sorted((Path(__file__).parent.parent / "fixtures" / "bad").glob("*.yaml"))
SCENARIO = Path(__file__).parent.parent.parent / "scenarios" / "scenario1.yaml"
WORLD = SCENARIO.parent.parent / "worlds" / "mde_challenge.yaml"


def expected(path: Path) -> str:
    first = path.read_bytes().split(b"\n", 1)[0].decode()
    assert first.startswith("# expect: "), f"{path.name} has no '# expect:' line"
    return first[len("# expect: ") :]


def test_corpus_is_large_enough() -> None:
    assert len(BAD) >= 20


@pytest.mark.parametrize("path", BAD, ids=[p.stem for p in BAD])
def test_validate_refuses_with_one_clear_line(
    path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["validate", str(path)])
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"error: {path}"), lines[0]
    assert expected(path) in lines[0]
    assert "Traceback" not in err


def test_run_with_bad_scenario_exits_2_without_traceback(tmp_path: Path) -> None:
    bad = Path(__file__).parent.parent / "fixtures" / "bad" / "scenario_set_out_of_range.yaml"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "amsa_phys",
            "run",
            str(bad),
            "--headless",
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "PYTHONPATH": str(Path(__file__).parent.parent)},
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1
    assert "Traceback" not in proc.stderr
    assert "timeline[0].set.Src.gain: 99 is above the maximum 10" in proc.stderr
    assert not (tmp_path / "out").exists()  # nothing started, nothing written


def test_bad_set_override_names_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = Path(__file__).parent.parent.parent / "scenarios" / "scenario1.yaml"
    code = main(
        [
            "run",
            str(scen),
            "--headless",
            "--out",
            str(tmp_path / "o"),
            "--set",
            "MyFollowerController.Kv=abc",
        ]
    )
    assert code == 2
    assert capsys.readouterr().err == (
        "error: --set MyFollowerController.Kv: expected a number, got string 'abc'\n"
    )


def test_overrides_that_break_a_rule_name_the_override(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["run", str(SCENARIO), "--headless", "--out", str(tmp_path / "o")]
    argv += ["--set", "MyNormalizePower.powerMin=80", "--set", "MyNormalizePower.powerMax=20"]
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        "error: --set MyNormalizePower.powerMax: powerMin 80 is above powerMax 20\n"
    )
    assert not (tmp_path / "o").exists()


def test_an_override_of_a_key_the_file_sets_is_named_as_the_override(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--set`` replacing a value the file's ``set:`` gives, and breaking a rule with the
    file's other values, is the override's fault: named ``--set``, not the file's line."""
    scen = tmp_path / "s.yaml"
    scen.write_text(
        f"world: {WORLD}\nduration: 5\n"
        "set: {MyNormalizePower.powerMax: 80, MyNormalizePower.powerMin: -50, "
        "Leader.cruisePower: 9}\n"
    )
    argv = ["run", str(scen), "--headless", "--out", str(tmp_path / "o")]
    assert main([*argv, "--set", "MyNormalizePower.powerMax=-60"]) == 2
    assert capsys.readouterr().err == (
        "error: --set MyNormalizePower.powerMax: powerMin -50 is above powerMax -60\n"
    )
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "argv",
    [["run"], ["nope"], ["sweep", "x.yaml", "--seeds", "abc"]],
    ids=["missing-arg", "unknown-command", "bad-int"],
)
def test_usage_errors_are_one_line_exit_2(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith("error: amsa-phys")
    assert "--help)" in err


def test_a_set_override_can_repair_a_rule_the_file_breaks(tmp_path: Path) -> None:
    scen = tmp_path / "s.yaml"
    world = Path(__file__).parent.parent.parent / "worlds" / "mde_challenge.yaml"
    scen.write_text(
        f"world: {world}\nduration: 2\nset: {{MyNormalizePower.powerMin: 50}}\n"
        "timeline:\n  - {at: 1, set: {MyNormalizePower.powerMax: 40}}\n"
    )
    assert main(["validate", str(scen)]) == 2  # the file alone breaks powerMin <= powerMax
    argv = ["run", str(scen), "--headless", "-q", "--no-plot", "--out", str(tmp_path / "o")]
    assert main([*argv, "--set", "MyNormalizePower.powerMin=-10"]) == 0


def test_a_refused_option_value_of_thousands_of_characters_is_said_by_its_ends(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """argparse quotes the value it refused whole: 5,000 characters made a 5,000-character
    line. The value is said by its first 40 and last 20 characters."""
    value = "x" + "9" * 5000
    with pytest.raises(SystemExit) as exited:
        main(["run", str(SCENARIO), "--headless", "--seed", value])
    assert exited.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert len(err) < 200
    assert f"'{value[:40]}...{value[-20:]}'" in err


@pytest.mark.parametrize("value", ["9" * 5000, "1e400", "inf"])
def test_a_duration_beyond_a_float_says_so(
    value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """5,000 digits of --duration read as a float's infinity: the line said "got inf", a
    number the user never typed."""
    argv = ["run", str(SCENARIO), "--headless", "--out", str(tmp_path / "o")]
    assert main([*argv, "--duration", value]) == 2
    assert capsys.readouterr().err == (
        "error: --duration: must be a positive finite number, got infinity or a number too "
        "large for a float\n"
    )
    assert not (tmp_path / "o").exists()
