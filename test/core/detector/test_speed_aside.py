"""Tests for the ball samples the speed check set aside: judged again, or dropped late."""

import itertools
from typing import Any, List

from baseball_collision.core.detector import Detector, DetectorConfig, Impact
from baseball_collision.core.detector.speed_aside import ASIDE_MAX
import numpy as np
import pytest
from support.events import detect_late_drops, hit_after_gap, on_bat_axis, without_ball_frame


def _impacts(events: List[Any]) -> List[Any]:
    return [event for event in events if isinstance(event, Impact)]


@pytest.mark.parametrize('back', [3, 4])
def test_a_frame_the_speed_check_refused_after_a_glitch_is_judged_again(back: int) -> None:
    """
    A glitch (the first sample after a gap, on the bat's axis) and the good frame after it.

    The good frame is too far from the glitch to be reached at ``max_speed``: the speed check
    refused it, and it stayed dropped once the glitch was forgotten, so the hit a few frames
    on was found from one frame fewer (moved, or lost; good frames after it dropped as
    glitches). Kept aside, it is judged again against the stream without the glitch and
    taken: the impacts and the drops are those of the run without the glitch frame, to the
    bit, but the glitch's own ``ball_glitch`` drop.
    """
    refused = found = 0
    for seed, look_ahead in itertools.product(range(3), (0, 2)):
        lost, k = hit_after_gap(seed, back)
        config = DetectorConfig(tracker_noise=0.0, look_ahead=look_ahead)
        glitched = on_bat_axis(lost, k)
        step = np.linalg.norm(glitched.ball_positions[k + 1] - glitched.ball_positions[k])
        refused += step > config.max_speed * 1e-9 * float(
            glitched.ball_stamps_ns[k + 1] - glitched.ball_stamps_ns[k])
        events, late = detect_late_drops(config, glitched)
        expected, late_without = detect_late_drops(config, without_ball_frame(lost, k))
        assert [(drop.reason, drop.stamp_ns) for drop in late] == \
            [('ball_glitch', lost.ball_stamps_ns[k])] + \
            [(drop.reason, drop.stamp_ns) for drop in late_without]
        assert _impacts(events) == _impacts(expected)
        found += len(_impacts(expected))
    assert refused and found  # (the speed check refused the frame after the glitch)


def test_a_frame_set_aside_is_dropped_once_the_walk_passes_it() -> None:
    """
    Samples refused against a newest sample that is no glitch are dropped, counted late.

    A ball that moves 2 m in one 360 Hz frame, near nothing: its first two frames there are
    refused against the frame before (the third in a row is taken: it really moved), each
    waits aside (no drop counted yet: the frame they were refused against may be a glitch
    still to be judged) and is counted as ``speed_limit`` once the walk passed it; at the
    recording's end, whatever still waits.
    """
    base, step = 1_700_000_000_000_000_000, 2_777_778
    for last in (40, 21):
        detector = Detector(DetectorConfig(tracker_noise=0.0))
        late = []
        for i in range(last):
            stamp = base + i * step
            detector.add_bat_pose(stamp, (5.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
            detector.add_ball(stamp + 1, (0.01 * i + (2.0 if i >= 20 else 0.0), 0.0, 1.0))
            late += detector.stats.late_drops
            if i == 20:
                assert detector.stats.last_drop_reason is None and not detector.stats.dropped
        detector.finish()
        late += detector.stats.late_drops
        assert [(drop.reason, drop.stamp_ns) for drop in late] == \
            [('speed_limit', base + i * step + 1) for i in range(20, min(last, 22))]
        assert detector.stats.dropped == {'speed_limit': min(last, 22) - 20}
    assert ASIDE_MAX >= 2
