"""Hostile files and values are refused fast, in one line, at load: what validates runs.

Numbers too big for a float, files that never end (devices, FIFOs), files and structures
that expand beyond the limits (size, components, aliases), worlds that would load but not
run (rates, walls, seeds), trace windows that check nothing; YAML merge keys work. Every
fixture is generated here; the large ones are sparse or expand from a few bytes.
"""

from __future__ import annotations

import os
import tracemalloc
from pathlib import Path

import pytest
import yaml

from amsa_phys.cli.main import main
from amsa_phys.model.scenario import load_scenario, written_values
from amsa_phys.model.world import MAX_COMPONENTS
from amsa_phys.model.yamlio import MAX_FILE_BYTES, MAX_NODES, parse_yaml
from amsa_phys.runs.resolve import resolved_scenario

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
QUALITY = (
    "quality: {signal: MyDistanceMonitor.distanceFollowerToLeader, reference: 15, tolerance: 1.5}\n"
)
BIG = "1" * 401


def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def scenario(tmp_path: Path, extra: str = "", duration: str = "2", name: str = "s") -> Path:
    return write(tmp_path / f"{name}.yaml", f"world: {WORLD}\nduration: {duration}\n{extra}")


def refused(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    """Run the CLI in-process; it must refuse with exit 2 and exactly one line."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err
    return err.removeprefix("error: ").rstrip("\n")


TOO_BIG = "number too large (401 digits; a number must fit a float, at most about 1.8e308)"


@pytest.mark.parametrize(
    ("extra", "duration", "where"),
    [
        ("", BIG, ":2: duration"),
        (f"quality: {{signal: Leader.posX, reference: {BIG}}}\n", "2", ":3: quality.reference"),
        (f"set: {{MyFollowerController.Kv: {BIG}}}\n", "2", ":3: set.MyFollowerController.Kv"),
        (f"set: {{LeaderGPS.lostDataGPS: {BIG}}}\n", "2", ":3: set.LeaderGPS.lostDataGPS"),
    ],
    ids=["duration", "quality-reference", "float-param", "int-param-max-100"],
)
def test_a_401_digit_number_in_a_file_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: str, duration: str, where: str
) -> None:
    path = scenario(tmp_path, extra, duration)
    assert refused(capsys, ["validate", str(path)]) == f"{path}{where}: {TOO_BIG}"


def test_a_401_digit_number_on_the_command_line_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = scenario(tmp_path)
    out = str(tmp_path / "o")
    run = ["run", str(path), "--headless", "--out", out, "--set", f"Leader.x={BIG}"]
    assert refused(capsys, run) == f"--set Leader.x: {TOO_BIG}"
    sweep = ["sweep", str(path), "--out", out, "--grid", f"Leader.x=1,{BIG}"]
    assert refused(capsys, sweep) == f"--grid Leader.x: {TOO_BIG}"
    huge_int = [
        "run",
        str(path),
        "--headless",
        "--out",
        out,
        "--set",
        f"LeaderGPS.lostDataGPS={BIG}",
    ]
    assert refused(capsys, huge_int).startswith("--set LeaderGPS.lostDataGPS: integer too large")
    assert not Path(out).exists()


def test_files_that_never_end_are_refused_without_reading_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fifo = tmp_path / "fifo.yaml"
    os.mkfifo(fifo)  # nobody ever writes to it: reading would block forever
    for path, kind in [("/dev/zero", "device"), ("/dev/urandom", "device"), (fifo, "FIFO")]:
        why = f"is not a regular file (a {kind}), expected a YAML file"
        assert refused(capsys, ["validate", str(path)]) == f"{path}: {why}"
    out = str(tmp_path / "o")
    assert refused(capsys, ["run", "/dev/zero", "--headless", "--out", out]).startswith(
        "/dev/zero: is not a regular file"
    )
    world_zero = write(tmp_path / "wz.yaml", "world: /dev/zero\nduration: 1\n")
    assert refused(capsys, ["validate", str(world_zero)]).startswith(
        "/dev/zero: is not a regular file (a device)"
    )
    assert not Path(out).exists()


def test_binary_and_oversized_files_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    binary = tmp_path / "bin.yaml"
    binary.write_bytes(bytes(range(256)) * 16)
    assert refused(capsys, ["validate", str(binary)]).startswith(f"{binary}: not ")
    huge = tmp_path / "huge.yaml"
    with huge.open("wb") as fh:  # sparse: 50 MB on paper, nothing on disk
        fh.truncate(50 * 2**20)
    assert refused(capsys, ["validate", str(huge)]) == (
        f"{huge}: file too large (50.0 MiB or more; the limit is {MAX_FILE_BYTES // 2**20} MiB)"
    )


def test_a_file_of_too_many_values_is_refused_before_it_is_composed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 1.2 MB of "1," is 600,000 values: counted from the parser's events, refused before
    # PyYAML resolves each one (the file-level message has no line: nothing was built)
    path = write(tmp_path / "many.yaml", "description: [" + "1," * 600_000 + "1]\n")
    assert refused(capsys, ["validate", str(path)]) == (
        f"{path}: document too large: over {MAX_NODES:,} values"
    )


def test_a_world_of_too_many_components_is_refused_before_building_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    leaves = "".join(f"  C{i}: {{template: ConstantPower}}\n" for i in range(MAX_COMPONENTS + 1))
    many = write(tmp_path / "many.yaml", "components:\n" + leaves)
    assert refused(capsys, ["validate", str(many)]) == (
        f"{many}:{MAX_COMPONENTS + 2}: components.C{MAX_COMPONENTS}: the world has over "
        f"{MAX_COMPONENTS:,} components (count: copies included), the limit"
    )
    # 30 aliases of a count: 10000 Composite: 300,000 components from ~1 KB
    amp = "world:\n  components:\n    Car: &car\n      count: 10000\n      components:\n"
    amp += "        R: {template: ConstantPower}\n"
    amp += "".join(f"    Copy{chr(97 + i % 26)}{i}_: *car\n" for i in range(30))
    path = write(tmp_path / "amp.yaml", amp + "duration: 1\n")
    assert len(amp) < 1200
    assert refused(capsys, ["validate", str(path)]).endswith(
        f"world.components.Copya0_: the world has over {MAX_COMPONENTS:,} components "
        "(count: copies included), the limit"
    )


LAUGHS = (
    "{"
    + ", ".join(
        [f"a0: &a0 [{', '.join(['x'] * 9)}]"]
        + [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]
    )
    + "}"
)


def test_alias_bombs_are_refused_in_files_and_in_set_values(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bomb = write(tmp_path / "bomb.yaml", f"description: {LAUGHS}\n")
    assert refused(capsys, ["validate", str(bomb)]).endswith(
        "document too large: aliases expand to over 100,000 values (an alias bomb?)"
    )
    path = scenario(tmp_path)
    run = ["run", str(path), "--headless", "--out", str(tmp_path / "o"), "--set"]
    assert refused(capsys, [*run, f"Leader.x={LAUGHS}"]) == (
        "--set Leader.x: document too large: over 10,000 values"
    )


def test_yaml_merge_keys_work_as_yaml_defines_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    merged = write(
        tmp_path / "merged.yaml",
        "world:\n  components:\n"
        "    A: &power {template: ConstantPower, freq: 4, params: {left: 10, right: 20}}\n"
        "    B:\n      <<: *power\n      freq: 2\n"
        "duration: 1\n",
    )
    scen = load_scenario(merged)
    assert (scen.world.leaves["B"].freq, scen.world.leaves["B"].params["left"]) == (2, 10.0)
    assert scen.world.leaves["A"].freq == 4
    dup = write(tmp_path / "dup.yaml", "components:\n  A:\n    template: GPS\n    template: X\n")
    assert refused(capsys, ["validate", str(dup)]) == (
        f"{dup}:4: components.A.template: duplicate key 'template' (first defined on line 3)"
    )


@pytest.mark.parametrize(
    ("world", "extra", "message"),
    [
        (
            "    L: {template: freeRobot}\n"
            "    G: {template: GPS, freq: 1000000000, inputs: {posX: L.posX, posY: L.posY}}\n",
            "",
            ":4: world.components.G.freq: 1e+09 Hz is outside the rates amsa-phys runs "
            "(0.001 to 10000 Hz)",
        ),
        (
            "    C: {template: ConstantPower, freq: 0.000000001}\n",
            "",
            ":3: world.components.C.freq: 1e-09 Hz is outside the rates amsa-phys runs "
            "(0.001 to 10000 Hz)",
        ),
        (
            "    L: {template: freeRobot}\n",
            "physics: {rate: 1000000000}",
            ":2: world.physics.rate: 1e+09 Hz is outside the rates amsa-phys runs (1 to 10000 Hz)",
        ),
        (
            "    L: {template: freeRobot}\n",
            "physics: {walls: {xmin: 10, xmax: -10, ymin: -5, ymax: 5}}",
            ":2: world.physics.walls.xmax: xmax (-10) must be greater than xmin (10)",
        ),
        (
            "    1: {template: ConstantPower}\n",
            "",
            ":3: world.components.1: '1' is not a valid name (letters, digits and _, "
            "not starting with a digit)",
        ),
        (
            "    Slow: {template: ConstantPower, freq: 0.001}\n"
            "    Fast: {template: ConstantPower, freq: 9999}\n",
            "",
            ":2: world.components: the rates repeat only every 1000 s (10,099,001 events per "
            "cycle, the limit is 2,000,000); use commensurate frequencies",
        ),
    ],
    ids=["gps-1e9-hz", "1e-9-hz", "physics-rate", "walls", "integer-key", "incommensurate"],
)
def test_a_world_that_would_not_run_is_refused_at_load(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], world: str, extra: str, message: str
) -> None:
    physics = f"  {extra}\n" if extra else ""
    path = write(tmp_path / "w.yaml", f"world:\n{physics}  components:\n{world}duration: 1\n")
    assert refused(capsys, ["validate", str(path)]) == f"{path}{message}"
    out = tmp_path / "o"  # and run refuses it the same way, before anything runs
    assert refused(capsys, ["run", str(path), "--headless", "--out", str(out)]) == (
        f"{path}{message}"
    )
    assert not out.exists()


def test_trace_rates_out_of_bounds_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = scenario(tmp_path, "log_rate: 1000000000\n")
    assert refused(capsys, ["validate", str(path)]) == (
        f"{path}:3: log_rate: 1e+09 Hz is outside the rates amsa-phys runs (0.001 to 10000 Hz)"
    )
    ok = scenario(tmp_path, name="ok")
    run = ["run", str(ok), "--headless", "--out", str(tmp_path / "o"), "--log-rate"]
    assert refused(capsys, [*run, "1e9"]) == (
        "--log-rate: 1e+09 Hz is outside the rates amsa-phys runs (0.001 to 10000 Hz)"
    )


@pytest.mark.parametrize("seed", ["-1", str(2**64)])
def test_seeds_outside_the_schema_are_refused_on_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], seed: str
) -> None:
    path = scenario(tmp_path)
    run = ["run", str(path), "--headless", "--out", str(tmp_path / "o"), "--seed", seed]
    assert refused(capsys, run) == (
        "--seed: must be an integer from 0 to 9223372036854775807 (2**63 - 1), like seed: in a "
        f"scenario; got {seed}"
    )
    in_file = scenario(tmp_path, f"seed: {seed}\n", name="f")
    assert refused(capsys, ["validate", str(in_file)]).startswith(f"{in_file}:3: seed: must be ")


def test_the_largest_seed_runs_and_its_resolved_scenario_validates(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = scenario(tmp_path, QUALITY, duration="1")
    out = tmp_path / "o"
    run = ["run", str(path), "--headless", "--out", str(out), "-q", "--no-plot"]
    assert main([*run, "--seed", str(2**63 - 1)]) == 0
    resolved = yaml.safe_load((out / "scenario.yaml").read_text())
    assert resolved["seed"] == 2**63 - 1
    assert main(["validate", str(out / "scenario.yaml")]) == 0


@pytest.mark.parametrize("name", ["platoon", "scenario2", "context_sweep"])
def test_the_written_size_bound_covers_what_the_loader_counts(tmp_path: Path, name: str) -> None:
    # a scenario is refused when its written-out form would pass the loader's value limit:
    # the estimate must never be below what the loader builds from the run's scenario.yaml
    scen = load_scenario(ROOT / "scenarios" / f"{name}.yaml")
    resolved = resolved_scenario(scen)
    doc = parse_yaml(yaml.safe_dump(resolved, sort_keys=False), tmp_path / "scenario.yaml")
    estimate = written_values(scen.world, resolved)
    assert doc.values <= estimate <= 1.5 * doc.values + 100  # and not absurdly above it


def test_a_trace_window_that_checks_nothing_is_refused_or_said_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    reversed_window = scenario(
        tmp_path, QUALITY + "expect:\n  - {trace: Leader.posX, after: 5, before: 1, below: 1}\n"
    )
    assert refused(capsys, ["validate", str(reversed_window)]) == (
        f"{reversed_window}:5: expect[0].before: before (1 s) is earlier than after (5 s): "
        "the window holds no instant"
    )
    late = QUALITY + "expect:\n  - {trace: Leader.posX, after: 3, before: 4, below: 100}\n"
    assert refused(capsys, ["validate", str(scenario(tmp_path, late, name="late"))]) == (
        f"{tmp_path / 'late.yaml'}:5: expect[0].after: 3 s is after the end of the scenario "
        "(duration 2 s): the window would never hold a sample"  # it would check nothing
    )
    windows = scenario(
        tmp_path,
        QUALITY + "expect:\n"
        "  - {trace: Leader.posX, after: 1, before: 50, below: 100}\n"  # past the end
        "  - {trace: Leader.posX, after: 3, before: 4, below: 100}\n"  # after the cut
        "  - {trace: Leader.posX, after: 0.51, before: 0.52, below: 100}\n",  # between rows
        duration="5",
        name="w",
    )
    out = tmp_path / "o"
    argv = ["run", str(windows), "--headless", "--out", str(out), "-q", "--no-plot"]
    assert main([*argv, "--duration", "2"]) == 1
    captured = capsys.readouterr()
    lines = captured.out.splitlines() + captured.err.splitlines()
    assert (  # held until the cut: not judged (the rest of the window might not have held)
        "expect Leader.posX in [1, 50] s: skipped (the run was cut short at t=2 s inside "
        "the window; held until then)" in lines
    )
    assert (
        "expect Leader.posX in [3, 4] s: skipped (no sample: the window starts after the "
        "run's end at t=2 s)" in lines
    )
    assert (
        "expect Leader.posX in [0.51, 0.52] s: FAIL (no sample: no logged instant in the "
        "window; widen it or raise log_rate)" in lines
    )
    assert all(line.count("sample") <= 1 for line in lines)  # said once, not "...: no sample"


def test_an_error_about_a_file_never_shows_what_the_file_holds(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    secret = write(tmp_path / "secret.txt", "root:x:0:0:token-1234567890:/root:/bin/bash\n")
    for target in [secret, Path("/etc/passwd")]:
        if not target.is_file():
            continue
        path = write(tmp_path / "s.yaml", f"world: {target}\nduration: 1\n")
        err = refused(capsys, ["validate", str(path)])
        assert err == f"{target}:1: expected a mapping, got string: not a world or scenario file"


def test_a_10_billion_run_grid_is_refused_before_anything_is_allocated(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = scenario(tmp_path)
    argv = ["sweep", str(path), "--out", str(tmp_path / "o")]
    argv += ["--range", "MyFollowerController.Kv=0:1:100000", "--range", "Leader.x=0:1:100000"]
    tracemalloc.start()
    try:
        message = refused(capsys, argv)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert message == (
        "sweep: 100000 × 100000 grid points × 1 seed = 10,000,000,000 runs; a sweep has at "
        "most 1,000,000"
    )
    assert peak < 64 * 2**20  # the two axes' values, not 10^10 jobs
    assert not (tmp_path / "o").exists()
