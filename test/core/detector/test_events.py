"""Tests for the detector's events: the enums are plain strings wherever they go."""

from collections import Counter
import csv
import io
import json

from baseball_collision.core.detector import (
    DROP_REASONS, DropReason, ResetReason, Role, StateReset)


def test_drop_reasons_keep_their_tuple_of_values() -> None:
    """DROP_REASONS lists every DropReason's value, as plain strings, in order."""
    assert DROP_REASONS == (
        'wrong_frame', 'non_finite', 'bad_stamp', 'duplicate_stamp', 'out_of_order',
        'bad_quaternion', 'zero_length_bat', 'bat_length_jump', 'speed_limit',
        'unexpected_input', 'stale_stamp', 'stamp_ahead', 'bad_frame', 'lost_body',
        'ball_glitch', 'bat_glitch', 'no_common_frame')
    assert all(type(reason) is str for reason in DROP_REASONS)
    assert tuple(DropReason) == DROP_REASONS


def test_members_count_print_and_serialise_as_their_values() -> None:
    """Counters, f-strings, JSON and CSV see the value; plain strings find the members."""
    counter = Counter([DropReason.SPEED_LIMIT, DropReason.SPEED_LIMIT, Role.BALL])
    assert counter['speed_limit'] == 2 and counter == {'speed_limit': 2, 'ball': 1}
    assert f'{Role.BAT_POSE} {ResetReason.REQUESTED}' == 'bat_pose requested'
    event = StateReset(stamp_ns=5, reason=ResetReason.TIME_JUMP_FORWARD)
    assert json.dumps(event.__dict__) == '{"stamp_ns": 5, "reason": "time_jump_forward"}'
    out = io.StringIO()
    csv.writer(out).writerow([DropReason.NON_FINITE, Role.TIP])
    assert out.getvalue() == 'non_finite,tip\r\n'
    assert [str(role) for role in Role] == ['ball', 'bat_pose', 'knob', 'tip']
