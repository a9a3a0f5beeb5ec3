"""A live plot pane in the window: any traced signals the user picks, drawn with pygame.

``g`` opens a list of every traced Data (up/down, or ``/`` and type to filter, Enter adds or
removes the selected signal, ``g``/Esc closes); the picked signals are drawn as lines over the last
:data:`SPAN_S` seconds, each in its own colour with its current value. Drawn with pygame
lines rather than matplotlib: a matplotlib redraw costs tens of milliseconds, the window
draws at 60 frames a second. The same pane serves the live run (samples gathered from the
simulation's log listener, from the moment a signal is picked) and the replay (read from the
trace, whole history).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Sequence

import numpy as np

from ..palette import SIGNAL, rover_colour
from .draw import INK, MUTED, Renderer
from .pg import font, pygame

#: seconds of simulated time the pane shows
SPAN_S = 30.0
#: most signals drawn at once
MAX_PICKED = 6
#: samples kept per picked signal in a live run (a minute at the default 20 Hz log rate)
LIVE_POINTS = 1200
LIST_ROWS = 12
#: the first picked signal is near-black like the quality signal in the plots; the others
#: take rover colours past the leader's, follower's and the reference's green
PANE_COLOURS = (SIGNAL, *(rover_colour(k) for k in (3, 4, 5, 8, 9)))

Series = Callable[[str, float], tuple[np.ndarray, np.ndarray]]


class SignalPicker:
    """The list of traced signals, a filter typed by the user, and the picked ones (no pygame)."""

    def __init__(self, columns: Sequence[str]) -> None:
        self.columns = [c for c in columns if c != "t"]
        self.visible = False
        self.filter = ""
        #: typing goes into the filter (after ``/``, as in less and vim): otherwise the
        #: window's own keys (``c`` camera, ``z`` zoom, space) keep working with the list open
        self.filtering = False
        self.index = 0
        self.picked: list[str] = []
        self.message = ""

    @property
    def matches(self) -> list[str]:
        """The signals whose name holds the typed filter (case-insensitive)."""
        f = self.filter.lower()
        return [c for c in self.columns if f in c.lower()]

    def move(self, delta: int) -> None:
        """Select another row of the filtered list."""
        n = len(self.matches)
        self.index = (self.index + delta) % n if n else 0

    def type_char(self, ch: str) -> None:
        """Narrow the list (the selection goes back to its first row)."""
        self.filter += ch
        self.index = 0

    def backspace(self) -> None:
        """Widen the list again."""
        self.filter = self.filter[:-1]
        self.index = 0

    def toggle(self) -> str | None:
        """Pick the selected signal, or drop it if picked; returns the signal or None."""
        matches = self.matches
        if not matches:
            self.message = f"no traced signal contains {self.filter!r}"
            return None
        name = matches[min(self.index, len(matches) - 1)]
        if name in self.picked:
            self.picked.remove(name)
            self.message = f"dropped {name}"
        elif len(self.picked) >= MAX_PICKED:
            self.message = f"at most {MAX_PICKED} signals: drop one first"
            return None
        else:
            self.picked.append(name)
            self.message = f"plotting {name}"
        return name

    def lines(self) -> list[str]:
        """The list as drawn: filter, then rows around the selection (* marks picked ones)."""
        matches = self.matches
        if self.filtering:
            head = f"signals, filter: {self.filter}_  (enter: pick / drop, esc: end filter)"
        else:
            shown = f" [{self.filter}]" if self.filter else ""
            head = f"signals{shown}  /: filter  enter: pick / drop  g: close"
        start = max(0, min(self.index - LIST_ROWS // 2, len(matches) - LIST_ROWS))
        rows = []
        for i in range(start, min(len(matches), start + LIST_ROWS)):
            mark = ">" if i == self.index else " "
            star = "*" if matches[i] in self.picked else " "
            rows.append(f"{mark}{star} {matches[i]}")
        return [head, *(rows or ["(no match)"])]


class LiveSeries:
    """Samples of the picked signals in a live run, taken at every logged instant."""

    def __init__(self, picker: SignalPicker) -> None:
        self.picker = picker
        self.samples: dict[str, deque[tuple[float, float]]] = {}

    def __call__(self, t_s: float, values: dict[str, float]) -> None:
        """The simulation's log listener."""
        for name in self.picker.picked:
            buf = self.samples.get(name)
            if buf is None:
                buf = self.samples[name] = deque(maxlen=LIVE_POINTS)
            buf.append((t_s, float(values[name])))

    def series(self, name: str, span_s: float) -> tuple[np.ndarray, np.ndarray]:
        """The samples of ``name`` over its last ``span_s`` seconds."""
        buf = self.samples.get(name)
        if not buf:
            return np.empty(0), np.empty(0)
        arr = np.asarray(buf, dtype=float)
        keep = arr[:, 0] >= arr[-1, 0] - span_s
        return arr[keep, 0], arr[keep, 1]


def draw_pane(
    surface: pygame.Surface,
    rect: pygame.Rect,
    picked: Sequence[str],
    series: Series,
    text_px: int,
) -> None:
    """The picked signals over the last :data:`SPAN_S` s in ``rect``, each on its own scale.

    Every signal is scaled to its own range over the span (a distance in metres and a power
    in percent share one pane), and its name, current value and range are written in its
    colour, so no shared axis is needed.
    """
    box = pygame.Surface(rect.size, pygame.SRCALPHA)
    box.fill((255, 255, 255, 225))
    surface.blit(box, rect.topleft)
    pygame.draw.rect(surface, (150, 150, 150), rect, 1)
    small = font(max(8, text_px - 2))
    plot = rect.inflate(-16, -16)
    legend_h = small.get_linesize() * len(picked)
    plot.height -= legend_h + small.get_linesize()  # the legend above, the time span below
    plot.y += legend_h
    if plot.height < 10 or plot.width < 20:
        return
    t_end = -math.inf
    data = []
    for name in picked:
        t, v = series(name, SPAN_S)
        data.append((name, t, v))
        if t.size:
            t_end = max(t_end, float(t[-1]))
    y = rect.y + 6
    for k, (name, t, v) in enumerate(data):
        colour = PANE_COLOURS[k % len(PANE_COLOURS)]
        finite = v[np.isfinite(v)] if v.size else v
        if not finite.size:
            text = f"{name}: no sample yet"
        else:
            lo, hi = float(finite.min()), float(finite.max())
            text = fit_text(small, name, f" {v[-1]:.4g}  [{lo:.4g} .. {hi:.4g}]", rect.w - 16)
            _polyline(surface, plot, t, v, t_end, lo, hi, colour)
        surface.blit(small.render(text, True, colour), (rect.x + 8, y))
        y += small.get_linesize()
    if math.isfinite(t_end):
        label = small.render(f"last {SPAN_S:g} s to t = {t_end:.2f} s", True, (110, 110, 116))
        surface.blit(label, (plot.right - label.get_width(), plot.bottom + 2))


def fit_text(face: pygame.font.Font, name: str, rest: str, width: int) -> str:
    """``name + rest`` in ``width`` pixels: the name loses its start first (``…Leader``:
    the port at its end tells signals apart), the value and range are kept whole."""
    text = name + rest
    cut = 0
    while face.size(text)[0] > width and cut < len(name) - 1:
        cut += 1
        text = "\u2026" + name[cut:] + rest
    return text


def _polyline(
    surface: pygame.Surface,
    plot: pygame.Rect,
    t: np.ndarray,
    v: np.ndarray,
    t_end: float,
    lo: float,
    hi: float,
    colour: tuple[int, int, int],
) -> None:
    """One signal's samples as a line in ``plot`` (non-finite samples break the line)."""
    span = hi - lo if hi > lo else 1.0
    px = plot.right - (t_end - t) / SPAN_S * plot.width
    py = plot.bottom - (v - lo) / span * plot.height if hi > lo else np.full(v.shape, plot.centery)
    ok = np.isfinite(py)
    pts = np.column_stack((px, py))
    start = 0
    for stop in [*np.flatnonzero(~ok).tolist(), len(pts)]:
        seg = pts[start:stop]
        if len(seg) >= 2:
            pygame.draw.lines(surface, colour, False, seg.tolist(), 2)
        elif len(seg) == 1:
            pygame.draw.circle(surface, colour, seg[0].tolist(), 2)
        start = stop + 1


def picker_key(picker: SignalPicker, key: int, text: str) -> bool:
    """The signal list's keys (the player and the live window share them). Letters filter
    only after ``/``; otherwise they are the window's (False)."""
    if picker.filtering:
        if key == pygame.K_ESCAPE:
            picker.filtering = False
            return True
        if key == pygame.K_BACKSPACE and not picker.filter:
            picker.filtering = False
            return True
        if text and text.isprintable() and not text.isspace():
            picker.type_char(text)
            return True
    if key in (pygame.K_g, pygame.K_ESCAPE):
        picker.visible = False
        picker.filtering = False
    elif text == "/":
        picker.filtering = True
    elif key == pygame.K_UP:
        picker.move(-1)
    elif key == pygame.K_DOWN:
        picker.move(1)
    elif key in (pygame.K_RETURN, pygame.K_KP_ENTER):
        picker.toggle()
    elif key == pygame.K_BACKSPACE:
        picker.backspace()
    else:
        return False
    return True


def draw_side_panes(
    screen: pygame.Surface,
    renderer: Renderer,
    picker: SignalPicker,
    series: Series,
    show_help: bool,
    help_lines: list[str],
    area: pygame.Rect,
) -> tuple[pygame.Rect | None, pygame.Rect | None]:
    """The plot pane (bottom right), the signal list and the help (right, or left when it
    would reach the pane or the signal list is open at the right), under the HUD.

    Returns the boxes drawn at the right and at the left (None where nothing is): the
    camera frames the rovers beside them, so the key list never hides the leader.
    """
    top = max(box.bottom for box in renderer.boxes.values()) + 6 if renderer.boxes else 10
    pane = pane_rect(area, picker)
    if pane is not None:
        draw_pane(screen, pane, picker.picked, series, renderer.text_px)
    line_px = renderer.font.get_linesize()
    if picker.visible:
        lines = picker.lines()
        colours = [MUTED] + [INK] * (len(lines) - 1)
        if picker.message:
            lines.append(picker.message)
            colours.append(INK)
        margin, width = beside_pane(screen, pane, top, len(lines), line_px)
        box = renderer.panel(screen, lines, colours, (margin, top), align_right=True, width=width)
        if show_help:  # the list holds the right: the help goes at the left, both readable
            ink = [INK] * len(help_lines)
            return box, renderer.panel(screen, help_lines, ink, (10, top), align_right=False)
        return box, None
    if show_help:
        ink = [INK] * len(help_lines)
        if reaches_pane(pane, top, len(help_lines), line_px):  # at the left, clear of it
            return None, renderer.panel(screen, help_lines, ink, (10, top), align_right=False)
        return renderer.panel(screen, help_lines, ink, (10, top), align_right=True), None
    return None, None


def reaches_pane(pane: pygame.Rect | None, top: int, n_lines: int, line_px: int) -> bool:
    """Whether a box of ``n_lines`` drawn from ``top`` at the right would reach down to the
    plot pane (the help drawn over the pane, or under it, hid both): it goes at the left."""
    return pane is not None and top + n_lines * line_px + 12 >= pane.top


def pane_rect(area: pygame.Rect, picker: SignalPicker) -> pygame.Rect | None:
    """Where the plot pane goes (bottom right of ``area``), None when nothing is picked."""
    if not picker.picked:
        return None
    w = max(240, area.width * 2 // 5)
    h = max(120, area.height // 3)
    return pygame.Rect(area.right - w - 10, area.bottom - h - 10, w, h)


def beside_pane(
    screen: pygame.Surface, pane: pygame.Rect | None, top: int, n_lines: int, line_px: int
) -> tuple[int, int | None]:
    """(right margin, width) of a box of ``n_lines`` drawn at the right from ``top``: 10 px
    and the frame's width, or left of the plot pane, in the room left of it, when the box
    would reach down to the pane (the help or the list drawn over the pane hid both); over
    the pane when the room left of it is under a third of the window (320x240: 50 px)."""
    if pane is None or top + n_lines * line_px + 12 < pane.top:
        return 10, None
    room = pane.left - 20
    if room < screen.get_width() // 3:  # a small window: a column that narrow wraps every
        return 10, None  # word onto its own line, so the box goes over the pane instead
    return screen.get_width() - pane.left + 10, room
