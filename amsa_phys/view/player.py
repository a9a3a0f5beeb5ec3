"""The finished-run player (``amsa-phys view RUNDIR``): play, pause, scrub, jump to events.

Same renderer, camera and HUD as the live window, fed by a
:class:`~amsa_phys.view.replay.ReplayScene`; a slider along the bottom shows where the
cursor is in the run, with a mark for every event in the palette's language
(``marks.draw_slider_mark``: grey for the timeline, red for alerts). Click or drag on it to
seek. The cursor always sits on a logged instant, so every picture is exactly the trace's
row.

``frame(real_dt)`` runs one iteration (events, advance, draw) so that tests drive the player
with injected events and an exact clock under SDL's dummy driver, as they do the window.
"""

from __future__ import annotations

import numpy as np

from .camera import Camera
from .draw import INK, MUTED, Renderer
from .marks import SLIDER_ORDER, draw_slider_mark, slider_kind
from .mouse import pan_zoom
from .pg import font, pygame
from .plotpane import SignalPicker, draw_side_panes, picker_key
from .replay import Event, ReplayScene
from .scene import Frame

SPEEDS = (1 / 16, 1 / 8, 1 / 4, 1 / 2, 1, 2, 4, 8, 16, 32, 64)
MAX_REAL_DT = 0.1
FPS = 60
#: seconds a shift+arrow moves the cursor
BIG_STEP_S = 5.0
SLIDER_H = 34

HELP = [
    "space         play / pause",
    "left right    one logged instant back / on",
    "  + shift     5 s back / on",
    "home end      start / end of the run",
    "n b           next / previous event",
    "pgdn pgup     next / previous phase start",
    "click, drag   the slider: seek",
    "] [ or + -    faster / slower",
    "g             plot signals (list: / filters,",
    "              enter picks / drops, g closes)",
    "c             camera: fit, then follow each rover",
    "z x           zoom about the rover followed",
    "wheel         zoom about the mouse",
    "h or F1       this help (any other key closes it)",
    "q or esc      quit",
]


class Player:
    """One replay session on one finished run."""

    def __init__(
        self, scene: ReplayScene, *, title: str = "amsa-phys", size: tuple[int, int] = (1280, 720)
    ) -> None:
        pygame.display.init()
        pygame.font.init()
        self.screen = pygame.display.set_mode(size, pygame.RESIZABLE)
        pygame.display.set_caption(f"amsa-phys view: {title}")
        self.scene = scene
        self.picker = SignalPicker(scene.columns)
        self.row = 0
        self.playing = False
        self.speed_index = SPEEDS.index(1)
        self.running = True
        self.show_help = False
        self.notice = ""
        #: the row an event's notice (``125.00 s: phase 1: ...``) is about: it is shown only
        #: there, so a later seek (End, a click on the slider, playing on) never leaves it
        #: describing an instant the picture no longer shows
        self._notice_row: int | None = None
        self._owed = 0.0
        self._seeking = False
        self._drag: tuple[int, int] | None = None
        self._layout(size)

    def _layout(self, size: tuple[int, int]) -> None:
        w, h = size
        self.size = size
        self.view_rect = pygame.Rect(0, 0, w, max(100, h - SLIDER_H))
        self.slider = pygame.Rect(12, self.view_rect.bottom + 10, w - 24, SLIDER_H - 20)
        self.camera = Camera(self.view_rect.size)
        self.renderer = Renderer(self.view_rect.size)

    # -- time --------------------------------------------------------------------------------
    @property
    def t(self) -> float:
        """Simulated time of the row shown."""
        return float(self.scene.t[self.row])

    @property
    def speed(self) -> float:
        """Simulated seconds per wall-clock second while playing."""
        return SPEEDS[self.speed_index]

    def seek(self, t: float) -> None:
        """Show the last logged instant at or before ``t`` (clamped to the run)."""
        self.row = self.scene.row_at(t)
        self._owed = 0.0

    def step(self, rows: int) -> None:
        """Move by ``rows`` logged instants (pauses)."""
        self.playing = False
        self.row = min(max(self.row + rows, 0), self.scene.rows - 1)

    def jump(self, direction: int, kinds: tuple[str, ...] | None = None) -> Event | None:
        """To the next (1) or previous (-1) event, of ``kinds`` or any; pauses there."""
        self.playing = False
        now = self.t
        events = [e for e in self.scene.events if kinds is None or e.kind in kinds]
        if direction > 0:
            found = next((e for e in events if e.t > now + 1e-9), None)
        else:
            found = next((e for e in reversed(events) if e.t < now - 1e-9), None)
        if found is None:
            # the run's start is no event (phase 0 starts with it): Home goes there
            self.notice = (
                "no later event" if direction > 0 else "no earlier event (Home: the start)"
            )
            self._notice_row = self.row
            return None
        self.seek(found.t)
        self.notice = f"{found.t:.2f} s: {found.text}"
        self._notice_row = self.row
        return found

    # -- the loop ------------------------------------------------------------------------------
    def run(self) -> None:
        """Until the user closes the window."""
        clock = pygame.time.Clock()
        try:
            while self.frame(clock.tick(FPS) / 1000):
                pass
        finally:
            pygame.display.quit()

    def frame(self, real_dt: float) -> bool:
        """One iteration: events, advance by ``speed * real_dt`` if playing, draw."""
        for event in pygame.event.get():
            self.handle(event)
        if not self.running:
            return False
        if self.playing:
            self._owed += self.speed * min(real_dt, MAX_REAL_DT)
            target = self.scene.row_at(self.t + self._owed)
            if target > self.row:
                self._owed -= float(self.scene.t[target]) - self.t
                self.row = target
            if self.row >= self.scene.rows - 1:
                self.playing = False
        self.draw()
        return True

    # -- input -----------------------------------------------------------------------------------
    def handle(self, event: pygame.event.Event) -> None:
        """React to one pygame event: the time slider first, then the map's mouse."""
        if self._slider_event(event):
            return
        handled, self._drag = pan_zoom(event, self.camera, self._drag)
        if handled:
            return
        if event.type == pygame.QUIT:
            self.running = False
        elif event.type == pygame.KEYDOWN:
            self._key(event)
        elif event.type == pygame.VIDEORESIZE:
            size = (max(320, event.w), max(240, event.h))
            self.screen = pygame.display.set_mode(size, pygame.RESIZABLE)
            self._layout(size)

    def _slider_event(self, event: pygame.event.Event) -> bool:
        """A press on the slider starts seeking, motion while seeking seeks; True if taken.
        A release ends seeking and is passed on (it also ends a map drag)."""
        if event.type == pygame.MOUSEBUTTONDOWN and event.button == 1:
            if self.slider.inflate(0, 12).collidepoint(event.pos):
                self._seeking = True
                self._seek_x(event.pos[0])
                return True
        elif event.type == pygame.MOUSEMOTION and self._seeking:
            self._seek_x(event.pos[0])
            return True
        elif event.type == pygame.MOUSEBUTTONUP and event.button == 1:
            self._seeking = False
        return False

    def _seek_x(self, x: int) -> None:
        """Seek to the time under pixel column ``x`` of the slider."""
        k = min(max((x - self.slider.x) / max(1, self.slider.width), 0.0), 1.0)
        self.playing = False
        self.seek(float(self.scene.t[0]) + k * self._span())

    def _span(self) -> float:
        return max(float(self.scene.t[-1] - self.scene.t[0]), 1e-9)

    def _key(self, event: pygame.event.Event) -> None:
        key = event.key
        shift = bool(event.mod & pygame.KMOD_SHIFT)
        if self.picker.visible and self._picker_key(key, event.unicode):
            return
        if self.show_help and key not in (pygame.K_h, pygame.K_F1):
            self.show_help = False  # any key puts the help away (and does its job) ...
            if key == pygame.K_ESCAPE:
                return  # ... but Esc only that: it never quits from the help
        if key in (pygame.K_q, pygame.K_ESCAPE):
            self.running = False
        elif key == pygame.K_SPACE:
            if self.row >= self.scene.rows - 1:
                self.row = 0  # play again from the start
            self.playing = not self.playing
            self._owed = 0.0
        elif key == pygame.K_RIGHT:
            if shift:
                self.playing = False
                self.seek(self.t + BIG_STEP_S)
            else:
                self.step(1)
        elif key == pygame.K_LEFT:
            if shift:
                self.playing = False
                self.seek(self.t - BIG_STEP_S)
            else:
                self.step(-1)
        elif key == pygame.K_HOME:
            self.step(-self.scene.rows)
        elif key == pygame.K_END:
            self.step(self.scene.rows)
        elif key == pygame.K_n:
            self.jump(1)
        elif key == pygame.K_b:
            self.jump(-1)
        elif key == pygame.K_PAGEDOWN:
            self.jump(1, ("phase",))
        elif key == pygame.K_PAGEUP:
            self.jump(-1, ("phase",))
        elif key == pygame.K_RIGHTBRACKET or key in (pygame.K_PLUS, pygame.K_EQUALS):
            self.speed_index = min(len(SPEEDS) - 1, self.speed_index + 1)
        elif key == pygame.K_LEFTBRACKET or key == pygame.K_MINUS:
            self.speed_index = max(0, self.speed_index - 1)
        elif key == pygame.K_g:
            self.picker.visible = True
        elif key == pygame.K_c:
            self.notice = "camera: " + self.camera.cycle(self.scene.rover_names)
            self._notice_row = None  # not about an instant: it stays
        elif key in (pygame.K_z, pygame.K_x):
            factor = 1.25 if key == pygame.K_z else 1 / 1.25
            self.notice = "camera: " + self.camera.key_zoom(factor, self.scene.rover_names)
            self._notice_row = None  # not about an instant: it stays
        elif key in (pygame.K_UP, pygame.K_DOWN):
            self.camera.pan(0, 60 if key == pygame.K_UP else -60)
        elif key in (pygame.K_h, pygame.K_F1):
            self.show_help = not self.show_help

    def _picker_key(self, key: int, text: str) -> bool:
        """Keys the open signal list takes; False lets the player have them."""
        return picker_key(self.picker, key, text)

    # -- drawing ---------------------------------------------------------------------------------
    def status(self) -> list[str]:
        """Top-right lines: play state, speed, camera (the last notice goes in the HUD)."""
        state = "playing" if self.playing else "PAUSED"
        if self.row >= self.scene.rows - 1:
            state = "end of the run"
        lines = [
            f"replay {state}  x{self.speed:g}",
            f"camera {self.camera.label()}  h: help",
        ]
        status = str(self.scene.metrics.get("status") or "")
        if status and status != "completed":
            lines.append(f"run {status}")
        return lines

    def shown_notice(self) -> str:
        """The HUD's last line: what the last key did, an event's only at its instant."""
        stale = self._notice_row is not None and self._notice_row != self.row
        return "" if stale else self.notice

    def draw(self) -> None:
        """The current row, the slider, and the open panes (drawn again when what covers
        the map moved, so the picture and the camera agree: ``Window.draw``)."""
        frame = self.scene.frame(self.row)
        cam = self.camera
        points = [(r.x, r.y, r.name) for r in frame.rovers]
        cam.update(points, 0.05 if self.playing else 1e9)
        for _ in range(2):
            room = (cam.top, cam.right, cam.left)
            self._paint(frame)
            if (cam.top, cam.right, cam.left) == room:
                break
            cam.update(points, 0.05 if self.playing else 1e9)
        pygame.display.flip()

    def _paint(self, frame: Frame) -> None:
        """Draw ``frame``, the slider and the panes; set the camera's covers from them."""
        view = self.screen.subsurface(self.view_rect)
        cam = self.camera
        self.renderer.draw(view, frame, cam, self.status(), self.shown_notice())
        cam.top = max(box.bottom for box in self.renderer.boxes.values()) + 6  # under the HUD
        self._slider()
        right, left = draw_side_panes(
            self.screen,
            self.renderer,
            self.picker,
            self.scene_series,
            self.show_help,
            HELP,
            self.view_rect,
        )
        # beside the help or the signal list
        cam.right = self.view_rect.right - right.left if right is not None else 0
        cam.left = left.right if left is not None else 0

    def scene_series(self, name: str, span_s: float) -> tuple[np.ndarray, np.ndarray]:
        """The pane's samples of ``name`` up to the row shown (the replay's whole history)."""
        return self.scene.series(name, self.row, span_s)

    def slider_x(self, t: float) -> int:
        """Pixel column of time ``t`` on the slider."""
        k = (t - float(self.scene.t[0])) / self._span()
        return round(self.slider.x + k * self.slider.width)

    def _slider(self) -> None:
        bar = self.slider
        screen = self.screen
        pygame.draw.rect(
            screen, (246, 246, 241), (0, self.view_rect.bottom, self.size[0], SLIDER_H)
        )
        pygame.draw.rect(screen, (225, 225, 218), bar)
        done = bar.copy()
        done.width = self.slider_x(self.t) - bar.x
        pygame.draw.rect(screen, (190, 200, 215), done)
        rank = {kind: i for i, kind in enumerate(SLIDER_ORDER)}
        for e in sorted(self.scene.events, key=lambda e: rank[slider_kind(e.kind)]):
            draw_slider_mark(screen, e.kind, self.slider_x(e.t), bar)
        x = self.slider_x(self.t)
        pygame.draw.rect(screen, INK, (x - 3, bar.top - 6, 6, bar.height + 12))
        label = font(max(9, self.renderer.text_px - 3)).render(
            f"{self.t:.2f} s / {self.scene.duration:g} s", True, MUTED
        )
        screen.blit(label, (bar.right - label.get_width(), bar.top - label.get_height() - 6))
