"""Saving a figure atomically (rendered in memory, then written under its final name)."""

from __future__ import annotations

import io
from pathlib import Path

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from ..engine.recorder import write_atomic


def save_png(fig: Figure, out: Path) -> Path:
    """Render ``fig`` to PNG, write it atomically to ``out`` and close the figure."""
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    write_atomic(out, buf.getvalue())
    return out
