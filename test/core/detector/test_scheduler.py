"""Tests for the detector's scheduler: the walk over the union of stamps."""

from baseball_collision.core.detector import DetectorConfig
from baseball_collision.core.detector.scheduler import Scheduler
from baseball_collision.core.detector.streams import SILENT_AFTER, SILENT_KEEP, Stream


def _streams(ball_times, bat_times):
    ball, bat = Stream('ball'), Stream('bat')
    for t in ball_times:
        ball.append(t, int(t * 1e9) + 1, (0.0, 0.0, 0.0), False)
    for t in bat_times:
        bat.append(t, int(t * 1e9) + 1, (0.0, 0.0, 0.0), False)
    return ball, bat


def _walk(scheduler: Scheduler, final: bool = False):
    visited = []
    moved = scheduler.advance(lambda ta, tb, events: visited.append((ta, tb)), [], final)
    return moved, visited


def test_walks_the_union_of_both_streams_up_to_the_watermark() -> None:
    """Every interval between consecutive union times, from the later first sample."""
    ball, bat = _streams([0.0, 0.01, 0.02, 0.03], [0.005, 0.012, 0.025])
    scheduler = Scheduler(DetectorConfig(model='linear'), ball, bat)
    moved, visited = _walk(scheduler)
    assert moved
    assert visited == [(0.005, 0.01), (0.01, 0.012), (0.012, 0.02), (0.02, 0.025)]
    assert scheduler.cursor == 0.025  # the bat's newest is the watermark
    assert _walk(scheduler) == (False, [])
    bat.append(0.04, 40_000_001, (0.0, 0.0, 0.0), False)
    assert _walk(scheduler) == (True, [(0.025, 0.03)])


def test_a_visit_that_forgets_a_sample_skips_no_union_time() -> None:
    """
    A visit that removes the sample its interval opens at (a glitch) leaves the walk whole.

    The walk's indices into the streams moved with the removal: the next union time was
    skipped, and an interval spanned a sample (a 60 Hz ball beside a 360 Hz bat).
    """
    ball, bat = _streams([0.0, 0.01, 0.02, 0.03, 0.04], [0.0, 0.005, 0.015, 0.025, 0.035, 0.045])
    scheduler = Scheduler(DetectorConfig(model='linear'), ball, bat)
    visited = []

    def visit(ta: float, tb: float, events: list) -> None:
        visited.append((ta, tb))
        if ta == 0.01 and 0.01 in ball.times:
            ball.remove(ball.times.index(0.01))

    scheduler.advance(visit, [])
    assert visited == [(0.0, 0.005), (0.005, 0.01), (0.01, 0.015), (0.015, 0.02),
                       (0.02, 0.025), (0.025, 0.03), (0.03, 0.035), (0.035, 0.04)]


def test_an_interval_that_waits_stops_the_walk_before_it() -> None:
    """A visit that returns False (the sweep waits for samples): the cursor stays before it."""
    ball, bat = _streams([0.0, 0.01, 0.02, 0.03], [0.0, 0.01, 0.02, 0.03])
    scheduler = Scheduler(DetectorConfig(model='linear'), ball, bat)
    visited = []

    def visit(ta: float, tb: float, events: list) -> bool:
        visited.append((ta, tb))
        return ta != 0.01 or len(ball.times) > 4

    assert scheduler.advance(visit, [])
    assert visited == [(0.0, 0.01), (0.01, 0.02)] and scheduler.cursor == 0.01
    visited.clear()
    assert not scheduler.advance(visit, [])  # (nothing new: the same interval waits)
    assert visited == [(0.01, 0.02)] and scheduler.cursor == 0.01
    for stream in (ball, bat):
        stream.append(0.04, 40_000_001, (0.0, 0.0, 0.0), False)
    visited.clear()
    assert scheduler.advance(visit, [])
    assert visited == [(0.01, 0.02), (0.02, 0.03), (0.03, 0.04)]


def test_the_spline_waits_for_the_next_sample_until_the_end() -> None:
    """One sample behind each stream's newest; ``final`` walks the rest."""
    ball, bat = _streams([0.0, 0.01, 0.02], [0.0, 0.01, 0.02])
    scheduler = Scheduler(DetectorConfig(model='spline'), ball, bat)
    assert _walk(scheduler) == (True, [(0.0, 0.01)])
    assert _walk(scheduler, final=True) == (True, [(0.01, 0.02)])


def test_nothing_to_walk_without_both_streams() -> None:
    """A stream with too few samples holds the walk."""
    ball, bat = _streams([0.0, 0.01], [])
    assert _walk(Scheduler(DetectorConfig(), ball, bat)) == (False, [])
    ball, bat = _streams([0.0, 0.01], [0.0])
    assert _walk(Scheduler(DetectorConfig(model='spline'), ball, bat)) == (False, [])


def test_trims_behind_the_cursor() -> None:
    """After a walk the streams keep only the fits' history behind the cursor."""
    times = [0.001 * i for i in range(400)]
    ball, bat = _streams(times, times)
    config = DetectorConfig(model='linear')
    scheduler = Scheduler(config, ball, bat)
    _walk(scheduler)
    history = 1.5 * max(config.velocity_window, config.prediction_window)
    assert ball.times[0] >= 0.399 - history - 0.005 - 1e-9
    assert len(ball.times) < 400 and len(bat.times) < 400


def test_a_silent_stream_does_not_grow_the_other() -> None:
    """The bat stops after 10 ms; the ball goes on 3 s at 1 kHz: it keeps only its own history."""
    ball, bat = _streams([0.0], [0.0, 0.005, 0.01])
    scheduler = Scheduler(DetectorConfig(model='linear'), ball, bat)
    for i in range(1, 3000):
        ball.append(i * 0.001, i + 1, (0.0, 0.0, 0.0), False)
        _walk(scheduler)
    assert len(ball.times) < max(SILENT_AFTER * 1000, SILENT_KEEP) + 200
    assert ball.times[-1] == 2.999 and len(bat.times) == 3


def test_a_stream_never_seen_does_not_grow_the_other() -> None:
    """No bat at all: the ball is trimmed by its own newest all the same."""
    ball, bat = _streams([0.0], [])
    scheduler = Scheduler(DetectorConfig(model='linear'), ball, bat)
    largest = 0
    for i in range(1, 6000):
        ball.append(i * 0.001, i + 1, (0.0, 0.0, 0.0), False)
        _walk(scheduler)
        largest = max(largest, len(ball.times))
    assert largest <= SILENT_KEEP + 1 and len(ball.times) < 3000
