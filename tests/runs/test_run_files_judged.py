"""``plot`` and ``view`` judge a run's ``metrics.json`` and ``trace.csv`` on reading: a
damaged or forged file is one line naming the file and the key or line, exit 2 -- never a
traceback (AttributeError, OverflowError, numpy's ``SVD did not converge``)."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = ROOT / "tests" / "fixtures" / "mde_short.yaml"


@pytest.fixture(scope="module")
def clean_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("made") / "run"
    argv = ["run", str(SCENARIO), "--headless", "-q", "--no-plot", "--duration", "4"]
    assert main([*argv, "--out", str(out)]) == 0
    return out


def _metrics(change: Callable[[dict[str, Any]], None]) -> Callable[[Path], None]:
    def edit(run: Path) -> None:
        m = json.loads((run / "metrics.json").read_text())
        change(m)
        (run / "metrics.json").write_text(json.dumps(m))

    return edit


def _raw_metrics(text: str) -> Callable[[Path], None]:
    return lambda run: (run / "metrics.json").write_text(text)


def _set(key: str, value: Any) -> Callable[[dict[str, Any]], None]:
    def change(m: dict[str, Any]) -> None:
        where: Any = m
        parts = key.split("/")
        for part in parts[:-1]:
            where = where[int(part)] if isinstance(where, list) else where[part]
        last = parts[-1]
        if isinstance(where, list):
            where[int(last)] = value
        else:
            where[last] = value

    return change


def _trace_rows(change: Callable[[list[str]], None]) -> Callable[[Path], None]:
    def edit(run: Path) -> None:
        lines = (run / "trace.csv").read_text().splitlines()
        change(lines)
        (run / "trace.csv").write_text("\n".join(lines) + "\n")

    return edit


def _cell(row: int, col: int, value: str) -> Callable[[list[str]], None]:
    def change(lines: list[str]) -> None:
        cells = lines[row].split(",")
        cells[col] = value
        lines[row] = ",".join(cells)

    return change


def _every_value(value: str) -> Callable[[list[str]], None]:
    def change(lines: list[str]) -> None:
        for i in range(1, len(lines)):
            t = lines[i].split(",")[0]
            lines[i] = ",".join([t] + [value] * (lines[i].count(",")))

    return change


#: case -> (damage, what the one line must say)
REFUSED = {
    "event-a-string": (
        _metrics(_set("events", ["boom"])),
        "metrics.json: not a run's metrics: events[0] is not an object (got str)",
    ),
    "events-list-of-ints": (
        _metrics(_set("events", [1, 2])),
        "events[0] is not an object (got int)",
    ),
    "event-time-text": (
        _metrics(_set("events", [{"t": "x", "kind": "collision"}])),
        "events[0].t is not a number",
    ),
    "event-time-nan": (
        _raw_metrics('{"events": [{"t": NaN, "kind": "collision"}]}'),
        "events[0].t is not finite (nan)",
    ),
    "event-kind-a-list": (
        _metrics(_set("events", [{"t": 1.0, "kind": [1]}])),
        "events[0].kind is not text",
    ),
    "phase-change-an-int": (
        _metrics(_set("phases/0/changes", [7])),
        "phases[0].changes[0] is not an object",
    ),
    "phase-at-1e308": (
        _metrics(_set("phases/0/start", 1e308)),
        "phases[0].start is outside 0..1,000,000 s (1e+308)",
    ),
    "phase-start-negative": (
        _metrics(_set("phases/0/start", -5)),
        "phases[0].start is outside 0..1,000,000 s (-5)",
    ),
    "phase-set-nested": (
        _metrics(_set("phases/0/set", {"A.b": {"c": 1}})),
        "phases[0].set.A.b is not a parameter value",
    ),
    "phase-label-a-number": (
        _metrics(_set("phases/0/label", 3)),
        "phases[0].label is not text",
    ),
    "overall-metric-text": (
        _metrics(_set("overall/rms_error", "oops")),
        "metrics.json: not a run's metrics: overall.rms_error is not a number",
    ),
    "phase-metric-a-list": (
        _metrics(_set("phases/0/max_distance", [1])),
        "phases[0].max_distance is not a number",
    ),
    "overall-partial-text": (
        _metrics(_set("overall/partial", "yes")),
        "overall.partial is not true or false",
    ),
    "quality-reference-inf": (
        _raw_metrics('{"quality": {"signal": "a", "reference": Infinity, "tolerance": 1}}'),
        "quality.reference is not a finite number",
    ),
    "deep-json": (
        _raw_metrics("[" * 100000 + "]" * 100000),
        "metrics.json: invalid JSON: nested too deeply",
    ),
    "trace-t-inf": (
        _trace_rows(_cell(5, 0, "inf")),
        "trace.csv:6: t is not a finite time (inf)",
    ),
    "trace-t-nan": (
        _trace_rows(_cell(5, 0, "nan")),
        "trace.csv:6: t is not a finite time (nan)",
    ),
    "trace-t-backwards": (
        _trace_rows(_cell(5, 0, "0")),
        "trace.csv:6: t goes backwards",
    ),
    "trace-t-1e300": (
        _trace_rows(_cell(5, 0, "1e300")),
        "trace.csv:6: t is outside 0..1,000,000 s",
    ),
}


def _damaged(clean: Path, tmp: Path, damage: Callable[[Path], None]) -> Path:
    run = tmp / "r"
    shutil.copytree(clean, run)
    damage(run)
    return run


@pytest.mark.parametrize("case", REFUSED, ids=list(REFUSED))
def test_plot_refuses_in_one_line(
    clean_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    damage, said = REFUSED[case]
    run = _damaged(clean_run, tmp_path, damage)
    assert main(["plot", str(run)]) == 2
    err = capsys.readouterr().err
    assert said in err
    assert len(err.strip().splitlines()) == 1, err
    assert not (run / "distance.png").exists()


@pytest.mark.parametrize("case", REFUSED, ids=list(REFUSED))
def test_view_refuses_in_one_line(clean_run: Path, tmp_path: Path, case: str) -> None:
    from amsa_phys.cli.view import load_run
    from amsa_phys.errors import ConfigError

    damage, said = REFUSED[case]
    run = _damaged(clean_run, tmp_path, damage)
    with pytest.raises(ConfigError) as caught:
        load_run(run)
    assert said.split(": ", 1)[-1] in str(caught.value)


#: damaged values that are still a run: drawn (the unplottable left out), never a traceback
DRAWN = {
    "all-nan": _trace_rows(_every_value("nan")),
    "values-1e300": _trace_rows(_every_value("1e300")),
    "values-inf": _trace_rows(_every_value("-inf")),
}


@pytest.mark.parametrize("case", DRAWN, ids=list(DRAWN))
def test_unplottable_values_are_drawn_as_gaps(clean_run: Path, tmp_path: Path, case: str) -> None:
    from amsa_phys.cli.view import load_run

    run = _damaged(clean_run, tmp_path, DRAWN[case])
    assert main(["plot", str(run)]) == 0
    assert (run / "trajectory.png").stat().st_size > 0
    scene = load_run(run)
    scene.frame(scene.rows - 1)  # the replay draws a frame of it


def _scenario_line(old: str, new: str) -> Callable[[Path], None]:
    def edit(run: Path) -> None:
        text = (run / "scenario.yaml").read_text()
        assert old in text
        (run / "scenario.yaml").write_text(text.replace(old, new, 1))

    return edit


#: hand edits of the resolved scenario.yaml -> what the one line says (file:line: key: why)
SCENARIO_EDITS = {
    "a-misspelt-key": (
        _scenario_line("\nduration: 4\n", "\nduraton: 4\n"),
        "scenario.yaml:197: duraton: unknown key (did you mean duration?)",
    ),
    "a-gain-as-text": (
        _scenario_line("MyFollowerController.Kv: 0.35", "MyFollowerController.Kv: x"),
        "scenario.yaml:204: set.MyFollowerController.Kv: expected a number, got string 'x'",
    ),
    "an-unknown-parameter": (
        _scenario_line("MyFollowerController.Kv: 0.35", "MyFollowerController.Kz: 0.35"),
        "scenario.yaml:204: set.MyFollowerController.Kz: unknown parameter of template",
    ),
    "a-timeline-entry-without-set": (
        _scenario_line("\nduration: 4\n", "\nduration: 4\ntimeline: [{at: 2}]\n"),
        "scenario.yaml:198: timeline[0]: missing required key 'set'",
    ),
}


@pytest.mark.parametrize("case", SCENARIO_EDITS, ids=list(SCENARIO_EDITS))
def test_a_hand_edited_scenario_is_refused_by_view_and_said_by_plot(
    clean_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    """``view`` draws from the resolved scenario.yaml, so an edit it cannot trust is refused
    with its line and key, as ``validate`` refuses it; ``plot`` says the same line and draws
    the paths without the world (what it does whenever that file cannot be read)."""
    from amsa_phys.cli.view import load_run
    from amsa_phys.errors import ConfigError

    edit, said = SCENARIO_EDITS[case]
    run = _damaged(clean_run, tmp_path, edit)
    with pytest.raises(ConfigError) as caught:
        load_run(run)
    assert said in str(caught.value)
    assert main(["plot", str(run)]) == 0
    err = capsys.readouterr().err
    assert said in err
    assert err.strip().endswith("the paths are drawn without the world")
    assert len(err.strip().splitlines()) == 1, err


def test_the_clean_run_is_read_whole(clean_run: Path) -> None:
    """The checks refuse no run as a run writes it."""
    from amsa_phys.cli.view import load_run

    scene = load_run(clean_run)
    assert scene.t[-1] > 3.9
