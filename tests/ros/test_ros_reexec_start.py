"""A node re-executed with ``AMSA_PHYS_PYTHON`` and stopped while that Python initialises ends
quietly.

The generated script re-executes itself with the Python that has amsa-phys (a venv). On a
loaded machine roslaunch's SIGINT (a C++ Leaf failed, the launch stops) could reach the new
interpreter while it was still importing ``site``, before the script's quiet handler was in
place: "Fatal Python error: init_import_site ... KeyboardInterrupt", a traceback under the
one line that said what was wrong. Here the new interpreter's ``site`` waits (a
``sitecustomize``) until the test's SIGINT has been sent: the node must end with 130 and say
nothing. Mutation-checked: without the mask held across the exec (``files/node.py.in``) the
interpreter dies with the fatal error.
"""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import sigint
from deadlines import HANG_S

from amsa_phys.cli.main import main

SCENARIO = Path(__file__).resolve().parent.parent / "fixtures" / "ros_short.yaml"
SYSTEM_PYTHON = shutil.which("python3", path="/usr/bin:/bin")
#: the re-executed interpreter's ``site``: says it is initialising, then waits for a SIGINT
#: (delivered, or held pending by the script's mask) before initialisation goes on
SLOW_SITE = """import os, signal, time
if os.environ.get("AMSA_PHYS_REEXEC") == "1":
    os.write(1, b"interpreter starting\\n")
    end = time.monotonic() + 60
    while signal.SIGINT not in signal.sigpending() and time.monotonic() < end:
        time.sleep(0.01)
"""


@pytest.mark.skipif(SYSTEM_PYTHON is None, reason="no python3 in /usr/bin to start the node")
def test_a_node_stopped_while_its_python_initialises_says_nothing(tmp_path: Path) -> None:
    out = tmp_path / "mdeChallenge"
    assert main(["export", "ros", str(SCENARIO), "-o", str(out)]) == 0
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(SLOW_SITE)
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": str(site), "AMSA_PHYS_PYTHON": sys.executable}
    probe = subprocess.run(
        [SYSTEM_PYTHON, "-c", "import amsa_phys"], env=env, capture_output=True, cwd=tmp_path
    )
    if probe.returncode == 0:
        pytest.skip("the system python3 has amsa_phys: the node would not re-execute")
    proc = subprocess.Popen(
        [SYSTEM_PYTHON, str(out / "nodes" / "amsa_scenario.py")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
        cwd=tmp_path,
        preexec_fn=sigint.at_default,
    )
    try:
        assert proc.stdout is not None
        assert proc.stdout.readline() == b"interpreter starting\n"
        proc.send_signal(signal.SIGINT)
        out_rest, err = proc.communicate(timeout=HANG_S)
    finally:
        proc.kill()
    assert err == b""
    assert out_rest == b""
    assert proc.returncode == 128 + signal.SIGINT
