"""Every file amsa-phys writes: a full disk, a read-only file system, a directory in the way
or a planted symbolic link gives one line naming the file and a documented exit code, never a
truncated file under its final name, never a write through the link; metrics.json is valid
JSON and is still written when the trace filled the disk.

The disk-full cases run on a small tmpfs (root only: skipped with the reason elsewhere).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from amsa_phys.atomic import write_atomic
from amsa_phys.cli.main import main
from amsa_phys.engine.tracefile import TraceWriter

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
PAGE = 4096
ENOSPC = "No space left on device"


def scenario(folder: Path, duration: float = 2, extra: str = "") -> Path:
    path = folder / "s.yaml"
    path.write_text(
        f"world: {WORLD}\nduration: {duration}\nseed: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
        "expect:\n  - {metric: collisions, below: 1}\n" + extra
    )
    return path


def strict_json(path: Path) -> Any:
    """Parse as JSON proper: ``Infinity`` or ``NaN`` is an error, as in every other reader."""

    def refuse(constant: str) -> None:
        raise ValueError(f"{constant} is not JSON")

    return json.loads(path.read_text(), parse_constant=refuse)


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*.tmp"))


def _mount(where: Path, options: str) -> str | None:
    """Mount a tmpfs at ``where``; the reason it cannot be done, or None."""
    if not hasattr(os, "geteuid") or os.geteuid() != 0 or shutil.which("mount") is None:
        return "mounting a tmpfs needs root and mount(8)"
    proc = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(where)],
        capture_output=True,
        text=True,
        check=False,
    )
    return None if proc.returncode == 0 else f"cannot mount a tmpfs here: {proc.stderr.strip()}"


@pytest.fixture(scope="module")
def tmpfs(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """An 8 MiB file system to fill up, shared by this module's tests."""
    root = tmp_path_factory.mktemp("tmpfs")
    why = _mount(root, "size=8m")
    if why is not None:
        pytest.skip(why)
    yield root
    subprocess.run(["umount", "-l", str(root)], check=False)


@pytest.fixture
def full_disk(tmpfs: Path) -> Iterator[Callable[[int], Path]]:
    """``leave(n)``: a fresh folder on the tmpfs with only ``n`` bytes left free."""
    made: list[Path] = []

    def leave(free: int) -> Path:
        folder = tmpfs / f"case{len(made)}"
        folder.mkdir()
        made.append(folder)
        st = os.statvfs(tmpfs)
        filler = st.f_bavail * st.f_frsize - free
        with (folder / "filler").open("wb") as fh:  # written, not sparse: tmpfs counts pages
            while filler > 0:
                chunk = min(filler, 1 << 20)
                fh.write(b"\0" * chunk)
                filler -= chunk
        (folder / "filler").rename(tmpfs / f"filler{len(made)}")
        return folder

    yield leave
    for path in tmpfs.iterdir():
        if path.is_dir():
            shutil.rmtree(path)
        else:
            path.unlink()


def one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1, err
    return err.rstrip("\n")


def test_the_trace_filling_the_disk_leaves_no_trace_and_still_writes_metrics(
    tmp_path: Path, full_disk: Callable[[int], Path], capsys: pytest.CaptureFixture[str]
) -> None:
    out = full_disk(6 * PAGE) / "o"  # the marker fits; a 30 s trace (~300 KB) does not
    argv = ["run", str(scenario(tmp_path, 30)), "--headless", "--out", str(out), "-q"]
    assert main([*argv, "--no-plot"]) == 3
    assert one_line(capsys) == f"error: cannot write {out / 'trace.csv'}: {ENOSPC}"
    assert not (out / "trace.csv").exists()
    assert leftovers(out) == []  # the torn temporary file is gone: its space went to metrics
    metrics = strict_json(out / "metrics.json")
    assert metrics["status"] == f"fault: cannot write {out / 'trace.csv'}: {ENOSPC}"
    assert metrics["simulated"] < 30


def test_plots_that_do_not_fit_are_named_and_never_left_torn(
    tmp_path: Path, full_disk: Callable[[int], Path], capsys: pytest.CaptureFixture[str]
) -> None:
    scen = scenario(tmp_path)
    sizes = tmp_path / "sizes"  # the same run without plots: what the text files take
    assert main(["run", str(scen), "--headless", "--out", str(sizes), "-q", "--no-plot"]) == 0
    pages = sum(-(-f.stat().st_size // PAGE) for f in sizes.iterdir())
    out = full_disk((pages + 1) * PAGE) / "o"  # a page to spare: a plot is ~10 pages
    assert main(["run", str(scen), "--headless", "--out", str(out), "-q"]) == 3
    assert one_line(capsys) == f"error: cannot write {out / 'distance.png'}: {ENOSPC}"
    names = sorted(p.name for p in out.iterdir())
    assert names == [".amsa-phys-run", "metrics.json", "scenario.yaml", "trace.csv"]
    assert (out / "trace.csv").read_bytes() == (sizes / "trace.csv").read_bytes()


@pytest.mark.parametrize("what", ["snapshot", "video", "graph", "junit", "results"])
def test_other_outputs_on_a_full_disk_exit_3_naming_the_file(
    tmp_path: Path,
    full_disk: Callable[[int], Path],
    capsys: pytest.CaptureFixture[str],
    what: str,
) -> None:
    full = full_disk(PAGE if what == "results" else 0)
    scen = scenario(tmp_path)
    run = ["run", str(scen), "--headless", "--out", str(tmp_path / "o"), "-q", "--no-plot"]
    if what == "snapshot":
        assert main([*run, "--snapshot", str(full / "s.png"), "--size", "320x240"]) == 3
        assert one_line(capsys) == f"error: cannot write {full / 's.png'}: {ENOSPC}"
        assert "snapshot" not in strict_json(tmp_path / "o" / "metrics.json")
    elif what == "video":
        assert main([*run, "--record", str(full / "v.mp4"), "--size", "320x240"]) == 3
        err = one_line(capsys)
        assert err.startswith("error: run fault at t=")
        assert f"in recorder: ffmpeg failed writing {full / 'v.mp4'}: " in err
        assert strict_json(tmp_path / "o" / "metrics.json")["status"].startswith("fault: ")
    elif what == "graph":
        assert main(["graph", str(WORLD), "-o", str(full / "g.png")]) == 3
        assert one_line(capsys) == f"error: cannot write {full / 'g.png'}: {ENOSPC}"
    elif what == "junit":
        assert main(["test", str(scen), "--junit", str(full / "j.xml"), "-j", "1"]) == 3
        assert one_line(capsys) == f"error: cannot write {full / 'j.xml'}: {ENOSPC}"
    else:
        out = full / "sw"
        argv = ["sweep", str(scen), "--grid", "MyFollowerController.Kv=0.1,0.2", "-j", "1"]
        assert main([*argv, "--out", str(out)]) == 3
        # the sweep's first file is the scenario it runs (adapt reads it back), then results
        assert one_line(capsys) == f"error: cannot write {out / 'scenario.yaml'}: {ENOSPC}"
    names = [p.name for p in full.rglob("*") if p.is_file()]
    assert set(names) <= {".amsa-phys-run"}, names  # nothing torn under any name


def test_a_read_only_file_system_is_refused_before_the_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ro = tmp_path / "ro"
    ro.mkdir()
    why = _mount(ro, "ro,size=64k")
    if why is not None:
        pytest.skip(why)
    try:
        assert main(["graph", str(WORLD), "-o", str(ro / "g.png")]) == 2
        assert one_line(capsys) == f"error: {ro}: --output: directory is not writable"
        scen = scenario(tmp_path)
        assert main(["test", str(scen), "--junit", str(ro / "j.xml")]) == 2
        assert one_line(capsys) == f"error: {ro}: --junit: directory is not writable"
    finally:
        subprocess.run(["umount", "-l", str(ro)], check=False)


def test_a_directory_where_an_output_file_goes_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scen = scenario(tmp_path)
    for name in ("v.mp4", "s.png", "g.png", "j.xml"):
        (tmp_path / name).mkdir()
    run = ["run", str(scen), "--headless", "--out", str(tmp_path / "o"), "--force"]
    for flag, name in (("--record", "v.mp4"), ("--snapshot", "s.png")):
        assert main([*run, flag, str(tmp_path / name)]) == 2
        assert one_line(capsys) == (
            f"error: {tmp_path / name}: {flag}: is a directory; give a file name"
        )
    assert main(["graph", str(WORLD), "-o", str(tmp_path / "g.png")]) == 2
    assert (
        one_line(capsys)
        == f"error: {tmp_path / 'g.png'}: --output: is a directory; give a file name"
    )
    assert main(["test", str(scen), "--junit", str(tmp_path / "j.xml")]) == 2
    assert (
        one_line(capsys)
        == f"error: {tmp_path / 'j.xml'}: --junit: is a directory; give a file name"
    )
    assert not (tmp_path / "o").exists()  # refused before the run


def test_junit_into_a_missing_folder_creates_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    report = tmp_path / "reports" / "ci" / "junit.xml"
    assert main(["test", str(scenario(tmp_path)), "--junit", str(report), "-j", "1"]) == 0
    assert report.read_text().startswith("<?xml")


def test_a_planted_link_at_the_temporary_name_is_never_followed(tmp_path: Path) -> None:
    victim = tmp_path / "victim"
    victim.write_text("precious\n")
    target = tmp_path / "out.json"
    (tmp_path / "out.json.tmp").symlink_to(victim)
    write_atomic(target, "{}\n")
    assert victim.read_text() == "precious\n"
    assert target.read_text() == "{}\n"
    assert not target.is_symlink()
    assert leftovers(tmp_path) == []
    (tmp_path / "trace.csv.tmp").symlink_to(victim)
    trace = TraceWriter(tmp_path / "trace.csv", ["a"])
    trace.write(0.0, [1.0])
    trace.close()
    assert victim.read_text() == "precious\n"
    assert (tmp_path / "trace.csv").read_text() == "t,a\n0.0,1.0\n"


def test_video_snapshot_and_graph_do_not_write_through_planted_links(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    victim = tmp_path / "victim"
    victim.write_text("precious\n")
    for name in ("v.mp4.tmp", "s.png.tmp", "g.svg.tmp"):
        (tmp_path / name).symlink_to(victim)
    argv = ["run", str(scenario(tmp_path, 1)), "--headless", "--out", str(tmp_path / "o")]
    argv += ["-q", "--no-plot", "--size", "64x64", "--fps", "5"]
    assert (
        main([*argv, "--record", str(tmp_path / "v.mp4"), "--snapshot", str(tmp_path / "s.png")])
        == 0
    )
    assert main(["graph", str(WORLD), "-o", str(tmp_path / "g.svg")]) == 0
    assert victim.read_text() == "precious\n"
    assert (tmp_path / "v.mp4").stat().st_size > 0
    assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "g.svg").read_text().lstrip().startswith("<?xml")
    assert leftovers(tmp_path) == []


def test_metrics_json_stays_json_when_a_metric_overflows(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 1.7e308 is finite; its error against a reference of -1.7e308 is not
    scen = tmp_path / "max.yaml"
    scen.write_text(
        "world:\n  components:\n"
        "    R: {template: 'rogue:Rogue', freq: 4, params: {mode: max, at: 0}}\n"
        "duration: 2\nquality: {signal: R.u, reference: -1.7e+308}\n"
    )
    out = tmp_path / "o"
    assert main(["run", str(scen), "--headless", "--out", str(out), "-q"]) == 0
    assert capsys.readouterr().err == ""  # plots drawn without warnings either
    metrics = strict_json(out / "metrics.json")
    assert metrics["overall"]["rms_error"] is None
    assert metrics["overall"]["max_distance"] == 1.7e308
    assert metrics["nonfinite"] == [
        "overall.mean_error",
        "overall.rms_error",
        "phases[0].mean_error",
        "phases[0].rms_error",
    ]
    assert (out / "distance.png").stat().st_size > 0


def test_a_bag_where_no_file_can_be_made_is_refused_before_the_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--bag /proc/x.mcap`` (a directory root may write to by its permissions, where no
    file can be made) ended the run with exit 3 and a run directory without trace or
    metrics; an empty name was ignored, a file taken for a directory called missing. Each is
    refused before the run, naming --bag, exit 2, nothing written."""
    scen = scenario(tmp_path)
    (tmp_path / "plain").write_text("a file\n")
    run = ["run", str(scen), "--headless", "-q", "--out", str(tmp_path / "o")]
    cases = [
        ("", "error: --bag: an empty file name"),
        (
            str(tmp_path / "plain" / "x.mcap"),
            f"error: {tmp_path / 'plain' / 'x.mcap'}: --bag: {tmp_path / 'plain'} is not a "
            "directory",
        ),
        (
            str(tmp_path / "none" / "x.mcap"),
            f"error: {tmp_path / 'none' / 'x.mcap'}: --bag: directory does not exist",
        ),
    ]
    if Path("/proc").is_dir():  # a directory that takes no new file, root or not
        cases.append(("/proc/x.mcap", "error: /proc/x.mcap: --bag: directory is not writable"))
    for bag, said in cases:
        assert main([*run, "--bag", bag]) == 2
        assert one_line(capsys).startswith(said)
        assert not (tmp_path / "o").exists()
