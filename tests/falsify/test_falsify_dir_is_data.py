"""A falsification's directory handed over is data: ``falsify --resume`` and ``plot`` read it
bounded in time and memory, refuse what is not theirs in one line naming the file (exit 2,
no traceback), and never write outside ``--out``, not even through a link planted in it."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from deadlines import HANG_S

from amsa_phys.cli.main import main
from amsa_phys.falsify.resume import MAX_RESULTS_BYTES, results_limit

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "scenarios" / "scenario1.yaml"
SEARCH = [
    "falsify",
    str(SCENARIO),
    "--range",
    "MyNormalizePower.motorCoef=50:100",
    "--budget",
    "4",
    "--duration",
    "5",
    "-j",
    "1",
    "--trials",
    "2",
]
DEEP = "[" * 200_000 + "]" * 200_000


@pytest.fixture(scope="module")
def finished(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished two-trial falsification (made once; each test works on a copy)."""
    out = tmp_path_factory.mktemp("f0") / "f"
    assert main([*SEARCH, "--out", str(out)]) == 0
    return out


@pytest.fixture
def fdir(finished: Path, tmp_path: Path) -> Path:
    copy = tmp_path / "f"
    shutil.copytree(finished, copy)
    return copy


def resume(out: Path) -> int:
    return main([*SEARCH, "--out", str(out), "--resume"])


def refused(capsys: pytest.CaptureFixture[str], names: str) -> str:
    """The one line a refusal printed (it names ``names``)."""
    err = capsys.readouterr().err.strip()
    assert "\n" not in err, err
    assert "Traceback" not in err
    assert names in err, err
    return err


def snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and not p.is_symlink()
    }


# -- nothing is written outside --out -------------------------------------------------------


def test_a_trial_directory_that_is_a_link_is_refused_before_anything_is_written(
    fdir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A link where trial-002 goes made resume replace the results.csv it points to."""
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "results.csv").write_text("precious\n")
    shutil.rmtree(fdir / "trial-002")
    (fdir / "trial-002").symlink_to(outside)
    (fdir / "trial-001" / "trial.json").unlink()  # trial 1 would run again first
    before = snapshot(fdir)
    capsys.readouterr()
    assert resume(fdir) == 2
    assert "symbolic link" in refused(capsys, "trial-002")
    assert [p.name for p in outside.iterdir()] == ["results.csv"]
    assert (outside / "results.csv").read_text() == "precious\n"
    assert snapshot(fdir) == before  # refused before trial 1 wrote anything


@pytest.mark.parametrize("what", ["file", "link to a file"])
def test_a_trial_directory_that_is_not_a_directory_is_refused(
    fdir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], what: str
) -> None:
    shutil.rmtree(fdir / "trial-002")
    target = tmp_path / "precious.txt"
    target.write_text("precious\n")
    if what == "file":
        (fdir / "trial-002").write_text("x\n")
    else:
        (fdir / "trial-002").symlink_to(target)
    capsys.readouterr()
    assert resume(fdir) == 2
    refused(capsys, "trial-002")
    assert target.read_text() == "precious\n"


def test_a_counterexample_directory_that_is_a_link_is_refused(
    fdir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The counterexample's run is replaced under a trial: never through a link."""
    outside = tmp_path / "outside"
    outside.mkdir()
    (fdir / "trial-002" / "trial.json").unlink()
    (fdir / "trial-002" / "counterexample").symlink_to(outside)
    capsys.readouterr()
    assert resume(fdir) == 2
    assert "symbolic link" in refused(capsys, "counterexample")
    assert list(outside.iterdir()) == []


def test_resume_refuses_an_out_that_is_a_link(
    fdir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """As for a new --out: amsa-phys never writes through a link given as --out."""
    (fdir / "trial-002" / "trial.json").unlink()
    before = snapshot(fdir)
    link = tmp_path / "link"
    link.symlink_to(fdir)
    capsys.readouterr()
    assert resume(link) == 2
    assert "symbolic link" in refused(capsys, "--out")
    assert snapshot(fdir) == before


# -- reads are bounded ----------------------------------------------------------------------


@pytest.mark.parametrize("name", ["trial-002/trial.json", "falsify.json"])
def test_a_record_that_is_a_device_is_refused_unread(
    fdir: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    """trial.json linked to /dev/zero grew to 12 GB before the kernel killed it: a file of
    the directory that is a link is refused unread (it must not lead out of it)."""
    (fdir / name).unlink()
    (fdir / name).symlink_to("/dev/zero")
    capsys.readouterr()
    assert resume(fdir) == 2
    assert "is a symbolic link" in refused(capsys, name)


def test_a_results_file_linked_out_of_the_directory_is_refused_unread(
    fdir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An unfinished trial's results.csv linked to a file outside: resume read it and said
    its first bad cell (a credential) in the error. Refused as a link, never read."""
    secret = tmp_path / "creds.csv"
    secret.write_text("run,seed_index,seed,error,api_token\n0,0,1,,sk-LIVE-SECRET\n")
    (fdir / "trial-002" / "trial.json").unlink()
    (fdir / "trial-002" / "results.csv").unlink()
    (fdir / "trial-002" / "results.csv").symlink_to(secret)
    capsys.readouterr()
    assert resume(fdir) == 2
    line = refused(capsys, "trial-002/results.csv")
    assert "is a symbolic link" in line
    assert "SECRET" not in line


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs are POSIX")
@pytest.mark.parametrize("name", ["trial-002/trial.json", "falsify.json"])
def test_a_record_that_is_a_fifo_is_refused_without_waiting(fdir: Path, name: str) -> None:
    """A FIFO nobody writes to: resume waited for ever. Run in a child with a timeout so a
    regression fails this test instead of hanging the suite."""
    (fdir / name).unlink()
    os.mkfifo(fdir / name)
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    cmd = [sys.executable, "-m", "amsa_phys", *SEARCH, "--out", str(fdir), "--resume"]
    done = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=HANG_S)
    assert done.returncode == 2
    err = done.stderr.strip()
    assert "\n" not in err, err
    assert "FIFO" in err, err
    assert name in err, err


@pytest.mark.parametrize("name", ["trial-002/results.csv", "trial-002/trial.json"])
def test_a_huge_file_is_refused_by_its_size(
    fdir: Path, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    """A sparse 1 GiB results.csv took 2 GB and ended in a MemoryError traceback."""
    if name.endswith("results.csv"):
        (fdir / "trial-002" / "trial.json").unlink()
    os.truncate(fdir / name, 1 << 30)  # sparse: no disk used, never read
    capsys.readouterr()
    assert resume(fdir) == 2
    assert "too large" in refused(capsys, name)


def test_the_results_limit_grows_with_the_budget_and_is_capped() -> None:
    assert results_limit(4) < results_limit(400) <= MAX_RESULTS_BYTES
    assert results_limit(1_000_000) == MAX_RESULTS_BYTES < 1 << 30


# -- what is read is judged -----------------------------------------------------------------


def _json(edit: Callable[[dict], object]) -> Callable[[Path], None]:
    def apply(path: Path) -> None:
        doc = json.loads(path.read_text())
        path.write_text(json.dumps(edit(doc)))

    return apply


def _set(key: str, value: object) -> Callable[[dict], dict]:
    return lambda doc: {**doc, key: value}


def _lines(edit: Callable[[list[str]], None]) -> Callable[[Path], None]:
    def apply(path: Path) -> None:
        lines = path.read_text().splitlines()
        edit(lines)
        path.write_text("\n".join(lines) + "\n")

    return apply


def _append(text: str) -> Callable[[list[str]], None]:
    return lambda lines: lines.append(text)


def _cell(row: int, column: int, value: str) -> Callable[[list[str]], None]:
    def edit(lines: list[str]) -> None:
        cells = lines[row].split(",")
        cells[column] = value
        lines[row] = ",".join(cells)

    return edit


def _widen(lines: list[str]) -> None:
    lines[1] += ",x,y"


def _repeat(lines: list[str]) -> None:
    lines.append(lines[1])


TRIAL_JSON = "trial-002/trial.json"
RESULTS = "trial-002/results.csv"

BAD = {
    "simulations text": (TRIAL_JSON, _json(_set("simulations", "abc")), "simulations"),
    "falsified without simulations": (TRIAL_JSON, _json(_set("falsified", True)), "simulations"),
    "least text": (TRIAL_JSON, _json(_set("least", "low")), "least"),
    "runs beyond the budget": (TRIAL_JSON, _json(_set("runs", 10**9)), "runs"),
    "another trial's seed": (TRIAL_JSON, _json(_set("seed", 1)), "seed"),
    "an unknown key": (TRIAL_JSON, _json(_set("extra", 1)), "extra"),
    "a trial that is an array": (TRIAL_JSON, _json(lambda d: [d]), "array"),
    "a trial nested too deeply": (TRIAL_JSON, lambda p: p.write_text(DEEP), "nested too deeply"),
    "settings nested too deeply": ("falsify.json", lambda p: p.write_text(DEEP), "too deeply"),
    "settings not JSON": ("falsify.json", lambda p: p.write_text("{"), "invalid JSON"),
    "settings an array": ("falsify.json", _json(lambda d: list(d)), "array"),
    "a short row": (RESULTS, _lines(_append("1")), ":6:"),
    "a long row": (RESULTS, _lines(_widen), ":2:"),
    "a metric that is text": (RESULTS, _lines(_cell(1, 6, "abc")), "not a number"),
    "a run number twice": (RESULTS, _lines(_repeat), "twice"),
    "a run beyond the budget": (RESULTS, _lines(_cell(1, 0, "99")), "run is 99"),
    "a header without run": (RESULTS, _lines(_cell(0, 0, "nur")), "no run"),
    "not UTF-8": (RESULTS, lambda p: p.write_bytes(b"run\n\xff\xfe\n"), "not UTF-8"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_damaged_file_is_one_line_naming_it(
    fdir: Path, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    """Each was a traceback (TypeError in the summary, RecursionError, AttributeError on a
    short row), a row taken as the search's own, or a trial summarised from nonsense. A
    damaged record is refused before any trial runs again (trial 1 here: a damaged
    results.csv of trial 2 was read only once trial 1 had run again)."""
    name, damage, said = BAD[case]
    if name == RESULTS:
        (fdir / TRIAL_JSON).unlink()  # an unfinished trial reads its rows back
        (fdir / "trial-001" / "trial.json").unlink()  # and so does the one before it
    else:
        (fdir / "trial-001" / "trial.json").unlink()
    damage(fdir / name)
    before = snapshot(fdir)
    capsys.readouterr()
    assert resume(fdir) == 2
    assert said in refused(capsys, name)
    assert snapshot(fdir) == before


def test_an_intact_directory_still_resumes(fdir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (fdir / TRIAL_JSON).unlink()
    capsys.readouterr()
    assert resume(fdir) == 0
    assert "resumed: 4 finished runs taken from results.csv" in capsys.readouterr().err
    assert (fdir / TRIAL_JSON).is_file()


# -- plot reads the record the same way -----------------------------------------------------

PLOT_BAD = {
    "nested too deeply": lambda p: p.write_text(DEEP),
    "file too large": lambda p: os.truncate(p, 1 << 30),
    "is not text": _json(_set("objective", ["rms_error"])),
    "expected a JSON object": _json(lambda d: 1),
}


@pytest.mark.parametrize("said", sorted(PLOT_BAD))
def test_plot_refuses_a_damaged_record_in_one_line(
    fdir: Path, capsys: pytest.CaptureFixture[str], said: str
) -> None:
    PLOT_BAD[said](fdir / "falsify.json")
    capsys.readouterr()
    assert main(["plot", str(fdir / "trial-001")]) == 2
    assert said in refused(capsys, "falsify.json")
    assert not (fdir / "trial-001" / "samples.png").exists()
