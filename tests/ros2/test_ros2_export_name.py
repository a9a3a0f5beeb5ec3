"""``export ros2 --name PKG``: two scenarios of one world, two packages, one workspace;
and ``ros2 lockstep --bag``.

Without ``--name`` every export of a world is named after its root component, and a ROS 2
workspace refuses two packages of one name. A named package is the same package under its
own name (package.xml, resource marker, Python package, console scripts), and it locksteps
as any: the trace of ``run --duration``, byte for byte. A name that is no REP 144 package
name is refused (one line, exit 2, nothing written).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from ros2net import EXPORT_ENV, PY, ROOT, amsa, in_private_network, ros2_missing

SCENARIO = ROOT / "scenarios" / "scenario1.yaml"


def test_a_named_package_carries_its_name_everywhere(tmp_path: Path) -> None:
    a, b = tmp_path / "ws" / "src" / "s1", tmp_path / "ws" / "src" / "f6"
    amsa("export", "ros2", str(SCENARIO), "-o", str(a), "--name", "s1_follow", "-q")
    amsa("export", "ros2", str(ROOT / "scenarios" / "paper_fig6.yaml"), "-o", str(b))
    names = [ET.parse(d / "package.xml").getroot().findtext("name") for d in (a, b)]
    assert names == ["s1_follow", "mde_challenge"]
    assert (a / "resource" / "s1_follow").exists()
    assert (a / "s1_follow" / "__init__.py").exists()
    assert "s1_follow.MyFollowerController:main" in (a / "setup.py").read_text()
    assert not (a / "mde_challenge").exists()


@pytest.mark.parametrize("bad", ["S1", "1st", "a-b", "a b", "x'); import os #"])
def test_a_name_that_cannot_name_a_package_is_refused(tmp_path: Path, bad: str) -> None:
    out = tmp_path / "pkg"
    res = amsa("export", "ros2", str(SCENARIO), "-o", str(out), "--name", bad, check=False)
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, lines
    assert "--name" in lines[0], lines
    assert "REP 144" in lines[0], lines
    assert "Traceback" not in res.stderr
    assert not out.exists()


@pytest.mark.parametrize(
    ("name", "why"),
    [
        ("rclpy", "the nodes import the Python module rclpy"),
        ("amsa_phys", "the nodes import the Python module amsa_phys"),
        ("std_msgs", "the nodes import the Python module std_msgs"),
        ("json", "json is a module of Python's standard library"),
    ],
)
def test_a_name_that_would_shadow_a_module_the_nodes_import_is_refused(
    tmp_path: Path, name: str, why: str
) -> None:
    """A package is a Python package of its name too: called ``rclpy`` it would shadow
    rclpy itself wherever both are installed."""
    out = tmp_path / "pkg"
    res = amsa("export", "ros2", str(SCENARIO), "-o", str(out), "--name", name, check=False)
    assert res.returncode == 2, res.stderr
    assert (
        res.stderr == f"error: --name {name!r}: {why}, which the package would shadow; "
        "choose another\n"
    )
    assert not out.exists()


@pytest.mark.ros2
def test_a_named_package_locksteps_as_run(tmp_path: Path) -> None:
    missing = ros2_missing()
    if missing:
        pytest.skip(missing)
    pkg, ref, out = tmp_path / "pkg", tmp_path / "ref", tmp_path / "lock"
    amsa("export", "ros2", str(SCENARIO), "-o", str(pkg), "--duration", "20", "--name", "s1x")
    ref_bag, bag = tmp_path / "ref.mcap", tmp_path / "lock.mcap"
    amsa(
        "run", str(SCENARIO), "--headless", "--no-plot", "-q", "--out", str(ref),
        "--duration=20", "--bag", str(ref_bag),
    )  # fmt: skip
    script = tmp_path / "netns.sh"
    # the README's own command, in the package folder
    assert "amsa-phys ros2 lockstep . --out RUNDIR" in (pkg / "README.md").read_text()
    script.write_text(
        f"ip link set lo up\n{PY} -m amsa_phys ros2 lockstep . --out {out} --no-plot -q "
        f"--bag {bag}\n"
    )
    log = tmp_path / "netns.log"
    rc, left = in_private_network(script, EXPORT_ENV, log, cwd=pkg)
    assert rc == 0, log.read_text()
    assert left == []
    assert (out / "trace.csv").read_bytes() == (ref / "trace.csv").read_bytes()
    # and its bag is run --bag's, byte for byte
    assert bag.read_bytes() == ref_bag.read_bytes()
