"""Config fuzzing: mutated worlds and scenarios are accepted and run, or refused cleanly.

Each generated case is written to a file and given to the CLI in-process. It must either be
accepted (then a 1 s run ends with exit 0, 1 or 3), or refused with exit 2 and exactly one
line that names the file — never a traceback (any other exception fails the test) and never a
hang (hypothesis's deadline). ``AMSA_FUZZ_EXAMPLES`` raises the number of cases (default 500).

Besides wrong types, missing and unknown keys, NaN, duplicates, tags, truncation and junk,
the generators make numbers too big for a float (401 digits), resource-amplifying structures
(aliases of a ``count:`` Composite, nested aliases: "billion laughs") and files that are not
regular files at all (devices, FIFOs, directories, links to them, sparse giants).
"""

from __future__ import annotations

import contextlib
import copy
import io
import os
import tempfile
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from amsa_phys.cli.main import main

ROOT = Path(__file__).resolve().parent.parent.parent
BASE_WORLD = yaml.safe_load((ROOT / "worlds" / "mde_challenge.yaml").read_text())
BASE = {
    "world": BASE_WORLD,
    "duration": 1,
    "seed": 1,
    "quality": {"signal": "MyDistanceMonitor.distanceFollowerToLeader", "reference": 15},
    "set": {"MyFollowerController.Kv": 0.2},
    "timeline": [{"at": 0.5, "set": {"LeaderGPS.lostDataGPS": 10}}],
    "expect": [{"metric": "max_distance", "below": 100}],
}
EXAMPLES = int(os.environ.get("AMSA_FUZZ_EXAMPLES", "500"))

#: integers of 300..420 digits: most are too big for a float (about 1.8e308)
huge_ints = st.builds(
    lambda digits, sign: sign * int("7" * digits), st.integers(300, 420), st.sampled_from([1, -1])
)

weird = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**20), max_value=10**20),
    huge_ints,
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.lists(st.integers(), max_size=3),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=2),
    st.sampled_from(["Leader.posX", "Nope.out", "GPS", "freeRobot", "-1", "1e400", "", "Kv"]),
)


def paths(node: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    out = [prefix]
    if isinstance(node, dict):
        for k, v in node.items():
            out += paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += paths(v, (*prefix, i))
    return out


def get(node: Any, path: tuple[Any, ...]) -> Any:
    for p in path:
        node = node[p]
    return node


@st.composite
def mutated(draw: st.DrawFn) -> str:
    doc = copy.deepcopy(BASE)
    for _ in range(draw(st.integers(1, 3))):
        all_paths = [p for p in paths(doc) if p]
        if not all_paths:
            break
        path = draw(st.sampled_from(all_paths))
        parent = get(doc, path[:-1])
        kind = draw(st.sampled_from(["replace", "delete", "add", "rename", "scale", "scale"]))
        value = parent[path[-1]]
        if kind == "scale":
            # mostly-valid cases: a number moved within a few times its value, so runs happen
            if isinstance(value, int | float) and not isinstance(value, bool):
                factor = draw(st.sampled_from([0, 0.5, 2, 3]))
                with contextlib.suppress(OverflowError):  # a huge int from a "replace": kept
                    parent[path[-1]] = type(value)(value * factor)
        elif kind == "replace":
            parent[path[-1]] = draw(weird)
        elif kind == "delete":
            del parent[path[-1]]
        elif kind == "add" and isinstance(parent, dict):
            parent[draw(st.text(min_size=1, max_size=8))] = draw(weird)
        elif kind == "rename" and isinstance(parent, dict):
            parent[str(path[-1]) + draw(st.sampled_from(["x", "_", "s"]))] = parent.pop(path[-1])
    amplify = draw(st.sampled_from(["none", "none", "none", "count", "laughs"]))
    if amplify == "count" and isinstance(doc.get("world"), dict):
        # one Composite written once, used many times: the dumper writes it as aliases
        car = {"count": draw(st.sampled_from([2, 100, 10000])), "components": {}}
        car["components"]["Power"] = {"template": "ConstantPower"}
        components = doc["world"].setdefault("components", {})
        if isinstance(components, dict):
            for i in range(draw(st.integers(1, 40))):
                components[f"Copy{i}_"] = car
    elif amplify == "laughs":
        nested: Any = ["lol"] * 9
        for _ in range(draw(st.integers(2, 9))):
            nested = [nested] * 9  # shared, so written as nested aliases
        doc[draw(st.sampled_from(["description", "set", "sweep"]))] = nested
    text = yaml.safe_dump(doc, sort_keys=False, allow_unicode=True)
    textual = draw(
        st.sampled_from(
            ["none", "none", "none", "dup", "tag", "cut", "junk", "deep", "empty", "cycle"]
        )
    )
    if textual == "dup":
        text += "duration: 5\n"
    elif textual == "tag":
        text = text.replace("seed: 1", "seed: !!python/object/apply:os.getcwd []", 1)
    elif textual == "cut":
        text = text[: draw(st.integers(0, len(text)))]
    elif textual == "junk":
        text = draw(st.binary(max_size=64)).decode("latin-1") + text
    elif textual == "deep":
        text += "description: " + "[" * 200 + "]" * 200 + "\n"
    elif textual == "empty":
        text = ""
    elif textual == "cycle":
        text = text.replace("schedule:", "schedule_removed:")
    return text


@pytest.mark.slow  # hundreds of mutated scenarios validated and run: 11 s of CPU
@settings(
    max_examples=EXAMPLES,
    deadline=None,  # speed is the benchmarks' business; a loaded CI box must not fail this
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(mutated())
def test_mutated_scenarios_run_or_are_refused_in_one_line(text: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.yaml"
        path.write_bytes(text.encode("utf-8", errors="surrogateescape"))
        err, out = io.StringIO(), io.StringIO()
        with redirect_stderr(err), redirect_stdout(out):
            code = main(["validate", str(path)])
        event("refused" if code == 2 else "accepted")
        if code == 2:
            lines = err.getvalue().splitlines()
            assert len(lines) == 1, err.getvalue()
            assert lines[0].startswith(f"error: {path}"), lines[0]
            return
        assert code == 0, (code, err.getvalue())
        with redirect_stderr(err), redirect_stdout(out):
            code = main(
                [
                    "run",
                    str(path),
                    "--headless",
                    "--out",
                    str(Path(tmp) / "o"),
                    "-q",
                    "--no-plot",
                    "--duration",
                    "1",
                ]
            )
        assert code in (0, 1, 3), (code, err.getvalue())
        event(f"run exit {code}")
        if code == 3:
            assert err.getvalue().startswith("error: run fault at t=")


SPECIAL = ["fifo", "/dev/zero", "/dev/urandom", "directory", "link-to-zero", "sparse-giant"]


@settings(max_examples=24, deadline=None, derandomize=True)
@given(
    st.sampled_from(SPECIAL),
    st.sampled_from(["validate", "run", "world-of-a-scenario", "describe", "test"]),
)
def test_files_that_are_not_regular_files_are_refused_in_one_line(kind: str, command: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        target = Path(tmp) / "special.yaml"
        if kind == "fifo":
            os.mkfifo(target)  # nobody writes to it: reading it would never end
        elif kind == "directory":
            target.mkdir()
        elif kind == "link-to-zero":
            target.symlink_to("/dev/zero")
        elif kind == "sparse-giant":
            with target.open("wb") as fh:
                fh.truncate(1 << 30)
        else:
            target = Path(kind)
        named = target
        if command == "world-of-a-scenario":
            named = Path(tmp) / "s.yaml"
            named.write_text(f"world: {target}\nduration: 1\n")
            command = "validate"
        argv = {
            "validate": ["validate", str(named)],
            "describe": ["describe", str(named)],
            "test": ["test", str(named)],
            "run": ["run", str(named), "--headless", "--out", str(Path(tmp) / "o")],
        }[command]
        err, out = io.StringIO(), io.StringIO()
        with redirect_stderr(err), redirect_stdout(out):
            code = main(argv)
        # `test` reports a file it cannot load as an ERROR row (exit 1) and searches a
        # directory (none found: exit 2); the other commands refuse the file itself
        assert code in ((1, 2) if command == "test" else (2,)), (code, err.getvalue())
        lines = err.getvalue().splitlines()
        assert len(lines) == 1, err.getvalue()
        assert lines[0].startswith("error: "), lines[0]
        if command != "test":
            assert any(w in lines[0] for w in ("regular file", "too large", "is a directory"))
        assert not (Path(tmp) / "o").exists()
