"""Draws a :class:`~amsa_phys.view.scene.Frame` onto a pygame Surface.

One renderer serves the window and the recorder, so what you debug is what you record. It
draws in world order — grid, terrain zones, obstacles, trails, GPS fixes, the distance line,
rovers — then the HUD in screen space. A zone is filled in a colour that says what it is
(brown: soft ground, the darker the more it resists rolling; blue: slippery, friction below
0.2) and labelled with its name, friction and rolling resistance as they are now. Rovers are
drawn to scale (body, wheels at the track width, a nose for the heading) and never smaller
than a few pixels, so they stay visible when zoomed out.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Sequence

import numpy as np

from ..palette import ALERT, LOST_FIX, REFERENCE, rover_colour
from ..palette import INK as PALETTE_INK
from ..palette import WARN as PALETTE_WARN
from ..physics.terrain import zone_colours
from .camera import Camera
from .marks import darker, dashed, draw_collision, draw_lost_fix
from .pg import font, pygame
from .scene import Frame, LidarScan, RoverPose, ZoneView

BACKGROUND = (246, 246, 241)
GRID_MINOR = (228, 228, 221)
GRID_MAJOR = (205, 205, 197)
INK = PALETTE_INK
MUTED = (110, 110, 116)
OBSTACLE = (120, 116, 108)
WHEEL = (40, 40, 44)
LOST = LOST_FIX.colour
OK = REFERENCE
WARN = PALETTE_WARN  # clear of the leader's orange (palette.py)
BAD = ALERT
MIN_ROVER_PX = 5.0


def error_colour(error: float, tolerance: float) -> tuple[int, int, int]:
    """Green within the tolerance band, amber up to twice it, red beyond: three colours, never
    a blend. Green blended towards amber is an olive that reads as "fine"; amber blended
    towards red is the leader's orange, and the line between the rovers vanished into the
    leader's trail (``palette.py``)."""
    r = abs(error) / tolerance if tolerance > 0 else (0.0 if error == 0 else math.inf)
    if r <= 1:
        return OK
    if r <= 2:
        return WARN
    return BAD


def hud_number(value: float, signed: bool = False) -> str:
    """A metric as the HUD prints it: two decimals, but a huge (legal) value in
    scientific notation and a non-finite one as a word.

    ``reference: 1.0e+308`` is a legal scenario: its error printed with ``.2f`` is a
    309-digit number that buried the HUD, and its rms error overflows to infinity
    (``metrics.json`` writes it as null and lists it in ``nonfinite``)."""
    if not math.isfinite(value):
        return "overflow" if not math.isnan(value) else "nan"
    sign = "+" if signed else ""
    return f"{value:{sign}.2f}" if abs(value) < 1e9 else f"{value:{sign}.3g}"


def nice_step(target_m: float) -> float:
    """The 1-2-5 series value nearest above ``target_m`` (grid spacing, scale bar)."""
    exp = math.floor(math.log10(target_m))
    for m in (1, 2, 5, 10):
        if m * 10**exp >= target_m:
            return m * 10.0**exp
    return 10.0 ** (exp + 1)


class Renderer:
    """Draws frames at one size; the HUD's font and layout scale with the frame.

    The text size follows the smaller of height / 48 and width / 85 (at least 9 px), HUD
    lines wrap to the room they have, and the status box moves below the HUD when the two
    would not fit side by side: nothing is clipped or overlaps from 320x240 up.
    """

    MARGIN = 10

    def __init__(self, size: tuple[int, int]) -> None:
        self.size = size
        self.text_px = max(9, round(min(size[1] / 48, size[0] / 85)))
        self.font = font(self.text_px)
        self.small = font(max(8, self.text_px - 3))
        #: the text boxes of the last frame drawn (``hud``, ``status``), in pixels
        self.boxes: dict[str, pygame.Rect] = {}
        #: the lines of those boxes as drawn (wrapped), for tests
        self.texts: dict[str, list[str]] = {}
        #: the lines of the last :meth:`panel` as drawn (wrapped)
        self.last_text: list[str] = []
        #: the rovers' name boxes of the last frame, in the frame's rover order
        self.labels: list[pygame.Rect] = []
        #: the distance labels of the last frame (names are placed clear of them)
        self._distance_labels: list[pygame.Rect] = []

    def draw_under_boxes(
        self, surface: pygame.Surface, frame: Frame, camera: Camera, status: Sequence[str] = ()
    ) -> None:
        """:meth:`draw`, the rovers framed in the room under the HUD and status boxes, as the
        window and ``view`` frame them: known once drawn, so when the boxes moved the
        camera's room the frame is drawn again in it (a small frame's status box sat on
        the leader)."""
        points = [(r.x, r.y, r.name) for r in frame.rovers]
        for _ in range(2):
            room = camera.top
            self.draw(surface, frame, camera, status)
            camera.top = max(box.bottom for box in self.boxes.values()) + 6
            if camera.top == room:
                break
            camera.update(points, 0.0)  # no glide: only keeps every rover in the new room

    def draw(
        self,
        surface: pygame.Surface,
        frame: Frame,
        camera: Camera,
        status: Sequence[str] = (),
        notice: str = "",
    ) -> None:
        """Draw ``frame`` as seen by ``camera``; ``status`` lines go top-right, a ``notice``
        (what the last key did: a live change, the camera's mode) under the HUD's lines."""
        surface.fill(BACKGROUND)
        self._grid(surface, camera)
        for zone in frame.zones:
            self._zone(surface, camera, zone)
        for ob in frame.obstacles:
            self._obstacle(surface, camera, ob.kind, ob.points, ob.radius)
        colours = {
            r.name: rover_colour(r.index if r.index >= 0 else i) for i, r in enumerate(frame.rovers)
        }
        for name, trail in frame.trails.items():
            if len(trail) >= 2:
                pts = _screen(camera, trail)
                pygame.draw.lines(surface, _tint(colours.get(name, MUTED), 0.45), False, pts, 2)
        for track in frame.gps:
            col = _tint(colours.get(track.rover or "", MUTED), 0.25)
            for x, y in track.fixes:
                px, py = camera.to_screen(x, y)
                pygame.draw.line(surface, col, (px - 3, py), (px + 3, py))
                pygame.draw.line(surface, col, (px, py - 3), (px, py + 3))
            if track.fixes:
                px, py = camera.to_screen(*track.fixes[-1])
                pygame.draw.circle(surface, col, (px, py), 5, 1)
            for x, y in track.lost:
                draw_lost_fix(surface, camera.to_screen(x, y))
        for x, y in frame.collisions:
            draw_collision(surface, camera.to_screen(x, y))
        for scan in frame.scans:
            self._scan(surface, camera, scan, colours.get(scan.mount, MUTED))
        self._distance_lines(surface, camera, frame)
        for r in frame.rovers:
            self._rover(surface, camera, r, colours[r.name])
        self._labels(surface, camera, frame.rovers)
        self._hud(surface, frame, camera, status, notice)

    # -- world layer -------------------------------------------------------------------------
    def _grid(self, surface: pygame.Surface, camera: Camera) -> None:
        w, h = self.size
        step = nice_step(40 / camera.scale)
        x0, y1 = camera.to_world(0, 0)
        x1, y0 = camera.to_world(w, h)
        for i in range(math.floor(x0 / step), math.ceil(x1 / step) + 1):
            px = camera.to_screen(i * step, 0)[0]
            col = GRID_MAJOR if i % 5 == 0 else GRID_MINOR
            pygame.draw.line(surface, col, (px, 0), (px, h))
        for j in range(math.floor(y0 / step), math.ceil(y1 / step) + 1):
            py = camera.to_screen(0, j * step)[1]
            col = GRID_MAJOR if j % 5 == 0 else GRID_MINOR
            pygame.draw.line(surface, col, (0, py), (w, py))
        # scale bar, bottom left
        bar_m = nice_step(120 / camera.scale)
        bar_px = bar_m * camera.scale
        x, y = 16, h - 18
        pygame.draw.line(surface, INK, (x, y), (x + bar_px, y), 3)
        pygame.draw.line(surface, INK, (x, y - 6), (x, y + 2), 2)
        pygame.draw.line(surface, INK, (x + bar_px, y - 6), (x + bar_px, y + 2), 2)
        label = self.small.render(f"{bar_m:g} m", True, INK)
        surface.blit(label, (x + bar_px + 8, y - label.get_height() + 4))

    def _zone(self, surface: pygame.Surface, camera: Camera, zone: ZoneView) -> None:
        fill, edge = zone_colours(zone.friction, zone.rolling_resistance, BACKGROUND)
        pts = _screen(camera, zone.polygon)
        pygame.draw.polygon(surface, fill, pts)
        pygame.draw.polygon(surface, edge, pts, 1)
        name = zone.name.rpartition(".")[2]
        text = f"{name}  μ {zone.friction:g}  Crr {zone.rolling_resistance:g}"
        label = self.small.render(text, True, edge)
        # inside the top edge, where it seldom covers a rover crossing the zone
        left = min(p[0] for p in pts)
        top = max(min(p[1] for p in pts), 0.0)  # a zone taller than the view: label at its top
        width = max(p[0] for p in pts) - left
        surface.blit(label, (left + max(4.0, (width - label.get_width()) / 2), top + 4))

    def _obstacle(
        self,
        surface: pygame.Surface,
        camera: Camera,
        kind: str,
        points: Sequence[tuple[float, float]],
        radius: float,
    ) -> None:
        if kind == "poly":
            pygame.draw.polygon(surface, OBSTACLE, _screen(camera, points))
        elif kind == "circle":
            px, py = camera.to_screen(*points[0])
            pygame.draw.circle(surface, OBSTACLE, (px, py), max(2.0, radius * camera.scale))
        else:
            width = max(2, round(2 * radius * camera.scale))
            pygame.draw.lines(surface, OBSTACLE, False, _screen(camera, points), width)

    def _scan(
        self, surface: pygame.Surface, camera: Camera, scan: LidarScan, colour: tuple[int, int, int]
    ) -> None:
        """Lidar beams: a faint ray to each echo and a dot (the rover's colour, darker: red is
        only ever an alert) where it hit; no echo, no ray."""
        origin = camera.to_screen(scan.x, scan.y)
        ray = _tint(colour, 0.6)
        for a, r in zip(scan.angles, scan.ranges, strict=True):
            if r >= scan.range_max:
                continue
            hit = camera.to_screen(scan.x + r * math.cos(a), scan.y + r * math.sin(a))
            pygame.draw.line(surface, ray, origin, hit, 1)
            pygame.draw.circle(surface, darker(colour), hit, 2)  # red is only an alert

    def _distance_lines(self, surface: pygame.Surface, camera: Camera, frame: Frame) -> None:
        self._distance_labels = []
        if not frame.pair_lines:
            return
        q = frame.quality
        for a, b in itertools.pairwise(frame.rovers):
            d = math.hypot(a.x - b.x, a.y - b.y)
            col = error_colour(d - q.reference, q.tolerance) if q else MUTED
            pa, pb = camera.to_screen(a.x, a.y), camera.to_screen(b.x, b.y)
            # dashed and thin: the trails under it (the leader's orange) show through
            dashed(surface, col, pa, pb)
            label = self.small.render(f"true {d:.1f} m", True, darker(col))
            mx, my = (pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2
            at = (mx - label.get_width() / 2, my - label.get_height() - 4)
            box = pygame.Rect(
                round(at[0]) - 2, round(at[1]), label.get_width() + 4, label.get_height()
            )
            if box.collidelist(self._distance_labels) >= 0:
                continue  # a column of close rovers: the line's colour still tells the error
            self._distance_labels.append(box)
            self._label_box(surface, label, at)

    def _rover(
        self, surface: pygame.Surface, camera: Camera, r: RoverPose, colour: tuple[int, int, int]
    ) -> None:
        c, s = math.cos(r.heading), math.sin(r.heading)

        def at(fx: float, fy: float) -> tuple[float, float]:  # body frame -> screen
            return camera.to_screen(r.x + c * fx - s * fy, r.y + s * fx + c * fy)

        if r.length * camera.scale < MIN_ROVER_PX:
            px, py = camera.to_screen(r.x, r.y)
            pygame.draw.circle(surface, colour, (px, py), MIN_ROVER_PX)
            pygame.draw.line(
                surface, INK, (px, py), (px + 2.5 * MIN_ROVER_PX * c, py - 2.5 * MIN_ROVER_PX * s)
            )
        else:
            hl, hw = r.length / 2, r.width / 2
            body = [at(-hl, -hw), at(hl, -hw), at(hl, hw), at(-hl, hw)]
            pygame.draw.polygon(surface, colour, body)
            pygame.draw.polygon(surface, INK, body, 1)
            nose = [at(hl, 0), at(hl * 0.35, hw * 0.55), at(hl * 0.35, -hw * 0.55)]
            pygame.draw.polygon(surface, _tint(colour, 0.6), nose)
            # wheels at +-track/2, drawn over the body so they show at any track width
            wl, ww = 0.22 * r.length, max(0.05, 0.08 * r.width)
            for side, power in ((1, r.power_l), (-1, r.power_r)):
                wy = side * r.track / 2
                wheel = [at(-wl, wy - ww), at(wl, wy - ww), at(wl, wy + ww), at(-wl, wy + ww)]
                pygame.draw.polygon(surface, WHEEL, wheel)
                # power bar along the wheel: how hard this motor is driven, and which way
                k = max(-1.0, min(1.0, power / 100.0))
                if abs(k) > 0.01:
                    pygame.draw.line(surface, OK if k > 0 else BAD, at(0, wy), at(wl * k, wy), 2)

    def _labels(self, surface: pygame.Surface, camera: Camera, rovers: Sequence[RoverPose]) -> None:
        """Each rover's name above it; a name that would overlap one already placed moves
        up a line at a time (close rovers, a platoon's column), so every name stays readable.
        """
        placed: list[pygame.Rect] = []
        self.labels = placed  # for tests: where each name went
        taken = list(self._distance_labels)  # names never sit on a distance label either
        for r in rovers:
            label = self.small.render(r.name, True, INK)
            px, py = camera.to_screen(r.x, r.y)
            reach = max(MIN_ROVER_PX, 0.6 * max(r.length, r.width) * camera.scale)
            rect = pygame.Rect(0, 0, label.get_width() + 4, label.get_height())
            rect.midbottom = (round(px), round(py - reach))
            for _ in range(len(placed) + len(taken) + 1):
                if rect.collidelist(placed) < 0 and rect.collidelist(taken) < 0:
                    break
                rect.move_ip(0, -rect.height)
            placed.append(rect)
            self._label_box(surface, label, (rect.x + 2, rect.y))

    @staticmethod
    def _label_box(surface: pygame.Surface, label: pygame.Surface, at: tuple[float, float]) -> None:
        """A label on a faint white box, readable over trails and grid."""
        box = pygame.Surface((label.get_width() + 4, label.get_height()), pygame.SRCALPHA)
        box.fill((255, 255, 255, 170))
        surface.blit(box, (at[0] - 2, at[1]))
        surface.blit(label, at)

    # -- HUD ---------------------------------------------------------------------------------
    def _hud(
        self,
        surface: pygame.Surface,
        frame: Frame,
        camera: Camera,
        status: Sequence[str],
        notice: str = "",
    ) -> None:
        m, q = frame.metrics, frame.quality
        lines = [f"t {frame.t:8.2f} s / {frame.duration:g} s", frame.phase_text]
        colours = [INK, INK]
        if q is not None and m.value is not None:
            err = m.value - q.reference
            lines.append(
                f"measured {hud_number(m.value):>6} m  ref {q.reference:g} ± {q.tolerance:g}  "
                f"error {hud_number(err, signed=True)} m"
            )
            colours.append(darker(error_colour(err, q.tolerance)))  # readable on white
            rms = m.rms_error
            lines.append(
                f"max {hud_number(m.max)} m  min {hud_number(m.min)} m  rms error "
                f"{hud_number(rms) if rms is not None else '-'} m  collisions {m.collisions}"
            )
            colours.append(INK)
        else:
            lines.append(f"collisions {m.collisions}")
            colours.append(INK)
        if notice:  # in the HUD's room, not the status box's: the status stays narrow
            lines.append(notice)
            colours.append(MUTED)
        w = self.size[0]
        gap = self.MARGIN
        full = w - 2 * gap
        status_w = self.text_width(status) if status else 0
        beside = full - status_w - gap  # room left of the status box
        # the status beside the HUD, or under it: whichever ends higher (the map keeps the
        # most room); side by side when the HUD fits there whole
        status_h = self.text_height(status, full) if status else 0
        side = self.text_height(lines, beside) if beside > 40 else None
        under = self.text_height(lines, full) + gap // 2 + status_h
        if not status or (side is not None and max(side, status_h) <= under):
            hud = self.panel(surface, lines, colours, (gap, gap), align_right=False, width=beside)
            top = gap
        else:  # too narrow for both on one row: the status goes under the HUD
            hud = self.panel(surface, lines, colours, (gap, gap), align_right=False, width=full)
            top = hud.bottom + gap // 2
        self.boxes = {"hud": hud}
        self.texts = {"hud": self.last_text}
        if status:
            self.boxes["status"] = self.panel(
                surface, list(status), [INK] * len(status), (gap, top), align_right=True
            )
            self.texts["status"] = self.last_text

    def text_height(self, lines: Sequence[str], width: int) -> int:
        """Height of a panel holding ``lines`` wrapped to ``width`` (padding included)."""
        room = max(40, width - 12)
        count = sum(len(_wrap(t, self.font, room)) for t in lines)
        return count * self.font.get_height() + 12

    def text_width(self, lines: Sequence[str]) -> int:
        """Width of a panel holding ``lines`` unwrapped, padding included."""
        return max(self.font.size(t)[0] for t in lines) + 12

    def panel(
        self,
        surface: pygame.Surface,
        lines: Sequence[str],
        colours: Sequence[tuple[int, int, int]],
        at: tuple[int, int],
        *,
        align_right: bool,
        width: int | None = None,
    ) -> pygame.Rect:
        """Text lines on a translucent box, from the top-left or top-right corner.

        Lines longer than ``width`` (default: the frame less the margins) wrap at spaces.
        Returns the box drawn.
        """
        pad = 6
        room = max(40, (width if width is not None else self.size[0] - 2 * at[0]) - 2 * pad)
        parts = [
            (part, c)
            for t, c in zip(lines, colours, strict=True)
            for part in _wrap(t, self.font, room)
        ]
        self.last_text = [part for part, _ in parts]
        rendered = [self.font.render(part, True, c) for part, c in parts]
        box_w = max(r.get_width() for r in rendered) + 2 * pad
        box_h = sum(r.get_height() for r in rendered) + 2 * pad
        x = self.size[0] - box_w - at[0] if align_right else at[0]
        box = pygame.Surface((box_w, box_h), pygame.SRCALPHA)
        box.fill((255, 255, 255, 215))
        surface.blit(box, (x, at[1]))
        y = at[1] + pad
        for r in rendered:
            surface.blit(r, (x + pad, y))
            y += r.get_height()
        return pygame.Rect(x, at[1], box_w, box_h)


#: Where a HUD line may break first: after an item of a list (``Kv=0.2 live at 9.4 s, ``),
#: after a label (``from 0 s: ``, ``| ``) or between the HUD's fields (two spaces).
_BREAKS = re.compile(r"(?<=, )|(?<=: )|(?<=\| )|(?<=  )")


def _wrap(text: str, fnt: pygame.font.Font, room: int) -> list[str]:
    """``text`` split into lines at most ``room`` pixels wide: between items first, so that
    ``Kv=0.2 live at 9.4 s`` never loses its ``s``, then at spaces, then inside a word."""
    if fnt.size(text)[0] <= room:
        return [text]
    out: list[str] = []
    line = ""
    for item in _BREAKS.split(text):
        if fnt.size(line + item.rstrip())[0] <= room:
            line += item
            continue
        if line:
            out.append(line.rstrip())
            line = ""
        if fnt.size(item.rstrip())[0] <= room:
            line = item
        else:  # an item wider than the room on its own: at its spaces
            parts = _wrap_words(item.rstrip(), fnt, room)
            out += parts[:-1]
            line = parts[-1] + " "
    out.append(line.rstrip())
    return out


def _wrap_words(text: str, fnt: pygame.font.Font, room: int) -> list[str]:
    """``text`` split at spaces into lines at most ``room`` pixels wide (words cut if need be)."""
    out: list[str] = []
    line = ""
    for word in text.split(" "):
        trial = f"{line} {word}" if line else word
        if fnt.size(trial)[0] <= room:
            line = trial
            continue
        if line:
            out.append(line)
        while fnt.size(word)[0] > room and len(word) > 1:  # a word wider than the box
            cut = max(1, int(len(word) * room / fnt.size(word)[0]))
            out.append(word[:cut])
            word = word[cut:]
        line = word
    out.append(line)
    return out


def _screen(camera: Camera, points: Sequence[tuple[float, float]]) -> list[list[float]]:
    """Many world points to pixels at once (numpy: trails hold hundreds of points)."""
    arr = np.asarray(points, dtype=float)
    out = np.empty_like(arr)
    out[:, 0] = camera.mid_x + (arr[:, 0] - camera.cx) * camera.scale
    out[:, 1] = camera.mid_y - (arr[:, 1] - camera.cy) * camera.scale
    np.clip(out, -1e5, 1e5, out=out)  # SDL draws garbage for coordinates near int limits
    return out.tolist()


def _tint(colour: tuple[int, int, int], amount: float) -> tuple[int, int, int]:
    """Blend ``colour`` toward white by ``amount`` (0: unchanged, 1: white)."""
    return tuple(int(c + (255 - c) * amount) for c in colour)  # type: ignore[return-value]
