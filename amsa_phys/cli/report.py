"""Plain-text tables for the terminal."""

from __future__ import annotations

from pathlib import Path
from typing import Any, TextIO

from ..errors import one_line
from ..valuetext import value_text


def _fmt(value: Any, digits: int = 2) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


def _dwell_text(q: dict[str, Any]) -> str:
    dwell = q.get("dwell")
    return "10 s (a tenth of a shorter block)" if dwell is None else f"{dwell:g} s"


#: adapt switches listed in the summary; the rest are counted (all are in metrics.json)
SHOWN_SWITCHES = 5


def adapt_line(switches: list[dict[str, Any]], total: int | None = None) -> str:
    """``adapt: 3 switches: at 40.1 s rule 2 (random leader): Kv=0.25; ...`` — the rules that
    fired, as live changes are shown in the table (the values without their estimates)."""
    parts = []
    for e in switches[:SHOWN_SWITCHES]:
        rule, _, rest = str(e.get("detail", "")).partition(": ")
        sets = rest.rsplit(" (", 1)[0]
        short = ", ".join(
            p.split("=", 1)[0].rsplit(".", 1)[-1] + "=" + p.split("=", 1)[-1]
            for p in sets.split(", ")
            if p
        )
        parts.append(f"at {float(e['t']):g} s {rule}: {short}")
    n = max(len(switches), total or 0)  # total: every switch, listed or not
    listed = min(len(switches), n)
    more = listed - SHOWN_SWITCHES
    tail = f"; {more} more in metrics.json's events" if more > 0 else ""
    if n > listed:
        tail += f"; {n - listed} more not listed (metrics.json keeps the first events only)"
    return f"adapt: {n} switch{'es' if n != 1 else ''}: " + "; ".join(parts) + tail


def print_summary(metrics: dict[str, Any], out_dir: Path, stream: TextIO) -> None:
    """Per-phase metrics, the overall line, speed and where the files are."""
    cols = (
        "phase",
        "start",
        "max",
        "max after",
        "min",
        "mean err",
        "rms err",
        "settle",
        "coll",
        "set",
    )
    rows = []
    blocks = [(str(i), p) for i, p in enumerate(metrics["phases"])]
    blocks.append(("all", {**metrics["overall"], "start": 0.0, "set": {}}))
    for name, b in blocks:
        changes = ", ".join(f"{k}={value_text(v)}" for k, v in b.get("set", {}).items())
        for c in b.get("changes", []):  # changes inside the phase (live, new_phase: false)
            inner = ", ".join(f"{k}={value_text(v)}" for k, v in c["set"].items())
            changes += f"{'; ' if changes else ''}at {c['at']:g} s: {inner}"
        rows.append(
            (
                name + (" (cut)" if b.get("partial") else ""),
                _fmt(b.get("start"), 1),
                _fmt(b.get("max_distance")),
                _fmt(b.get("max_after_approach")),
                _fmt(b.get("min_distance")),
                _fmt(b.get("mean_error")),
                _fmt(b.get("rms_error")),
                _fmt(b.get("settling_time"), 1),
                _fmt(b.get("collisions")),
                changes,
            )
        )
    widths = [max(len(c), *(len(r[i]) for r in rows)) for i, c in enumerate(cols)]
    line = "  ".join(c.ljust(w) for c, w in zip(cols, widths, strict=True))
    print(line.rstrip(), file=stream)
    for r in rows:
        text = "  ".join(v.ljust(w) for v, w in zip(r, widths, strict=True)).rstrip()
        print(one_line(text), file=stream)
    switches = [e for e in metrics.get("events") or [] if e.get("kind") == "adapt"]
    if switches:
        print(one_line(adapt_line(switches, metrics.get("adapt_switches"))), file=stream)
    if metrics["overall"].get("partial"):
        print(
            f"(cut): the run stopped at t={metrics['simulated']:g} s, inside this block; "
            "its checks are skipped unless already failed (a count or maximum past its bound)",
            file=stream,
        )
    q = metrics.get("quality")
    if q:
        print(
            f"quality: {q['signal']} vs {q['reference']:g} m ± {q['tolerance']:g} m; "
            "max after = max once first within tolerance (the paper's figure); settle needs "
            f"{_dwell_text(q)} in the band",
            file=stream,
        )
    else:
        print("no quality: section, so no metrics of control and no distance.png", file=stream)
    paused = metrics.get("paused_s")
    print(
        one_line(
            f"simulated {metrics['simulated']:.1f} s in {metrics['wall_time_s']:.2f} s"
            + (f", {paused:.2f} s of it paused or ended with the window open" if paused else "")
            + f" ({metrics['real_time_factor']}x real time); outputs in {out_dir}"
        ),
        file=stream,
    )
    video = metrics.get("video")
    if video:
        w, h = video["size"]
        print(
            one_line(
                f"video {video['path']}: {video['frames']} frames, {w}x{h} at {video['fps']} fps"
            ),
            file=stream,
        )
