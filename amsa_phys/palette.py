"""Colours shared by the window, the video and the plots, so a rover looks the same in each.

Rovers are coloured by their rank among the world's rovers in declaration order (the order
of their ``X.posX`` Data, which is also the order of the trace's columns): in the MDE
challenge the leader is orange and the follower blue everywhere. A top-level module (like
``errors.py``) because the renderer (``view``) and the plots (``plots``) sit in one layer and
must not import each other.
"""

from __future__ import annotations

RGB = tuple[int, int, int]

ROVER_COLOURS: tuple[RGB, ...] = (
    (230, 120, 30),  # first rover (the leader): orange
    (31, 119, 180),  # second (the follower): blue
    (44, 160, 44),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
)
#: lost GPS fixes and collisions
ALERT: RGB = (214, 39, 40)


def rover_colour(index: int) -> RGB:
    """Colour of the index-th rover (declaration order), as 0-255 RGB."""
    return ROVER_COLOURS[index % len(ROVER_COLOURS)]


def hex_colour(rgb: RGB) -> str:
    """``#e6781e``: the form matplotlib takes."""
    return "#{:02x}{:02x}{:02x}".format(*rgb)


def rover_names(columns: list[str]) -> list[str]:
    """The rovers of a world or trace: every ``X`` with ``X.posX`` and ``X.posY``, in order."""
    present = set(columns)
    return [
        c[: -len(".posX")] for c in columns if c.endswith(".posX") and c[:-4] + "posY" in present
    ]
