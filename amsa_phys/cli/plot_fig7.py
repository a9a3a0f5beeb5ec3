"""``amsa-phys plot --paper fig7``: run the adaptive scenario and every fixed gain, draw Fig. 7."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..engine import interrupt
from ..engine.tracemem import TraceMemory
from ..errors import ConfigError, one_line
from ..model.scenario import Scenario, load_scenario, traced_columns, without_adapt
from ..runs.rundir import check_output
from ..runs.single import execute

#: The fixed gains of the comparison.
GAINS = (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35)


def plot_fig7(args: argparse.Namespace) -> int:
    """Run ``scenarios/adaptive.yaml`` (or the one scenario named) with its rules and with
    each fixed gain (``--no-adapt --set Param=K``), then draw the figure."""
    from ..plots.fig7 import Fig7Run, fig7  # matplotlib: only once the runs are in

    if len(args.rundir) > 1:
        raise ConfigError("Fig. 7 takes one adaptive scenario", key="--paper fig7")
    source = Path(args.rundir[0]) if args.rundir else Path("scenarios/adaptive.yaml")
    if not source.is_file():
        raise ConfigError("no such scenario (run it from the project's folder)", file=source)
    out = Path(args.output) if args.output else Path("paper_fig7.png")
    check_output(out, "--output")
    scenario = load_scenario(source)
    if not scenario.adapt:
        raise ConfigError("the scenario has no adapt: rules", file=source)
    key = scenario.adapt[0].changes[0].key  # the parameter the rules tune

    def one(value: float | None) -> Fig7Run:
        s: Scenario = (
            scenario
            if value is None
            else without_adapt(load_scenario(source, overrides=[f"{key}={value}"]))
        )
        memory = TraceMemory(traced_columns(s))
        with interrupt.deferred():
            ended = execute(s, memory, progress=False)
        if ended.error is not None:
            raise ended.error
        columns, data = ["t", *memory.columns], memory.matrix()
        q = ended.metrics["quality"]
        d = data[:, columns.index(q["signal"])]
        return Fig7Run(s.name, value, data[:, 0], d, ended.metrics)

    adaptive = one(None)
    fixed = [one(k) for k in GAINS]
    fig7(adaptive, fixed, out, key.rsplit(".", 1)[-1])
    best = min(fixed, key=lambda r: r.rms)
    print(
        one_line(
            f"wrote {out}: adaptive rms {adaptive.rms:.3f} m, best fixed "
            f"{key}={best.value:g} rms {best.rms:.3f} m"
        )
    )
    return 0
