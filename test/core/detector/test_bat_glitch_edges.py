"""Tests for baseball_collision.core.detector.bat_glitch_edges: a segment's start, a hole."""

import math
from typing import Any

from baseball_collision.core.detector import bat_glitch_edges
from baseball_collision.core.detector.bat_glitch_edges import (
    beside_hole, early, EARLY_AFTER, early_glitch, first_frame_glitch, hole_glitch,
    segment_first)
from baseball_collision.core.detector.bat_glitches import judged
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.motion import BatSample
import numpy as np
import pytest
from support.scenes import turning_bat


def test_a_segments_early_frames_are_judged_against_the_frames_after_them() -> None:
    """
    ``early_glitch``: a segment's 2nd to 8th frames, with time run backwards.

    The frame moved 15 cm is a glitch once the seven frames after it have come (None before:
    wait; ``EARLY_AFTER``), and the frames beside it (which its neighbours' spline pulls) are
    not; on the swing without it, none is. A segment's first frame and its 9th on are not early.
    """
    assert EARLY_AFTER == 7
    bat = turning_bat(90.0, 20, turned=3, off=0.15)
    assert [early(bat, j, 0.05) for j in range(10)] == [False] + [True] * 7 + [False] * 2
    assert early_glitch(bat, 3, 0.05, 8, 0.0) is True
    assert [early_glitch(bat, j, 0.05, 8, 0.0) for j in (1, 2, 4, 5)] == [False] * 4
    assert early_glitch(turning_bat(90.0, 10, turned=3, off=0.15), 3, 0.05, 8, 0.0) is None
    assert early_glitch(turning_bat(90.0, 11, turned=3, off=0.15), 3, 0.05, 8, 0.0) is True
    clean = turning_bat(90.0, 20)
    assert not any(early_glitch(clean, j, 0.05, 8, 0.0) for j in range(1, 8))
    gap = turning_bat(90.0, 20, turned=3, off=0.15)
    gap.breaks[7] = True  # (the segment ends before the frames its judgment reads)
    assert early_glitch(gap, 3, 0.05, 8, 0.0) is False


def test_a_segments_first_frame_is_judged_by_its_departure_from_the_frames_after_it() -> None:
    """
    ``first_frame_glitch``: a segment's first frame, off the bat continued back from seven after.

    The first frame moved 15 cm is a glitch once the seven frames after it have come (None
    before: wait), not on the swing without it, nor where the segment ends first, nor where
    the frame after it departed too (the glitch may be that one: ``early_glitch`` judges it).
    """
    bat = turning_bat(90.0, 12, turned=0, off=0.15)
    assert [segment_first(bat, j, 0.05) for j in range(3)] == [True, False, False]
    assert first_frame_glitch(bat, 0, 0.05, 8, 0.0) is True
    assert first_frame_glitch(turning_bat(90.0, 7, turned=0, off=0.15), 0, 0.05, 8, 0.0) is None
    assert first_frame_glitch(turning_bat(90.0, 12), 0, 0.05, 8, 0.0) is False
    gap = turning_bat(90.0, 12, turned=0, off=0.15)
    gap.breaks[5] = True
    assert first_frame_glitch(gap, 0, 0.05, 8, 0.0) is False
    second = turning_bat(90.0, 12, turned=1, off=0.15)
    assert first_frame_glitch(second, 0, 0.05, 8, 0.0) is False
    assert early_glitch(second, 1, 0.05, 8, 0.0) is True


def test_a_still_bats_noise_is_no_glitch_at_a_segments_start(monkeypatch: Any) -> None:
    """
    A still bat with 20 mm of noise the detector was not told of: no early frame is a glitch.

    Judged with time run backwards at the floor of no noise (not estimated yet), against four
    frames' scatter (``EARLY_SCATTER``); against three (six frames after), these frames of
    1,500 such segments were glitches (10 in all; forward, with three, none).
    """
    rng, found = np.random.default_rng(11), {}
    for run in range(1000):
        knob, tip = (rng.normal(0.0, 0.02, (16, 3)) + centre
                     for centre in ((0.0, 0.0, 1.0), (0.86, 0.0, 1.0)))
        if run in (210, 552, 684, 996):
            bat = Stream('bat')
            for i in range(16):
                bat.append(i / 90.0, int(round(i / 90.0 * 1e9)) + 1,
                           BatSample(tuple(knob[i]), tuple(tip[i])), i == 0)
            found[run] = bat
    for bat in found.values():
        assert not any(early_glitch(bat, j, 0.05, 8, 0.0) for j in range(1, 8))
    monkeypatch.setattr(bat_glitch_edges, 'EARLY_SCATTER', 3)
    monkeypatch.setattr(bat_glitch_edges, 'EARLY_AFTER', 6)
    for run, j in ((210, 5), (552, 5), (684, 1), (996, 1)):
        found[run].aligned.clear()
        assert early_glitch(found[run], j, 0.05, 8, 0.0), run


@pytest.mark.parametrize('lost', [-2, -1, 1])
def test_a_frame_beside_a_long_hole_is_judged_with_the_frames_after_it(lost: int) -> None:
    """
    Beside a 22 ms hole (one frame lost at 90 Hz) ``hole_glitch`` judges a frame moved 15 cm.

    ``judged`` does not (the hole is over ``LOST_HOLE``); ``hole_glitch`` does, from the three
    frames after it (None before they come: wait); the swing's own frames there are no glitch.
    """
    bat = turning_bat(90.0, 24, turned=14, off=0.15)
    bat.remove(14 + lost)
    j = 14 - (lost < 0)
    assert beside_hole(bat, j) and not judged(bat, j, 0.05, 8, 0.0)
    assert judged(bat, j, 0.05, 8, 0.0, j + 2, hole=math.inf)
    # (beside the hole its next frame, without it, spans two holes and stays isolated on this
    # fast-turning swing: the glitch is dropped only where that one is not)
    assert hole_glitch(bat, j, 0.05, 8, 0.0) is (lost == -2)
    early_cut = turning_bat(90.0, 24, turned=14, off=0.15)
    early_cut.remove(14 + lost)
    for _ in range(len(early_cut.times) - (j + 2)):
        early_cut.remove(len(early_cut.times) - 1)
    assert hole_glitch(early_cut, j, 0.05, 8, 0.0) is None
    clean = turning_bat(90.0, 24)
    clean.remove(14 + lost)
    assert not any(hole_glitch(clean, i, 0.05, 8, 0.0) for i in range(10, 18)
                   if beside_hole(clean, i))
