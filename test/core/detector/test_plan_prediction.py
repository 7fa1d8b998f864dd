"""Tests of ``core/detector/plan_prediction.py``: a plan's due frames and forecast windows."""

from typing import List, Optional

from baseball_collision.core.detector.plan_prediction import _due_frames, _histories
from baseball_collision.core.detector.streams import Stream
from baseball_collision.core.prediction import prediction_due
from hypothesis import given, settings, strategies as st
import numpy as np
from support import examples


@settings(max_examples=examples(300), deadline=None)
@given(gaps=st.lists(st.sampled_from([1e-4, 2.7e-3, 2.8e-3, 5e-3, 0.011, 0.05]), min_size=1,
                     max_size=120),
       breaks=st.sets(st.integers(0, 119)), data=st.data(),
       window=st.sampled_from([0.0, 0.01, 0.061, 0.1, 0.3]))
def test_histories_are_the_stream_history_of_each_frame(gaps: List[float], breaks: set,
                                                        data: st.DataObject,
                                                        window: float) -> None:
    """
    ``_histories``: per frame, ``Stream.history`` of the stream's samples [start, count).

    Frames at times between, on and around the samples, with trimmed starts, counts short of
    the samples, segment breaks and windows from none to 0.3 s, against a ``Stream`` holding
    the frame's samples (from ``start``: a trimmed stream's indices count from its first).
    """
    times = np.cumsum(gaps)
    flags = np.array([i in breaks for i in range(len(times))])
    frames = data.draw(st.lists(st.tuples(st.integers(0, len(times) - 1),
                                          st.integers(1, len(times)),
                                          st.floats(-0.01, float(times[-1]) + 0.01)),
                                min_size=1, max_size=20))
    starts = np.array([min(a, b - 1) for a, b, _ in frames], np.int64)
    counts = np.array([b for _, b, _ in frames], np.int64)
    _assert_histories(times, flags, starts, counts, np.array([t for _, _, t in frames]), window)


def test_histories_hold_at_most_the_stream_historys_samples() -> None:
    """``_histories`` of 1 kHz samples over 0.1 s: ``MAX_HISTORY`` samples, as the stream's."""
    times = np.arange(300) * 1e-3
    t0s = np.arange(0.0, 0.31, 0.0037)
    starts = np.minimum(np.arange(len(t0s)) % 7 * 20, 299)
    _assert_histories(times, np.arange(300) % 97 == 5, starts, np.full(len(t0s), 300), t0s, 0.1)


def _assert_histories(times: np.ndarray, flags: np.ndarray, starts: np.ndarray,
                      counts: np.ndarray, t0s: np.ndarray, window: float) -> None:
    """Assert ``_histories`` is ``Stream.history`` of a stream of each frame's samples."""
    found = _histories(times, flags, starts, counts, t0s, window)
    for (first, end), start, count, t0 in zip(found.tolist(), starts, counts, t0s):
        stream = Stream('ball')
        for i in range(start, count):
            stream.append(float(times[i]), i, (0.0, 0.0, 0.0), bool(flags[i]))
        stream.breaks[0] = bool(flags[start])  # (as kept: not forced as a first sample)
        expected = stream.history(float(t0), window)
        assert (first - start, end - start) == (
            (expected.start, expected.stop) if len(expected) else (first - start, first - start))


@settings(max_examples=examples(300), deadline=None)
@given(steps=st.lists(st.sampled_from([0, 1, 2_777_777, 2_777_778, 5_000_000, 10_000_000]),
                      max_size=200),
       start=st.integers(0, 10 ** 9), last=st.one_of(st.none(), st.integers(0, 2 * 10 ** 9)),
       period=st.sampled_from([0.0, 1e-10, 0.004, 0.01, 0.0100000004, 0.3]))
def test_due_frames_are_prediction_due_frame_by_frame(steps: List[int], start: int,
                                                      last: Optional[int], period: float) -> None:
    """
    ``_due_frames``: the frames ``prediction_due`` says predict, each due one the last.

    Not decreasing stamps (equal ones too), from before, at or after the last frame that
    predicted (or none), with periods of none, under a nanosecond, and a rounded one.
    """
    now = (start + np.cumsum(steps, dtype=np.int64)).tolist()
    expected, current = [], last
    for k, stamp in enumerate(now):
        if prediction_due(current, stamp, period):
            expected.append(k)
            current = stamp
    assert _due_frames(now, last, period) == expected
