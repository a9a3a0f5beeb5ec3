"""``graph -o`` and ``plot -o`` follow the project's rule for an output file.

Nothing already written is lost: an existing file amsa-phys did not draw (a text file named
``x.png``, a user's DOT graph) is refused without ``--force``; a picture amsa-phys drew is
replaced, so regenerating a figure needs no flag; a symbolic link is refused without
``--force`` and replaced, not followed, with it; and ``plot -o`` naming one of the files the
plot reads (the sweep's ``results.csv``) is refused even with ``--force``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from refusal import assert_one_line_refusal

from amsa_phys.cli.main import main
from amsa_phys.runs.outfile import drawn_by_us

ROOT = Path(__file__).resolve().parents[2]
WORLD = str(ROOT / "worlds" / "mde_challenge.yaml")
ROWS = (
    "run,MyFollowerController.Kv,seed_index,seed,error,rms_error\n0,0.1,0,1,,0.8\n1,0.2,0,1,,0.4\n"
)


def _sweep(tmp_path: Path) -> Path:
    sweep = tmp_path / "sweep"
    sweep.mkdir()
    (sweep / "results.csv").write_text(ROWS)
    return sweep


@pytest.mark.parametrize("name", ["g.png", "g.svg", "g.dot"])
def test_graph_replaces_its_own_picture_and_refuses_anything_else(
    tmp_path: Path, capsys, name: str
) -> None:
    out = tmp_path / name
    assert main(["graph", WORLD, "-o", str(out)]) == 0
    assert main(["graph", WORLD, "-o", str(out)]) == 0  # regenerated: no --force needed
    mine = tmp_path / f"mine-{name}"
    mine.write_text("digraph mine { a -> b }\n")
    capsys.readouterr()
    code = main(["graph", WORLD, "-o", str(mine)])
    assert_one_line_refusal(code, capsys.readouterr().err, "not written by amsa-phys", "error:")
    assert mine.read_text() == "digraph mine { a -> b }\n"
    assert main(["graph", WORLD, "-o", str(mine), "--force"]) == 0
    assert drawn_by_us(mine)


def test_graph_replaces_a_link_only_with_force_and_never_its_target(tmp_path: Path, capsys) -> None:
    target = tmp_path / "notes.txt"
    target.write_text("keep me\n")
    link = tmp_path / "g.png"
    link.symlink_to(target)
    code = main(["graph", WORLD, "-o", str(link)])
    assert_one_line_refusal(code, capsys.readouterr().err, "symbolic link", "error:")
    assert main(["graph", WORLD, "-o", str(link), "--force"]) == 0
    assert not link.is_symlink()
    assert drawn_by_us(link)
    assert target.read_text() == "keep me\n"


def test_plot_refuses_to_replace_a_file_it_did_not_draw(tmp_path: Path, capsys) -> None:
    sweep = _sweep(tmp_path)
    photo = tmp_path / "photo.png"
    photo.write_bytes(b"not a picture amsa-phys drew")
    code = main(["plot", str(sweep), "-o", str(photo)])
    assert_one_line_refusal(code, capsys.readouterr().err, "not written by amsa-phys", "error:")
    assert photo.read_bytes() == b"not a picture amsa-phys drew"
    assert main(["plot", str(sweep), "-o", str(photo), "--force"]) == 0
    assert main(["plot", str(sweep), "-o", str(photo)]) == 0  # now its own: redrawn


def test_plot_never_writes_over_the_sweep_it_reads(tmp_path: Path, capsys) -> None:
    sweep = _sweep(tmp_path)
    code = main(["plot", str(sweep), "-o", str(sweep / "results.csv"), "--force"])
    assert_one_line_refusal(code, capsys.readouterr().err, "is an input", "error:")
    assert (sweep / "results.csv").read_text() == ROWS


def test_plot_of_a_run_checks_the_trajectory_beside_o_too(tmp_path: Path, capsys) -> None:
    scen = tmp_path / "s.yaml"
    scen.write_text(
        f"world: {WORLD}\nduration: 1\n"
        "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15}\n"
    )
    run = tmp_path / "run"
    assert main(["run", str(scen), "--headless", "--out", str(run), "-q", "--no-plot"]) == 0
    mine = tmp_path / "d-trajectory.png"
    mine.write_text("my notes\n")
    capsys.readouterr()
    code = main(["plot", str(run), "-o", str(tmp_path / "d.png")])
    assert_one_line_refusal(code, capsys.readouterr().err, "d-trajectory.png", "error:")
    assert mine.read_text() == "my notes\n"
    assert not (tmp_path / "d.png").exists()  # refused before anything was drawn
    code = main(["plot", str(run), "-o", str(run / "metrics.json"), "--force"])
    assert_one_line_refusal(code, capsys.readouterr().err, "is an input", "error:")
