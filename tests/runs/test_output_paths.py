"""Output directories can never reach outside ``--out`` nor destroy a user's files.

The critical case of the hostile audit: a scenario's ``name:`` joined to ``test --out`` used
to be removed with ``rmtree`` (``name: ".."`` deleted the parent of ``--out``, an absolute
name deleted that directory). Every test here snapshots a temporary root and asserts that
nothing outside the output directory changed.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import pytest
import yaml

from amsa_phys.cli.main import main
from amsa_phys.runs.rundir import MARKER, safe_name, unique_names

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"


def _scenario(path: Path, name: str, duration: float = 2) -> Path:
    path.write_text(
        f"name: {name!r}\n"
        f"world: {WORLD}\n"
        f"duration: {duration}\n"
        "seed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15,"
        " tolerance: 1.5}\n"
        "expect:\n  - {metric: collisions, below: 1}\n",
        encoding="utf-8",
    )
    return path


def _snapshot(root: Path, skip: Path | None = None) -> dict[str, bytes | None]:
    """Every file and directory under ``root`` (outside ``skip``) with its content."""
    seen: dict[str, bytes | None] = {}
    for dirpath, dirnames, filenames in os.walk(root):
        here = Path(dirpath)
        if skip is not None and (here == skip or skip in here.parents):
            dirnames[:] = []
            continue
        for d in dirnames:
            if skip is None or here / d != skip:
                seen[str(here / d)] = None
        for f in filenames:
            seen[str(here / f)] = (here / f).read_bytes()
    return seen


def _plant(root: Path) -> None:
    """User files that a bad name or --force must never touch."""
    (root / "precious").mkdir()
    (root / "precious" / "thesis.tex").write_text("years of work")
    (root / "notes.txt").write_text("keep me")


@pytest.mark.parametrize("name", ["..", ".", "../..", "/ABS", "a/../../b", "\x1b[2J\n", ""])
def test_test_out_never_touches_anything_outside_out(
    tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    root = tmp_path / "root"
    root.mkdir()
    _plant(root)
    if name == "/ABS":  # an absolute path under the temporary root, pointing at user files
        name = str(root / "precious")
    out = root / "out"
    out.mkdir()
    scen = _scenario(root / "s.yaml", name)
    before = _snapshot(root, skip=out)
    main(["test", str(scen), "--out", str(out), "-j", "1"])
    assert _snapshot(root, skip=out) == before
    made = [p for p in out.iterdir()]
    assert len(made) == 1
    assert made[0].parent == out
    assert (made[0] / "metrics.json").is_file()
    assert (made[0] / MARKER).is_file()
    capsys.readouterr()


def test_run_default_directory_stays_under_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    _plant(tmp_path)
    scen = _scenario(tmp_path / "s.yaml", "../precious")
    before = _snapshot(tmp_path, skip=tmp_path / "runs")
    assert main(["run", str(scen), "--headless", "--no-plot", "-q"]) == 0
    assert _snapshot(tmp_path, skip=tmp_path / "runs") == before
    (made,) = (tmp_path / "runs").iterdir()
    assert made.name.startswith("___precious-")
    capsys.readouterr()


def test_same_name_twice_in_parallel_gets_two_directories(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = _scenario(tmp_path / "a.yaml", "twin")
    b = _scenario(tmp_path / "b.yaml", "twin")
    out = tmp_path / "out"
    assert main(["test", str(a), str(b), "--out", str(out), "-j", "2"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["twin", "twin-2"]
    for d in out.iterdir():
        assert (d / "metrics.json").is_file()
    capsys.readouterr()


def test_force_refuses_a_directory_amsa_phys_did_not_make(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = _scenario(tmp_path / "s.yaml", "s")
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "data.csv").write_text("1,2,3")
    code = main(["run", str(scen), "--headless", "--out", str(mine), "--force", "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1
    assert "--out" in err[0]
    assert "not made by amsa-phys" in err[0]
    assert (mine / "data.csv").read_text() == "1,2,3"


def test_force_replaces_a_run_directory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scen = _scenario(tmp_path / "s.yaml", "s")
    out = tmp_path / "run"
    args = ["run", str(scen), "--headless", "--no-plot", "--out", str(out), "-q"]
    assert main(args) == 0
    (out / "metrics.json").write_text("stale")
    assert main(args) == 2  # without --force an existing run directory is kept
    assert main([*args, "--force"]) == 0
    assert (out / "metrics.json").read_text() != "stale"
    capsys.readouterr()


#: an observer that, at its first step, copies what ``--out`` holds then (the earlier run's
#: metrics.json) to a file beside it
WITNESS = """\
from pathlib import Path

from amsa_phys.model.template import Kind, Port, Template


class Witness(Template):
    kind = Kind.OBSERVER
    inputs = (Port("x"),)
    outputs = (Port("y", 0.0),)
    params = ()

    def do_step(self, t, inp):
        here = Path(__file__).parent
        seen = here / "seen.txt"
        if not seen.exists():
            old = here / "run" / "metrics.json"
            seen.write_text(old.read_text() if old.exists() else "nothing")
        return {"y": 0.0}
"""


def _witnessed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A scenario of the MDE world with the :data:`WITNESS` observer added."""
    (tmp_path / "witness.py").write_text(WITNESS)
    monkeypatch.syspath_prepend(str(tmp_path))
    world = yaml.safe_load(WORLD.read_text())
    world["components"]["W"] = {
        "template": "witness:Witness",
        "freq": 1,
        "inputs": {"x": "MyDistanceMonitor.distanceFollowerToLeader"},
    }
    (tmp_path / "w.yaml").write_text(yaml.safe_dump(world))
    scen = _scenario(tmp_path / "s.yaml", "s")
    scen.write_text(scen.read_text().replace(f"world: {WORLD}", "world: w.yaml"))
    return scen


def test_force_keeps_the_earlier_run_whole_until_the_new_one_ends(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """While a run replaces another with --force, the earlier one stays whole in ``--out``
    (the new one is written beside it and renamed into place when it ends), and no staged
    directory is left behind."""
    scen = _witnessed(tmp_path, monkeypatch)
    out = tmp_path / "run"
    args = ["run", str(scen), "--headless", "--no-plot", "--out", str(out), "-q"]
    assert main(args) == 0
    (out / "metrics.json").write_text("the earlier run")
    (tmp_path / "seen.txt").unlink()
    assert main([*args, "--force"]) == 0
    assert (tmp_path / "seen.txt").read_text() == "the earlier run"  # whole during the run
    assert (out / "metrics.json").read_text() != "the earlier run"  # replaced at its end
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
    capsys.readouterr()


def test_force_keeps_the_earlier_run_when_the_new_one_fails_outside_the_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A failure that is not the run's (here: the trace's writer cannot start) leaves the
    earlier run as it was, and no staged directory behind; a run that faults replaces it
    with its own outputs, as an interrupted one does (they are the run's)."""
    scen = _scenario(tmp_path / "s.yaml", "s")
    out = tmp_path / "run"
    args = ["run", str(scen), "--headless", "--no-plot", "--out", str(out), "-q"]
    assert main(args) == 0
    before = _snapshot(out)

    def broken(*_args: object, **_kwargs: object) -> None:
        raise RuntimeError("a bug")

    monkeypatch.setattr("amsa_phys.runs.single.TraceWriter", broken)
    with pytest.raises(RuntimeError, match="a bug"):
        main([*args, "--force"])
    assert _snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
    capsys.readouterr()


@pytest.mark.parametrize("where", ["scenario_dir", "parent", "cwd"])
def test_force_onto_the_inputs_or_cwd_is_refused(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    where: str,
) -> None:
    proj = tmp_path / "proj"
    (proj / "scenarios").mkdir(parents=True)
    scen = _scenario(proj / "scenarios" / "s.yaml", "s")
    # make the directory look like ours too: the input rule must hold regardless
    for d in (proj, proj / "scenarios"):
        (d / MARKER).write_text("planted")
    monkeypatch.chdir(proj)
    out = {"scenario_dir": proj / "scenarios", "parent": proj, "cwd": Path(".")}[where]
    before = _snapshot(tmp_path)
    code = main(["run", str(scen), "--headless", "--out", str(out), "--force", "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1
    assert "--out" in err[0]
    assert _snapshot(tmp_path) == before


def test_force_does_not_follow_a_symlink(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = _scenario(tmp_path / "s.yaml", "s")
    target = tmp_path / "target"
    target.mkdir()
    (target / MARKER).write_text("x")
    (target / "keep.txt").write_text("keep")
    link = tmp_path / "link"
    link.symlink_to(target)
    code = main(["run", str(scen), "--headless", "--out", str(link), "--force", "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1
    assert "symbolic link" in err[0]
    assert (target / "keep.txt").read_text() == "keep"


@pytest.mark.parametrize("force", [False, True])
def test_a_dangling_link_as_out_is_refused_as_a_link(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], force: bool
) -> None:
    """``--out`` a link to nothing (yet): refused as a link, with or without --force, and
    nothing is made where it points."""
    scen = _scenario(tmp_path / "s.yaml", "s")
    link = tmp_path / "link"
    link.symlink_to(tmp_path / "elsewhere")
    argv = ["run", str(scen), "--headless", "--out", str(link), "-q", *(["--force"] * force)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "is a symbolic link" in err[0]
    assert not (tmp_path / "elsewhere").exists()


def test_safe_name_is_one_harmless_component() -> None:
    assert safe_name("..") == "__"
    assert safe_name(".") == "_"
    assert safe_name("/etc") == "_etc"
    assert safe_name("a/b\\c") == "a_b_c"
    assert safe_name("\x1b[2J") == "__2J"
    assert safe_name("") == "scenario"
    assert safe_name("scenario1") == "scenario1"
    assert len(safe_name("x" * 1000)) == 80
    assert unique_names(["a", "A", "a", "b"]) == ["a", "A-2", "a-3", "b"]


@pytest.mark.parametrize("out", ["new/..", "new/../.", "a/b/../.."])
def test_out_through_a_new_directory_and_back_is_judged_as_where_it_lands(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    out: str,
) -> None:
    # "new/.." is the current directory: it used to pass as "does not exist", was created
    # (making new/) and the run wrote among the user's files
    monkeypatch.chdir(tmp_path)
    scen = _scenario(tmp_path / "s.yaml", "x")
    (tmp_path / "mine.txt").write_text("keep")
    before = _snapshot(tmp_path)
    assert main(["run", str(scen), "--headless", "--out", out, "--force", "-q"]) == 2
    assert capsys.readouterr().err == (
        f"error: {tmp_path}: --out: is the current directory; choose a new directory for "
        "the outputs\n"
    )
    assert _snapshot(tmp_path) == before


def test_a_link_planted_where_the_staged_run_would_go_is_never_written_through(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``run --force`` stages the new run in a directory beside ``--out`` made by ``mkdir``
    under a fresh name: a link someone planted at a name it would choose (here: the very
    first) is skipped, and the directory it points to gets nothing. The same for the name
    the earlier run is moved to before it is removed."""
    scen = _scenario(tmp_path / "s.yaml", "s")
    out = tmp_path / "run"
    args = ["run", str(scen), "--headless", "--no-plot", "--out", str(out), "-q"]
    assert main(args) == 0
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "p.txt").write_text("precious")
    pid = os.getpid()
    (tmp_path / f".run.amsa-tmp-{pid}-planted1").symlink_to(victim)
    old = tmp_path / f".run.amsa-old-{pid}-planted2"
    old.mkdir()
    (old / "x").write_text("someone's")
    # the first name each would take is taken: the staged run goes to fresh001, the
    # earlier run to fresh002
    tokens = iter(["planted1", "fresh001", "planted2", "fresh002"])
    monkeypatch.setattr("amsa_phys.runs.rundir.secrets.token_hex", lambda _n: next(tokens))
    assert main([*args, "--force"]) == 0
    assert sorted(p.name for p in victim.iterdir()) == ["p.txt"]
    assert (old / "x").read_text() == "someone's"
    assert not out.is_symlink()
    assert (out / "metrics.json").is_file()
    left = sorted(p.name for p in tmp_path.iterdir() if p.name.startswith("."))
    assert left == [f".run.amsa-old-{pid}-planted2", f".run.amsa-tmp-{pid}-planted1"]
    capsys.readouterr()


def test_a_run_whose_output_another_put_in_place_meanwhile_says_so_in_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two commands replacing one directory: the one that renames its outputs into place
    last finds the other's there. It removes nothing, and says in one line where its own
    outputs are kept."""
    from amsa_phys.errors import ConfigError
    from amsa_phys.runs import rundir

    out = tmp_path / "run"
    staged = rundir.staged_dir(out, force=False, flag="--out", kind="run")
    (staged / "trace.csv").write_text("mine")
    real = os.replace

    def another_first(src: Any, dst: Any) -> None:
        if Path(dst) == out and not out.exists():  # the other command's rename lands first
            out.mkdir()
            (out / "trace.csv").write_text("theirs")
        real(src, dst)

    monkeypatch.setattr(rundir.os, "replace", another_first)
    with pytest.raises(ConfigError, match="was replaced by another command") as err:
        rundir.commit_staged(staged, out)
    assert str(staged) in str(err.value)
    assert (out / "trace.csv").read_text() == "theirs"
    assert (staged / "trace.csv").read_text() == "mine"
