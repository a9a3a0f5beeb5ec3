"""World metres to screen pixels, and where the camera looks.

Three modes. ``fit`` (the default, and the only one a recording uses) frames every rover with
a margin and glides there, so a 500 s run stays readable without anybody steering the view.
``follow`` centres one rover at the current zoom. ``free`` is wherever the user panned and
zoomed. The glide is driven by *simulated* time, so a video is the same at any ``--speedup``
of the wall clock and the same on every machine.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

#: Smallest field of view (m) in fit mode: two rovers 1 m apart are not drawn 10 m long.
MIN_SPAN_M = 24.0
#: Margin around the rovers in fit mode, as a share of the span.
MARGIN = 0.25
#: Time constant (simulated seconds) of the glide toward the fit target.
GLIDE_S = 0.8


class Camera:
    """A zoomable, pannable view onto the plane (y up on screen, as on a map)."""

    def __init__(self, size: tuple[int, int], center: tuple[float, float] = (0.0, 0.0)) -> None:
        self.width, self.height = size
        self.cx, self.cy = center
        self.scale = min(self.width, self.height) / MIN_SPAN_M  # pixels per metre
        self.mode = "fit"
        self.target: str | None = None  # rover followed in ``follow`` mode
        self._placed = False
        #: pixels covered at the left (the parameter panel), at the right (the help, the
        #: signal list) and at the top (the HUD and status boxes): fit mode frames the rovers
        #: in the room they leave, so nothing the window draws over the map hides a rover
        self.left = 0
        self.right = 0
        self.top = 0

    # -- transforms ------------------------------------------------------------------------
    def to_screen(self, x: float, y: float) -> tuple[float, float]:
        """Pixel coordinates of the world point (x, y)."""
        return (
            self.mid_x + (x - self.cx) * self.scale,
            self.mid_y - (y - self.cy) * self.scale,
        )

    def to_world(self, px: float, py: float) -> tuple[float, float]:
        """World point under the pixel (px, py)."""
        return (
            self.cx + (px - self.mid_x) / self.scale,
            self.cy - (py - self.mid_y) / self.scale,
        )

    def room(self) -> tuple[float, float, float, float]:
        """The pixels (x0, y0, x1, y1) the map is framed in: what the panels and the HUD
        leave. A cover that would leave less than a quarter of the window is ignored (in a
        320x240 window the help covers nearly all of it: it is an overlay there)."""
        x0, x1 = self.left, self.width - self.right
        if x1 - x0 < self.width // 4:
            x1 = self.width
            if x1 - x0 < self.width // 4:
                x0 = 0
        y0 = self.top if self.height - self.top >= self.height // 4 else 0
        return x0, y0, x1, self.height

    @property
    def mid_x(self) -> float:
        """Pixel column the camera centres on: the middle of the room beside the panels."""
        x0, _, x1, _ = self.room()
        return (x0 + x1) / 2

    @property
    def mid_y(self) -> float:
        """Pixel row the camera centres on: the middle of the room under the HUD."""
        _, y0, _, y1 = self.room()
        return (y0 + y1) / 2

    # -- following the action --------------------------------------------------------------
    def update(self, points: Sequence[tuple[float, float, str]], dt_sim: float) -> None:
        """Move toward the mode's target; ``points`` are (x, y, rover name)."""
        if not points or self.mode == "free":
            return
        if self.mode == "follow":
            for x, y, name in points:
                if name == self.target:
                    self.cx, self.cy = x, y
            return
        xs = [p[0] for p in points]
        ys = [p[1] for p in points]
        span_x = max(max(xs) - min(xs), MIN_SPAN_M)
        span_y = max(max(ys) - min(ys), MIN_SPAN_M * self.height / self.width)
        x0, y0, x1, y1 = self.room()
        scale = min((x1 - x0) / span_x, (y1 - y0) / span_y) / (1 + 2 * MARGIN)
        tx, ty = (max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2
        if not self._placed:
            self.cx, self.cy, self.scale = tx, ty, scale
            self._placed = True
            return
        k = 1 - math.exp(-max(dt_sim, 0.0) / GLIDE_S)
        self.cx += (tx - self.cx) * k
        self.cy += (ty - self.cy) * k
        # zoom in log space so zooming in and out glide alike
        self.scale *= math.exp((math.log(scale) - math.log(self.scale)) * k)
        # never let a rover leave the picture while gliding
        for x, y, _ in points:
            px, py = self.to_screen(x, y)
            if not (x0 <= px <= x1 and y0 <= py <= y1):
                self.cx, self.cy, self.scale = tx, ty, scale
                break

    def zoom(self, factor: float, around: tuple[float, float] | None = None) -> None:
        """Zoom by ``factor`` keeping the pixel ``around`` (default: the centre) in place."""
        px, py = around if around is not None else (self.width / 2, self.height / 2)
        wx, wy = self.to_world(px, py)
        self.scale = min(max(self.scale * factor, 0.2), 2000.0)
        nx, ny = self.to_world(px, py)
        self.cx += wx - nx
        self.cy += wy - ny
        if self.mode == "fit":
            self.mode = "free"

    def key_zoom(self, factor: float, names: Sequence[str]) -> str:
        """Zoom from the keyboard (``z``, ``x``): about the rover followed, so it stays in the
        middle. From ``fit`` the camera starts following the first rover (the world's first,
        the leader in the MDE worlds): zooming about the window's centre, as the wheel does
        about the mouse, lost the rovers the fit was showing. Returns the HUD's label."""
        if self.mode == "fit" and names:
            self.mode, self.target = "follow", names[0]
        if self.mode == "follow":
            self.scale = min(max(self.scale * factor, 0.2), 2000.0)  # update() re-centres
        else:
            self.zoom(factor)
        return self.label()

    def pan(self, dx_px: float, dy_px: float) -> None:
        """Move the view by a drag of (dx, dy) pixels."""
        self.cx -= dx_px / self.scale
        self.cy += dy_px / self.scale
        self.mode = "free"

    def cycle(self, names: Sequence[str]) -> str:
        """fit -> follow each rover -> fit; returns a label for the HUD."""
        if self.mode != "follow":
            if names:
                self.mode, self.target = "follow", names[0]
            else:
                self.mode = "fit"
        else:
            i = list(names).index(self.target) if self.target in names else -1
            if i + 1 < len(names):
                self.target = names[i + 1]
            else:
                self.mode, self.target = "fit", None
        return self.label()

    def label(self) -> str:
        """Current mode as shown in the window."""
        return f"follow {self.target}" if self.mode == "follow" else self.mode
