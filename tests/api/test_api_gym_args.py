"""Wrong arguments to ``amsa_phys.run`` and the Gymnasium env (issue 33, 8).

Each one is the documented error class with one line naming the argument (README "From
Python": a ConfigError named by the CLI option, or by the argument for the env's own;
TypeError for something that is not a scenario or a directory), raised where it is passed:
never an AttributeError, RecursionError, ZeroDivisionError or pygame.error from inside, and
never silently accepted. A run whose in-memory trace cannot fit is refused before it starts.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import amsa_phys as ap
from amsa_phys.api.memory import TraceSizeWarning, check_trace_memory
from amsa_phys.errors import ConfigError

gymnasium = pytest.importorskip("gymnasium")
import amsa_phys.gym  # noqa: E402  registers amsa_phys/Follow-v0 (needs gymnasium)

ROOT = Path(__file__).resolve().parent.parent.parent
SCENARIO = str(ROOT / "scenarios" / "scenario2.yaml")
SEED_RANGE = "must be an integer from 0 to 9223372036854775807 (2**63 - 1), like seed: in a "
SEED_RANGE += "scenario; got "


def _cycle() -> dict[str, Any]:
    loop: dict[str, Any] = {"world": "../worlds/mde_challenge.yaml", "duration": 5}
    loop["set"] = {"Leader.behavior": loop}
    return loop


def _deep() -> list[Any]:
    value: list[Any] = []
    for _ in range(5000):  # past the recursion limit: a RecursionError before the fix
        value = [value]
    return value


def _shared() -> list[Any]:
    value: list[Any] = []
    for _ in range(60):  # 2**60 values when walked: the walk must stop at the node limit
        value = [value, value]
    return value


KV = "MyFollowerController.Kv"
API_CASES: dict[str, tuple[Callable[[], Any], str]] = {
    "set-list": (
        lambda: ap.run(SCENARIO, set=[f"{KV}=0.2"]),
        f"set=: expected a mapping like {{\"Comp.param\": value}}, got list ['{KV}=0.2'] "
        '(the command line\'s "Comp.param=value" is {"Comp.param": value} here)',
    ),
    "set-string": (
        lambda: ap.run(SCENARIO, set=f"{KV}=0.2"),
        f"set=: expected a mapping like {{\"Comp.param\": value}}, got str '{KV}=0.2' "
        '(the command line\'s "Comp.param=value" is {"Comp.param": value} here)',
    ),
    "set-value-contains-itself": (
        lambda: ap.run(SCENARIO, set={KV: _cycle()["set"]}),
        f'set={{"{KV}": ...}}: Leader.behavior.set: contains itself (a mapping or list cannot)',
    ),
    "mapping-contains-itself": (
        lambda: ap.run(_cycle()),
        "<mapping>: set.Leader.behavior: contains itself (a mapping or list cannot)",
    ),
    "mapping-too-deep": (
        lambda: ap.run({"world": "w.yaml", "duration": 5, "set": {"A.b": _deep()}}),
        "<mapping>: set.A.b" + "[0]" * 63 + ": nesting deeper than 64 levels",
    ),
    "mapping-shared-list-explodes": (
        lambda: ap.run({"world": "w.yaml", "duration": 5, "set": {"A.b": _shared()}}),
        "<mapping>: too large: more than 500,000 values",
    ),
    "adapt-text": (  # a true string: the rules stayed on
        lambda: ap.run(SCENARIO, adapt="no"),
        "adapt=: expected True or False, got 'no'",
    ),
    "load-adapt-text": (
        lambda: ap.load(SCENARIO, adapt="off"),
        "adapt=: expected True or False, got 'off'",
    ),
    "progress-text": (
        lambda: ap.run(SCENARIO, progress="yes"),
        "progress=: expected True or False, got 'yes'",
    ),
    "seed-2**64": (lambda: ap.run(SCENARIO, seed=2**64), "seed=: " + SEED_RANGE + str(2**64)),
    "duration-nan": (
        lambda: ap.run(SCENARIO, duration=math.nan),
        "duration=: must be a positive finite number, got nan",
    ),
    "duration-1e308": (
        lambda: ap.run(SCENARIO, duration=1e308),
        "duration=: must be at most 1,000,000 s of simulated time (11.6 days, the limit on a "
        "run's length), got 1e+308",
    ),
}


@pytest.mark.parametrize("case", list(API_CASES))
def test_api_argument_is_a_one_line_config_error(case: str) -> None:
    call, message = API_CASES[case]
    with pytest.raises(ConfigError) as info:
        call()
    assert str(info.value) == message
    assert "\n" not in str(info.value)


def test_api_base_dir_of_a_wrong_type_is_a_type_error() -> None:
    with pytest.raises(TypeError, match=r"^base_dir= is a directory path, got int$"):
        ap.run({"world": "w.yaml", "duration": 5}, base_dir=5)


MEMORY = re.compile(
    r"duration=: the trace kept in memory would be about 2080\.0 GB \(25 columns at 10000 Hz "
    r"for 1e\+06 s\), more than this machine's memory \(about [0-9.e+]+ GB\); shorten "
    r"duration=, lower log_rate= or narrow trace_columns=, or use `amsa-phys run`, which "
    r"streams the trace to a file"
)


def test_api_run_longer_than_memory_is_refused_before_it_starts() -> None:
    """The longest run (1e6 s) of the MDE world logged at 10 kHz is 2.1 TB of packed doubles:
    no machine running the suite has that, and growing towards it would take the machine
    down hours later."""
    with pytest.raises(ConfigError) as info:
        ap.run(SCENARIO, duration=1e6, log_rate=10_000)
    assert MEMORY.fullmatch(str(info.value))


def test_a_trace_over_1_gb_warns_as_the_cli_does() -> None:
    scenario = ap.load(SCENARIO, duration=400_000)  # t + 25 columns, 20 Hz, 8 B: 1.7 GB
    with pytest.warns(TraceSizeWarning) as record:
        size = check_trace_memory(scenario, limit_bytes=math.inf)
    assert size == (400_000 * 20 + 1) * 26 * 8
    assert str(record[0].message) == (
        "the trace kept in memory will be about 1.7 GB (25 columns at 20 Hz for 400000 s); "
        "trace_columns= or log_rate= make it smaller"
    )
    with pytest.raises(
        ConfigError, match=re.escape("more than this machine's memory (about 1.0 GB)")
    ):
        check_trace_memory(scenario, limit_bytes=1e9)  # the refusal follows the limit given
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a short or narrow run: silent
        check_trace_memory(ap.load(SCENARIO, duration=300), limit_bytes=math.inf)
        check_trace_memory(
            ap.load(SCENARIO, duration=400_000, trace_columns="Leader.posX"),
            limit_bytes=math.inf,
        )


def _env(**kwargs: Any) -> Any:
    return gymnasium.make("amsa_phys/Follow-v0", scenario=SCENARIO, **kwargs)


def _reset(env_kwargs: dict[str, Any], **reset_kwargs: Any) -> Any:
    env = _env(**env_kwargs)
    try:
        return env.reset(**reset_kwargs)
    finally:
        env.close()


RENDER = {"render_mode": "rgb_array"}
SIDES = "render_size: each side must be 1 to 8192 pixels, got "
ENV_CASES: dict[str, tuple[Callable[[], Any], str]] = {
    "render-size-zero": (lambda: _env(**RENDER, render_size=(0, 0)), SIDES + "(0, 0)"),
    "render-size-negative": (lambda: _env(**RENDER, render_size=(-5, 10)), SIDES + "(-5, 10)"),
    "render-size-huge": (
        lambda: _env(**RENDER, render_size=(10**6, 10**6)),
        SIDES + "(1000000, 1000000)",
    ),
    "render-size-text": (
        lambda: _env(render_size="640x360"),
        "render_size: expected (width, height) in pixels, got '640x360'",
    ),
    "render-size-float": (
        lambda: _env(render_size=(640.5, 360)),
        "render_size: expected whole numbers of pixels, got (640.5, 360)",
    ),
    "action-scale-nan": (
        lambda: _env(action_scale=math.nan),
        "action_scale: must be a positive finite number, got nan",
    ),
    "action-scale-zero": (
        lambda: _env(action_scale=0),
        "action_scale: must be a positive finite number, got 0",
    ),
    "action-scale-text": (
        lambda: _env(action_scale="100"),
        "action_scale: expected a number, got '100'",
    ),
    "collision-penalty-inf": (
        lambda: _env(collision_penalty=math.inf),
        "collision_penalty: must be a finite number >= 0, got inf",
    ),
    "collision-penalty-negative": (
        lambda: _env(collision_penalty=-1),
        "collision_penalty: must be a finite number >= 0, got -1",
    ),
    "controller-int": (
        lambda: _env(controller=5),
        "controller: expected a component's path (a string), got 5",
    ),
    "actions-string": (
        lambda: _env(actions="LeftPower"),
        "actions: expected a list of names, got 'LeftPower' (one name: ['LeftPower'])",
    ),
    "set-list": (
        lambda: _env(set=["a=b"]),
        "set=: expected a mapping like {\"Comp.param\": value}, got list ['a=b'] "
        '(the command line\'s "Comp.param=value" is {"Comp.param": value} here)',
    ),
    "record-trace-text": (
        lambda: _env(record_trace="no"),
        "record_trace: expected True or False, got 'no'",
    ),
    "reset-seed-2**64": (lambda: _reset({}, seed=2**64), "seed: " + SEED_RANGE + str(2**64)),
    "reset-seed-2**63": (lambda: _reset({}, seed=2**63), "seed: " + SEED_RANGE + str(2**63)),
    "reset-seed-negative": (lambda: _reset({}, seed=-1), "seed: " + SEED_RANGE + "-1"),
    "reset-seed-float": (lambda: _reset({}, seed=1.5), "seed: " + SEED_RANGE + "1.5"),
    "reset-options-list": (
        lambda: _reset({}, seed=1, options=[1]),
        'options: expected a mapping like {"set": {...}}, got [1]',
    ),
    "reset-options-set-list": (
        lambda: _reset({}, seed=1, options={"set": [1]}),
        'options.set: expected a mapping like {"Comp.param": value}, got [1]',
    ),
}


@pytest.mark.parametrize("case", list(ENV_CASES))
def test_env_argument_is_a_one_line_config_error(case: str) -> None:
    call, message = ENV_CASES[case]
    with pytest.raises(ConfigError) as info:
        call()
    assert str(info.value) == message


def test_env_largest_seed_and_picture_are_accepted() -> None:
    env = _env(**RENDER, render_size=(1, 1))
    try:
        _obs, info = env.reset(seed=2**63 - 1)
        assert info["seed"] == 2**63 - 1
        assert env.render().shape == (1, 1, 3)
    finally:
        env.close()


def test_env_keeping_a_trace_longer_than_memory_is_refused_at_reset() -> None:
    env = _env(duration=1e6, log_rate=10_000, record_trace=True)
    try:
        with pytest.raises(ConfigError, match=r"^duration=: the trace kept in memory would be"):
            env.reset(seed=1)
    finally:
        env.close()
    # without the trace nothing grows with the duration: the episode starts
    env = _env(duration=1e6, log_rate=10_000)
    try:
        _obs, info = env.reset(seed=1)
        assert info["t"] == 0.0
    finally:
        env.close()


def test_api_switches_take_true_false_and_numpys_bool() -> None:
    import numpy as np

    assert ap.load(SCENARIO, adapt=np.bool_(False)).adapt == ()
    run = ap.run(SCENARIO, duration=1, adapt=False, progress=np.bool_(False))
    assert run.status == "completed"
