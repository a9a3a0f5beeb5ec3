"""The compiled physics step (``physics/_step.c``) against the pure-Python one.

The suite runs with the compiled step by default (where it was built); these tests run the
pure path next to it (``AMSA_PHYS_PURE=1``, in-process and in a subprocess) and hold the two
to byte-identical traces on every shipped scenario, on the few-rover path and on the fleet
path (which, compiled, does the few-rover arithmetic per rover: it equals the pure few-rover
path exactly, and so does the pure fleet, which calls the same per-rover arithmetic over its
arrays). An install without a C compiler
(``CC=false``) must still succeed and run pure.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from regimes import DT, every_regime

from amsa_phys.model.scenario import load_scenario
from amsa_phys.physics import compiled, fleet
from amsa_phys.physics.bodyio import BodyIO
from amsa_phys.physics.fewrovers import FewRovers
from amsa_phys.physics.forces import ground_list
from amsa_phys.physics.space import PhysicsWorld
from amsa_phys.physics.step_path import PURE_ENV, extension
from amsa_phys.runs.single import run_scenario

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = sorted((ROOT / "scenarios").glob("*.yaml"))
#: shipped scenarios whose compiled-versus-pure trace is compared in the full suite only (the
#: longest, and two of the four Kv steps of Fig. 5): the quick tier keeps one of each kind (a
#: follower, a Kv step, the obstacle course's contacts, sensed and GPS-denied runs), and the
#: fleet and every regime of the wheel model are compared by the tests below and above
FULL_SUITE_ONLY = {
    "paper_fig5_kv005",
    "paper_fig5_kv015",
    "long_mission",
    "adaptive",
    "adaptive_sweep",
    "adaptive_sweep_fine",
    "adaptive_sweep_gps",
    "paper_fig6_urban",
    "paper_fig5_kv035",
    "platoon",
}

built = pytest.mark.skipif(
    extension() is None, reason="the compiled step was not built (no C compiler at install)"
)


def run_trace(
    scenario: Path, out: Path, monkeypatch: pytest.MonkeyPatch, pure: bool, duration: float | None
) -> tuple[bytes, list[str]]:
    """(trace.csv bytes, force-model classes the run's physics worlds chose)."""
    chosen: list[str] = []
    start = PhysicsWorld._start

    def spy(self: PhysicsWorld) -> object:
        model = start(self)
        chosen.append(type(model).__name__)
        return model

    out.mkdir()
    with monkeypatch.context() as m:
        m.setattr(PhysicsWorld, "_start", spy)
        if pure:
            m.setenv(PURE_ENV, "1")
        else:
            m.delenv(PURE_ENV, raising=False)
        run_scenario(load_scenario(scenario, duration=duration), out, plot=False, progress=False)
    return (out / "trace.csv").read_bytes(), chosen


@built
@pytest.mark.parametrize("cls", ["CompiledFewRovers", "CompiledFleet"])
def test_every_regime_of_the_wheel_model_is_bit_identical(cls: str) -> None:
    """Rims stuck, breaking away, current-limited, regenerating, tyres saturated on ice and
    mud (test_fast_paths.every_regime): state and rims equal to the last bit after every one
    of 40 steps, as the regimes change. The shipped scenarios seldom reach the rare branches;
    this does, all in one call."""
    results = []
    for model_cls in (FewRovers, getattr(compiled, cls)):
        space, rovers, rims, grounds = every_regime(60)
        terms = [ground_list(r, *g) for r, g in zip(rovers, grounds, strict=True)]
        io = BodyIO(space, [r.body for r in rovers])
        model = model_cls(io, rovers, DT, (100.0, 1e4), terms)
        flat = [u for pair in rims for u in pair]
        # assigned as test_fast_paths assigns them: the compiled classes copy into their buffers
        model.rims = np.array(rims).T.copy() if model_cls is compiled.CompiledFleet else flat
        steps = []
        for _ in range(40):
            model.advance()
            steps.append([(*model.kinematics(k), *model.rim_speeds(k)) for k in range(60)])
        results.append(steps)
    assert results[0] == results[1]


@built
@pytest.mark.parametrize(
    "scenario",
    [
        pytest.param(p, id=p.stem, marks=[pytest.mark.slow] if p.stem in FULL_SUITE_ONLY else [])
        for p in SHIPPED
    ],
)
def test_compiled_and_pure_steps_write_the_same_trace(
    scenario: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    fast, fast_models = run_trace(scenario, tmp_path / "c", monkeypatch, False, None)
    pure, pure_models = run_trace(scenario, tmp_path / "p", monkeypatch, True, None)
    assert fast_models == ["CompiledFewRovers"]  # the run used physics, through the C step
    assert pure_models == ["FewRovers"]
    assert fast.count(b"\n") > 100
    assert fast == pure


@built
def test_the_cli_honours_the_pure_switch_and_gives_the_same_trace(tmp_path: Path) -> None:
    """CI's second path: the whole program under ``AMSA_PHYS_PURE=1`` in a subprocess."""
    traces = []
    for pure in ("1", "0"):
        env = {**os.environ, PURE_ENV: pure, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
        out = tmp_path / f"run{pure}"
        argv = [sys.executable, "-m", "amsa_phys", "run", str(ROOT / "scenarios/scenario2.yaml")]
        argv += ["--headless", "--no-plot", "-q", "--out", str(out), "--duration", "60"]
        subprocess.run(argv, check=True, env=env, capture_output=True)
        traces.append((out / "trace.csv").read_bytes())
        version = subprocess.run(
            [sys.executable, "-m", "amsa_phys", "--version"],
            env=env,
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        assert ("pure Python (AMSA_PHYS_PURE is set)" in version) == (pure == "1"), version
        assert ("compiled (C)" in version) == (pure == "0"), version
    assert traces[0] == traces[1]


def platoon(cars: int, tmp: Path) -> Path:
    """worlds/platoon.yaml with ``count: cars`` and a 20 s scenario around it."""
    world = yaml.safe_load((ROOT / "worlds" / "platoon.yaml").read_text())
    world["components"]["Car"]["count"] = cars
    (tmp / "platoon.yaml").write_text(yaml.safe_dump(world))
    scen = tmp / "scenario.yaml"
    scen.write_text("world: platoon.yaml\nduration: 20\nseed: 1\n")
    return scen


@built
def test_compiled_fleet_is_the_few_rover_arithmetic_and_so_is_the_pure_fleet(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scen = platoon(59, tmp_path)  # 60 rovers: the fleet path (fleet.BATCH_MIN is 40)
    fast, models = run_trace(scen, tmp_path / "c", monkeypatch, False, None)
    assert models == ["CompiledFleet"]
    pure_fleet, models = run_trace(scen, tmp_path / "p", monkeypatch, True, None)
    assert models == ["Fleet"]
    with monkeypatch.context() as m:
        m.setattr(fleet, "BATCH_MIN", 10**9)
        few, models = run_trace(scen, tmp_path / "f", monkeypatch, True, None)
    assert models == ["FewRovers"]
    assert fast == few
    # one pure path (issue 32): the array fleet without C is the same arithmetic, bit for bit
    assert pure_fleet == fast


@built
def test_wheel_parameter_changes_mid_run_reach_the_compiled_step(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Worn motors and a slippery tyre from t = 20 s (``PhysicsWorld.update_wheel`` ->
    ``refresh``): no shipped scenario changes a wheel mid-run, this one does (terrain zones,
    ``set_ground``, are in the shipped obstacle course)."""
    scen = tmp_path / "wear.yaml"
    scen.write_text(
        f"world: {ROOT / 'worlds' / 'mde_challenge.yaml'}\nduration: 60\nseed: 3\n"
        "timeline:\n  - {at: 20, set: {Follower.efficiency: 40, Leader.stallForce: 30,"
        " Follower.slipComplianceLateral: 0.3}}\n"
    )
    calls: list[int] = []
    refresh = compiled.CompiledFewRovers.refresh
    monkeypatch.setattr(
        compiled.CompiledFewRovers, "refresh", lambda self: calls.append(1) or refresh(self)
    )
    fast, _ = run_trace(scen, tmp_path / "c", monkeypatch, False, None)
    assert len(calls) >= 2  # at the start, and at the change
    pure, _ = run_trace(scen, tmp_path / "p", monkeypatch, True, None)
    unchanged, _ = run_trace(
        ROOT / "scenarios" / "scenario1.yaml", tmp_path / "u", monkeypatch, False, 60
    )
    assert fast == pure
    assert fast != unchanged


def test_the_path_in_use_is_said_and_forced_pure_wins(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(PURE_ENV, "1")
    assert compiled.status() == (False, "pure Python (AMSA_PHYS_PURE is set)")
    monkeypatch.setenv(PURE_ENV, "0")
    on, why = compiled.status()
    assert on == (extension() is not None)
    assert why == ("compiled (C)" if on else why)


@pytest.mark.build  # pip installs the package
def test_an_install_without_a_c_compiler_succeeds_and_runs_pure(tmp_path: Path) -> None:
    """``CC=false``: the optional extension fails to build, the install does not."""
    src = tmp_path / "src"
    src.mkdir()
    for name in ("pyproject.toml", "setup.py", "README.md"):
        shutil.copy(ROOT / name, src / name)
    shutil.copytree(
        ROOT / "amsa_phys",
        src / "amsa_phys",
        ignore=shutil.ignore_patterns("*.so", "__pycache__", "*.pyd"),
    )
    target = tmp_path / "site"
    env = {**os.environ, "CC": "false", "PIP_DISABLE_PIP_VERSION_CHECK": "1"}
    argv = [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(target)]
    try:
        done = subprocess.run(
            [*argv, str(src)], env=env, capture_output=True, text=True, timeout=300
        )
    except subprocess.TimeoutExpired:
        pytest.skip("pip could not build the package within 300 s (no package index here?)")
    if done.returncode != 0 and "setuptools" in done.stderr and "No matching" in done.stderr:
        pytest.skip("pip cannot fetch setuptools for the isolated build (no package index)")
    assert done.returncode == 0, done.stderr[-2000:]
    assert not list(target.rglob("_step*.so"))
    probe = (
        "import sys; sys.path.insert(0, sys.argv[1]); import amsa_phys\n"
        "assert amsa_phys.__file__.startswith(sys.argv[1]), amsa_phys.__file__\n"
        "from amsa_phys.cli.main import main\n"
        "sys.exit(main(['run', sys.argv[2], '--headless', '--no-plot', '-q', '--duration', '20',"
        " '--out', sys.argv[3]]))\n"
    )
    out = tmp_path / "run"
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "MPLBACKEND": "Agg"}
    env.pop(PURE_ENV, None)
    scen = str(ROOT / "scenarios" / "scenario1.yaml")
    ran = subprocess.run(
        [sys.executable, "-c", probe, str(target), scen, str(out)],
        env=env,
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert ran.returncode == 0, ran.stderr[-2000:]
    assert (out / "trace.csv").stat().st_size > 0
    version = subprocess.run(
        [sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv[1]); "
         "from amsa_phys.cli.main import main; main(['--version'])", str(target)],
        env=env, capture_output=True, text=True, cwd=tmp_path,
    )  # fmt: skip
    assert "pure Python (the compiled step was not built" in version.stdout, version
