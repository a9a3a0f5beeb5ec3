"""One visual language: the colours and marks the window, the video, the snapshot, the
replay (``amsa-phys view``) and the plots share, so a mark means one thing everywhere.

``docs/visual-language.md`` is the table a reader sees; this module is where every picture
takes its choices from (a test compares the two). Rovers are coloured by their rank among
the *world's* rovers in declaration order (the order of the world's ``X.posX`` Data), never
by their rank among the columns a trace happens to keep: in the MDE challenge the leader is
orange and the follower blue everywhere, and a trace that keeps only the follower still
draws it blue. A top-level module (like ``errors.py``) because the renderer (``view``) and
the plots (``plots``) sit in one layer and must not import each other.
"""

from __future__ import annotations

from dataclasses import dataclass

RGB = tuple[int, int, int]

#: Twenty colours no two alike (matplotlib's tab10 and tab20b/c, reordered): a 20-car platoon
#: gets 20 colours; Car9 and Car10 no longer reuse the leader's orange and Car1's blue. Left
#: out: red (the alert), the reference's green, the warning's amber, neutral grey (a GPS fix
#: of an unknown rover) and near-black (the quality signal), so a rover never looks like a mark.
ROVER_COLOURS: tuple[RGB, ...] = (
    (230, 120, 30),  # first rover (the leader): orange
    (31, 119, 180),  # second (the follower): blue
    (148, 103, 189),  # purple
    (140, 86, 75),  # brown
    (227, 119, 194),  # pink
    (188, 189, 34),  # olive
    (23, 190, 207),  # cyan
    (57, 59, 121),  # indigo
    (99, 121, 57),  # moss
    (140, 109, 49),  # ochre
    (123, 65, 115),  # plum
    (107, 110, 207),  # periwinkle
    (0, 128, 128),  # teal
    (82, 84, 163),  # slate
    (181, 207, 107),  # lime
    (165, 81, 148),  # orchid
    (189, 158, 57),  # khaki
    (158, 202, 225),  # sky
    (197, 176, 213),  # lavender
    (196, 156, 148),  # tan
)
#: alerts: lost GPS fixes, collisions, a motor driven backwards
ALERT: RGB = (214, 39, 40)
#: text and outlines in the window (HUD, names, a collision's edge)
INK: RGB = (32, 32, 36)
#: the quality signal (the measured distance) in every plot: near-black, because blue and
#: orange are rovers (the paper's Fig. 5/6 redrawn use it too)
SIGNAL: RGB = (38, 38, 38)
#: the reference value and the tolerance band
REFERENCE: RGB = (44, 160, 44)
#: the timeline: phase starts and changes inside a phase (a timeline entry with
#: ``new_phase: false``, a live change made in the window, an ``adapt:`` switch) -- lines
#: in the plots, lines and ticks on the replay's slider; grey, never red (red is an alert)
PHASE: RGB = (102, 102, 102)
#: the true-distance line between rovers in the window: dashed, in the error colour
#: (green / amber / red); amber is kept clear of the leader's orange (hue and lightness)
WARN: RGB = (250, 200, 40)


@dataclass(frozen=True)
class Mark:
    """A mark drawn at a place and time, the same in every picture."""

    name: str
    #: matplotlib marker code (the window draws the same shape by hand)
    marker: str
    colour: RGB
    meaning: str


#: where a GPS sample was lost (the rover's true position then): a red ×
LOST_FIX = Mark("lost GPS fix", "x", ALERT, "a GPS sample lost: the rover's true position then")
#: where two bodies touched: a red filled diamond with a black edge
COLLISION = Mark("collision", "D", ALERT, "two bodies touched: the midpoint of the rovers")
#: a GPS fix as published: a + in the measured rover's colour, faded
GPS_FIX = Mark("GPS fix", "+", (127, 127, 127), "a fix as published (measured position)")
#: start and end of a path
START = Mark("start", "o", (0, 0, 0), "where a rover's path starts")
END = Mark("end", "s", (0, 0, 0), "where a rover's path ends (or the run was cut)")

#: where an ``adapt:`` rule switched parameters: a grey ▼ (a change, made by a rule: not an
#: alert, so never red)
ADAPT_SWITCH = Mark(
    "adapt switch", "v", PHASE, "an adapt: rule switched parameters (the values it set beside it)"
)
#: anything else a component recorded (``record_event``): a small dark dot
OTHER_EVENT = Mark("other event", ".", INK, "an event a component recorded (its kind and detail)")

MARKS: tuple[Mark, ...] = (LOST_FIX, COLLISION, GPS_FIX, START, END, ADAPT_SWITCH, OTHER_EVENT)


def rover_colour(index: int) -> RGB:
    """Colour of the index-th rover (the world's declaration order), as 0-255 RGB."""
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


def rover_ranks(world_rovers: list[str], shown: list[str]) -> dict[str, int]:
    """Each shown rover's colour index: its rank among the world's rovers.

    ``shown`` are the rovers a picture has (a trace's columns may keep only some); a rover
    the world does not name (an older run without its world) goes after the world's.
    """
    rank = {name: i for i, name in enumerate(world_rovers)}
    extra = len(rank)
    out = {}
    for name in shown:
        if name not in rank:
            rank[name] = extra
            extra += 1
        out[name] = rank[name]
    return out
