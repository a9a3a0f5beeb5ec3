"""convergence.png: what its axes tell a reader of a falsification's directory."""

from __future__ import annotations

from pathlib import Path

import pytest
from figcapture import keep_figures

from amsa_phys.plots import convergence


def test_run_axis_names_the_file_that_numbers_the_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The x axis sends the reader to the file whose `run` column it counts: falsify writes
    results.csv (there is no runs.csv), so the label must name results.csv."""
    figures = keep_figures(monkeypatch, convergence)
    convergence.plot_convergence(
        [0.4, 0.9, None, 1.3], [0, 0, 1, 1], "rms_error", True, tmp_path / "c.png", "t"
    )
    (ax,) = [a for a in figures[0].axes if a.get_label() != "<colorbar>"]
    assert ax.get_xlabel() == "run (as numbered in results.csv)"
