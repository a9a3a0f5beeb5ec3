"""STL requirements in scenarios: refused at load when a run could not judge them, judged in
metrics.json, ``amsa-phys test`` and JUnit, and the same robustness from every executor."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
DIST = "MyDistanceMonitor.distanceFollowerToLeader"


def scenario(tmp_path: Path, *expect: str, duration: int = 40, name: str = "s") -> Path:
    """A short scenario of the MDE world with these ``expect:`` lines."""
    text = (
        f"world: {WORLD}\nduration: {duration}\nseed: 1\nlog_rate: 4\n"
        f"quality: {{signal: {DIST}, reference: 15, tolerance: 1.5}}\n"
        "set: {Leader.behavior: 1, MyFollowerController.Kv: 0.35}\nexpect:\n"
        + "".join(f"  - {e}\n" for e in expect)
    )
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("entry", "words"),
    [
        (
            '{stl: "always[0:10](MyDistanceMonitor.distanceFollowerToLeader <= )", name: a}',
            "does not parse",
        ),
        (
            '{stl: "always[0:10](MyDistanceMonitor.distanceFolowerToLeader <= 20)", name: a}',
            "did you mean MyDistanceMonitor.distanceFollowerToLeader?",
        ),
        (
            '{stl: "always[0:10.1](MyDistanceMonitor.distanceFollowerToLeader <= 20)", name: a}',
            "not a multiple of the log period 0.25 s",
        ),
        (
            '{stl: "always[30:50](MyDistanceMonitor.distanceFollowerToLeader <= 20)", name: a}',
            "reads samples to t = 50 s, after the run's end at 40 s",
        ),
        ('{stl: "always(MyDistanceMonitor.distanceFollowerToLeader <= 20)"}', "needs a name"),
        ('{stl: "always(t >= 0)", name: "a b"}', "is not a requirement name"),
        ('{stl: "always(t >= 0)", name: a, below: 3}', "takes only stl and name"),
    ],
)
def test_a_formula_a_run_could_not_judge_is_refused_at_load(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], entry: str, words: str
) -> None:
    path = scenario(tmp_path, entry)
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err
    assert "\n" not in err
    assert f"{path}:8: expect[0]" in err  # file and line of the entry
    assert "Traceback" not in err


def test_a_name_used_twice_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = scenario(
        tmp_path, '{stl: "always(t >= 0)", name: a}', '{stl: "always(t >= 1)", name: a}'
    )
    assert main(["validate", str(path)]) == 2
    assert "used twice" in capsys.readouterr().err


def test_robustness_verdict_and_instant_in_metrics_test_and_junit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = scenario(
        tmp_path,
        f'{{stl: "always[20:40](abs({DIST} - 15) <= 3.5)", name: band}}',
        f'{{stl: "always[0:40]({DIST} <= 15.5)", name: tight}}',
    )
    out = tmp_path / "run"
    code = main(["run", str(path), "--headless", "--out", str(out)])
    assert code == 1  # the tight requirement fails: the follower starts 15 m behind and drifts
    req = json.loads((out / "metrics.json").read_text())["requirements"]
    assert main(["validate", str(out / "scenario.yaml")]) == 0  # the requirements written back
    assert "always[20:40]" in (out / "scenario.yaml").read_text()
    trace = list(csv.DictReader(io.StringIO((out / "trace.csv").read_text())))
    dist = [(float(r["t"]), float(r[DIST])) for r in trace]
    band = min(3.5 - abs(d - 15) for t, d in dist if 20 <= t <= 40)
    assert req["band"]["robustness"] == pytest.approx(band, abs=1e-12)
    assert req["band"]["verdict"] == "pass"
    worst_t, worst_d = max(dist, key=lambda td: td[1])
    assert req["tight"]["robustness"] == pytest.approx(15.5 - worst_d, abs=1e-12)
    assert req["tight"]["verdict"] == "fail"
    assert req["tight"]["instant"] == worst_t
    capsys.readouterr()
    junit = tmp_path / "j.xml"
    assert main(["test", str(path), "--junit", str(junit)]) == 1
    table = capsys.readouterr().out
    assert "requirement tight" in table
    assert "FAIL" in table
    xml = junit.read_text()
    assert "requirement band" in xml
    assert "<failure" in xml


def test_batched_and_pool_sweeps_give_the_same_robustness(tmp_path: Path) -> None:
    path = scenario(
        tmp_path,
        f'{{stl: "always[10:30](abs({DIST} - 15) <= 3.5)", name: band}}',
        f'{{stl: "eventually[0:5](({DIST} < 15.2) until[0:5] (t > 3))", name: nested}}',
        duration=30,
    )
    got = {}
    for executor, jobs in (("batch", "1"), ("local", "2")):
        out = tmp_path / executor
        args = ["sweep", str(path), "--grid", "MyFollowerController.Kv=0.05,0.35"]
        args += ["--seeds", "2", "--executor", executor, "-j", jobs, "--out", str(out)]
        assert main(args) == 0
        got[executor] = list(csv.DictReader(io.StringIO((out / "results.csv").read_text())))
    assert len(got["batch"]) == 4
    for a, b in zip(got["batch"], got["local"], strict=True):
        for name in ("robustness.band", "robustness.nested"):
            assert a[name] != ""
            assert abs(float(a[name]) - float(b[name])) <= 1e-12
    assert len({r["robustness.band"] for r in got["batch"]}) == 4  # each run its own column


def test_a_run_cut_before_a_formulas_end_skips_it_and_its_replay_loads(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = scenario(tmp_path, f'{{stl: "always[20:40]({DIST} <= 15.5)", name: tight}}')
    out = tmp_path / "short"
    assert main(["run", str(path), "--headless", "--duration", "30", "--out", str(out)]) == 0
    assert "requirement tight: skipped (it reads until t=40 s" in capsys.readouterr().out
    # metrics.json says the same: a robustness over the cut windows, but no verdict
    entry = json.loads((out / "metrics.json").read_text())["requirements"]["tight"]
    assert entry["verdict"] == "skipped"
    assert entry["note"] == "it reads until t=40 s; the run ended at t=30 s"
    assert main(["validate", str(out / "scenario.yaml")]) == 0


def test_a_log_rate_given_on_the_command_line_is_asked_the_same(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    """The loader judges a window against the file's log rate; ``--log-rate 4`` on a file
    logging at 20 Hz ran to the end, then died with a SamplingError traceback (no metrics).
    Refused before the run, one line naming --log-rate, exit 2."""
    from amsa_phys.cli.main import main

    path = scenario(
        tmp_path,
        '{stl: "always[0:10.1](MyDistanceMonitor.distanceFollowerToLeader <= 90)", name: a}',
    )
    path.write_text(path.read_text().replace("log_rate: 4\n", "log_rate: 20\n"))
    out = tmp_path / "o"
    assert main(["run", str(path), "--headless", "-q", "--no-plot", "--out", str(out)]) == 0
    capsys.readouterr()
    argv = ["run", str(path), "--headless", "-q", "--no-plot", "--log-rate", "4"]
    assert main([*argv, "--out", str(tmp_path / "p")]) == 2
    assert capsys.readouterr().err == (
        "error: --log-rate: the requirement a cannot be judged: always[0:10.1]: 10.1 s is not "
        "a multiple of the log period 0.25 s (the run logs no sample there)\n"
    )
    assert not (tmp_path / "p").exists()


@pytest.mark.parametrize("text", ["foo", "MyDistanceMonitor.distanceFollowerToLeader", "3"])
def test_a_value_alone_is_said_to_be_a_value_not_a_number(text: str) -> None:
    """A signal alone read "foo is a number, not a formula"."""
    from amsa_phys.stl.syntax import FormulaError, parse

    with pytest.raises(FormulaError) as caught:
        parse(text)
    assert str(caught.value) == (
        f"{text} is a value (a signal or a number), not a formula: compare it (e.g. {text} > 0)"
    )
