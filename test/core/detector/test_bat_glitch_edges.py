"""Tests for baseball_collision.core.detector.bat_glitch_edges: a segment's start, a hole."""

import math
from typing import Any, Tuple

from baseball_collision.core.detector import bat_glitch_edges, DetectorConfig, Impact
from baseball_collision.core.detector.bat_glitch_edges import (
    beside_hole, braked_departure, early, EARLY_AFTER, early_glitch, first_frame_glitch,
    hole_glitch, segment_first)
from baseball_collision.core.detector.bat_glitches import departure, judged
from baseball_collision.core.detector.streams import reversed_excerpt, Stream
from baseball_collision.core.motion import BatSample
from baseball_collision.tools.parameters import OFFLINE_PARAMETERS
from baseball_collision.tools.sim import make_scenario, sample
import numpy as np
import pytest
from support.events import detect_late_drops
from support.scenes import turning_bat

NODE = DetectorConfig()
OFFLINE = DetectorConfig(**OFFLINE_PARAMETERS)


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


def _segment_scene(kind: str, seed: int, family: str, rate: float, noise_m: float, offset: int,
                   segment: int, turn: float = 0.0) -> Tuple[Any, int, int]:
    """
    Return a scene drawn as ``bench_glitches`` draws it, the bat re-acquired before a frame.

    Bat frame j is ``offset`` from the closest approach's (or the contact's); with ``turn``
    (m) it is turned that far toward the ball. The bat frames over 60 ms before frame
    j - ``segment`` + 1 are deleted (``bench_glitches.py --segment``: j its segment's
    ``segment``-th frame). Returns the samples, j's stamp (ns) and the segment's first's.
    """
    rng = np.random.default_rng(seed)
    scenario = make_scenario(kind, rng, family=family)
    samples = sample(scenario, rate, rng, noise_m=noise_m)
    closest = samples.start_ns + int(scenario.truth.min_gap_time_s * 1e9)
    j = int(np.argmin(np.abs(samples.bat_stamps_ns - closest))) + offset
    if turn:
        samples = samples.with_bat_frame_turned(j, samples.ball_positions[j], turn)
    stamps = samples.bat_stamps_ns
    lost = int(math.ceil(0.06 * (len(stamps) - 1) / ((stamps[-1] - stamps[0]) * 1e-9)))
    first = int(stamps[j - segment + 1])
    return samples.without_bat_frames(first, lost), int(stamps[j]), first


def test_a_braked_first_frame_far_off_the_frames_after_it_unsmoothed_stays() -> None:
    """
    A braking barrel at 120 Hz with 1 mm, the bat re-acquired at the contact's frame.

    The bat's noise estimate is still 0 there: the frames after the contact, continued back
    unsmoothed, miss the first frame by more than the floor on the braked bat too (9.9 cm),
    as far as a glitch turned 10 cm is (``bench_glitches.py --rates 120 --noises 1 --segment
    1``: 8 cm); the frame after it departed 4.3 cm, so it is not ``ISOLATION_RATIO`` times the
    frames after it, and no glitch. It stays and the hit is found, under the node's and
    ``analyze``'s settings. (A rule for a segment's first frame that reads a noise figure from
    the frames after it must keep it: smoothed at theirs, 0.9 mm, it lies 1.6 cm off.)
    """
    samples, stamp, _ = _segment_scene('barrel', 1, 'braking', 120.0, 1e-3, 0, 1)
    for config in (NODE, OFFLINE):
        config = DetectorConfig(**{**config.__dict__, 'bat_input': 'points'})
        events, late = detect_late_drops(config, samples)
        assert late == [] and sum(isinstance(event, Impact) for event in events) == 1
    first = int(np.flatnonzero(samples.bat_stamps_ns == stamp)[0])
    bat = Stream('bat')
    for i in range(first, first + EARLY_AFTER + 1):
        bat.append(samples.bat_stamps_ns[i] * 1e-9, int(samples.bat_stamps_ns[i]),
                   BatSample(tuple(samples.knobs[i]), tuple(samples.tips[i])), i == first)
    backwards = reversed_excerpt(bat, 0, EARLY_AFTER)
    assert braked_departure(backwards, EARLY_AFTER, 0.06, 8, 0.0) > 0.05
    assert departure(backwards, EARLY_AFTER - 1, 0.06, 8, 0.0) > 0.04
    assert first_frame_glitch(bat, 0, 0.06, 8, 0.0) is False


@pytest.mark.parametrize('noise_m', [0.0, 1e-3])
def test_a_glitch_second_in_its_segment_before_a_hit_is_dropped_not_the_first(
        noise_m: float) -> None:
    """
    A rebound barrel at 90 Hz, the frame before the contact's turned 10 cm, its segment's 2nd.

    The bat rebounds at the contact: the frames after it, continued back, miss the segment's
    (genuine) first frame by 37 cm, and the glitch, its next, by 5.8-8.5 cm, over the floor,
    so the first is no glitch and the glitch is dropped (``early_glitch``); the hit is found
    where it is with the glitch deleted. Smoothed at the noise the frames after the first
    show (a trial in session 59: 0.9-2.2 mm there, the rebound's own motion), the glitch came
    within the floor, the genuine first frame was dropped in its place and the hit moved 0.4
    ms (``bench_glitches.py --rates 90 --seeds 1 --segment 2``): a rule must keep this.
    """
    samples, stamp, first = _segment_scene('barrel', 0, 'rebound', 90.0, noise_m, -1, 2, 0.1)
    config = DetectorConfig(**{**NODE.__dict__, 'bat_input': 'pose'})
    events, late = detect_late_drops(config, samples)
    assert [drop.stamp_ns for drop in late] == [stamp]
    assert sum(isinstance(event, Impact) for event in events) == 1
    assert first < stamp
