"""``import amsa_phys as ap; ap.run(...)``: the CLI's run in memory, its files on request."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import amsa_phys as ap
from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO2 = ROOT / "scenarios" / "scenario2.yaml"
HEAVY = ("numpy", "pymunk", "matplotlib", "jsonschema", "tqdm", "pygame", "yaml", "orjson")


def test_importing_the_package_imports_nothing_heavy() -> None:
    # every amsa-phys command imports the package: it must stay cheap (lazy names, PEP 562)
    code = (
        "import sys, amsa_phys\n"
        "amsa_phys.__version__\n"
        f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))\n"
        "amsa_phys.run\n"
        "print('numpy' in sys.modules)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.split("\n")
    assert out[0] == "[]"
    assert out[1] == "True"  # and the API is there on first use


def test_lazy_names_are_listed_and_resolve() -> None:
    public = set(ap.__all__) - {"__version__"}
    assert public == set(ap._LAZY)
    assert public <= set(dir(ap))
    for name in public:
        assert getattr(ap, name) is not None
    with pytest.raises(AttributeError, match="has no attribute 'nope'"):
        _ = ap.nope  # type: ignore[attr-defined]


def cli_run(out: Path, *extra: str) -> None:
    argv = ["run", str(SCENARIO2), "--headless", "--out", str(out), "-q", *extra]
    assert main(argv) == 0


def test_saved_run_is_what_the_cli_writes_byte_for_byte(tmp_path: Path) -> None:
    opts = {"seed": 3, "duration": 60, "set": {"MyFollowerController.Kv": 0.2}}
    saved = ap.run(SCENARIO2, **opts).save(tmp_path / "api")
    cli_run(
        tmp_path / "cli", "--seed", "3", "--duration", "60", "--set", "MyFollowerController.Kv=0.2"
    )
    cli = tmp_path / "cli"
    assert saved == tmp_path / "api"
    assert sorted(p.name for p in saved.iterdir()) == sorted(p.name for p in cli.iterdir())
    for name in ("trace.csv", "scenario.yaml"):
        assert (saved / name).read_bytes() == (cli / name).read_bytes(), name
    timing = ("wall_time_s", "real_time_factor")
    a, b = (json.loads((d / "metrics.json").read_text()) for d in (saved, cli))
    assert {k: v for k, v in a.items() if k not in timing} == {
        k: v for k, v in b.items() if k not in timing
    }


def test_run_holds_metrics_trace_events_and_resolved_scenario_in_memory(tmp_path: Path) -> None:
    before = set(Path.cwd().iterdir())
    run = ap.run(SCENARIO2, seed=3, duration=30)
    assert set(Path.cwd().iterdir()) == before  # no file, no runs/ directory
    assert run.status == "completed"
    assert run.metrics["seed"] == 3
    assert run.metrics["duration"] == 30.0
    assert run.metrics["overall"]["rms_error"] > 0
    assert run.columns[0] == "t"
    assert "MyDistanceMonitor.distanceFollowerToLeader" in run.columns
    assert list(run.trace.dtype.names) == run.columns
    assert len(run.trace) == 30 * 20 + 1  # 20 Hz, both ends
    assert run.trace["t"][-1] == 30.0
    np.testing.assert_array_equal(np.diff(run.trace["t"][:3]), [0.05, 0.05])
    # the trace is the CSV's numbers exactly
    written = run.save(tmp_path / "r", plot=False)
    header, *rows = (written / "trace.csv").read_text().splitlines()
    assert header.split(",") == run.columns
    last = [float(x) for x in rows[-1].split(",")]
    assert last == [float(run.trace[c][-1]) for c in run.columns]
    assert run.scenario["seed"] == 3
    assert run.scenario["duration"] == 30
    assert "components" in run.scenario["world"]  # inlined
    # phase 0 runs to 100 s: cut short by the duration, so not judged (nor phase 1)
    assert run.checks[0].skipped
    assert run.checks[0].describe().startswith("rms_error (phase 0): skipped (phase 0 was cut")
    assert run.checks[1].skipped
    assert run.passed  # nothing failed, as the CLI's exit 0 says ...
    # ... and nothing of the phases was judged, nor the requirement that reads until 200 s
    assert run.skipped == [*run.checks[:2], run.checks[3]]
    assert run.checks[3].what == "requirement band_after_150"


def test_a_mapping_runs_like_the_file_and_the_resolved_scenario_replays(tmp_path: Path) -> None:
    from_file = ap.run(SCENARIO2, duration=20)
    mapping = {
        "world": "../worlds/mde_challenge.yaml",  # relative to base_dir
        "duration": 200,
        "seed": 1,
        "quality": {
            "signal": "MyDistanceMonitor.distanceFollowerToLeader",
            "reference": 15,
            "tolerance": 1.5,
        },
        "set": {
            "Leader.behavior": 4,
            "Leader.cruisePower": 9.0,
            "LeaderGPS.lostDataGPS": np.int64(10),  # numpy numbers are accepted
            "MyNormalizePower.motorCoef": 60,
            "MyFollowerController.Kv": 0.35,
        },
        "timeline": ({"at": Fraction(100), "set": {"MyFollowerController.Kv": 0.05}},),
    }
    from_mapping = ap.run(mapping, duration=20, base_dir=ROOT / "scenarios")
    assert from_mapping.trace.tobytes() == from_file.trace.tobytes()
    assert from_mapping.metrics["scenario"] == "mapping"
    replay = ap.run(ap.run(SCENARIO2, seed=5).scenario, duration=20)
    assert replay.trace.tobytes() == ap.run(SCENARIO2, seed=5, duration=20).trace.tobytes()


def test_relative_world_of_a_mapping_resolves_against_the_cwd_by_default(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(ROOT / "worlds")
    run = ap.run({"world": "mde_challenge.yaml", "duration": 1})
    assert run.status == "completed"
    with pytest.raises(ap.ConfigError) as err:
        ap.run({"world": "mde_challenge.yaml", "duration": 1}, base_dir=ROOT)
    assert str(err.value) == (
        f"<mapping>: world: world file not found: {ROOT / 'mde_challenge.yaml'} "
        "(written mde_challenge.yaml)"
    )


KVV = 'set={"MyFollowerController.Kvv": ...}'
CLI_ERRORS = [
    (["--set", "MyFollowerController.Kvv=0.2"], {"set": {"MyFollowerController.Kvv": 0.2}}, KVV),
    (
        ["--set", "MyFollowerController.Kv=-1"],
        {"set": {"MyFollowerController.Kv": -1}},
        'set={"MyFollowerController.Kv": ...}',
    ),
    (
        ["--set", "Leader.behavior=flying"],
        {"set": {"Leader.behavior": "flying"}},
        'set={"Leader.behavior": ...}',
    ),
    (
        ["--set", "LeaderGPS.lostDataGPS=true"],
        {"set": {"LeaderGPS.lostDataGPS": True}},
        'set={"LeaderGPS.lostDataGPS": ...}',
    ),
    (["--set", "Nobody.x=1"], {"set": {"Nobody.x": 1}}, 'set={"Nobody.x": ...}'),
    (["--duration", "-5"], {"duration": -5}, "duration="),
    (["--log-rate", "0"], {"log_rate": 0}, "log_rate="),
    (["--seed", "-1"], {"seed": -1}, "seed="),
    (["--trace-columns", "Nobody.*"], {"trace_columns": "Nobody.*"}, "trace_columns="),
    (["--ros2", "Nobody"], {"ros2": "Nobody"}, "ros2="),
    (
        ["--ros2", "MyFollowerController", "--ros2-timeout", "-1.5"],
        {"ros2": "MyFollowerController", "ros2_timeout": -1.5},
        "ros2_timeout=",
    ),
]


@pytest.mark.parametrize(
    ("argv", "kwargs", "argument"),
    CLI_ERRORS,
    ids=[
        "unknown-param",
        "out-of-range",
        "bad-enum",
        "bool-for-int",
        "unknown-comp",
        "duration",
        "log-rate",
        "seed",
        "trace-columns",
        "ros2",
        "ros2-timeout",
    ],
)
def test_errors_are_the_cli_messages_naming_the_api_argument(
    argv: list[str],
    kwargs: dict[str, object],
    argument: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The same message from both front ends, each naming what its user typed: the CLI its
    flag (``--set Comp.param``), the API its argument (``set={"Comp.param": ...}``)."""
    code = main(["run", str(SCENARIO2), "--headless", "--out", str(tmp_path / "o"), *argv])
    cli = capsys.readouterr().err.strip()
    assert code == 2
    with pytest.raises(ap.ConfigError) as err:
        ap.run(SCENARIO2, **kwargs)  # type: ignore[arg-type]
    api = str(err.value)
    assert err.value.exit_code == 2
    flag = argv[-2] + (" " + argv[-1].partition("=")[0] if argv[-2] == "--set" else "")
    assert cli.startswith(f"error: {flag}: "), cli
    reason = cli.removeprefix(f"error: {flag}: ")
    assert api == f"{argument}: {reason}"
    assert "--" not in api


def test_a_bad_file_raises_the_cli_message(capsys: pytest.CaptureFixture[str]) -> None:
    bad = ROOT / "tests" / "fixtures" / "bad" / "scenario_set_unknown_comp.yaml"
    assert main(["validate", str(bad)]) == 2
    cli = capsys.readouterr().err.strip()
    with pytest.raises(ap.ConfigError) as err:
        ap.run(bad)
    assert f"error: {err.value}" == cli
    with pytest.raises(ap.ConfigError) as err2:
        ap.validate(bad)
    assert str(err2.value) == str(err.value)
    with pytest.raises(ap.ConfigError, match="file not found"):
        ap.load(ROOT / "no_such.yaml")


@pytest.mark.parametrize(
    ("mapping", "message"),
    [
        ({"world": {"components": {}}, "duration": 1, "sed": 1}, "<mapping>: sed: unknown key"),
        (
            {"world": {"components": {"A": {"template": "GPSS"}}}, "duration": 1},
            "<mapping>: world.components.A.template: unknown template 'GPSS' (did you mean GPS?)",
        ),
        ({"world": {"components": {}}, "duration": 1, 3: 1}, "<mapping>: keys must be strings"),
        ({"world": {"components": {}}, "duration": object()}, "<mapping>: duration: a object"),
    ],
    ids=["unknown-key", "unknown-template", "int-key", "object-value"],
)
def test_a_bad_mapping_names_the_key(mapping: dict[object, object], message: str) -> None:
    with pytest.raises(ap.ConfigError) as err:
        ap.run(mapping)  # type: ignore[arg-type]
    assert str(err.value).startswith(message), str(err.value)
    assert "\n" not in str(err.value)


def test_validate_tells_worlds_from_scenarios() -> None:
    assert ap.validate(SCENARIO2) == "scenario"
    assert ap.validate(ROOT / "worlds" / "mde_challenge.yaml") == "world"
    assert ap.validate({"components": {"L": {"template": "freeRobot"}}}) == "world"
    with pytest.raises(TypeError, match="base_dir= is for a scenario given as a mapping"):
        ap.load(SCENARIO2, base_dir=ROOT)
    scenario = ap.load(SCENARIO2, seed=9, duration=Fraction(7, 3))
    assert (scenario.seed, scenario.duration) == (9, Fraction(7, 3))


TOY = {"world": {"components": {}}, "quality": {"signal": "K.u", "reference": 0}}


def toy(template: str, params: str, duration: float) -> dict[str, object]:
    comps = {"K": {"template": template, "freq": 4, "params": params}}
    return {**TOY, "world": {"components": comps}, "duration": duration}


@pytest.fixture
def toys_importable(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(ROOT / "tests"))


@pytest.mark.usefixtures("toys_importable")
def test_a_fault_raises_the_cli_message_with_the_run_so_far() -> None:
    with pytest.raises(ap.RunFault) as err:
        ap.run(toy("toys:Bad", {"boom": True}, 5))
    assert str(err.value) == (
        "run fault at t=1.000 s in K (Bad): do_step raised ZeroDivisionError('division by zero')"
    )
    assert isinstance(err.value.__cause__, ZeroDivisionError)  # the template's own traceback
    partial = err.value.run  # type: ignore[attr-defined]
    assert partial.status.startswith("fault: run fault at t=1.000 s")
    assert partial.trace["t"][-1] == 0.95  # every whole instant before the fault


@pytest.mark.usefixtures("toys_importable", "python_sigint")
def test_ctrl_c_stops_between_instants_and_keeps_the_run() -> None:
    with pytest.raises(ap.Interrupted) as err:
        ap.run(toy("toys:CtrlC", {"at": 2.5}, 100))
    assert str(err.value) == "interrupted at t=3.00 s; the run so far is the error's .run"
    partial = err.value.run  # type: ignore[attr-defined]
    assert partial.status == "interrupted"
    assert (partial.trace["t"][-1], partial.trace["K.u"][-1]) == (3.0, 13.0)


def test_save_follows_the_run_directory_rules(tmp_path: Path) -> None:
    run = ap.run(SCENARIO2, duration=2)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me")
    with pytest.raises(ap.ConfigError) as err:
        run.save(mine)
    # a directory the user made: force=True would not help, so the first message says so
    # (in the API's words: save's arguments, not the CLI's --out and --force)
    assert str(err.value) == (
        f"{mine}: out=: directory exists and was not made by amsa-phys (no .amsa-phys-run in "
        "it); force=True replaces only run directories: choose a new one"
    )
    with pytest.raises(ap.ConfigError, match="was not made by amsa-phys"):
        run.save(mine, force=True)
    ours = run.save(tmp_path / "ours", plot=False)
    with pytest.raises(
        ap.ConfigError,
        match=r"out=: directory exists and is not empty \(use force=True to replace it\)$",
    ):
        run.save(ours)
    assert (mine / "notes.txt").read_text() == "keep me"
    out = run.save(tmp_path / "r", plot=False)
    assert run.save(out, force=True, plot=False) == out  # our own directory may be replaced
    assert sorted(p.name for p in out.iterdir()) == [
        ".amsa-phys-run",
        "metrics.json",
        "scenario.yaml",
        "trace.csv",
    ]


def test_save_defaults_to_the_clis_runs_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    out = ap.run(SCENARIO2, duration=1).save(plot=False)
    assert out.parent == Path("runs")
    assert out.name.startswith("scenario2-")
    assert os.path.isfile(out / "trace.csv")
