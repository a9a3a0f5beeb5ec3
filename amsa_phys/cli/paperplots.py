"""``amsa-phys plot --paper fig6-sensed`` and ``fig5-start``: Fig. 6 in the sensed wiring,
Fig. 5 against the initial gap.

Each runs the paper's scenarios many times over (every GPS loss rate; every initial gap),
in memory, through :func:`~amsa_phys.cli.paperruns.paper_run`, and hands the
runs to a drawing module (``plots/paperloss.py``, ``plots/paperstart.py``).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..errors import ConfigError, one_line
from ..model.scenario import load_scenario
from ..runs.rundir import check_output
from .paperruns import kv_at_start, paper_run, paper_scenarios


def plot_losses(args: argparse.Namespace) -> int:
    """``--paper fig6-sensed``: each scenario at every GPS loss rate, one panel each."""
    from ..plots import paperloss  # matplotlib: only once the runs are in

    sources = [Path(s) for s in args.rundir]
    if not sources:
        sources = [paper_scenarios("fig6-sensed")[0], paper_scenarios("fig6")[0]]
    for src in sources:
        if src.is_dir():
            raise ConfigError(
                "fig6-sensed runs each scenario at every loss rate: name scenario files",
                file=src,
            )
    out = Path(args.output) if args.output else Path("paper_fig6_sensed.png")
    check_output(out, "--output")
    panels = []
    for src in sources:
        runs = [
            (loss, paper_run(src, [f"LeaderGPS.lostDataGPS={loss}"]))
            for loss in paperloss.LOSS_RATES
        ]
        panels.append((runs[0][1].label, runs))
    paperloss.fig6_losses(panels, out)
    count = len(panels) * len(paperloss.LOSS_RATES)
    print(one_line(f"wrote {out} ({count} runs)"))
    return 0


def plot_starts(args: argparse.Namespace) -> int:
    """``--paper fig5-start``: each Fig. 5 scenario from every initial gap."""
    from ..plots import paperstart  # matplotlib: only once the runs are in

    sources = [Path(s) for s in args.rundir] or paper_scenarios("fig5")
    for src in sources:
        if src.is_dir():
            raise ConfigError(
                "fig5-start runs each scenario from every gap: name scenario files", file=src
            )
    out = Path(args.output) if args.output else Path("paper_fig5_start.png")
    check_output(out, "--output")
    table: dict[tuple[float, float], dict[str, Any]] = {}
    kvs = []
    for src in sources:
        scenario = load_scenario(src)
        kv = kv_at_start(scenario)
        if kv is None:
            raise ConfigError("the scenario's controller has no Kv", file=src)
        kvs.append(kv)
        leader_x = float(scenario.world.leaves["Leader"].params["x"])
        for change in scenario.timeline.initial:
            if change.key == "Leader.x":
                leader_x = float(change.value)
        for gap in paperstart.GAPS:
            run = paper_run(src, [f"Follower.x={leader_x - gap!r}", "Follower.y=0"])
            table[(gap, kv)] = run.metrics["overall"]
    kvs.sort(reverse=True)
    paperstart.start_figure(table, paperstart.GAPS, tuple(kvs), out)
    for gap in paperstart.GAPS:
        best = [paperstart.best_kv(table, gap, m) for m in ("max_after_approach", "rms_error")]
        order = "yes" if paperstart.ordering_holds(table, gap) else "no"
        print(
            one_line(
                f"gap {gap:g} m: paper's ordering of the maxima {order}; best Kv by max "
                f"{best[0]:g}, by rms {best[1]:g}"
            )
        )
    print(one_line(f"wrote {out} ({len(table)} runs)"))
    return 0
