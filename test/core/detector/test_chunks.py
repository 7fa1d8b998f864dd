"""
Tests for baseball_collision.core.detector.chunks: ``Detector.add_chunk`` is ``add`` in turn.

Sessions of pitches (hits, misses, grazes) tracked at 360 Hz, with faults injected (non-finite
values, duplicate and out-of-order stamps, stamps glitched ahead, stray frames, lost bodies,
gaps, a jump back, a message sent twice: as it was, with other values, in another frame or
with a bad quaternion), are fed once sample by sample and once in random chunk sizes: the events,
the drops (by role and reason) and the counters must be identical, and so must the streams
(their turns too) and the predictor's state with prediction on.
"""

from collections import Counter
from dataclasses import replace
import math
from typing import Any, Callable, List, Optional, Sequence, Tuple

from baseball_collision.core.detector import (
    Detector, DetectorConfig, Impact, NearMiss, Prediction, PredictionCleared)
from baseball_collision.core.detector.bat_judgment import BEFORE, NEWEST
from baseball_collision.core.detector.broadphase import apart_margins, clearly_apart
import baseball_collision.core.detector.chunks as chunks_module
from baseball_collision.core.detector.events import DropReason
from baseball_collision.core.detector.noise import ESTIMATES, HISTORY, POSE_SPAN
from baseball_collision.core.detector.plan_far import _closed
import baseball_collision.core.detector.plans as plans_module
from baseball_collision.core.detector.predictor import Predictor
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.detector.sweep import Sweep
from baseball_collision.core.motion import BatSample
from baseball_collision.errors import CoreError
from baseball_collision.tools.sim import make_scenario, sample
from hypothesis import example, given, HealthCheck, settings, strategies as st
import numpy as np
import pytest
from support import examples
from support.events import (
    arrays, ball_lost_before, glitched_pitch, lost_glitched_pitch, on_bat_axis, Row)
from support.far import tilting_bat
from support.scenes import BASE_NS, pitch, pose, swing

STATS = ('received', 'dropped', 'impacts', 'near_misses', 'gaps', 'resets', 'intervals',
         'substeps', 'newest_stamp_ns', 'last_drop_reason')
FAULTS = ('nan', 'duplicate', 'behind', 'ahead', 'frame', 'lost', 'gap', 'jump_back', 'bad_q',
          'twice', 'twice_moved', 'twice_frame', 'twice_bad_q')


def session(heights: Sequence[float], rate: float = 360.0, bat_as: str = 'pose',
            spacing: float = 0.5) -> List[Row]:
    """
    Return pitches ``spacing`` s apart, each with a swing over its first 0.2 s, in stamp order.

    Tracked throughout: after 0.5 s the ball rests where it flew (17 m past the bat) and the
    bat where its swing ended, until the next pitch.
    """
    rows: List[Row] = []
    per = int(spacing * rate)
    for p, height in enumerate(heights):
        ball = pitch(height)
        for i in range(per):
            t = i / rate
            stamp = BASE_NS + int(round((p * spacing + t) * 1e9)) + (i % 3) * 100_000
            rows.append(('ball', stamp, tuple(float(x) for x in ball(min(t, 0.5))), 'world'))
            swing_t = min(t, 0.2)
            if bat_as == 'pose':
                position, quaternion = pose(swing_t)
                rows.append(('bat_pose', stamp + 50_000, tuple(float(x) for x in position)
                             + tuple(float(x) for x in quaternion), 'world'))
            else:
                knob, tip = swing(swing_t)
                rows.append(('knob', stamp + 50_000, tuple(float(x) for x in knob), 'world'))
                rows.append(('tip', stamp + 60_000, tuple(float(x) for x in tip), 'world'))
    return rows


def inject(rows: List[Row], faults: Sequence[Tuple[int, str]]) -> List[Row]:
    """Return the rows with faults applied at the given indices (modulo the length)."""
    rows = list(rows)
    for index, kind in faults:
        i = index % len(rows)
        role, stamp, values, frame = rows[i]
        if kind == 'nan':
            rows[i] = (role, stamp, (math.nan,) + values[1:], frame)
        elif kind == 'duplicate' and i > 0:
            rows[i] = (role, rows[i - 1][1], values, frame)
        elif kind == 'behind':
            rows[i] = (role, stamp - 20_000_000, values, frame)
        elif kind == 'ahead':
            rows[i] = (role, stamp + 300_000_000, values, frame)
        elif kind == 'frame':
            rows[i] = (role, stamp, values, 'elsewhere')
        elif kind == 'lost' and role == 'bat_pose':
            rows[i] = (role, stamp, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0), frame)
        elif kind == 'bad_q' and role == 'bat_pose':
            rows[i] = (role, stamp, values[:3] + tuple(2.0 * q for q in values[3:]), frame)
        elif kind == 'gap':
            del rows[i:i + 60]
        elif kind == 'jump_back':
            rows[i:] = [(r, s - 2_000_000_000, v, f) for r, s, v, f in rows[i:]]
        elif kind.startswith('twice'):  # the message again, right after it (a relay)
            if kind == 'twice_moved':
                values = (values[0] + 0.01,) + values[1:]
            elif kind == 'twice_frame':
                frame = 'elsewhere'
            elif kind == 'twice_bad_q' and role == 'bat_pose':
                values = values[:3] + tuple(2.0 * q for q in values[3:])
            rows.insert(i + 1, (role, stamp, values, frame))
    return rows


Prepare = Optional[Callable[[Detector], None]]
"""Called on each new detector before it is fed (a bat plan set), or None."""


def one_at_a_time(config: DetectorConfig, rows: Sequence[Row],
                  prepare: Prepare = None) -> Tuple[list, Counter, Detector]:
    """Feed rows through ``add``; return (events, drops by (role, reason), detector)."""
    detector, events, drops = Detector(config), [], Counter()
    if prepare is not None:
        prepare(detector)
    for role, stamp, values, frame in rows:
        events += detector.add(role, stamp, values, frame)
        if detector.stats.last_drop_reason is not None:
            drops[role, detector.stats.last_drop_reason] += 1
        for late in detector.stats.late_drops:
            drops[late.role, late.reason] += 1
    events += detector.finish()
    for late in detector.stats.late_drops:
        drops[late.role, late.reason] += 1
    return events, drops, detector


def in_chunks(config: DetectorConfig, rows: Sequence[Row], sizes: Sequence[int],
              prepare: Prepare = None) -> Tuple[list, Counter, Detector]:
    """Feed rows through ``add_chunk`` in chunks of the given sizes (cycled)."""
    detector, events, drops = Detector(config), [], Counter()
    if prepare is not None:
        prepare(detector)
    i, k = 0, 0
    while i < len(rows):
        part = rows[i:i + sizes[k % len(sizes)]]
        events += detector.add_chunk(*arrays(part), drops)
        i, k = i + len(part), k + 1
    events += detector.finish()
    for late in detector.stats.late_drops:
        drops[late.role, late.reason] += 1
    return events, drops, detector


def assert_same(config: DetectorConfig, rows: Sequence[Row], sizes: Sequence[int],
                prepare: Prepare = None) -> list:
    """Assert chunks give the events, drops and counters of one sample at a time."""
    expected, expected_drops, one = one_at_a_time(config, rows, prepare)
    events, drops, chunked = in_chunks(config, rows, sizes, prepare)
    assert events == expected
    assert drops == expected_drops
    for name in STATS:
        assert getattr(chunked.stats, name) == getattr(one.stats, name), name
    assert chunked.watermark_ns == one.watermark_ns
    for name in ('_ball', '_bat'):  # the streams trimmed alike
        kept, expected_kept = getattr(chunked, name), getattr(one, name)
        for buffer in ('times', 'stamps', 'values', 'breaks', 'turns', 'noise'):
            assert getattr(kept, buffer) == getattr(expected_kept, buffer), (name, buffer)
    if one._noise is not None:  # tracker_noise auto: the estimators' state alike
        for mine, theirs in zip(chunked._noise, one._noise):
            assert mine.residuals == theirs.residuals and mine.sigma == theirs.sigma
            assert mine.motion_residuals == theirs.motion_residuals
    for name in ('last_ns', 'predicting'):
        assert getattr(chunked._predictor, name) == getattr(one._predictor, name), name
    return events


HEIGHTS = (1.0, 1.3, 0.95, 2.0, 1.1)


@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline', 'c2'])
def test_clean_session_same_events_in_any_chunks(model: str) -> None:
    """A clean session: impacts and near misses found, the same in chunks as one at a time."""
    events = assert_same(DetectorConfig(model=model, bat_input='pose'), session(HEIGHTS),
                         (4096,))
    assert any(isinstance(e, Impact) for e in events)
    assert any(isinstance(e, NearMiss) for e in events)


def test_most_samples_skip_the_per_sample_path(monkeypatch: pytest.MonkeyPatch) -> None:
    """In a clean session most samples are fast-forwarded, and few go through ``add``."""
    taken = [0]
    original = chunks_module.fast_forward

    def counting(plan, pos, end, *args, **kwargs):  # type: ignore[no-untyped-def]
        taken[0] += end - pos
        return original(plan, pos, end, *args, **kwargs)
    monkeypatch.setattr(chunks_module, 'fast_forward', counting)
    rows = session(HEIGHTS)
    assert_same(DetectorConfig(model='spline', bat_input='pose'), rows, (8192,))
    assert taken[0] > 0.5 * len(rows)  # (the rest: each pitch near the bat, the wraps)


def test_points_fall_back_to_sample_by_sample(monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Knob and tip input is not planned: ``add_chunk`` is ``add`` in a loop, the same events.

    The fall-back's check (no sample is fast-forwarded); the planned path on the same pitches
    is the next test's.
    """
    calls = [0]
    original = chunks_module.fast_forward

    def counting(*args, **kwargs):  # type: ignore[no-untyped-def]
        calls[0] += 1
        return original(*args, **kwargs)
    monkeypatch.setattr(chunks_module, 'fast_forward', counting)
    events = assert_same(DetectorConfig(model='rigid', bat_input='points'),
                         session(HEIGHTS[:2], bat_as='points'), (100, 1000))
    assert calls[0] == 0
    assert any(isinstance(e, Impact) for e in events)


def test_points_with_a_bat_point_lost_as_nan_in_the_first_chunk() -> None:
    """
    A tip lost as NaN mid-swing, in the first chunk: the same as one sample at a time.

    ``add`` notes the lost frame against the tip's newest sample (its knob is then not paired
    across it); taken ahead of the chunk's other samples (as a plan's would be) it came before
    the tip had any, and the knob was paired on the chord, a bat sample ``add`` does not make.
    """
    rows = session(HEIGHTS[:1], rate=90.0, bat_as='points')
    tips = [i for i, row in enumerate(rows) if row[0] == 'tip']
    role, stamp, values, frame = rows[tips[8]]
    rows[tips[8]] = (role, stamp, (math.nan,) * 3, frame)
    assert_same(DetectorConfig(model='c2', bat_input='points'), rows, (len(rows),))
    _, drops, _ = one_at_a_time(DetectorConfig(model='c2', bat_input='points'), rows)
    assert drops == Counter({('tip', 'non_finite'): 1})


@settings(max_examples=examples(10), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(rate=st.sampled_from([90.0, 360.0]),
       sizes=st.lists(st.integers(1, 700), min_size=1, max_size=4),
       faults=st.lists(st.tuples(st.integers(0, 10_000), st.sampled_from(FAULTS)),
                       max_size=5))
def test_points_random_chunks_and_faults_same_as_one_at_a_time(
        rate: float, sizes: List[int], faults: List[Tuple[int, str]]) -> None:
    """The bat as knob and tip, any chunk sizes and faults: as one sample at a time."""
    rows = inject(session(HEIGHTS[:2], rate=rate, bat_as='points'), faults)
    assert_same(DetectorConfig(model='c2', bat_input='points'), rows, sizes)


def test_the_same_pitches_with_a_pose_bat_take_the_array_path(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The same two pitches and chunk sizes, the bat as poses: most samples taken on arrays."""
    taken = count_taken(monkeypatch)
    rows = session(HEIGHTS[:2])
    events = assert_same(DetectorConfig(model='rigid', bat_input='pose'), rows, (100, 1000))
    assert taken[0] > 0.5 * len(rows)
    assert any(isinstance(e, Impact) for e in events)


def predicting(model: str, period: float) -> DetectorConfig:
    """Return a pose-input configuration that predicts 0.3 s ahead every ``period`` s."""
    return DetectorConfig(model=model, bat_input='pose', prediction_horizon=0.3,
                          prediction_period=period)


def count_taken(monkeypatch: pytest.MonkeyPatch) -> List[int]:
    """Count the samples ``fast_forward`` takes in runs (walked) from now on: [count]."""
    taken = [0]
    original = chunks_module.fast_forward

    def counting(plan, pos, end, *args, **kwargs):  # type: ignore[no-untyped-def]
        if kwargs.get('walk', True):
            taken[0] += end - pos
        return original(plan, pos, end, *args, **kwargs)
    monkeypatch.setattr(chunks_module, 'fast_forward', counting)
    return taken


def planned_swing(detector: Detector) -> None:
    """Give the detector the first pitch's swing as a commanded bat plan (every 5 ms)."""
    times = np.arange(0.0, 0.25, 0.005)
    poses = [pose(min(t, 0.2)) for t in times]
    detector.set_bat_plan([BASE_NS + 50_000 + int(round(t * 1e9)) for t in times],
                          [p.tolist() for p, _ in poses], [q.tolist() for _, q in poses])


@pytest.mark.parametrize('period', [0.0, 0.004, 0.01])
@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline', 'c2'])
def test_prediction_planned_same_as_one_at_a_time(model: str, period: float,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """
    With prediction on, chunks are planned: predictions and clears as one sample at a time.

    Pitches 2 s apart, tracked throughout: the due frames while a pitch flies forecast (the
    ball may reach the bat), the ones while ball and bat rest are taken in runs, which move
    the predictor's last frame as it would. In chunks a due frame where ``_may_reach`` holds
    is a stop only when its forecasts may meet (the plan's ``forecast_outcomes``) or the frame
    before's may have: fewer stops, every prediction among them.
    """
    reaching: List[int] = []
    may_reach = Predictor._may_reach

    def recording(self: Predictor) -> bool:
        result = may_reach(self)
        if result:
            reaching.append(self.last_ns)  # (the frame predicting: ``predict`` just set it)
        return result
    monkeypatch.setattr(Predictor, '_may_reach', recording)
    rows = session((1.0, 2.0, 1.3), spacing=2.0)
    one_at_a_time(predicting(model, period), rows)
    expected, reaching[:] = list(reaching), []
    taken = count_taken(monkeypatch)
    events = assert_same(predicting(model, period), rows, (4096, 333))
    assert reaching[:len(expected)] == expected  # (assert_same runs both ways)
    chunked = reaching[len(expected):]
    assert set(chunked) < set(expected)
    made = {e.made_at_ns for e in events if isinstance(e, Prediction)}
    assert made and made <= set(chunked)
    assert any(isinstance(e, Impact) for e in events)
    assert any(isinstance(e, PredictionCleared) for e in events)
    assert taken[0] > 0.5 * len(rows)


@pytest.mark.parametrize('period', [0.0, 0.01])
def test_prediction_with_a_bat_plan_same_as_one_at_a_time(period: float) -> None:
    """A commanded bat plan may reach anywhere: every due frame stops, the same events."""
    events = assert_same(predicting('spline', period), session((1.0, 1.2), spacing=1.0),
                         (700, 5000), planned_swing)
    assert any(isinstance(e, Prediction) and e.planned for e in events)


def _count_through(monkeypatch: pytest.MonkeyPatch) -> List[int]:
    """
    Count the held pairs ``plans._through`` sends through ``add`` from now on, per call.

    Only those whose taker was no stop yet (a pair sent for a due frame alone).
    """
    through: List[int] = []
    send = plans_module._through

    def counting(plan, ok, stops, pairs) -> None:  # type: ignore[no-untyped-def]
        through.append(sum(not stops[y] for _, y in pairs))
        send(plan, ok, stops, pairs)
    monkeypatch.setattr(plans_module, '_through', counting)
    return through


@pytest.mark.parametrize('period', [0.0, 0.01])
@pytest.mark.parametrize('model', ['rigid', 'spline'])
def test_prediction_across_pauses_same_as_one_at_a_time(model: str, period: float,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Tracking pauses 0.1 s after each pitch: across them, predictions as one at a time.

    A pause moves the cursor past the fits' history at once: the bat's turns are trimmed
    past the last one summed, and the next forecast sums from a new zero reference. Each
    stream's first sample after it is held until its next, which takes both in two steps,
    each a frame where it moves the cursor: a pair whose held sample's step is a due frame
    goes through ``add``, which predicts after each (``rigid``'s bat takers stop anyway, their
    interval across the pause near). The ball's pairs go through it anyway (a ball sample
    after a gap over ``max_gap`` stops: ``Sweep.note_gap``), so no pair is sent for its due
    frame alone here (``spline``'s, a frame behind, with every frame due at period 0, were).
    """
    through = _count_through(monkeypatch)
    rows = [row for row in session((1.0, 1.3, 0.95, 1.1), spacing=0.6)
            if (row[1] - BASE_NS) % 600_000_000 < 500_000_000]
    events = assert_same(predicting(model, period), rows, (8192,))
    assert any(isinstance(e, Prediction) for e in events)
    assert sum(through) == 0


@pytest.mark.parametrize('restarts', [True, False])
def test_prediction_across_ball_pauses_sends_a_due_pair_through_add(
        restarts: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    The ball's held pairs across pauses at a due frame: through ``add``, as one at a time.

    ``spline`` predicting at every frame (period 0), both streams paused 0.1 s after each
    pitch (as ``test_prediction_across_pauses_same_as_one_at_a_time``). A ball sample after a
    gap over ``max_gap`` goes through ``add`` (``plans._ball_restarts``), its held pair with
    it, before the rule that sends a pair whose held sample's step is a due frame through it
    (``plans._prediction_stops``: ``_through``) looks, so that rule is sent no pair here.
    Without that stop (were it ever narrowed) the ball's pairs reach the rule, and it sends
    them through ``add`` for their due frame alone: the chunks are one at a time's either way.
    """
    through = _count_through(monkeypatch)
    if not restarts:
        monkeypatch.setattr(plans_module, '_ball_restarts',
                            lambda config, arrays, is_ball: np.flatnonzero(is_ball)[:0])
    rows = [row for row in session((1.0, 1.3, 0.95, 1.1), spacing=0.6)
            if (row[1] - BASE_NS) % 600_000_000 < 500_000_000]
    events = assert_same(predicting('spline', 0.0), rows, (8192,))
    assert any(isinstance(e, Prediction) for e in events)
    assert (sum(through) == 0) == restarts


@settings(max_examples=examples(8), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(model=st.sampled_from(['linear', 'rigid', 'spline', 'c2']),
       period=st.sampled_from([0.0, 0.003, 0.01, 0.05]),
       plan=st.booleans(),
       sizes=st.lists(st.integers(1, 9000), min_size=1, max_size=4),
       faults=st.lists(st.tuples(st.integers(0, 10_000), st.sampled_from(FAULTS)),
                       max_size=5))
def test_prediction_long_sessions_any_chunks_and_faults(model: str, period: float, plan: bool,
                                                        sizes: List[int],
                                                        faults: List[Tuple[int, str]]) -> None:
    """Prediction on, long sessions, any chunks and faults: the same as one at a time."""
    rows = inject(session((1.0, 1.2), spacing=4.0), faults)
    assert_same(predicting(model, period), rows, sizes, planned_swing if plan else None)


@settings(max_examples=examples(25), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(model=st.sampled_from(['linear', 'rigid', 'spline', 'c2']),
       heights=st.lists(st.floats(0.9, 1.4), min_size=1, max_size=3),
       sizes=st.lists(st.integers(1, 700), min_size=1, max_size=6),
       faults=st.lists(st.tuples(st.integers(0, 10_000), st.sampled_from(FAULTS)),
                       max_size=6))
def test_random_chunks_and_faults_same_as_one_at_a_time(model: str, heights: List[float],
                                                        sizes: List[int],
                                                        faults: List[Tuple[int, str]]) -> None:
    """Any chunk sizes, any faults: events, drops and counters as one sample at a time."""
    rows = inject(session(heights), faults)
    assert_same(DetectorConfig(model=model, bat_input='pose'), rows, sizes)


@settings(max_examples=examples(5), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(model=st.sampled_from(['linear', 'rigid', 'spline', 'c2']),
       sizes=st.lists(st.integers(600, 9000), min_size=1, max_size=3),
       faults=st.lists(st.tuples(st.integers(0, 10_000), st.sampled_from(FAULTS)),
                       max_size=4))
def test_long_far_runs_same_as_one_at_a_time(model: str, sizes: List[int],
                                             faults: List[Tuple[int, str]]) -> None:
    """
    Tracked between pitches 4 s apart, in long chunks: as one sample at a time.

    Plans grow past ``PLAN_MAX`` there, and a fast-forward run trims most of the samples it
    takes as it appends them (those are never made into the streams' lists).
    """
    rows = inject(session((1.0, 1.2), spacing=4.0), faults)
    assert_same(DetectorConfig(model=model, bat_input='pose'), rows, sizes)


def test_far_runs_are_planned_long(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each plan taken whole doubles the next, across chunks: far from the bat, thousands long."""
    lengths = _plans_made(monkeypatch, session((1.0, 1.2, 1.1), spacing=12.0),
                          DetectorConfig(model='spline', bat_input='pose'), 50_000)
    assert max(lengths) >= 8 * chunks_module.PLAN_MAX
    assert len(lengths) < 3 * 2 * 12.0 * 360 / chunks_module.PLAN_MAX / 2  # half as many
    # in chunks shorter than that, the length carries over: about one plan a chunk
    lengths.clear()
    rows = session((1.0, 1.2, 1.1), spacing=12.0)
    assert_same(DetectorConfig(model='spline', bat_input='pose'), rows, (3000,))
    assert len(lengths) < 3 * len(rows) / 3000  # (37 when each chunk starts at PLAN_MAX)


@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline', 'c2'])
def test_plans_run_across_pauses_between_pitches(model: str,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Tracking pauses 0.1 s after each pitch: one plan runs across them, the same events.

    Each stream's first sample after a pause waits for its next (``gate.hold_ahead``); the
    plan follows that instead of ending there.
    """
    planned = []
    original = chunks_module.plan_chunk

    def counting(*args, **kwargs):  # type: ignore[no-untyped-def]
        planned.append(original(*args, **kwargs))
        return planned[-1]
    monkeypatch.setattr(chunks_module, 'plan_chunk', counting)
    heights = (1.0, 1.3, 0.95, 1.1, 1.2, 1.05)
    rows = [row for row in session(heights, spacing=0.6)
            if (row[1] - BASE_NS) % 600_000_000 < 500_000_000]
    events = assert_same(DetectorConfig(model=model, bat_input='pose'), rows, (8192,))
    assert any(isinstance(e, Impact) for e in events)
    assert len(planned) < len(heights)


@pytest.mark.parametrize('bat_first', [False, True])
def test_streams_in_two_frames_are_dropped_alike_in_chunks(bat_first: bool) -> None:
    """
    A bat in 'arm_base' beside a ball in 'world' for a pitch, then both in 'world': as ``add``.

    No frame is adopted while the frames differ (``no_common_frame`` drops), then the agreed
    one (the waiting samples dropped, or taken after a reset when the bat's frame was the
    provisional one); the later pitches are found alike.
    """
    rows = session(HEIGHTS[:3])
    rows = [(role, stamp, values, 'arm_base' if role == 'bat_pose' and k < len(rows) // 3
             else frame) for k, (role, stamp, values, frame) in enumerate(rows)]
    if bat_first:
        rows[0], rows[1] = rows[1], rows[0]
    for config in (DetectorConfig(model='c2', bat_input='pose'),
                   DetectorConfig(model='linear', bat_input='pose', prediction_horizon=0.3)):
        events = assert_same(config, rows, (1, 7, 64, 500))
        _, drops, detector = one_at_a_time(config, rows)
        assert drops[('ball' if bat_first else 'bat_pose'), 'no_common_frame'] > 100
        assert detector.frame_id == 'world' and any(isinstance(e, Impact) for e in events)


@pytest.mark.parametrize('frames', ['none', 'ball_none', 'ball_none_stray', 'bat_none_stray'])
def test_empty_frames_before_agreement_alike_in_chunks(frames: str) -> None:
    """
    Streams that send empty frames (taken as in any frame), with a stray first frame: as ``add``.

    Before a frame is agreed an empty frame's role is noted by the vote (it holds no adoption
    up); a plan takes such samples only once ``add`` has noted their role.
    """
    rows = session(HEIGHTS[:3])
    empty = {'none': ('ball', 'bat_pose'), 'ball_none': ('ball',), 'ball_none_stray': ('ball',),
             'bat_none_stray': ('bat_pose',)}[frames]
    rows = [(role, stamp, values, '' if role in empty else frame)
            for role, stamp, values, frame in rows]
    if frames.endswith('stray'):  # the empty stream's first sample in a stray frame
        k = next(k for k, row in enumerate(rows) if row[0] == empty[0])
        rows[k] = rows[k][:3] + ('camera',)
    for config in (DetectorConfig(model='c2', bat_input='pose'),
                   DetectorConfig(model='rigid', bat_input='pose', prediction_horizon=0.3)):
        events = assert_same(config, rows, (1, 7, 64, 500))
        _, drops, detector = one_at_a_time(config, rows)
        assert any(isinstance(e, Impact) for e in events)
        assert not [key for key in drops if key[1] == 'no_common_frame']
        assert detector.frame_disagreement is None


@pytest.mark.parametrize('untracked', ['ball', 'bat_pose'])
def test_chunks_without_a_sample_of_one_stream(untracked: str) -> None:
    """
    One body tracked throughout, the other only 0.3 s of each 0.6 s pitch: the same events.

    (A robot arm's bat pose at 1 kHz beside a ball seen only in flight: many of its chunks
    hold no ball sample once the ball's stream has started. Such a chunk ended the plan with
    an IndexError before.)
    """
    rows = [row for row in session((1.0, 1.3, 0.95, 1.1), spacing=0.6)
            if row[0] != untracked or (row[1] - BASE_NS) % 600_000_000 < 300_000_000]
    sizes = (50, 97, 400)
    for size in sizes:
        parts = [rows[i:i + size] for i in range(0, len(rows), size)]
        assert any(all(row[0] != untracked for row in part) for part in parts[1:])
    for config in (DetectorConfig(model='rigid', bat_input='pose'),
                   DetectorConfig(model='c2', bat_input='pose', look_ahead=2,
                                  tracker_noise=-1.0, prediction_horizon=0.3)):
        events = assert_same(config, rows, sizes)
        assert sum(isinstance(e, Impact) for e in events) == 2  # (two of the four hit)


def test_a_ball_glitch_is_judged_alike_in_chunks() -> None:
    """
    Misses with one ball sample each reported on the bat's axis: the same drops and events.

    The glitch is judged by the sweep (a late ``ball_glitch`` drop) where the ball is near the
    bat, which in a chunk is a stop the plan gives to ``add``.
    """
    clean = session((1.1, 1.12, 1.15), spacing=0.6)  # misses 3-8 cm over the bat
    rows = list(clean)
    for p in range(3):
        near = [(_to_axis(np.array(row[2]), (row[1] - BASE_NS) * 1e-9 - 0.6 * p), i)
                for i, row in enumerate(rows) if row[0] == 'ball'
                and 0.0 <= (row[1] - BASE_NS) * 1e-9 - 0.6 * p <= 0.2]
        i = min(near)[1]
        t = (rows[i][1] - BASE_NS) * 1e-9 - 0.6 * p
        on_axis = np.array(rows[i][2]) - _to_axis(np.array(rows[i][2]), t, vector=True)
        rows[i] = ('ball', rows[i][1], tuple(float(x) for x in on_axis), 'world')
    for config in (DetectorConfig(model='rigid', bat_input='pose'),
                   DetectorConfig(model='c2', bat_input='pose', look_ahead=2,
                                  tracker_noise=-1.0)):
        events, drops, _ = in_chunks(config, rows, (7, 50, 400))
        expected, before, _ = one_at_a_time(config, clean)  # (the pitches' own restarts)
        assert drops == before + Counter({('ball', 'ball_glitch'): 3})
        assert not any(isinstance(e, Impact) for e in events + expected)
        assert [e for e in events if isinstance(e, NearMiss)] != []
        assert_same(config, rows, (7, 50, 400))


@pytest.mark.parametrize('rate', [90.0, 360.0])
def test_a_glitch_after_a_gap_is_judged_alike_in_chunks(rate: float) -> None:
    """
    A miss tracked again near the bat after a gap, its 1st or 2nd sample on the bat's axis.

    The interval that reaches it waits for the samples after it (the walk stops before it,
    ``Sweep.interval``; the 1st's for the bat's over its interval too): in a chunk that stop
    overturns the plan, and the rest is planned again from the cursor the per-sample path
    left. With prediction on too.
    """
    rng = np.random.default_rng(3)
    scenario = make_scenario('miss_under', rng, lead_s=0.4, trail_s=0.1)
    samples = sample(scenario, rate, rng)
    closest = int(np.searchsorted(samples.ball_stamps_ns, samples.start_ns + int(
        round(scenario.truth.min_gap_time_s * 1e9))))
    for first in (closest - 3, closest - 2):
        lost = ball_lost_before(samples, first)
        glitched = on_bat_axis(lost, int(np.searchsorted(lost.ball_stamps_ns,
                                                         samples.ball_stamps_ns[closest - 2])))
        rows = [(role, stamp, values, 'world') for stamp, role, values in glitched.messages()]
        for config in (DetectorConfig(bat_input='pose', prediction_horizon=0.3),
                       DetectorConfig(bat_input='pose', look_ahead=2)):
            events = assert_same(config, rows, (7, 50, 400))
            assert not any(isinstance(e, Impact) for e in events)
            assert one_at_a_time(config, rows)[1][('ball', 'ball_glitch')] == 1
            if first < closest - 2:  # (the 1st sample at the closest approach: no near miss)
                assert any(isinstance(e, NearMiss) for e in events)


def _to_axis(point: np.ndarray, t: float, vector: bool = False) -> Any:
    """Return a point's distance (m) from the swing's bat axis at t, or its offset from it."""
    knob, tip = swing(t)
    axis = tip - knob
    along = min(max(float(np.dot(point - knob, axis) / np.dot(axis, axis)), 0.0), 1.0)
    offset = point - (knob + along * axis)
    return offset if vector else float(np.linalg.norm(offset))


def _paused(heights: Sequence[float]) -> List[Row]:
    """Return a session tracked only in the first 0.5 s of every 0.6 s (a pause per pitch)."""
    return [row for row in session(heights, spacing=0.6)
            if (row[1] - BASE_NS) % 600_000_000 < 500_000_000]


def _restarts(rows: Sequence[Row]) -> List[int]:
    """Return the indices of each stream's first two samples after a pause (held, taker)."""
    found: List[int] = []
    previous: dict = {}
    pending: set = set()
    for i, (role, stamp, _, _) in enumerate(rows):
        if role in pending:
            found.append(i)
            pending.discard(role)
        elif role in previous and stamp - previous[role] > 50_000_000:
            found.append(i)
            pending.add(role)
        previous[role] = stamp
    return found


@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline', 'c2', 'c2-auto'])
def test_samples_after_a_pause_are_fast_forwarded(model: str,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A stream's held first sample after a pause and the one that takes it skip ``add``.

    The run that takes the second appends both, the first starting a segment (its turn zero,
    its stream's noise taken from it): the same events, drops, counters and streams as one at
    a time. Where the taker walks into an interval the sweep must see (the pause's: a model
    with one sample of look-ahead), both go through ``add``, which walks and trims after each:
    no plan is overturned. ``c2`` with look-ahead 2 takes the bat's as planned (all went
    through ``add`` before); the ball's go through it (a ball sample after a gap over
    ``max_gap`` stops: ``Sweep.note_gap`` keeps the flight before the gap from samples a run's
    trim would drop unmade).
    """
    through, overturned = [], []
    original_one, original_follow = chunks_module._one, chunks_module._follow

    def counting(detector, chunk, k, events, drops):  # type: ignore[no-untyped-def]
        through.append(int(chunk[1][k]))
        return original_one(detector, chunk, k, events, drops)

    def following(detector, plan, *args):  # type: ignore[no-untyped-def]
        taken = original_follow(detector, plan, *args)
        overturned.append(taken < plan.n)
        return taken
    monkeypatch.setattr(chunks_module, '_one', counting)
    monkeypatch.setattr(chunks_module, '_follow', following)
    rows = _paused((1.0, 1.3, 0.95, 1.1))
    restarts = {rows[i][1] for i in _restarts(rows) if rows[i][0] != 'ball'}
    ball_restarts = {rows[i][1] for i in _restarts(rows) if rows[i][0] == 'ball'}
    assert len(restarts) >= 6 and len(ball_restarts) >= 6  # (two samples, three pauses)
    auto = model == 'c2-auto'
    config = DetectorConfig(model='c2' if auto else model, bat_input='pose',
                            look_ahead=2 if auto else 0, tracker_noise=-1.0 if auto else 0.0)
    events = assert_same(config, rows, (8192,))
    assert any(isinstance(e, Impact) for e in events)
    assert not any(overturned)
    if auto:
        assert not restarts & set(through)
        assert ball_restarts <= set(through)


def test_a_plan_overturned_between_a_held_sample_and_its_taker_leaves_it_waiting(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A plan that ends between a held sample and the one that takes it leaves the first waiting.

    Each plan is made to stop at the sample after a held one and to find the state there not
    the planned one (as a misjudged plan would): the held sample then waits in the intake as
    ``add`` left it, and what follows goes one at a time: the same as one at a time.
    """
    forced = []
    original_plan, original_held = chunks_module.plan_chunk, plans_module.Plan.held

    def stopping(*args, **kwargs):  # type: ignore[no-untyped-def]
        plan = original_plan(*args, **kwargs)
        inside = [x + 1 for x, y in plan.holds if y > x + 1]
        plan.stops = sorted(set(plan.stops) | set(inside))
        return plan

    def misjudged(plan, j, ball, bat, cursor):  # type: ignore[no-untyped-def]
        if any(x + 1 == j < y for x, y in plan.holds):
            forced.append(j)
            return False
        return original_held(plan, j, ball, bat, cursor)
    monkeypatch.setattr(chunks_module, 'plan_chunk', stopping)
    monkeypatch.setattr(plans_module.Plan, 'held', misjudged)
    assert_same(DetectorConfig(model='c2', bat_input='pose', look_ahead=2, tracker_noise=-1.0),
                _paused((1.0, 1.3, 0.95)), (8192,))
    assert forced


@settings(max_examples=examples(6), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(look_ahead=st.integers(0, 2), window=st.integers(4, 12),
       heights=st.lists(st.floats(0.9, 1.4), min_size=1, max_size=2),
       sizes=st.lists(st.integers(1, 700), min_size=1, max_size=4),
       faults=st.lists(st.tuples(st.integers(0, 10_000), st.sampled_from(FAULTS)),
                       max_size=4))
def test_c2_chunks_same_at_any_look_ahead_and_window(look_ahead: int, window: int,
                                                     heights: List[float], sizes: List[int],
                                                     faults: List[Tuple[int, str]]) -> None:
    """``c2``'s vectorised far test at any look-ahead and window: as one sample at a time."""
    rows = inject(session(heights), faults)
    assert_same(DetectorConfig(model='c2', bat_input='pose', look_ahead=look_ahead,
                               spline_window=window), rows, sizes)


def noisy(rows: Sequence[Row], sigma: float, seed: int) -> List[Row]:
    """Return rows with Gaussian noise of ``sigma`` (m) on every position (not quaternions)."""
    rng = np.random.default_rng(seed)
    return [(role, stamp, tuple(float(v + e) for v, e in zip(values[:3], rng.normal(
        0.0, sigma, 3))) + tuple(values[3:]), frame) for role, stamp, values, frame in rows]


@settings(max_examples=examples(6), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(sigma=st.sampled_from([0.0, 2e-4, 1e-3]), look_ahead=st.integers(0, 2),
       sizes=st.lists(st.integers(1, 3000), min_size=1, max_size=3),
       faults=st.lists(st.tuples(st.integers(0, 10_000), st.sampled_from(FAULTS)),
                       max_size=3), told=st.sampled_from([-1.0, -1.0, 0.0, 1e-3]))
def test_c2_under_noise_planned_same_as_one_at_a_time(
        sigma: float, look_ahead: int, sizes: List[int],
        faults: List[Tuple[int, str]], told: float) -> None:
    """
    Under noise, auto or told, ``c2`` is planned as taken one at a time.

    Under auto the estimators take a run's samples in bulk, alike; the plan's far test takes
    the hulls less what the estimates may be by each interval (``NoiseEstimate.bounds``), or
    the noise told.
    """
    rows = inject(noisy(session(HEIGHTS[:2]), sigma, 5), faults)
    assert_same(DetectorConfig(model='c2', bat_input='pose', tracker_noise=told,
                               look_ahead=look_ahead), rows, sizes)


def hits(seeds: Sequence[int], rate: float = 360.0, noise_m: float = 0.0) -> List[Row]:
    """Return barrel hits of the ``rebound`` family (the ball leaves the bat), 1 s apart."""
    rows: List[Row] = []
    for i, seed in enumerate(seeds):
        scenario = make_scenario('barrel', np.random.default_rng(seed), family='rebound')
        samples = sample(scenario, rate, np.random.default_rng(seed), jitter_s=2e-4,
                         grid_s=1e-3, noise_m=noise_m, start_ns=BASE_NS + i * 1_000_000_000)
        rows += [(role, stamp, values, 'world') for stamp, role, values in samples.messages()]
    return rows


@pytest.mark.parametrize('model', ['linear', 'rigid', 'spline', 'c2'])
@pytest.mark.parametrize('noise_m', [0.0, 1e-3])
def test_hits_the_ball_rebounds_from_same_in_chunks(model: str, noise_m: float) -> None:
    """
    Hits whose ball leaves the bat: each found, the same in chunks as one at a time.

    The far tests on arrays must leave the free flight's interval to the sweep: both frames
    around a hit are far from the bat.
    """
    config = DetectorConfig(model=model, bat_input='pose')
    events = assert_same(config, hits(range(3), noise_m=noise_m), (7, 300, 2000))
    assert sum(isinstance(e, Impact) for e in events) == 3


@pytest.mark.parametrize('look_ahead', [0, 2])
def test_braked_hits_at_90_hz_same_in_chunks(look_ahead: int) -> None:
    """
    Hits at 90 Hz whose bat is continued from before the interval, or not: alike in chunks.

    The rebound family's first barrel and end-cap hits of ``bench_accuracy.py``'s set, exact,
    1 s apart: the closing frame's miss judged against the continuation's own miss carried over
    (``sweep_impact.braked_miss``) takes the continuation at some and not at others.
    """
    rng = np.random.default_rng(7)
    scenarios = [make_scenario(kind, rng, family='rebound', lead_s=0.15)
                 for kind in ('barrel', 'end_cap') for _ in range(4)]
    rows: List[Row] = []
    for i, scenario in enumerate(scenarios):
        samples = sample(scenario, 90.0, np.random.default_rng(i), jitter_s=2e-4, grid_s=1e-3,
                         start_ns=BASE_NS + i * 1_000_000_000)
        rows += [(role, stamp, values, 'world')
                 for stamp, role, values in samples.messages('points')]
    config = DetectorConfig(model='c2', bat_input='points', tracker_noise=-1.0,
                            look_ahead=look_ahead)
    events = assert_same(config, rows, (7, 300, 2000))
    assert sum(isinstance(e, Impact) for e in events) == len(scenarios)


def test_c2_under_auto_noise_is_planned(monkeypatch: pytest.MonkeyPatch) -> None:
    """A noisy session under auto: chunks are planned, and the estimates are the noise's."""
    planned = []
    original = chunks_module.plan_chunk

    def counting(*args, **kwargs):  # type: ignore[no-untyped-def]
        planned.append(1)
        return original(*args, **kwargs)
    monkeypatch.setattr(chunks_module, 'plan_chunk', counting)
    rows = noisy(session(HEIGHTS[:1]), 1e-3, 9)
    events = assert_same(DetectorConfig(model='c2', bat_input='pose', tracker_noise=-1.0),
                         rows, (500,))
    assert planned and any(isinstance(e, Impact) for e in events)
    _, _, chunked = in_chunks(DetectorConfig(model='c2', bat_input='pose', tracker_noise=-1.0),
                              rows, (500,))
    assert 0.5e-3 < chunked._ball.noise < 2e-3  # (the scene's ball starts and stops)
    assert 0.5e-3 < chunked._bat.noise < 2e-3


def test_a_near_stop_is_appended_with_the_run_before_it(monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A near stop that passes every check is appended by its run's fast-forward, not its own.

    One append, trim and bulk noise estimate where there were two (only a stop right after
    another appends alone); the events, drops, counters and streams stay those of ``add``.
    """
    calls: Counter = Counter()
    original = chunks_module.fast_forward

    def counting(*args, **kwargs):  # type: ignore[no-untyped-def]
        calls['with its run' if kwargs.get('stop') else 'run' if kwargs.get('walk', True)
              else 'alone'] += 1
        return original(*args, **kwargs)
    monkeypatch.setattr(chunks_module, 'fast_forward', counting)
    # both streams on one clock (a mocap system's): near a contact, each ball sample (the
    # watermark does not move) is a run of one before its bat sample's stop
    rows = [(role, stamp - 50_000 if role == 'bat_pose' else stamp, values, frame)
            for role, stamp, values, frame in session(HEIGHTS[:2])]
    events = assert_same(DetectorConfig(model='c2', bat_input='pose', tracker_noise=-1.0),
                         rows, (500,))
    assert any(isinstance(e, Impact) for e in events)
    assert calls['with its run'] > 10 * calls['alone']


def test_bad_chunks_are_refused() -> None:
    """Arrays of different lengths, or an unknown role code, are a CoreError."""
    detector = Detector(DetectorConfig(bat_input='pose'))
    roles, stamps, values, frames = arrays(session((1.0,))[:10])
    with pytest.raises(CoreError):
        detector.add_chunk(roles[:5], stamps, values, frames)
    with pytest.raises(CoreError):
        detector.add_chunk(roles, stamps, values[:, :3], frames)
    with pytest.raises(CoreError):
        detector.add_chunk(roles + 7, stamps, values, frames)
    # types a caller may try: role names, seconds, one frame for all (each was truncated,
    # read char by char or raised deep inside)
    with pytest.raises(CoreError, match='integer role codes'):
        detector.add_chunk(['ball'] * 10, stamps, values, frames)
    with pytest.raises(CoreError, match='integer role codes'):
        detector.add_chunk(roles, stamps * 1e-9, values, frames)
    with pytest.raises(CoreError, match='one frame_id per sample'):
        detector.add_chunk(roles[:5], stamps[:5], values[:5], 'world')
    # values that are not numbers (``add`` refuses one such sample too)
    with pytest.raises(CoreError, match='numbers as values'):
        detector.add_chunk(roles, stamps, [['x'] * 7] * 10, frames)
    # shapes a caller may get wrong: a column of roles or stamps, one stamp for all, frames
    # as a generator (each raised from deep inside numpy or the planner)
    for bad_roles, bad_stamps in ((roles[:, None], stamps), (roles, stamps[:, None]),
                                  (roles, stamps[0]), (1, stamps)):
        with pytest.raises(CoreError, match=r'1-d arrays\), got arrays of shape'):
            detector.add_chunk(bad_roles, bad_stamps, values, frames)
    with pytest.raises(CoreError, match='one frame_id per sample'):
        detector.add_chunk(roles, stamps, values, (frame for frame in frames))
    # unsigned stamps past int64 (they wrapped negative: every sample a bad stamp)
    with pytest.raises(CoreError, match='beyond int64'):
        detector.add_chunk(roles, stamps.astype(np.uint64) + np.uint64(2 ** 63), values, frames)
    assert detector.stats.received == {}  # nothing taken from a refused chunk


def _c2_streams(times: np.ndarray, breaks: Sequence[bool], start: Tuple[float, float, float],
                velocity: float, spin: float, tilt: float, jitter: float, seed: int
                ) -> Tuple[Stream, Stream, np.ndarray, np.ndarray, np.ndarray]:
    """Return a ball and a tilting bat sampled at ``times`` as streams and as arrays."""
    rng = np.random.default_rng(seed)
    ball, bat = Stream('ball'), Stream('bat')
    balls, knobs, tips = [], [], []
    for t, broken in zip(times, breaks):
        point = tuple(float(x) for x in np.array(start) + velocity * t * np.array([1.0, 0.2, 0.0])
                      + rng.normal(0.0, jitter, 3))
        knob, tip = tilting_bat(t, spin, tilt, rng, jitter)
        knob, tip = tuple(knob.tolist()), tuple(tip.tolist())
        ball.append(float(t), int(t * 1e9), point, broken)
        bat.append(float(t), int(t * 1e9), BatSample(knob=knob, tip=tip, position=knob,
                                                     quaternion=(0.0, 0.0, 0.0, 1.0)), broken)
        balls.append(point)
        knobs.append(knob)
        tips.append(tip)
    return ball, bat, np.array(balls), np.array(knobs), np.array(tips)


@settings(max_examples=examples(100), deadline=None)
@given(look_ahead=st.integers(0, 2), size=st.integers(4, 10),
       steps=st.lists(st.floats(0.002, 0.006), min_size=14, max_size=14),
       start=st.tuples(*[st.floats(-2.0, 2.0)] * 3), velocity=st.floats(-40.0, 40.0),
       spin=st.floats(-60.0, 60.0), tilt=st.floats(-3.0, 3.0), jitter=st.floats(0.0, 0.05),
       seed=st.integers(0, 1000))
@example(look_ahead=0, size=10, steps=[0.00390625] * 6 + [0.005859375] * 6 + [0.00390625] * 2,
         start=(0.0, 0.0, 0.0), velocity=0.0, spin=51.0, tilt=0.0, jitter=0.0, seed=0)
def test_vectorised_c2_far_test_is_confirmed_by_the_scalar_one(
        look_ahead: int, size: int, steps: List[float], start: Tuple[float, float, float],
        velocity: float, spin: float, tilt: float, jitter: float, seed: int) -> None:
    """
    ``apart_margins`` for ``c2``: ``clearly_apart`` clears every interval it clears.

    Without look-ahead, where the interval's whole window is in the streams (at least
    ``size`` samples up to its closing frame) the two are the same bound: just above the
    vectorised clearance the scalar test does not clear it either, so the vectorised test is
    not looser than it must be. (With look-ahead it also counts the ``look_ahead`` samples
    before the scalar window's first, which a break after the interval would bring in.)
    """
    times = np.concatenate(([0.0], np.cumsum(steps)))
    ball, bat, balls, knobs, tips = _c2_streams(times, [False] * len(times), start, velocity,
                                                spin, tilt, jitter, seed)
    ks = np.arange(len(times) - 2 - look_ahead)
    none = np.full(len(ks), -1)
    clearance = apart_margins(balls, knobs, tips, None, ks, ks, none, none, none, none, times,
                              times, 'c2', look_ahead, size)
    scale = 1e-9 * (1.0 + np.abs(balls).max() + np.abs(tips).max())
    for k in ks:
        if not np.isfinite(clearance[k]):
            continue
        assert clearly_apart(ball, bat, k, k, clearance[k] - scale, 'c2', 1.0, look_ahead, size)
        if k + 2 >= size and look_ahead == 0:  # (the spheres' bound: the scalar test's hulls,
            # which the vectorised test does not take, left out by unbounded noise)
            assert not clearly_apart(ball, bat, k, k, clearance[k] + scale, 'c2', 1.0,
                                     look_ahead, size, math.inf)


@settings(max_examples=examples(100), deadline=None)
@given(look_ahead=st.integers(0, 2), size=st.integers(4, 10),
       steps=st.lists(st.floats(0.004, 0.006), min_size=20, max_size=20),
       cut=st.integers(1, 18), kind=st.sampled_from(['pause', 'break', 'short gap']),
       start=st.tuples(*[st.floats(-2.0, 2.0)] * 3), velocity=st.floats(-40.0, 40.0),
       spin=st.floats(-60.0, 60.0), tilt=st.floats(-3.0, 3.0), jitter=st.floats(0.0, 0.05),
       seed=st.integers(0, 1000))
def test_vectorised_c2_far_test_across_segments_is_confirmed_by_the_scalar_one(
        look_ahead: int, size: int, steps: List[float], cut: int, kind: str,
        start: Tuple[float, float, float], velocity: float, spin: float, tilt: float,
        jitter: float, seed: int) -> None:
    """
    ``apart_margins`` for ``c2`` with the streams' segments: ``clearly_apart`` confirms it.

    Two segments: after a pause of 0.1 s (more than ``C2_STEP_RATIO`` steps: its windows stop
    there in both tests), a break without a gap, or a gap just over ``max_gap`` but within the
    steps' ratio (the scalar first stage's window crosses it).
    """
    steps = list(steps)
    breaks = [False] * (len(steps) + 1)
    max_gap = 0.05
    if kind == 'pause':
        steps[cut] = 0.1
    elif kind == 'break':
        breaks[cut + 1] = True
    else:
        max_gap, steps[cut] = 0.009, 0.0095
    times = np.concatenate(([0.0], np.cumsum(steps)))
    ball, bat, balls, knobs, tips = _c2_streams(times, breaks, start, velocity, spin, tilt,
                                                jitter, seed)
    closed = _closed(times, np.array(breaks), max_gap)
    ks = np.arange(len(times) - 1)
    none = np.full(len(ks), -1)
    clearance = apart_margins(balls, knobs, tips, None, ks, ks, none, none, none, none, times,
                              times, 'c2', look_ahead, size, closed=(closed, closed))
    scale = 1e-9 * (1.0 + np.abs(balls).max() + np.abs(tips).max())
    for k in ks[closed]:
        if np.isfinite(clearance[k]):
            assert clearly_apart(ball, bat, k, k, clearance[k] - scale, 'c2', max_gap,
                                 look_ahead, size)


def test_vectorised_c2_far_test_clears_a_segment_start_after_a_pause() -> None:
    """
    A pause between pitches ends the ``c2`` windows on arrays as it ends the scalar test's.

    The ball 4 m from the bat, 360 Hz, a 0.1 s pause: with the segments every interval on
    either side is cleared on arrays, as the scalar test clears it; without them the windows
    that reach across the pause give no bound (their steps are uneven).
    """
    steps = [1 / 360] * 40
    steps[20] = 0.1
    times = np.concatenate(([0.0], np.cumsum(steps)))
    breaks = [False] * len(times)
    ball, bat, balls, knobs, tips = _c2_streams(times, breaks, (5.0, 0.0, 1.0), 1.0, 20.0,
                                                1.0, 0.0, 1)
    closed = _closed(times, np.array(breaks), 0.05)
    ks = np.flatnonzero(closed)
    none = np.full(len(ks), -1)
    arguments = (balls, knobs, tips, None, ks, ks, none, none, none, none, times, times, 'c2',
                 2, 8)
    margin = 1.0
    segments = apart_margins(*arguments, closed=(closed, closed))
    assert (segments > margin).all()
    assert all(clearly_apart(ball, bat, k, k, margin, 'c2', 0.05, 2, 8) for k in ks)
    alone = apart_margins(*arguments)  # (the look-ahead's two before, the window's six after)
    across = ((ks >= 18) & (ks <= 19)) | ((ks >= 21) & (ks <= 26))
    assert not (alone[across] > margin).any() and (alone[~across] > margin).all()


@settings(max_examples=examples(200), deadline=None)
@given(model=st.sampled_from(['linear', 'rigid', 'spline']),
       points=st.lists(st.tuples(*[st.floats(-3.0, 3.0)] * 9), min_size=4, max_size=4),
       steps=st.lists(st.floats(0.002, 0.02), min_size=3, max_size=3))
def test_vectorised_far_test_is_the_scalar_one(model: str, points: List[Tuple[float, ...]],
                                               steps: List[float]) -> None:
    """``apart_margins`` over arrays agrees with ``clearly_apart`` on every interval."""
    times = np.concatenate(([0.0], np.cumsum(steps)))
    ball, bat = Stream('ball'), Stream('bat')
    balls, knobs, tips, positions = [], [], [], []
    for t, row in zip(times, points):
        ball.append(float(t), int(t * 1e9), row[0:3], False)
        knob, tip = row[3:6], row[6:9]
        bat.append(float(t), int(t * 1e9), BatSample(knob=knob, tip=tip, position=knob,
                                                     quaternion=(0.0, 0.0, 0.0, 1.0)), False)
        balls.append(row[0:3])
        knobs.append(knob)
        tips.append(tip)
        positions.append(knob)
    ks = np.arange(3)
    before = np.where(ks >= 1, ks - 1, -1)
    after = np.where(ks + 2 < 4, ks + 2, -1)
    clearance = apart_margins(np.array(balls), np.array(knobs), np.array(tips),
                              np.array(positions), ks, ks, before, after, before, after,
                              times, times, model)
    for k in range(3):
        for margin in (clearance[k] - 1e-7, clearance[k] + 1e-7):
            assert clearly_apart(ball, bat, k, k, margin, model, 1.0) == (clearance[k] > margin)


def test_the_kernels_bat_samples_are_the_samples_the_arrays_make() -> None:
    """
    ``_kernel.bat_samples`` gives the rows' ``BatSample`` s, equal field by field, and checks.

    Filled into the frozen dataclass's slots directly (the same instances its constructor
    makes: equal, hashed alike, frozen); a class without those slots is called; arrays of
    other shapes, rows outside them and non-float arrays are refused.
    """
    from baseball_collision.core.toi import _kernel
    rng = np.random.default_rng(5)
    knob, tip, position = rng.normal(size=(3, 9, 3))
    quaternion = rng.normal(size=(9, 4))
    made = _kernel.bat_samples(BatSample, knob, tip, position, quaternion, 2, 7)
    columns = (knob, tip, position, quaternion)
    expected = [BatSample(*(tuple(column[i].tolist()) for column in columns)) for i in range(2, 7)]
    assert made == expected and list(map(hash, made)) == list(map(hash, expected))
    assert all(type(x) is BatSample and type(x.knob) is tuple and type(x.knob[0]) is float
               for x in made)
    with pytest.raises(AttributeError):
        made[0].knob = (0.0, 0.0, 0.0)
    assert _kernel.bat_samples(BatSample, knob, tip, position, quaternion, 4, 4) == []

    class Plain:
        """A class without the slots: called with the four fields."""

        def __init__(self, *fields: Tuple[float, ...]) -> None:
            self.fields = fields

    plain = _kernel.bat_samples(Plain, knob, tip, position, quaternion, 8, 9)[0]
    assert plain.fields == (tuple(knob[8].tolist()), tuple(tip[8].tolist()),
                            tuple(position[8].tolist()), tuple(quaternion[8].tolist()))
    for columns, first, last in (((knob, tip, position, quaternion[:8]), 0, 1),
                                 ((knob, tip, position, knob), 0, 1),
                                 ((knob, tip, position, quaternion), 5, 10),
                                 ((knob, tip, position, quaternion), 3, 2),
                                 ((knob.astype(np.float32), tip, position, quaternion), 0, 1)):
        with pytest.raises(ValueError):
            _kernel.bat_samples(BatSample, *columns, first, last)


def test_the_kernels_fast_forward_refuses_what_is_not_a_plan() -> None:
    """
    ``_kernel.fast_forward_streams`` (the streams' part of ``fast_forward``) checks its input.

    Its taking samples as ``add`` does is the module's contract, tested above; here a run that
    is empty or reversed, missing arguments, a plan without its lists, stamps that are not
    int64, breaks that are not bool and streams whose samples are not lists are each an
    exception, the streams left as they were where the check comes first; a sample the plan
    says starts a segment is appended as one (its bat turn zero).
    """
    from baseball_collision.core.toi import _kernel

    class Planned:
        """The plan's fields ``fast_forward_streams`` reads: two ball and two bat samples."""

        n = 2
        pre = (0, 0)
        counts = ([1, 1], [0, 1])
        starts = ([0, 0], [0, 0])
        times = (np.array([0.0, 0.01]), np.array([0.0]))
        stamps = (np.array([0, 10_000_000], np.int64), np.array([0], np.int64))
        breaks = (np.zeros(2, bool), np.zeros(1, bool))
        values = (np.zeros((2, 3)), (np.zeros((1, 3)),) * 3 + (np.array([[0.0, 0, 0, 1]]),))

    ball, bat = Stream('ball'), Stream('bat')
    plan = Planned()
    assert _kernel.fast_forward_streams(plan, 0, 2, ball, bat, True, False, None,
                                        BatSample, 0.0, 0) == (0, 1, 1)
    assert ball.times == [0.0] and ball.values == [(0.0, 0.0, 0.0)] and bat.stamps == [0]
    assert bat.values == [BatSample((0.0,) * 3, (0.0,) * 3, (0.0,) * 3, (0.0, 0.0, 0.0, 1.0))]
    assert bat.turns == [None] and ball.breaks == [False]
    for pos, end in ((1, 1), (2, 1), (-1, 1)):
        with pytest.raises(ValueError):
            _kernel.fast_forward_streams(plan, pos, end, ball, bat, True, False, None,
                                         BatSample, 0.0, 0)
    with pytest.raises(TypeError):
        _kernel.fast_forward_streams(plan, 0, 1, ball, bat, True, False, None, BatSample, 0.0)
    with pytest.raises(TypeError):
        _kernel.fast_forward_streams(plan, 0, 1, ball, bat, True, False, None, BatSample, 'x',
                                     0)
    with pytest.raises(ValueError):
        _kernel.fast_forward_streams(plan, 0, 1, ball, bat, True, False, None, BatSample, 0.0,
                                     -1)
    with pytest.raises(AttributeError):
        _kernel.fast_forward_streams(object(), 0, 1, Stream('ball'), Stream('bat'), True,
                                     False, None, BatSample, 0.0, 0)
    plan.stamps = (np.array([0.0, 1e7]), plan.stamps[1])
    fresh = Stream('ball')
    with pytest.raises(ValueError):
        _kernel.fast_forward_streams(plan, 0, 1, fresh, Stream('bat'), True, False, None,
                                     BatSample, 0.0, 0)
    flagged = Planned()
    flagged.breaks = (np.zeros(2, np.int8), flagged.breaks[1])  # (not bool)
    with pytest.raises(ValueError):
        _kernel.fast_forward_streams(flagged, 0, 1, Stream('ball'), Stream('bat'), True, False,
                                     None, BatSample, 0.0, 0)
    flagged.breaks = (np.array([True, True]), np.array([True]))  # each sample starts a segment
    broken = (Stream('ball'), Stream('bat'))
    _kernel.fast_forward_streams(flagged, 0, 2, *broken, True, False, None, BatSample, 0.0, 0)
    assert broken[0].breaks == [True] and broken[1].breaks == [True]
    assert broken[1].turns == [(0.0, 0.0, 0.0, 0.0)]
    tupled = Stream('ball')
    tupled.times = ()  # type: ignore[assignment]
    with pytest.raises(TypeError):
        _kernel.fast_forward_streams(Planned(), 0, 1, tupled, Stream('bat'), True, False, None,
                                     BatSample, 0.0, 0)

    class Spy:
        """An estimator that counts the samples the kernel hands it."""

        sigma = 0.0

        def __init__(self) -> None:
            self.taken: List[Any] = []
            self.medians = (self,)  # (its one median: itself)

        def take_run(self, old_times: Any, old_points: Any, old_breaks: Any, times: np.ndarray,
                     points: np.ndarray) -> None:
            self.taken.append(len(times))

        def update(self, stream: Stream) -> float:
            self.taken.append(-1)  # one sample, after its append
            return 0.0

        def update_at(self, stream: Stream, last: int) -> float:
            self.taken.append(('at', last))  # one of the run's after record_after
            return 1e-3 * (last + 1)

    # the samples after record_after (s) but the stream's `ahead` first there are taken one by
    # one (``update_at``), each estimate kept (``noise.ESTIMATES``: None before them), the
    # stream's noise the newest
    balls = Planned()
    balls.counts = ([1, 2], [0, 0])  # (two ball samples, at 0 and 0.01 s)
    for plan, after, ahead, taken, kept in (
            (balls, 0.02, 0, [2], None), (balls, 0.005, 0, [1, ('at', 1)], [None, 2e-3]),
            (balls, -1.0, 0, [('at', 0), ('at', 1)], [1e-3, 2e-3]),
            (balls, -1.0, 1, [1, ('at', 1)], [None, 2e-3]), (balls, -1.0, 2, [2], None),
            (Planned(), 0.02, 0, [-1], None), (Planned(), -1.0, 0, [('at', 0)], [1e-3])):
        spies = (Spy(), Spy())
        streams = Stream('ball'), Stream('bat')
        _kernel.fast_forward_streams(plan, 0, 2, *streams, False, False, spies, BatSample,
                                     after, ahead)
        assert spies[0].taken == taken, after
        assert len(streams[0].times) == plan.counts[0][1]  # every sample appended
        assert streams[0].aligned.get(ESTIMATES) == kept, after
        if kept is not None:
            assert streams[0].noise == kept[-1]


def _plans_made(monkeypatch: pytest.MonkeyPatch, rows: Sequence[Row], config: DetectorConfig,
                size: int) -> List[int]:
    """Return the samples each plan made for ``rows`` in chunks of ``size`` covered."""
    planned: List[int] = []
    plan_chunk = chunks_module.plan_chunk

    def recording(*args, **kwargs):  # type: ignore[no-untyped-def]
        plan = plan_chunk(*args, **kwargs)
        planned.append(plan.n)
        return plan
    monkeypatch.setattr(chunks_module, 'plan_chunk', recording)
    assert_same(config, rows, (size,))
    monkeypatch.setattr(chunks_module, 'plan_chunk', plan_chunk)
    return planned


def test_after_a_short_plan_the_next_go_unplanned(monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A plan that took few samples is followed by samples unplanned, more while that goes on.

    At each pitch's start the plans' checks turn away a few samples in a row, and planning
    each cost a plan of one sample. After a plan shorter than ``PLAN_WORTH`` the next
    ``UNPLANNED_AFTER_EARLY`` samples go through ``add``, doubling while plans stay short:
    fewer such plans, and the events, drops, counters and streams those of ``add`` in turn.
    (The speed check's drops at each pitch's start, taken at once: set aside, they keep
    plans off until the walk passes them, ``Sweep.set_aside``.)
    """
    rows = session(HEIGHTS[:4])
    config = DetectorConfig(model='c2', bat_input='pose')
    at_once = (Sweep, 'set_aside', lambda *args: DropReason.SPEED_LIMIT)
    monkeypatch.setattr(*at_once)
    monkeypatch.setattr(chunks_module, 'UNPLANNED_AFTER_EARLY', 0)
    without = _plans_made(monkeypatch, rows, config, 700)
    monkeypatch.undo()
    monkeypatch.setattr(*at_once)
    with_rule = _plans_made(monkeypatch, rows, config, 700)
    short = chunks_module.PLAN_WORTH
    assert sum(n < short for n in with_rule) < sum(n < short for n in without) / 2


def test_a_stream_sent_twice_is_not_planned_sample_by_sample(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    Every ball sample twice (a relay): a plan every few hundred samples, not every other one.

    Each duplicate ended a plan (a plan call of about a millisecond for one sample taken, 170
    times slower than without); then a duplicate went straight through ``add`` and short plans
    backed off (``PLAN_WORTH``); now the plans drop the duplicates themselves. The same
    events, drops and counters either way.
    """
    rows = session(HEIGHTS[:2])
    twice = [copy for row in rows for copy in ([row, row] if row[0] == 'ball' else [row])]
    planned = _plans_made(monkeypatch, twice, DetectorConfig(model='c2', bat_input='pose'),
                          4096)
    assert len(planned) < len(twice) / 50


def test_samples_lost_as_nan_do_not_end_plans(monkeypatch: pytest.MonkeyPatch) -> None:
    """
    One bat frame in a hundred NaN (an occluded body): as many plans as without them.

    Each such sample ended a plan (8.6 times slower on a 300k-message session); a sample whose
    own stamp or values drop it changes nothing but the counters, so it goes through ``add``
    first and the plans run without it. The same events, drops and counters either way.
    """
    rows = session(HEIGHTS[:3])
    config = DetectorConfig(model='c2', bat_input='pose')
    clean = _plans_made(monkeypatch, rows, config, 4096)
    bats = [i for i, row in enumerate(rows) if row[0] == 'bat_pose']
    lost = list(rows)
    for i in bats[5::100] + [len(rows) - 1]:  # (the chunk's last sample too: taken last)
        role, stamp, values, frame = lost[i]
        lost[i] = (role, stamp, (math.nan,) * len(values), frame)
    planned = _plans_made(monkeypatch, lost, config, 4096)
    assert len(planned) <= len(clean) + 2


@pytest.mark.parametrize('role', ['ball', 'bat_pose'])
def test_messages_sent_twice_do_not_end_plans(role: str,
                                              monkeypatch: pytest.MonkeyPatch) -> None:
    """
    One message of a stream in a hundred sent twice (a relay): as many plans as without them.

    Each copy (its stamp its stream's newest: dropped as ``duplicate_stamp``) ended a plan,
    about 2x the clean bag's time for 1 % of the ball's messages; the plan now drops it as the
    per-sample path does, on its arrays. The same events, drops, counters and streams.
    """
    rows = session(HEIGHTS[:3])
    config = DetectorConfig(model='c2', bat_input='pose')
    clean = _plans_made(monkeypatch, rows, config, 4096)
    own = [i for i, row in enumerate(rows) if row[0] == role]
    twice = list(rows)
    for i in reversed(own[5::100] + own[-1:]):  # (the chunk's last sample too)
        twice.insert(i + 1, rows[i])
    planned = _plans_made(monkeypatch, twice, config, 4096)
    assert len(planned) <= len(clean) + 2
    _, drops, _ = one_at_a_time(config, twice)
    _, clean_drops, _ = one_at_a_time(config, rows)  # (speed_limit: each new pitch starts)
    assert drops - clean_drops == Counter({(role, 'duplicate_stamp'): len(own[5::100]) + 1})


@pytest.mark.parametrize('kind, reason', [('twice_moved', 'duplicate_stamp'),
                                          ('twice_frame', 'wrong_frame'),
                                          ('twice_bad_q', 'bad_quaternion')])
def test_a_copy_with_other_values_or_frame_is_judged_as_add_judges(kind: str,
                                                                   reason: str) -> None:
    """
    Bat poses sent again with their stamp but other values, another frame, a bad quaternion.

    A copy is dropped for its stamp only when its values and frame pass (``add`` checks them
    first): then the plan drops it; else it goes through ``add`` (its reason then), the same
    drops, events and streams either way.
    """
    rows = session(HEIGHTS[:2])
    bats = [i for i, row in enumerate(rows) if row[0] == 'bat_pose']
    twice = inject(rows, [(i + k, kind) for k, i in enumerate(bats[7::40])])
    config = DetectorConfig(model='c2', bat_input='pose')
    assert_same(config, twice, (4096,))
    _, drops, _ = one_at_a_time(config, twice)
    _, clean_drops, _ = one_at_a_time(config, rows)
    assert drops - clean_drops == Counter({('bat_pose', reason): len(bats[7::40])})


@pytest.mark.parametrize('copies', [1, 2])
def test_a_message_sent_twice_after_a_pause_takes_its_held_sample(copies: int) -> None:
    """
    The first ball message after the ball's pause in tracking, sent again: as one at a time.

    The intake holds that sample for the ball's next (a stamp well past the stream's steps);
    the copy, stamped as it, takes it (then is dropped as a duplicate), and the walk goes on
    there, over the bat's samples during the pause, where a plan would have the held sample
    taken by the ball's next one: a frame later for the predictor (which predicts every 10
    ms: its last frame another until a later frame puts them in step again, which the
    session's end hid). So the plan ends at the held sample.
    """
    rows = session(HEIGHTS[:3], spacing=0.6)
    paused = [row for row in rows if row[0] != 'ball' or not 520_000_000 <= (
        row[1] - BASE_NS) % 600_000_000 < 580_000_000]  # (the ball at rest; the bat tracked)
    balls = [i for i, row in enumerate(paused) if row[0] == 'ball']
    after = next(i for i, j in zip(balls, balls[1:]) if paused[j][1] - paused[i][1] > 50_000_000)
    first = balls[balls.index(after) + 1]
    twice = paused[:first + 1] + [paused[first]] * copies + paused[first + 1:]
    for config in (DetectorConfig(model='c2', bat_input='pose'), predicting('c2', 0.01)):
        for end in (first + copies + 3, first + copies + 8, len(twice)):  # (the ball's next: +2)
            for sizes in ((4096,), (first - 20,), (first - 20, 7), (first + 1, 4096)):
                assert_same(config, twice[:end], sizes)


@pytest.mark.parametrize('look_ahead', [0, 2])
def test_a_pose_bats_noise_windows_outlast_the_shortest_history(look_ahead: int) -> None:
    """
    The shortest fit windows (1 ms): a trim still leaves a pose's sixth-difference window.

    The streams trim to their newest few samples after every step once long; one at a time a
    trim falls between the samples a chunk's run takes at once, so the run's noise windows
    must not reach past what the trim leaves (``streams.TRIM_LEAVES``; one less fails): the
    estimators' residuals and estimates the same either way.
    """
    config = DetectorConfig(model='c2', bat_input='pose', tracker_noise=-1.0,
                            look_ahead=look_ahead, velocity_window=0.001,
                            prediction_window=0.001)
    rows = noisy(session(HEIGHTS[:2]), 3e-4, 11)
    assert_same(config, rows, (5000,))
    _, _, chunked = in_chunks(config, rows, (5000,))
    assert chunked._noise[1].span == POSE_SPAN and len(chunked._noise[1].residuals) == HISTORY


def _holds(monkeypatch: pytest.MonkeyPatch, test: str) -> List[int]:
    """Return the stamps (ns) of the frames the ``Predictor`` test named holds, as they come."""
    held: List[int] = []
    departed = getattr(Predictor, test)

    def recording(self: Predictor, *found: Any) -> Any:
        result = departed(self, *found)
        if result is True or result == NEWEST:
            held.append(self.last_ns)
        return result
    monkeypatch.setattr(Predictor, test, recording)
    return held


@pytest.mark.parametrize('rate, period', [(90.0, 0.01), (360.0, 0.0)])
def test_a_prediction_held_at_a_ball_glitch_alike_in_chunks(
        rate: float, period: float, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A hit whose ball sample 3 frames before the contact is moved 20 cm toward the bat.

    The frame whose forecast starts from it predicts nothing (``Predictor._ball_departed``),
    and the next frame is due: in a chunk that stop overturns the plan (the predictor's last
    frame is not the plan's), and the events are those of one sample at a time.
    """
    held = _holds(monkeypatch, '_ball_departed')
    rng = np.random.default_rng(17)
    scenario = make_scenario('barrel', rng, lead_s=0.4)
    samples = sample(scenario, rate, rng, jitter_s=2e-4)
    k = int(np.searchsorted(samples.ball_stamps_ns, samples.start_ns + int(
        round(scenario.truth.time_s * 1e9)))) - 3
    j = int(np.argmin(np.abs(samples.bat_stamps_ns - samples.ball_stamps_ns[k])))
    middle = 0.5 * (samples.knobs[j] + samples.tips[j])
    toward = middle - samples.ball_positions[k]
    positions = samples.ball_positions.copy()
    positions[k] += 0.2 * toward / np.linalg.norm(toward)
    glitched = replace(samples, ball_positions=positions)
    rows = [(role, stamp, values, 'world') for stamp, role, values in glitched.messages()]
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=period)
    events = assert_same(config, rows, (7, 50, 400))
    assert held and sum(isinstance(e, Impact) for e in events) == 1
    assert one_at_a_time(config, rows)[1][('ball', 'ball_glitch')] == 1


def test_a_prediction_held_at_a_bat_glitch_alike_in_chunks(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A 90 Hz miss whose bat frame 2 before the closest approach is turned 20 cm at the tip.

    The frame whose forecast starts from it predicts nothing (``Predictor._bat_off``: one
    sample at a time, it showed a contact the miss does not have), and the events in chunks are
    those of one sample at a time.
    """
    held = _holds(monkeypatch, '_bat_off')
    rows, _ = glitched_pitch('miss_over', 'jerky', 1, 90.0, -2)
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    events = assert_same(config, rows, (7, 50, 400))
    assert held and not any(isinstance(e, (Impact, Prediction)) for e in events)
    assert one_at_a_time(config, rows)[1][('bat_pose', 'bat_glitch')] == 1


@pytest.mark.parametrize('look_ahead', [0, 2])
def test_a_bat_glitch_the_prediction_drops_is_dropped_alike_in_chunks(look_ahead: int) -> None:
    """
    A 360 Hz miss whose bat frame 16 frames (44 ms) before the closest approach is turned 20 cm.

    A frame whose forecast would show a contact judges its bat frames first
    (``Predictor._bat_glitch_dropped``) and drops the glitch there, far from the ball: in
    chunks at a stop for the predictor alone, after which the rest of the chunk is planned
    again (its arrays held the frame). The events, drops and streams are those of one sample
    at a time.
    """
    rows, _ = glitched_pitch('miss_under', 'rebound', 0, 360.0, -16)
    config = DetectorConfig(look_ahead=look_ahead, prediction_horizon=0.3,
                            prediction_period=0.01)
    for sizes in ((1000,), (7, 50, 400)):
        assert_same(config, rows, sizes)
    assert one_at_a_time(config, rows)[1][('bat_pose', 'bat_glitch')] == 1


@pytest.mark.parametrize('family, seed, frame', [('tilted', 0, -3), ('braking', 0, -2)])
def test_a_bat_frame_stamped_off_is_left_out_alike_in_chunks(
        family: str, seed: int, frame: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A 90 Hz hit whose bat frame 2-3 before the contact is stamped 2 ms late (its pose right).

    The frame after it is off the forecast through it and on the one without it, and predicts
    from its forecast without it (``Predictor._bat_off``: ``BEFORE``): in chunks too, the
    events, drops and streams those of one sample at a time.
    """
    verdicts = []
    judged = Predictor._bat_off

    def recording(self: Predictor, found: Any) -> Any:
        verdicts.append(judged(self, found))
        return verdicts[-1]
    monkeypatch.setattr(Predictor, '_bat_off', recording)
    rows, _ = glitched_pitch('barrel', family, seed, 90.0, frame, stamp_off_s=0.002)
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    for sizes in ((1000,), (7, 50, 400)):
        assert_same(config, rows, sizes)
    assert BEFORE in verdicts


@pytest.mark.parametrize('kind, lost, segment, judged', [
    ('barrel', 0, 4, True), ('barrel', -2, 0, True), ('graze', 1, 0, False)])
def test_a_bat_glitch_the_window_cannot_judge_is_left_out_alike_in_chunks(
        kind: str, lost: int, segment: int, judged: bool,
        monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A 90 Hz pitch whose bat frame 4 before the approach, turned 10 cm, needs later frames.

    Its segment's 4th frame, or beside a frame lost two before it or right after it: it held a
    prediction, and the frames after it forecast without it while the sweep's rule for it waits
    or judges it a glitch (``Predictor._late_verdict``: wait, then a glitch: ``judged``; or the
    sweep drops it first): in chunks too, the events, drops and streams those of one sample at
    a time.
    """
    verdicts = []
    late = Predictor._late_verdict

    def recording(self: Predictor, j: int) -> Any:
        verdicts.append(late(self, j))
        return verdicts[-1]
    monkeypatch.setattr(Predictor, '_late_verdict', recording)
    rows, _, _ = lost_glitched_pitch(kind, 'plane', 0 if segment else 1, 4, lost, segment)
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    for sizes in ((1000,), (7, 50, 400)):
        assert_same(config, rows, sizes)
    assert None in verdicts and (True in verdicts) == judged


@pytest.mark.parametrize('kind, family, seed, frame', [
    ('graze', 'plane', 0, -4), ('barrel', 'plane', 0, -3), ('miss_over', 'tilted', 1, -3)])
def test_a_bat_frame_that_held_a_prediction_is_judged_alike_in_chunks(
        kind: str, family: str, seed: int, frame: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """
    A 90 Hz pitch (1 mm of noise) whose bat frame 3-4 before the approach is turned 10 cm.

    The frame held a prediction (``Predictor._bat_off``) and a later frame whose forecast
    shows nothing new judges it and drops it (``Predictor.suspect``): in chunks every due frame
    stops while it waits, and the events, drops and streams are those of one sample at a time.
    """
    judged = []
    dropped = Predictor._bat_glitch_dropped

    def recording(self: Predictor, found: Any) -> bool:
        unchanged = (found is None and not self.predicting) or not self._shown_changes(found)
        result = dropped(self, found)
        if result and unchanged:
            judged.append(self.last_ns)
        return result
    monkeypatch.setattr(Predictor, '_bat_glitch_dropped', recording)
    rows, _ = glitched_pitch(kind, family, seed, 90.0, frame, noise_m=0.001, turn=0.1)
    config = DetectorConfig(prediction_horizon=0.3, prediction_period=0.01)
    for sizes in ((1000,), (7, 50, 400)):
        assert_same(config, rows, sizes)
    assert judged
    assert one_at_a_time(config, rows)[1][('bat_pose', 'bat_glitch')] == 1


def test_a_bat_glitch_beside_a_lost_frame_with_noise_is_judged_alike_in_chunks() -> None:
    """
    A bat frame 4 before the approach turned 10 cm toward the ball, the frame after it lost.

    90 Hz with 1 mm of noise (``tracker_noise`` auto, no prediction): the glitch is dropped
    and forgotten in both paths, then the interval's bat path is read from the kept fits; the
    chunk path's impact came 0.15 ms earlier with a sweet-spot speed sigma of 38 m/s, not 0.35
    (``benchmarks/bench_prediction.py --faults --lost-only --chunks``: plane seed 1 barrel).
    The node's path, fed first, left ``motion.c2_rows``' last window charted; the chunk path's
    ``Sweep._hangs_on`` charted a window without the glitch with the same first, j-th and last
    samples and count, and got its rows: the kept fit was wrong from then on. Each detector's
    fits (``fitting._kept``) are kept by sample identity, so the order alone brought it out.
    """
    from baseball_collision.core.detector import fitting
    from baseball_collision.tools.sim import truth_dict
    rng = np.random.default_rng(1)
    scenario = make_scenario('barrel', rng, lead_s=0.4, family='plane')
    samples = sample(scenario, 90.0, rng, jitter_s=2e-4, noise_m=0.001)
    contact_ns = truth_dict(scenario, samples.start_ns)['stamp_ns']
    j = int(np.flatnonzero(samples.bat_stamps_ns < contact_ns)[-4])
    lost = samples.without_bat_frames(int(samples.bat_stamps_ns[j + 2]), 1)
    near = int(np.argmin(np.abs(lost.ball_stamps_ns - lost.bat_stamps_ns[j])))
    glitched = lost.with_bat_frame_turned(j, lost.ball_positions[near], 0.1)
    rows = [(role, stamp, tuple(values), 'world')
            for stamp, role, values in glitched.messages('pose')]
    config = DetectorConfig(prediction_horizon=0.0)
    fitting._FITS.clear()
    expected, _, _ = one_at_a_time(config, rows)
    events, _, _ = in_chunks(config, rows, (7, 50, 400))
    assert events == expected
