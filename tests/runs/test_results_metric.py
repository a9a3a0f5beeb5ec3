"""The one-line refusal of a metric name (`sweep`, `plot` and `falsify --metric`)."""

from __future__ import annotations

import pytest

from amsa_phys.runs.results import unknown_metric


@pytest.mark.parametrize(
    ("name", "meant"),
    [
        ("max_after", "max_after_approach"),  # the table's column is `max after`
        ("rms_eror", "rms_error"),
        ("phase0.rms_eror", "phase0.rms_error"),
        ("Collisions", "collisions"),
    ],
)
def test_a_misspelt_metric_gets_the_nearest_name(name: str, meant: str) -> None:
    why = unknown_metric(name, 2)
    assert why is not None
    assert why.startswith(f"unknown metric {name!r} (did you mean {meant}?); known: ")


def test_a_phase_the_runs_do_not_reach_is_not_called_a_typo() -> None:
    why = unknown_metric("phase1.rms_error", 1)
    assert why is not None
    assert "did you mean" not in why
    assert why.endswith("; or phase0.<metric>")


def test_a_known_column_is_accepted() -> None:
    assert unknown_metric("phase1.max_after_approach", 2) is None
    assert unknown_metric("max_after_approach", 0) is None


def test_a_requirements_robustness_is_a_sweep_column() -> None:
    """``robustness.NAME`` of one of the scenario's STL requirements names its column; a
    misspelt requirement gets the nearest name and the list of those there are."""
    from amsa_phys.runs.results import unknown_sweep_metric

    assert unknown_sweep_metric("robustness.band", 1, ["band", "settled"]) is None
    assert unknown_sweep_metric("rms_error", 1, ["band"]) is None
    why = unknown_sweep_metric("robustness.bnd", 1, ["band", "settled"])
    assert why == "unknown requirement 'bnd' (did you mean band?); known: band, settled"
    why = unknown_sweep_metric("robustness.band", 1, [])
    assert why is not None
    assert why.startswith("unknown requirement 'band'; known: none")
    assert unknown_sweep_metric("max_after", 1, ["band"]) == unknown_metric("max_after", 1)


def test_sweep_and_plot_take_a_robustness_metric(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """The end to end of the docs' promise: ``sweep --metric robustness.NAME`` runs, prints
    the highest mean as best, and ``plot --metric robustness.NAME`` redraws its summary; a
    misspelt name is refused by both, exit 2, one line."""
    from pathlib import Path

    from amsa_phys.cli.main import main

    scenario = Path(__file__).resolve().parents[2] / "scenarios" / "paper_fig5_kv01.yaml"
    out = tmp_path / "s"
    argv = ["sweep", str(scenario), "--grid", "MyFollowerController.Kv=0.05,0.1", "-j", "1"]
    argv += ["--out", str(out), "--metric", "robustness.settled_by_150"]
    assert main(argv) == 0
    said = capsys.readouterr().out.splitlines()
    assert said[-1].startswith(
        "best (highest robustness.settled_by_150): MyFollowerController.Kv=0.1 -> "
    )
    png = tmp_path / "r.png"
    assert main(["plot", str(out), "--metric", "robustness.settled_by_150", "-o", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    capsys.readouterr()
    assert main(["plot", str(out), "--metric", "robustness.setled_by_150"]) == 2
    err = capsys.readouterr().err
    assert err == (
        "error: --metric: unknown requirement 'setled_by_150' (did you mean settled_by_150?); "
        "known: settled_by_150\n"
    )
    assert main([*argv[:-4], "--out", str(tmp_path / "t"), "--metric", "robustness.x"]) == 2
    assert not (tmp_path / "t").exists()


def test_a_sweep_too_short_for_a_requirement_says_its_column_stays_empty(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """``--duration`` shorter than a requirement's windows: said once before the runs, and
    the column is indeed empty (it was left empty without a word)."""
    import csv
    from pathlib import Path

    from amsa_phys.cli.main import main

    scenario = Path(__file__).resolve().parents[2] / "scenarios" / "paper_fig5_kv01.yaml"
    out = tmp_path / "s"
    argv = ["sweep", str(scenario), "--grid", "MyFollowerController.Kv=0.05,0.1", "-j", "1"]
    assert main([*argv, "--out", str(out), "--duration", "30"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == [
        "warning: the requirement settled_by_150 reads until t=300 s: runs of 30 s cannot "
        "judge it, so results.csv's robustness.settled_by_150 stays empty"
    ]
    with (out / "results.csv").open() as fh:
        assert all(row["robustness.settled_by_150"] == "" for row in csv.DictReader(fh))
    # the summary's title says the runs were cut, and so does a redraw of another metric
    from amsa_phys.plots.save import png_text

    assert png_text(out / "summary.png")["Title"].startswith(
        "paper_fig5_kv01: rms_error (1 seed); runs cut to 30 s of 300 s"
    )
    assert main(["plot", str(out), "--metric", "max_distance"]) == 0
    assert png_text(out / "summary.png")["Title"].startswith(
        "paper_fig5_kv01: max_distance (1 seed); runs cut to 30 s of 300 s"
    )
    capsys.readouterr()
    assert main([*argv, "--out", str(tmp_path / "full")]) == 0
    assert "warning" not in capsys.readouterr().err
    assert "runs cut" not in png_text(tmp_path / "full" / "summary.png")["Title"]


@pytest.mark.parametrize("command", ["sweep", "falsify"])
def test_an_integer_range_given_to_grid_is_never_read_as_base_60(tmp_path, capsys, command) -> None:  # type: ignore[no-untyped-def]
    """YAML 1.1 reads ``1:30`` as 90 (base 60): ``--grid Leader.cruisePower=1:30`` ran
    cruisePower 90 without a word. It is the text written, refused with the hint of the
    command's own --range."""
    from pathlib import Path

    from amsa_phys.cli.main import main

    scenario = Path(__file__).resolve().parents[2] / "scenarios" / "scenario1.yaml"
    argv = [command, str(scenario), "--grid", "Leader.cruisePower=1:30", "-j", "1"]
    argv += ["--out", str(tmp_path / "o"), "--duration", "5"]
    if command == "falsify":
        argv += ["--budget", "2"]
    assert main(argv) == 2
    spec = "1:30:5" if command == "sweep" else "1:30"
    form = "start:stop:n" if command == "sweep" else "lo:hi"
    assert capsys.readouterr().err == (
        "error: --grid Leader.cruisePower: expected a number, got string '1:30' (a range "
        f"{form} is given by --range: --range Leader.cruisePower={spec})\n"
    )
    assert not (tmp_path / "o").exists()


def test_a_base_60_looking_value_in_a_scenario_is_text(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from amsa_phys.model.yamlio import parse_yaml

    doc = parse_yaml("a: 1:30\nb: 0:30.5\nc: 90\nd: 1.5\n", "t.yaml")
    assert doc.data == {"a": "1:30", "b": "0:30.5", "c": 90, "d": 1.5}
