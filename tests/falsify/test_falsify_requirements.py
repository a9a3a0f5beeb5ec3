"""``falsify --requirement``: stops at the first falsifying run, counts trials as ARCH-COMP
does, refuses bad seeds, and resumes after Ctrl-C without losing a finished run."""

from __future__ import annotations

import csv
import io
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
DIST = "MyDistanceMonitor.distanceFollowerToLeader"
BOX = ["--range", "Leader.changePeriod=2:40", "--range", "Leader.cruisePower=3:12"]


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    """The resonance problem, 60 s, with a band requirement a few percent of the box breaks."""
    path = tmp_path / "res.yaml"
    path.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 60\nseed: 1\nlog_rate: 4\n"
        "set: {Leader.behavior: 3, MyFollowerController.Kv: 0.35}\nexpect:\n"
        f'  - {{stl: "always[20:60](abs({DIST} - 15) <= 4.5)", name: band}}\n'
        f'  - {{stl: "always({DIST} >= 1)", name: no_contact}}\n'
    )
    return path


def rows(path: Path) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(path.read_text())))


def falsify(scenario: Path, out: Path, *extra: str) -> int:
    args = ["falsify", str(scenario), *BOX, "--out", str(out), "-j", "1", *extra]
    return main(args)


def test_stops_at_the_first_violation_and_counts_it(scenario: Path, tmp_path: Path) -> None:
    out = tmp_path / "stop"
    assert falsify(scenario, out, "--budget", "150", "--requirement", "band") == 1
    table = rows(out / "results.csv")
    rob = [float(r["robustness.band"]) for r in table]
    first = min(i for i, r in enumerate(rob) if r < 0)
    assert len(table) < 150  # it stopped
    assert max(int(r["generation"]) for r in table) == int(table[first]["generation"])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["table"][0]["simulations"] == first + 1
    assert summary["falsification_rate"] == 1.0
    on = tmp_path / "on"
    assert falsify(scenario, on, "--budget", "40", "--requirement", "band", "--search-on") in (0, 1)
    assert len(rows(on / "results.csv")) == 40  # told to search on: the whole budget


def test_trial_table_counts_each_trial(scenario: Path, tmp_path: Path) -> None:
    out = tmp_path / "trials"
    code = falsify(scenario, out, "--budget", "25", "--requirement", "all", "--trials", "3")
    summary = json.loads((out / "summary.json").read_text())
    sims = []
    for k, entry in enumerate(summary["table"]):
        table = rows(out / f"trial-{k + 1:03d}" / "results.csv")
        least = [min(float(r["robustness.band"]), float(r["robustness.no_contact"])) for r in table]
        hits = [i for i, v in enumerate(least) if v < 0]
        assert entry["seed"] == 1 + k
        assert entry["falsified"] == bool(hits)
        assert entry["simulations"] == (hits[0] + 1 if hits else None)
        if hits:
            sims.append(hits[0] + 1)
        else:
            assert entry["least"] == pytest.approx(min(least), abs=0)
    assert summary["falsified"] == len(sims)
    assert summary["falsification_rate"] == len(sims) / 3
    assert summary["mean_simulations"] == (sum(sims) / len(sims) if sims else None)
    assert code == (1 if sims else 0)
    assert (out / "trials.png").stat().st_size > 0


@pytest.mark.parametrize("seed", ["-1", str(2**70), str(2**63 - 1)])
def test_seeds_out_of_range_are_one_line_exit_2(
    scenario: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], seed: str
) -> None:
    extra = ["--trials", "2"] if seed == str(2**63 - 1) else []  # S+1 would overflow
    code = falsify(scenario, tmp_path / "o", "--budget", "5", "--seed", seed, *extra)
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert "--seed" in err
    assert "\n" not in err
    assert "Traceback" not in err


def test_unknown_requirement_has_a_did_you_mean(
    scenario: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert falsify(scenario, tmp_path / "o", "--budget", "5", "--requirement", "bnad") == 2
    assert "did you mean band?" in capsys.readouterr().err


def test_resume_after_ctrl_c_loses_no_finished_run(
    scenario: Path, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """Interrupted after its first generation, then resumed: the same rows, to the byte, as
    the search run straight through, and every row kept at the interrupt is among them."""
    straight = tmp_path / "straight"
    args = ["--budget", "60", "--requirement", "band", "--search-on", "--seed", "4"]
    falsify(scenario, straight, *args)
    out = tmp_path / "cut"
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    cmd = [sys.executable, "-m", "amsa_phys", "falsify", str(scenario), *BOX, "--out", str(out)]
    proc = subprocess.Popen(
        [*cmd, "-j", "1", *args], stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path
    )
    assert proc.stderr is not None
    for line in proc.stderr:  # wait for the event: a generation finished
        if "generation 1 done" in line:
            proc.send_signal(signal.SIGINT)
            break
    proc.communicate(timeout=300)
    kept = rows(out / "results.csv")
    assert proc.returncode == 130
    assert 0 < len(kept) < 60
    assert not (out / "trial.json").exists()
    capfd.readouterr()
    assert falsify(scenario, out, *args, "--resume") in (0, 1)
    assert f"resumed: {len(kept)} finished runs taken" in capfd.readouterr().err
    assert (out / "results.csv").read_bytes() == (straight / "results.csv").read_bytes()
    final = {r["run"]: r for r in rows(out / "results.csv")}
    for r in kept:
        assert final[r["run"]] == r


def test_minimised_counterexample_still_falsifies_and_is_no_further_from_nominal(
    scenario: Path, tmp_path: Path
) -> None:
    from amsa_phys.falsify.counterexample import distance, nominal
    from amsa_phys.falsify.space import build_space
    from amsa_phys.model.scenario import load_scenario

    out = tmp_path / "cx"
    assert falsify(scenario, out, "--budget", "150", "--requirement", "band") == 1
    replay = tmp_path / "replay"
    main(["run", str(out / "worst.yaml"), "--headless", "--out", str(replay)])
    rob = json.loads((replay / "metrics.json").read_text())["requirements"]["band"]
    assert rob["robustness"] < 0  # the minimised context, replayed, still falsifies
    sc = load_scenario(scenario)
    space = build_space(sc, [BOX[1], BOX[3]], [])
    nom = nominal(space, sc)
    keys = [d.key for d in space.dims]

    def point(path: Path) -> tuple:
        doc = yaml.safe_load(path.read_text())
        return tuple((k, doc["set"][k]) for k in keys)  # the searched values, set at t = 0

    table = rows(out / "results.csv")
    raw_rob = min(float(r["robustness.band"]) for r in table)
    assert raw_rob < 0
    raw_worst = next(r for r in table if float(r["robustness.band"]) == raw_rob)
    raw_point = tuple((k, float(raw_worst[k])) for k in keys)
    assert distance(point(out / "worst.yaml"), nom, space) <= distance(raw_point, nom, space)
    assert (out / "worst_raw.yaml").is_file()
    assert (out / "counterexample.png").stat().st_size > 0


def test_expect_judges_the_stl_requirements_too(tmp_path: Path) -> None:
    """``--expect`` takes the scenario's STL requirements with its metric checks: each row's
    robustness is at most each requirement's (it was judged from a result row as "the run
    ended at t=0 s", skipped, and a run breaking only the requirement passed)."""
    import csv

    from amsa_phys.cli.main import main

    scen = Path(__file__).resolve().parents[2] / "scenarios" / "falsify_resonance.yaml"
    out = tmp_path / "f"
    argv = ["falsify", str(scen), "--range", "Leader.cruisePower=20:80", "--budget", "10"]
    argv += ["--expect", "-j", "1", "--out", str(out)]
    main(argv)
    with (out / "results.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert rows
    for r in rows:
        assert float(r["robustness"]) <= float(r["robustness.band"])
