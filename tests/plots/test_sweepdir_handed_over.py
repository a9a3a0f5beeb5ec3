"""``amsa-phys plot SWEEPDIR`` on a sweep directory someone handed over: its ``summary.png``
and ``results.csv`` are data, read bounded in time and memory.

What ``plot`` reads of the old ``summary.png`` is its title's text (the scenario's name, the
"runs cut" note): read from the PNG's text chunks without decoding the picture, so a
"decompression bomb" (a huge image in a small file) still gives its title and a FIFO planted
under that name is not waited on. A ``results.csv`` larger than the limit is refused before
a byte of it is read: one line, exit 2.
"""

from __future__ import annotations

import os
import struct
import subprocess
import sys
import tracemalloc
import zlib
from pathlib import Path

import pytest
from deadlines import HANG_S
from refusal import assert_one_line_refusal

from amsa_phys.cli.main import main
from amsa_phys.errors import ConfigError
from amsa_phys.plots.save import png_text
from amsa_phys.runs.results import MAX_RESULTS_BYTES, read_results

ROWS = (
    "run,MyFollowerController.Kv,seed_index,seed,error,rms_error\n0,0.1,0,1,,0.8\n1,0.2,0,1,,0.4\n"
)
TITLE = "scenario1: rms_error (1 seed); runs cut to 20 s of 500 s"


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def _bomb_png(title: str) -> bytes:
    """A PNG that says it is 100000 x 100000 grey pixels (10 GB decoded), with a title."""
    head = struct.pack(">IIBBBBB", 100_000, 100_000, 8, 0, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + _chunk(b"IHDR", head)
        + _chunk(b"tEXt", b"Title\0" + title.encode("latin-1"))
        + _chunk(b"iTXt", "amsa-phys scenario\0\0\0\0\0scénario".encode())
        + _chunk(b"IDAT", zlib.compress(b"\0" * 100_001))
        + _chunk(b"IEND", b"")
    )


def _sweepdir(tmp_path: Path) -> Path:
    sweep = tmp_path / "sweep"
    sweep.mkdir()
    (sweep / "results.csv").write_text(ROWS)
    return sweep


def test_a_decompression_bomb_gives_its_title_without_being_decoded(tmp_path: Path) -> None:
    bomb = tmp_path / "summary.png"
    bomb.write_bytes(_bomb_png(TITLE))
    assert png_text(bomb) == {"Title": TITLE, "amsa-phys scenario": "scénario"}


def test_plot_redraws_a_sweep_whose_summary_is_a_bomb(tmp_path: Path, capsys) -> None:
    sweep = _sweepdir(tmp_path)
    (sweep / "summary.png").write_bytes(_bomb_png(TITLE))
    assert main(["plot", str(sweep)]) == 0
    assert capsys.readouterr().err == ""
    # the old title's scenario and cut note carried over into the redraw
    assert png_text(sweep / "summary.png")["Title"].startswith(
        "scénario: rms_error (1 seed); runs cut to 20 s of 500 s"
    )


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs are POSIX")
def test_plot_does_not_wait_on_a_fifo_planted_as_summary_png(tmp_path: Path) -> None:
    sweep = _sweepdir(tmp_path)
    os.mkfifo(sweep / "summary.png")
    env = {**os.environ, "MPLBACKEND": "Agg", "SDL_VIDEODRIVER": "dummy"}
    done = subprocess.run(
        [sys.executable, "-m", "amsa_phys", "plot", str(sweep)],
        capture_output=True,
        text=True,
        timeout=HANG_S,  # the old reader waited for a writer forever
        env=env,
    )
    assert done.returncode == 0, done.stderr
    assert (sweep / "summary.png").is_file()  # the FIFO replaced by the picture


def test_a_huge_results_csv_is_refused_before_it_is_read(tmp_path: Path) -> None:
    sweep = _sweepdir(tmp_path)
    with open(sweep / "results.csv", "r+b") as fh:  # a sparse file past the limit
        fh.truncate(MAX_RESULTS_BYTES + (64 << 20))
    tracemalloc.start()
    try:
        with pytest.raises(ConfigError, match="file too large"):
            read_results(sweep / "results.csv")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 8 << 20  # nothing of the file held


def test_plot_refuses_a_huge_results_csv_in_one_line(tmp_path: Path, capsys) -> None:
    sweep = tmp_path / "sS"
    sweep.mkdir()
    os.truncate(_touch(sweep / "results.csv"), 1 << 30)
    code = main(["plot", str(sweep)])
    assert_one_line_refusal(code, capsys.readouterr().err, "results.csv: file too large", "error:")


def _touch(path: Path) -> Path:
    path.touch()
    return path
