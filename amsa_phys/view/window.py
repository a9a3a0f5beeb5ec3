"""The interactive window: watch, pause, step, zoom, and change parameters live.

The simulation advances by ``speed x`` the wall-clock time between two displayed frames
(capped, so a stall does not jump ahead), to the last instant on the run's grid. Every
parameter change made in the panel goes through ``Simulation.apply_live`` and so lands at
one exact instant; the run directory's ``scenario.yaml`` lists it as a timeline entry, and
replaying that file reproduces the session's trace.

``frame(real_dt)`` runs one iteration (events, advance, draw) so that tests can drive the
window with injected events and an exact clock under SDL's dummy video driver.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from fractions import Fraction

from ..engine import interrupt
from ..engine.face import SimDriver
from ..model.scenario import Quality
from ..valuetext import value_text
from .camera import Camera
from .draw import INK, LOST, MUTED, Renderer
from .drive import advance
from .mouse import pan_zoom
from .panel import ParamPanel
from .pg import pygame
from .plotpane import (
    LiveSeries,
    SignalPicker,
    draw_side_panes,
    pane_rect,
    picker_key,
    reaches_pane,
)
from .scene import Frame, Scene
from .video import Recorder

SPEEDS = (1 / 16, 1 / 8, 1 / 4, 1 / 2, 1, 2, 4, 8, 16, 32, 64, 128, 256)
MAX_REAL_DT = 0.1  # seconds of wall clock a single frame may cover
FPS = 60

HELP = [  # every key _key and _panel_key handle
    "space         pause / resume",
    "s or .        one instant (pauses)",
    "] [ or + -    faster / slower",
    "c             camera: fit, then follow each rover",
    "z x           zoom about the rover followed",
    "wheel         zoom about the mouse",
    "drag, arrows  pan",
    "p or tab      parameter panel (open / close)",
    "  up down     row; pgup pgdn: component",
    "  left right  step the value (shift: fine)",
    "  0-9 . - e   type a value; enter applies, esc drops",
    "g             plot signals (list: / filters,",
    "              enter picks / drops, g closes)",
    "h or F1       this help (any other key closes it)",
    "q or esc      quit (the outputs are written;",
    "              esc first closes the panel)",
]


#: SDL's video drivers that show nothing: a window on them is never seen
INVISIBLE_DRIVERS = ("offscreen", "dummy")


def open_display(interactive: bool = False) -> None:
    """Start SDL's video, or raise ``RuntimeError`` saying why no window can be shown.

    With no X11/Wayland display SDL quietly falls back to its ``offscreen`` driver: a window
    would then run invisibly and never be closed. We refuse that unless the user (or a test)
    asked for an offscreen driver explicitly with ``SDL_VIDEODRIVER``. On Linux with neither
    ``DISPLAY`` nor ``WAYLAND_DISPLAY`` set we refuse before asking SDL: its Wayland probe
    would print its own ``error: XDG_RUNTIME_DIR ...`` line above ours.

    ``interactive``: a session that ends only when its window is closed (``run`` without
    ``--headless``, ``view``). On an invisible driver nobody can close it, so it is refused
    even when ``SDL_VIDEODRIVER`` asks for that driver (``SDL_VIDEODRIVER=dummy`` is a common
    setting for headless tests; with it such a session used to wait for ever).
    """
    asked = os.environ.get("SDL_VIDEODRIVER", "")
    if interactive and asked.strip().lower() in INVISIBLE_DRIVERS:
        raise RuntimeError(
            f"SDL_VIDEODRIVER={asked.strip()} shows no window, and the session would wait for "
            "ever for it to be closed"
        )
    env = os.environ
    if (
        sys.platform.startswith("linux")
        and not env.get("SDL_VIDEODRIVER")
        and not env.get("DISPLAY")
        and not env.get("WAYLAND_DISPLAY")
    ):
        raise RuntimeError("no display to open a window on (no X11 or Wayland session)")
    named = ", ".join(f"{k}={env[k]}" for k in ("DISPLAY", "WAYLAND_DISPLAY") if env.get(k))
    on = f" on {named}" if named and not asked else ""
    try:
        pygame.display.init()
    except pygame.error as exc:
        raise RuntimeError(f"cannot open a window{on}: {exc}") from None
    driver = pygame.display.get_driver()
    if driver in INVISIBLE_DRIVERS and (interactive or not asked):
        pygame.display.quit()
        if asked:  # another name SDL maps to an invisible driver
            raise RuntimeError(
                f"SDL_VIDEODRIVER={asked} opens SDL's {driver} driver, which shows no window"
            )
        if named:  # a session is named, but SDL could not connect to it
            raise RuntimeError(
                f"cannot open a window{on}: SDL could not connect to that display "
                "(is its server running, and does it accept this user?)"
            )
        raise RuntimeError("no display to open a window on (no X11 or Wayland session)")


#: the end of the warning shown when q would drop a queued live change (cleared once it lands)
QUEUED_NOTICE = " is queued, not applied yet: q again quits without it"


class Window:
    """One interactive session on one Simulation (already initialised)."""

    def __init__(
        self,
        sim: SimDriver,
        quality: Quality | None,
        *,
        title: str = "amsa-phys",
        size: tuple[int, int] = (1280, 720),
        recorder: Recorder | None = None,
        paused: bool = False,
        planned: Sequence[Fraction] | None = None,
    ) -> None:
        pygame.display.init()
        pygame.font.init()
        self.screen = pygame.display.set_mode(size, pygame.RESIZABLE)
        pygame.display.set_caption(f"amsa-phys: {title}")
        self.sim = sim
        self.recorder = recorder
        self.sinks = [recorder] if recorder is not None else []
        self.scene = Scene(sim, quality, planned)
        self.picker = SignalPicker(sim.columns)
        self.series = LiveSeries(self.picker)
        sim.add_log_listener(self.series)
        self.camera = Camera(size)
        self.renderer = Renderer(size)
        self.panel = ParamPanel(sim)
        self.speed_index = SPEEDS.index(1)
        self.paused = paused
        self.running = True
        self.show_help = False
        self.notice = ""
        self._owed = 0.0  # simulated seconds the wall clock has earned but not yet run
        self.idle_s = 0.0  # wall-clock seconds paused or finished: not part of the run's speed
        self._quit_asked = False  # q pressed once with a live change still queued
        self._drag: tuple[int, int] | None = None
        self._end = sim.grid.ticks(sim.duration)

    # -- the loop ------------------------------------------------------------------------
    @property
    def speed(self) -> float:
        """Simulated seconds per wall-clock second."""
        return SPEEDS[self.speed_index]

    @property
    def finished(self) -> bool:
        """The run reached its duration."""
        return self.sim.finished

    def run(self) -> float:
        """Until the user closes the window; returns the wall-clock seconds spent idle."""
        clock = pygame.time.Clock()
        try:
            while self.frame(clock.tick(FPS) / 1000):
                pass
        finally:
            pygame.display.quit()
        return self.idle_s

    def frame(self, real_dt: float) -> bool:
        """One iteration: events, advance by ``speed * real_dt``, draw. False once closed."""
        if self.finished and interrupt.requested():
            # the run is whole: Ctrl-C or SIGTERM now closes the window as `q` would (the
            # outputs are written as complete), not an interruption of a run that has ended
            self.running = False
            return False
        interrupt.check()  # Ctrl-C in the terminal, also while paused (advance checks too)
        for event in pygame.event.get():
            self.handle(event)
        if not self.running:
            return False
        if self.paused or self.finished:
            self.idle_s += real_dt
        else:
            self._owed += self.speed * min(real_dt, MAX_REAL_DT)
            target = self.sim.now + Fraction(self._owed).limit_denominator(10**6)
            tick = int(target / self.sim.grid.tick)
            if tick >= self.sim.grid.ticks(self.sim.now):
                before = self.sim.now
                self._advance(min(tick, self._end))
                self._owed -= float(self.sim.now - before)
        if self.notice.endswith(QUEUED_NOTICE) and not self.sim.pending_live:
            self._quit_asked = False  # the queued change has landed: the warning is stale
            self.notice = ""
        self.draw()
        return True

    def step_once(self) -> None:
        """Run the next instant only (and pause)."""
        self.paused = True
        if self.finished:
            return
        tick = self.sim.grid.ticks(self.sim.next_instant())
        self._advance(min(tick, self._end))

    def _advance(self, tick: int) -> None:
        """Run every instant up to ``tick``; the picture drawn then shows the rovers where
        that instant's log saw them (not one physics step on)."""
        self.scene.expect(float(self.sim.grid.time(tick)))
        advance(self.sim, tick, self.sinks)

    # -- input ---------------------------------------------------------------------------
    def handle(self, event: pygame.event.Event) -> None:
        """React to one pygame event."""
        handled, self._drag = pan_zoom(event, self.camera, self._drag)
        if handled:
            return
        if event.type == pygame.QUIT:
            self.running = False
        elif event.type == pygame.KEYDOWN:
            self._key(event)
        elif event.type == pygame.VIDEORESIZE:
            self._resize((event.w, event.h))

    def _key(self, event: pygame.event.Event) -> None:
        key = event.key
        shift = bool(event.mod & pygame.KMOD_SHIFT)
        panel = self.panel
        if panel.visible and self._panel_key(key, event.unicode, shift):
            return
        if self.picker.visible and picker_key(self.picker, key, event.unicode):
            return
        quit_asked, self._quit_asked = self._quit_asked, False
        if self.show_help and key not in (pygame.K_h, pygame.K_F1):
            self.show_help = False  # any key puts the help away (and does its job) ...
            if key == pygame.K_ESCAPE:
                return  # ... but Esc only that: it never quits from the help
        if key in (pygame.K_q, pygame.K_ESCAPE):
            self.quit(confirmed=quit_asked)
        elif key == pygame.K_SPACE:
            self.paused = not self.paused
        elif key in (pygame.K_s, pygame.K_PERIOD):
            self.step_once()
        elif key == pygame.K_RIGHTBRACKET or (key in (pygame.K_PLUS, pygame.K_EQUALS)):
            self.speed_index = min(len(SPEEDS) - 1, self.speed_index + 1)
        elif key == pygame.K_LEFTBRACKET or key == pygame.K_MINUS:
            self.speed_index = max(0, self.speed_index - 1)
        elif key in (pygame.K_z, pygame.K_x):
            names = [r.name for r in self.scene.rovers()]
            label = self.camera.key_zoom(1.25 if key == pygame.K_z else 1 / 1.25, names)
            self.notice = f"camera: {label}"
        elif key == pygame.K_c:
            self.notice = "camera: " + self.camera.cycle([r.name for r in self.scene.rovers()])
        elif key in (pygame.K_LEFT, pygame.K_RIGHT, pygame.K_UP, pygame.K_DOWN):
            dx = {pygame.K_LEFT: 60, pygame.K_RIGHT: -60}.get(key, 0)
            dy = {pygame.K_UP: 60, pygame.K_DOWN: -60}.get(key, 0)
            self.camera.pan(dx, dy)
        elif key in (pygame.K_p, pygame.K_TAB):
            panel.visible = True
        elif key == pygame.K_g:
            panel.visible = False
            self.picker.visible = True
        elif key in (pygame.K_h, pygame.K_F1):
            self.show_help = not self.show_help

    def _panel_key(self, key: int, text: str, shift: bool) -> bool:
        """Keys the open panel takes; False lets the window have them."""
        panel = self.panel
        if key in (pygame.K_p, pygame.K_TAB):
            panel.visible = False
            panel.cancel()
        elif key == pygame.K_UP:
            panel.move(-1)
        elif key == pygame.K_DOWN:
            panel.move(1)
        elif key == pygame.K_PAGEUP:
            panel.next_component(-1)
        elif key == pygame.K_PAGEDOWN:
            panel.next_component(1)
        elif key == pygame.K_LEFT:
            panel.step(-1, fine=shift)
        elif key == pygame.K_RIGHT:
            panel.step(1, fine=shift)
        elif key == pygame.K_BACKSPACE:
            panel.backspace()
        elif key == pygame.K_ESCAPE:  # drops an edit, else closes the panel: never quits
            if panel.pending is not None or panel.text is not None:
                panel.cancel()
            else:
                panel.visible = False
        elif key in (pygame.K_RETURN, pygame.K_KP_ENTER):
            self.apply_panel()
        elif text and (text.isdigit() or text in ".-+e"):
            panel.type_char(text)
        else:
            return False
        return True

    def quit(self, *, confirmed: bool = False) -> None:
        """Stop the session, asking once more if a live change is queued but not yet applied.

        A change queued while paused lands only at the next instant; quitting before then
        would drop it silently (it would be missing from the run and its scenario.yaml).
        """
        pending = self.sim.pending_live
        if pending and not confirmed and not self.finished:
            changes = ", ".join(f"{c.key}={value_text(c.value)}" for c in pending)
            self.notice = f"{changes}{QUEUED_NOTICE}"
            self._quit_asked = True
            return
        self.running = False

    def apply_panel(self) -> None:
        """Commit the panel's pending value as a live change at the next instant."""
        if self.finished:
            self.panel.message = "the run has ended; nothing more to change"
            self.panel.refused = True
            self.panel.cancel()
            return
        change = self.panel.commit()
        if change is not None:
            at = self.sim.apply_live(change)
            self.panel.message = (
                f"{change.key} = {value_text(change.value)} at t = {float(at):.2f} s"
            )
            self.notice = f"live: {self.panel.message}"

    def _resize(self, size: tuple[int, int]) -> None:
        size = (max(320, size[0]), max(240, size[1]))
        self.screen = pygame.display.set_mode(size, pygame.RESIZABLE)
        cam = self.camera
        cam.width, cam.height = size
        self.renderer = Renderer(size)

    # -- drawing -------------------------------------------------------------------------
    def status(self) -> list[str]:
        """Top-right lines: run state, speed, camera, recording (the notice goes in the HUD,
        which has the room: a long one here squeezed the HUD into wrapping at 1280x720)."""
        if self.finished:
            state = "finished (q to close)"
        elif self.paused:
            state = "PAUSED"
        else:
            state = "running"
        lines = [f"{state}  x{self.speed:g}", f"camera {self.camera.label()}  h: help"]
        if self.recorder is not None:
            name = self.recorder.options.path.name
            if self.finished:  # every frame is in; the file gets its name once the window closes
                lines.append(f"video {name}: saved when closed")
            elif self.paused:  # frames follow simulated time: none while it stands still
                lines.append(f"recording {name} (paused: no frames)")
            else:
                lines.append(f"recording {name}")
        return lines

    def draw(self) -> None:
        """Render the current state to the window.

        What covers the map (the HUD and status at the top, the parameter panel at the left,
        the help or signal list at the right) is known once drawn; the camera frames the
        rovers in the room they leave. When that room changed (a panel opened, the HUD grew)
        the frame is drawn again with it, so the picture and the camera always agree.
        """
        frame = self.scene.frame()
        cam = self.camera
        points = [(r.x, r.y, r.name) for r in frame.rovers]
        cam.update(points, 0.0 if self.paused else 0.05)
        for _ in range(2):
            room = (cam.left, cam.top, cam.right)
            self._paint(frame)
            if (cam.left, cam.top, cam.right) == room:
                break
            cam.update(points, 0.0)  # no glide: only keeps every rover in the new room
        pygame.display.flip()

    def _paint(self, frame: Frame) -> None:
        """Draw ``frame`` and the open panels; set the camera's covers from where they went."""
        self.renderer.draw(self.screen, frame, self.camera, self.status(), self.notice)
        h = self.screen.get_height()
        below = max(box.bottom for box in self.renderer.boxes.values()) + 6
        self.camera.top = below  # the rovers are framed under the HUD and status
        top = max(h // 3, below)  # under the HUD and status, however they were laid out
        line_px = self.renderer.font.get_linesize()

        def fitting(n_lines: int) -> int:  # a panel too tall for the room below moves up
            return max(10, min(top, h - n_lines * line_px - 22))

        if self.panel.visible:
            lines = ["parameters (p closes)", *self.panel.lines()]
            colours = [MUTED] + [INK] * (len(lines) - 1)
            if self.panel.message:
                lines.append(self.panel.message)
                # a refusal in the alert red, a confirmation in ink: never a faint grey
                colours.append(LOST if self.panel.refused else INK)
            at = (10, fitting(len(lines)))
            box = self.renderer.panel(self.screen, lines, colours, at, align_right=False)
            self.camera.left = box.right  # the rovers are framed beside the panel
        else:
            self.camera.left = 0
        right = None
        area = self.screen.get_rect()
        listed, _ = draw_side_panes(
            self.screen, self.renderer, self.picker, self.series.series, False, [], area
        )
        if self.show_help:  # after the pane, never under it
            y = fitting(len(HELP))
            ink = [INK] * len(HELP)
            # at the left when the right holds the signal list or the help would reach the pane
            if listed is not None or reaches_pane(
                pane_rect(area, self.picker), y, len(HELP), line_px
            ):
                if not self.panel.visible:  # at the left, clear of the pane
                    box = self.renderer.panel(self.screen, HELP, ink, (10, y), align_right=False)
                    self.camera.left = box.right
            else:
                right = self.renderer.panel(self.screen, HELP, ink, (10, y), align_right=True)
        right = listed or right
        # the help and the signal list sit at the right: the rovers are framed beside them
        self.camera.right = area.right - right.left if right is not None else 0
