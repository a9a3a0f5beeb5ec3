"""The ROS 1 export's hostile payloads through ``export ros2``: no code of a name ever runs.

With the refusal of hostile names switched off (only the escapers stand between the names and
the generated files), packages whose scenario name, file name and world description carry the
payloads of ``tests/ros/test_export_ros_payloads.py`` (a newline then YAML tags for a
parameter loader, ``\"\"\"`` then code for a Python docstring, XML for ``package.xml``) are
generated, every Python file compiled and imported, ``setup.py`` run as colcon would ask it,
and ``ros2 lockstep`` run on them (the nodes load the parameters file with rcl's YAML parser
and the resolved scenario), and ``ros2 robot`` (the robot boundary's script, the controller
side's nodes) on the sensed world's: everything completes and no payload's marker file exists.
"""

from __future__ import annotations

import json
import os
import random
import subprocess
import uuid
from pathlib import Path

import pytest
import yaml
from ros2net import PY, ROOT, WALL_LIMIT_S, leftovers, ros2_missing

from amsa_phys.ros.ros2 import export

pytestmark = pytest.mark.ros2
MISSING = ros2_missing()
if MISSING:
    pytest.skip(MISSING, allow_module_level=True)

WORLD = ROOT / "worlds" / "mde_challenge.yaml"
#: (file name, scenario name): every payload touches ``MARK`` in its working directory
CASES = [
    (
        "a\nexecute_process(COMMAND touch MARK)\n#.yaml",
        "x\npwn: !radians __import__('os').system('touch MARK')\namsa: {mode: free}\n#",
    ),
    (
        'b"""\nimport os; os.system("touch MARK")\n""".yaml',
        "y\n\x85q: !radians __import__('os').system('touch MARK')\n#",
    ),
    (
        "c'''\nimport os; os.system('touch MARK')\n'''.yaml",
        '</description><exec_depend>$(touch MARK)</exec_depend>"""\nimport os\n',
    ),
]


@pytest.mark.parametrize("case", range(len(CASES)))
def test_payloads_never_run_when_the_package_is_generated_imported_and_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, case: int
) -> None:
    monkeypatch.setattr(export, "check_name", lambda *_a, **_k: None)  # the escapers alone
    fname, name = CASES[case]
    world = tmp_path / "world.yaml"
    data = yaml.safe_load(WORLD.read_text())
    data["description"] = name  # into package.xml and the node scripts' docstrings
    world.write_text(yaml.safe_dump(data, sort_keys=False))
    src = tmp_path / "scenarios"
    src.mkdir()
    scenario = src / fname
    scenario.write_text(
        f"name: {json.dumps(name)}\nworld: {json.dumps(str(world))}\nduration: 2\nseed: 1\n"
    )
    from amsa_phys.model.scenario import load_scenario

    pkg = tmp_path / "pkg"
    pkg.mkdir()
    sc = load_scenario(scenario)
    assert sc.world.data.get("description") == name  # the payload reached the model
    export.generate(sc, str(scenario), pkg)
    work = tmp_path / "work"
    work.mkdir()
    modules = sorted((pkg / "mde_challenge").glob("*.py"))
    assert len(modules) > 2
    checks = [
        f"import ast, runpy, sys; sys.path.insert(0, {str(pkg)!r})",
        *[f"ast.parse(open({str(p)!r}).read())" for p in pkg.rglob("*.py")],
        *[f"import mde_challenge.{p.stem}" for p in modules if p.stem != "__init__"],
    ]
    token = uuid.uuid4().hex
    env = {
        **os.environ,
        "AMSA_ROS2_TEST": token,
        "ROS_DOMAIN_ID": str(random.randint(1, 100)),
        "SDL_VIDEODRIVER": "dummy",
        "MPLBACKEND": "Agg",
    }
    env.pop("VIRTUAL_ENV", None)
    body = (
        "ip link set lo up\n"
        f"{PY} -c {json.dumps('; '.join(checks))} || exit 10\n"
        f"(cd {pkg} && {PY} setup.py --name --version) || exit 11\n"
        f"{PY} -m amsa_phys ros2 lockstep {pkg} --out {work / 'run'} --no-plot -q || exit 12\n"
    )
    res = subprocess.run(
        ["unshare", "-n", "bash", "-c", body],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=WALL_LIMIT_S,
    )
    assert res.returncode == 0, res.stdout + res.stderr
    assert "mde_challenge" in res.stdout  # setup.py answered
    assert (work / "run" / "trace.csv").exists()
    marks = [p for p in tmp_path.rglob("MARK")] + list(Path.cwd().glob("MARK"))
    assert marks == []
    assert leftovers(token) == []


#: waits until the robot side's nodes are on the graph (they read the parameters file and
#: the resolved scenario at start), then prints them
PROBE = """
import time, rclpy
rclpy.init()
n = rclpy.create_node("probe")
want = {"amsa_boundary", "MyGpsDistance", "MyFollowerController", "MyNormalizePower"}
end = time.monotonic() + 300
while not want <= set(n.get_node_names()) and time.monotonic() < end:
    rclpy.spin_once(n, timeout_sec=0.2)
print("UP", sorted(want & set(n.get_node_names())))
"""


@pytest.mark.parametrize("case", range(len(CASES)))
def test_payloads_never_run_when_the_package_runs_on_a_robot(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, case: int
) -> None:
    """The robot side (``ros2 robot``: the boundary node's script, the controller side's
    nodes, the manifest's ``local``) of a package whose names carry the payloads."""
    monkeypatch.setattr(export, "check_name", lambda *_a, **_k: None)  # the escapers alone
    fname, name = CASES[case]
    world = tmp_path / "world.yaml"
    data = yaml.safe_load((ROOT / "worlds" / "mde_challenge_sensed.yaml").read_text())
    data["description"] = name
    world.write_text(yaml.safe_dump(data, sort_keys=False))
    (tmp_path / "scenarios").mkdir()
    scenario = tmp_path / "scenarios" / fname
    scenario.write_text(
        f"name: {json.dumps(name)}\nworld: {json.dumps(str(world))}\nduration: 2\nseed: 1\n"
    )
    from amsa_phys.model.scenario import load_scenario

    pkg = tmp_path / "pkg"
    pkg.mkdir()
    export.generate(load_scenario(scenario), str(scenario), pkg)
    assert (pkg / "mde_challenge_sensed" / "amsa_boundary.py").exists()
    (tmp_path / "probe.py").write_text(PROBE)
    work = tmp_path / "work"
    work.mkdir()
    token = uuid.uuid4().hex
    env = {
        **os.environ,
        "AMSA_ROS2_TEST": token,
        "ROS_DOMAIN_ID": str(random.randint(1, 100)),
        "SDL_VIDEODRIVER": "dummy",
        "MPLBACKEND": "Agg",
    }
    env.pop("VIRTUAL_ENV", None)
    body = (
        "set -m\nip link set lo up\n"
        f"{PY} -m amsa_phys ros2 robot {pkg} & AMSA=$!\n"
        f"{PY} {tmp_path / 'probe.py'}\n"
        "kill -TERM $AMSA; wait $AMSA; echo AMSA_RC=$?\n"
    )
    res = subprocess.run(
        ["unshare", "-n", "bash", "-c", body],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=WALL_LIMIT_S,
    )
    out = res.stdout + res.stderr
    assert (
        "UP ['MyFollowerController', 'MyGpsDistance', 'MyNormalizePower', 'amsa_boundary']" in out
    ), out
    assert "AMSA_RC=0" in out, out
    marks = [p for p in tmp_path.rglob("MARK")] + list(Path.cwd().glob("MARK"))
    assert marks == []
    assert leftovers(token) == []
