"""The signal list in the smallest window (320x240) stays readable: the room left of the
plot pane is 50 px there, where a list wrapped to fit put every word on its own line and
the signal names off the bottom. It goes over the pane instead, as the help does."""

from __future__ import annotations

import pytest

from amsa_phys.view.pg import pygame
from amsa_phys.view.plotpane import SignalPicker, beside_pane, pane_rect


@pytest.fixture
def display() -> object:
    pygame.display.init()
    yield None
    pygame.display.quit()


@pytest.mark.parametrize(("size", "beside"), [((320, 240), False), ((1280, 720), True)])
def test_the_list_goes_beside_the_pane_only_where_there_is_room(
    display: object, size: tuple[int, int], beside: bool
) -> None:
    screen = pygame.Surface(size)
    picker = SignalPicker(["t", "Leader.posX", "Follower.posX"])
    picker.picked = ["Leader.posX"]
    pane = pane_rect(screen.get_rect(), picker)
    assert pane is not None
    margin, width = beside_pane(screen, pane, 40, 30, 18)  # 30 lines reach the pane
    if beside:
        assert screen.get_width() - margin <= pane.left
        assert width is not None
        assert width >= size[0] // 3
    else:
        assert (margin, width) == (10, None)  # at the right edge, over the pane, unwrapped
