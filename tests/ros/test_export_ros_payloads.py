"""Issue 33's payloads through catkin_make and roslaunch: no code of a name ever runs.

With the refusal of hostile names switched off (so only the escapers stand between the names
and the generated files), a package whose scenario names and file names carry the issue's
payloads (a newline then ``!radians`` code for roslaunch's rosparam loader, a newline then
``execute_process`` for catkin_make, ``\"\"\"`` then code for the Python nodes) is built with
catkin and launched; the run completes and no payload's marker file exists anywhere.
Launched in a private network namespace (``unshare -n``) as tests/ros/test_ros.py does.
Skipped, with the reason, where ROS, catkin, unshare or root is missing.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import sigint

from amsa_phys.cli.main import main
from amsa_phys.ros import generate

ROOT = Path(__file__).resolve().parent.parent.parent
WORLD = ROOT / "worlds" / "mde_challenge.yaml"
LAUNCH_TIMEOUT = 600  # s of wall time before a launch is declared hung: a failure deadline


def _ros_missing() -> str | None:
    for tool in ("roslaunch", "catkin_make", "unshare", "ip"):
        if shutil.which(tool) is None:
            return f"{tool} is not installed (ROS 1 from Debian: see .ci/run)"
    if os.geteuid() != 0:
        return "unshare -n (a private network for roscpp) needs root"
    if subprocess.run(["unshare", "-n", "true"], capture_output=True).returncode != 0:
        return "unshare -n is not permitted here"
    return None


pytestmark = [
    pytest.mark.ros,
    pytest.mark.skipif(_ros_missing() is not None, reason=str(_ros_missing())),
]

#: (file name, scenario name): every payload touches ``MARK`` in its working directory.
CASES = [
    (
        "a\nexecute_process(COMMAND touch MARK)\n#.yaml",
        "x\npwn: !radians __import__('os').system('touch MARK')\namsa: {mode: free}\n#",
    ),
    (
        'b"""\nimport os; os.system("touch MARK")\n""".yaml',
        "y\n\x85q: !radians __import__('os').system('touch MARK')\n#",
    ),
]


def _no_ros_env() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if not k.startswith("ROS") and k != "PYTHONPATH"}


def test_payloads_never_run_at_catkin_make_or_roslaunch(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(generate, "check_names", lambda *_: None)  # the escapers alone
    src = tmp_path / "scenarios"
    src.mkdir()
    files = []
    for fname, name in CASES:
        path = src / fname
        path.write_text(
            f"name: {json.dumps(name)}\nworld: {json.dumps(str(WORLD))}\nduration: 2\nseed: 1\n"
        )
        files.append(str(path))
    ws = tmp_path / "ws"
    assert main(["export", "ros", *files, "-o", str(ws / "src" / "mdeChallenge")]) == 0
    monkeypatch.chdir(tmp_path)
    build = subprocess.run(
        ["catkin_make", "-C", str(ws), "-DPYTHON_EXECUTABLE=/usr/bin/python3"],
        cwd=ws,
        capture_output=True,
        text=True,
        env={**_no_ros_env(), "PWD": str(ws)},
    )
    assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
    launches = sorted(p.name for p in (ws / "src" / "mdeChallenge" / "launch").iterdir())
    assert len(launches) == 2
    script = ws / "launch.sh"
    script.write_text(
        "set -e\nip link set lo up\n"
        f"export ROS_LOG_DIR={ws}/roshome/log ROS_MASTER_URI=http://localhost:11311\n"
        "export ROS_HOSTNAME=localhost ROS_DISTRO=${ROS_DISTRO:-debian}\n"
        f"source {ws}/devel/setup.bash\n"
        'exec roslaunch mdeChallenge "$@"\n'
    )
    for i, launch in enumerate(launches):
        out = tmp_path / f"run{i}"
        proc = subprocess.Popen(
            ["unshare", "-n", "bash", str(script), launch, f"out:={out}", "plots:=false"],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            cwd=tmp_path,
            env={
                **_no_ros_env(),
                "ROS_HOME": str(ws / "roshome"),
                "PWD": str(tmp_path),
                "AMSA_PHYS_PYTHON": sys.executable,
            },
            start_new_session=True,
            preexec_fn=sigint.at_default,
        )
        try:
            text, _ = proc.communicate(timeout=LAUNCH_TIMEOUT)
        finally:
            if proc.poll() is None:  # hung: end the launch's process group (ours, by id)
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        assert "completed" in text, text[-3000:]
        assert (out / "trace.csv").is_file()
    assert sorted(str(p) for p in tmp_path.rglob("MARK")) == []
