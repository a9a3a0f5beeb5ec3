"""Numbers past Python's digit limit and YAML nested past the stack, said in our words.

A 5 000-digit integer (in a file, or ``--set``) gave Python's own text ("Exceeds the limit
(4300 digits) ... use sys.set_int_max_str_digits()"), a hexadecimal one a traceback-free
but foreign line from deep inside a message; a file nested past the composer's stack said
"YAML nesting too deep" with no line. Each is one line naming the file, its line and key.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"
LIMIT = sys.get_int_max_str_digits()
DECIMAL = "9" * (LIMIT + 700)
HEX = "0x" + "f" * (LIMIT + 700)
TOO_LARGE = f"number too large (more than {LIMIT} digits; a number must fit a float"


def _one_line(err: str) -> str:
    assert err.count("\n") == 1, err
    assert "set_int_max_str_digits" not in err
    assert "Exceeds the limit" not in err
    return err


@pytest.mark.parametrize("key", ["duration", "seed"])
@pytest.mark.parametrize("number", [DECIMAL, HEX, "-" + DECIMAL], ids=["dec", "hex", "neg"])
def test_a_huge_integer_in_a_file_is_too_large_in_our_words(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], key: str, number: str
) -> None:
    path = tmp_path / "s.yaml"
    values = {"duration": "10", "seed": "1", key: number}
    path.write_text(f"world: {WORLD}\nduration: {values['duration']}\nseed: {values['seed']}\n")
    assert main(["validate", str(path)]) == 2
    err = _one_line(capsys.readouterr().err)
    line = 2 if key == "duration" else 3
    assert err.startswith(f"error: {path}:{line}: {key}: {TOO_LARGE}")


@pytest.mark.parametrize(
    ("setting", "words"),
    [
        (f"Leader.x={DECIMAL}", TOO_LARGE),
        (f"Leader.x={HEX}", TOO_LARGE),
        (f"physics.rate={HEX}", TOO_LARGE),
        (f"Leader.x=[{HEX}]", f"got a list holding a number of more than {LIMIT} digits"),
        (f"Leader.behavior={HEX}", f"got a number of more than {LIMIT} digits"),
        (f"Leader.freq={HEX}", f"got a number of more than {LIMIT} digits"),
    ],
)
def test_a_huge_integer_set_on_the_command_line_is_said_in_our_words(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], setting: str, words: str
) -> None:
    argv = ["run", str(SCENARIO), "--headless", "--no-plot", "--out", str(tmp_path / "r")]
    assert main([*argv, "--set", setting]) == 2
    err = _one_line(capsys.readouterr().err)
    key = setting.partition("=")[0]
    assert err.startswith(f"error: --set {key}: ")
    assert words in err


@pytest.mark.parametrize(
    "deep",
    [
        "b: " + "[" * 5000 + "]" * 5000,
        "b: " + "{x: " * 3000 + "1" + "}" * 3000,
    ],
    ids=["lists", "mappings"],
)
def test_yaml_nested_past_the_stack_names_its_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], deep: str
) -> None:
    path = tmp_path / "deep.yaml"
    path.write_text(f"name: w\ndescription: x\n{deep}\n")
    assert main(["validate", str(path)]) == 2
    err = _one_line(capsys.readouterr().err)
    assert err == f"error: {path}:3: YAML nesting too deep (over 64 levels)\n"
