"""The simulator node's entry point: load the node's configuration, wait for the graph,
run the scenario through ``runs.single.run_scenario`` on a :class:`RosSimulation` over a
:class:`Link` (``simulator.py``), write the run directory and say how it went.

Split from ``simulator.py`` (the Link, the protocol side) to keep each module to one job.
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path
from typing import Any

from ...engine import interrupt
from ...errors import AmsaError, Interrupted, RunFault, one_line
from ...runs.expect import check_expectations
from ...runs.rundir import default_run_dir, prepare_run_dir
from ...runs.single import run_scenario
from .. import names
from . import adaptlink, ending, records, rosio, startup
from .config import load_config
from .rossim import RosSimulation
from .simulator import Link


def main() -> None:
    """The simulator node's entry point."""
    rospy = rosio.ros()
    rospy.init_node(names.SIMULATOR, disable_signals=True)  # Ctrl-C is the engine's
    code = 0
    try:
        cfg = load_config(rospy)
        check_seed(rospy)
        scenario, folded = records.fold_server_values(rospy, cfg.scenario)
        for change in folded:
            print(f"amsa_simulator: {change.key}={change.value} (parameter server)", flush=True)
        duration = str(rospy.get_param("~duration", "") or "")
        if duration:
            scenario = records.cut(scenario, duration)
        out = str(rospy.get_param("~out", "") or "")
        root = Path(str(rospy.get_param("~runs", "") or os.environ.get("PWD", "."))) / "runs"
        out_dir = Path(out) if out else default_run_dir(scenario.name, root)
        prepare_run_dir(out_dir, bool(rospy.get_param("~force", False)), flag="out:=")
        link = Link(rospy, cfg)
        adaptlink.attach(link)  # rules:=node: the adapt node runs the rules
        link.speed = float(rospy.get_param("~speed", 1.0))
        link.waves = bool(rospy.get_param("~waves", True))
        if not link.speed > 0 or math.isinf(link.speed):
            raise AmsaError(f"speed:= must be a positive number, got {link.speed}")
        # the nodes wait twice ``timeout:=`` for their readers (amsa_leaf_node.h, leaf.py):
        # the simulator waits as long for them to be ready
        ready_timeout = float(rospy.get_param("~ready_timeout", 2 * cfg.timeout))
        missing = link.wait_ready(ready_timeout)
        if missing:
            raise RunFault("ROS graph", 0, f"not connected after {ready_timeout:g} s: {missing}")
        running = (
            f"amsa_simulator: {len(cfg.graph.remote)} nodes connected, running "
            f"{scenario.name} ({cfg.mode}{', pipelined' if cfg.pipeline else ''})"
        )

        def simulation(sc: Any, trace: Any) -> Any:
            ros_sim = RosSimulation(sc, trace, link)
            # said once the run has read the parameters it starts from: a `rosparam set`
            # after this line is a live change (before it, the run took it as its start)
            print(running, flush=True)
            return ros_sim.sim

        startup.started()  # Ctrl-C and SIGTERM: the engine's, through the run
        with interrupt.sigterm_as_ctrl_c():
            outcome = run_scenario(
                scenario,
                out_dir,
                plot=bool(rospy.get_param("~plots", True)),
                progress=False,
                simulation=simulation,
            )
        if not link.drain_boundary(ready_timeout):
            print(
                f"amsa_simulator: the boundary node did not catch up in {ready_timeout:g} s; "
                "its last standard messages may be missing",
                file=sys.stderr,
                flush=True,
            )
        if link.bag_tail is not None:  # bag:=: the recorder has written the run's last messages
            link.bag_tail.finish()
        _summary(outcome.metrics, out_dir)
        checks = check_expectations(scenario.expect, outcome.metrics, out_dir / "trace.csv")
        for check in checks:
            print(f"expect {check.describe()}", flush=True)
        code = 0 if all(c.passed for c in checks) else 1
        print(ending.done_line(checks, out_dir), flush=True)
    except Interrupted as exc:
        print(f"error: {exc}", file=sys.stderr, flush=True)
        code = 130
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr, flush=True)
        code = 130
    except AmsaError as exc:
        print(f"error: {exc}", file=sys.stderr, flush=True)
        code = exc.exit_code
    rospy.signal_shutdown("the run is over")
    ending.end_launch(code)  # a passing run: roslaunch ends the launch, without alarm
    sys.exit(code)


#: the largest seed, as everywhere else (``--seed``, a scenario's ``seed:``)
MAX_SEED = 2**63 - 1


def check_seed(rospy: Any) -> None:
    """Refuse, before anything is written, a ``names.P_SEED`` that is not a seed: the C++
    sensors seed their random streams from it, and a hand-edited launch file holding ``-1``
    or text had faulted the run at its first step, naming the sensor, not the parameter
    (and one beyond 2^63 - 1, which no other part of amsa-phys takes, ran)."""
    if not rospy.has_param(names.P_SEED):
        return  # a launch file of the user's own: each C++ sensor says so at its first step
    text = str(rospy.get_param(names.P_SEED))
    if not (text.isascii() and text.isdigit() and int(text) <= MAX_SEED):
        raise AmsaError(
            one_line(
                f"{names.P_SEED}: expected a seed, 0 to 2^63 - 1 in digits, got {text!r} "
                "(export the package again with --seed N rather than editing its launch file)"
            )
        )


def _summary(metrics: dict[str, Any], out_dir: Path) -> None:
    overall = metrics["overall"]
    parts = [f"{k}={v:.3f}" for k, v in overall.items() if isinstance(v, float)]
    print(
        f"amsa_simulator: {metrics['status']}, simulated {metrics['simulated']:g} s in "
        f"{metrics['wall_time_s']:g} s; {' '.join([*parts, f'outputs in {out_dir}'])}",
        flush=True,
    )
