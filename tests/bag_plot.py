"""A picture of a run drawn from its MCAP bag alone (the README's ``assets/bag_plot.png``).

    python tests/bag_plot.py RUN.mcap OUT.png

Left: each robot's true track (``/<robot>/ground_truth/odom``) and its GPS fixes
(``NavSatFix`` put back on the plane); right: the quality signal's stamped scalars with the
phases from ``/amsa/events``. What a user sees opening the same topics in Foxglove's Map and
Plot panels or PlotJuggler.
"""

from __future__ import annotations

import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from amsa_phys.stdmsgs import DEFAULT_ORIGIN, geodetic_to_enu

NS = 1e9
SIGNAL = "/amsa/data/MyDistanceMonitor/distanceFollowerToLeader"


def _short(detail: str) -> str:
    """``phase 1 starts: A.b=1, C.d=2`` -> ``phase 1: A.b=1`` and ``C.d=2`` on the next line
    (every value the phase sets: its first alone could name a value another one overrides)."""
    head, _, sets = detail.partition(" starts: ")
    return f"{head}: " + "\n".join(sets.split(", ")) if sets else head


def plot_tracks(bag: Path, png: Path) -> dict[str, np.ndarray]:
    """Draw ``png`` from ``bag``; returns each track as rows (t, x, y), by topic."""
    tracks: dict[str, list[tuple[float, float, float]]] = defaultdict(list)
    signal: list[tuple[float, float]] = []
    phases: list[tuple[float, str]] = []
    with Path(bag).open("rb") as fh:
        reader = make_reader(fh, decoder_factories=[DecoderFactory()])
        for schema, channel, msg, m in reader.iter_decoded_messages():
            t = msg.log_time / NS
            if schema.name == "sensor_msgs/msg/NavSatFix":
                x, y = geodetic_to_enu(m.latitude, m.longitude, DEFAULT_ORIGIN)
                tracks[channel.topic].append((t, x, y))
            elif channel.topic.endswith("/ground_truth/odom"):
                p = m.pose.pose.position
                tracks[channel.topic].append((t, p.x, p.y))
            elif channel.topic == SIGNAL:
                signal.append((t, m.data))
            elif channel.topic == "/amsa/events" and m.kind == "phase":
                phases.append((t, _short(m.detail)))
    out = {k: np.array(v) for k, v in tracks.items()}
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    for topic, arr in sorted(out.items()):
        if topic.endswith("/fix"):
            left.plot(arr[:, 1], arr[:, 2], ".", ms=2.5, label=f"{topic} (NavSatFix)")
        else:
            left.plot(arr[:, 1], arr[:, 2], "-", lw=1, label=f"{topic} (Odometry)")
    left.set(xlabel="x east (m)", ylabel="y north (m)", title="tracks from the bag")
    left.set_aspect("equal", adjustable="datalim")
    left.legend(fontsize=7)
    left.grid(alpha=0.3)
    if signal:
        s = np.array(signal)
        right.plot(s[:, 0], s[:, 1], lw=1, label=SIGNAL)
        lo, hi = float(s[:, 1].min()), float(s[:, 1].max())
        right.set_ylim(lo - 0.05 * (hi - lo), hi + 0.35 * (hi - lo))  # room above for labels
        for i, (t, what) in enumerate(phases):
            right.axvline(t, color="grey", lw=0.8, ls="--")
            # horizontal, above the curve, stepped down so neighbours never overlap
            y = hi + (0.3 - 0.09 * (i % 3)) * (hi - lo)
            label = what.split(": ", 1)[-1].replace("MyFollowerController.", "")
            right.text(
                t,
                y,
                f" {label}",
                fontsize=7,
                va="top",
                clip_on=True,
                bbox={"boxstyle": "square,pad=0.1", "fc": "white", "ec": "none"},
            )
        # the topic goes in the title: a legend box would cover the curve's troughs
    right.set(xlabel="simulated time (s)", ylabel="m")
    right.set_title(f"{SIGNAL} and /amsa/events", fontsize=9)
    right.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return out


if __name__ == "__main__":
    plot_tracks(Path(sys.argv[1]), Path(sys.argv[2]))
