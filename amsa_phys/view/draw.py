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
from collections.abc import Sequence

import numpy as np

from ..physics.terrain import zone_colours
from .camera import Camera
from .pg import font, pygame
from .scene import Frame, RoverPose, ZoneView

BACKGROUND = (246, 246, 241)
GRID_MINOR = (228, 228, 221)
GRID_MAJOR = (205, 205, 197)
INK = (32, 32, 36)
MUTED = (110, 110, 116)
OBSTACLE = (120, 116, 108)
WHEEL = (40, 40, 44)
LOST = (214, 39, 40)
OK = (44, 160, 44)
WARN = (240, 170, 30)
BAD = (214, 39, 40)
ROVER_COLOURS = [
    (230, 120, 30),  # leader: orange
    (31, 119, 180),  # follower: blue
    (44, 160, 44),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
]
MIN_ROVER_PX = 5.0


def rover_colour(index: int) -> tuple[int, int, int]:
    """Colour of the index-th rover (leader first, as in the plots)."""
    return ROVER_COLOURS[index % len(ROVER_COLOURS)]


def error_colour(error: float, tolerance: float) -> tuple[int, int, int]:
    """Green within the tolerance band, amber at twice it, red from three times it."""
    r = abs(error) / tolerance if tolerance > 0 else (0.0 if error == 0 else math.inf)
    if r <= 1:
        return OK
    if r >= 3:
        return BAD
    a, b, k = (OK, WARN, r - 1) if r < 2 else (WARN, BAD, r - 2)
    return (
        int(a[0] + (b[0] - a[0]) * k),
        int(a[1] + (b[1] - a[1]) * k),
        int(a[2] + (b[2] - a[2]) * k),
    )


def nice_step(target_m: float) -> float:
    """The 1-2-5 series value nearest above ``target_m`` (grid spacing, scale bar)."""
    exp = math.floor(math.log10(target_m))
    for m in (1, 2, 5, 10):
        if m * 10**exp >= target_m:
            return m * 10.0**exp
    return 10.0 ** (exp + 1)


class Renderer:
    """Draws frames at one size; the HUD's font scales with the height."""

    def __init__(self, size: tuple[int, int]) -> None:
        self.size = size
        self.text_px = max(11, round(size[1] / 48))
        self.font = font(self.text_px)
        self.small = font(max(9, self.text_px - 3))

    def draw(
        self,
        surface: pygame.Surface,
        frame: Frame,
        camera: Camera,
        status: Sequence[str] = (),
    ) -> None:
        """Draw ``frame`` as seen by ``camera``; ``status`` lines go top-right."""
        surface.fill(BACKGROUND)
        self._grid(surface, camera)
        for zone in frame.zones:
            self._zone(surface, camera, zone)
        for ob in frame.obstacles:
            self._obstacle(surface, camera, ob.kind, ob.points, ob.radius)
        colours = {r.name: rover_colour(i) for i, r in enumerate(frame.rovers)}
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
                px, py = camera.to_screen(x, y)
                pygame.draw.line(surface, LOST, (px - 4, py - 4), (px + 4, py + 4), 2)
                pygame.draw.line(surface, LOST, (px - 4, py + 4), (px + 4, py - 4), 2)
        self._distance_lines(surface, camera, frame)
        for r in frame.rovers:
            self._rover(surface, camera, r, colours[r.name])
        self._hud(surface, frame, camera, status)

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
        top = min(p[1] for p in pts)
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

    def _distance_lines(self, surface: pygame.Surface, camera: Camera, frame: Frame) -> None:
        q = frame.quality
        for a, b in itertools.pairwise(frame.rovers):
            d = math.hypot(a.x - b.x, a.y - b.y)
            col = error_colour(d - q.reference, q.tolerance) if q else MUTED
            pa, pb = camera.to_screen(a.x, a.y), camera.to_screen(b.x, b.y)
            pygame.draw.line(surface, col, pa, pb, 2)
            label = self.small.render(f"true {d:.1f} m", True, col)
            mx, my = (pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2
            surface.blit(label, (mx - label.get_width() / 2, my - label.get_height() - 4))

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
        label = self.small.render(r.name, True, INK)
        px, py = camera.to_screen(r.x, r.y)
        reach = max(MIN_ROVER_PX, 0.6 * max(r.length, r.width) * camera.scale)
        surface.blit(label, (px - label.get_width() / 2, py - reach - label.get_height()))

    # -- HUD ---------------------------------------------------------------------------------
    def _hud(
        self, surface: pygame.Surface, frame: Frame, camera: Camera, status: Sequence[str]
    ) -> None:
        m, q = frame.metrics, frame.quality
        lines = [f"t {frame.t:8.2f} s / {frame.duration:g} s", frame.phase_text]
        colours = [INK, INK]
        if q is not None and m.value is not None:
            err = m.value - q.reference
            lines.append(
                f"measured {m.value:6.2f} m  ref {q.reference:g} ± {q.tolerance:g}  "
                f"error {err:+.2f} m"
            )
            colours.append(error_colour(err, q.tolerance))
            rms = m.rms_error
            lines.append(
                f"max {m.max:.2f} m  min {m.min:.2f} m  rms error "
                f"{rms:.2f} m  collisions {m.collisions}"
            )
            colours.append(INK)
        else:
            lines.append(f"collisions {m.collisions}")
            colours.append(INK)
        self.panel(surface, lines, colours, (10, 10), align_right=False)
        if status:
            self.panel(surface, list(status), [INK] * len(status), (10, 10), align_right=True)

    def panel(
        self,
        surface: pygame.Surface,
        lines: Sequence[str],
        colours: Sequence[tuple[int, int, int]],
        at: tuple[int, int],
        *,
        align_right: bool,
    ) -> None:
        """Text lines on a translucent box, from the top-left or top-right corner."""
        rendered = [self.font.render(t, True, c) for t, c in zip(lines, colours, strict=True)]
        pad = 6
        width = max(r.get_width() for r in rendered) + 2 * pad
        height = sum(r.get_height() for r in rendered) + 2 * pad
        x = self.size[0] - width - at[0] if align_right else at[0]
        box = pygame.Surface((width, height), pygame.SRCALPHA)
        box.fill((255, 255, 255, 215))
        surface.blit(box, (x, at[1]))
        y = at[1] + pad
        for r in rendered:
            surface.blit(r, (x + pad, y))
            y += r.get_height()


def _screen(camera: Camera, points: Sequence[tuple[float, float]]) -> list[list[float]]:
    """Many world points to pixels at once (numpy: trails hold hundreds of points)."""
    arr = np.asarray(points, dtype=float)
    out = np.empty_like(arr)
    out[:, 0] = camera.width / 2 + (arr[:, 0] - camera.cx) * camera.scale
    out[:, 1] = camera.height / 2 - (arr[:, 1] - camera.cy) * camera.scale
    np.clip(out, -1e5, 1e5, out=out)  # SDL draws garbage for coordinates near int limits
    return out.tolist()


def _tint(colour: tuple[int, int, int], amount: float) -> tuple[int, int, int]:
    """Blend ``colour`` toward white by ``amount`` (0: unchanged, 1: white)."""
    return tuple(int(c + (255 - c) * amount) for c in colour)  # type: ignore[return-value]
