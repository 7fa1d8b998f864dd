"""Tests for the detector's knob and tip pairing by stamp."""

from typing import List

from baseball_collision.core.detector.pairing import _merged, Pairing
from baseball_collision.core.detector.streams import SILENT_AFTER, SILENT_KEEP
from hypothesis import given, strategies as st
import pytest


def test_pairs_at_every_stamp_both_cover_interpolating_the_other() -> None:
    """Knob at 0, 10, 20 ms; tip at 5, 15 ms: pairs at 5, 10, 15 with the other interpolated."""
    pairing = Pairing()
    for i, t in enumerate((0.0, 0.01, 0.02)):
        pairing.knob.append(t, i + 1, (t * 100.0, 0.0, 0.0), False)
    for i, t in enumerate((0.005, 0.015)):
        pairing.tip.append(t, i + 10, (t * 100.0, 1.0, 0.0), False)
    pairs = pairing.pairs(max_gap=0.05)
    assert [t for t, _, _ in pairs] == [0.005, 0.01, 0.015]
    for t, knob, tip in pairs:
        assert knob == pytest.approx((t * 100.0, 0.0, 0.0))
        assert tip == pytest.approx((t * 100.0, 1.0, 0.0))
    assert pairing.cursor == 0.015
    assert pairing.pairs(max_gap=0.05) == []  # nothing new
    pairing.tip.append(0.025, 12, (2.5, 1.0, 0.0), False)
    assert [t for t, _, _ in pairing.pairs(max_gap=0.05)] == [0.02]


def test_no_pair_across_a_gap_or_before_the_first_sample() -> None:
    """The other point is not interpolated across more than max_gap, nor extrapolated back."""
    assert _sparse().pairs(max_gap=0.05) == []
    assert [t for t, _, _ in _sparse().pairs(max_gap=0.5)] == [0.1, 0.2]  # not 0.0, not 0.3


def _sparse() -> Pairing:
    """Return knob samples at 0 and 200 ms, tip samples at 100 and 300 ms."""
    pairing = Pairing()
    pairing.knob.append(0.0, 1, (0.0, 0.0, 0.0), False)
    pairing.knob.append(0.2, 2, (2.0, 0.0, 0.0), False)
    pairing.tip.append(0.1, 3, (1.0, 1.0, 0.0), False)
    pairing.tip.append(0.3, 4, (3.0, 1.0, 0.0), False)
    return pairing


def test_no_pair_across_a_frame_that_came_without_a_point() -> None:
    """
    Tip frame at 20 ms lost (``missed``): knob stamps between the tip's 10 and 30 ms unpaired.

    The knob at 20 ms (the lost frame's own) and at 25 ms would take a tip on the chord from
    10 to 30 ms; those at 10 and 30 ms pair with the tips sent then. A missed frame at or
    before the stream's newest (an old or duplicate stamp) breaks nothing.
    """
    pairing = Pairing()
    for t in (0.0, 0.01, 0.02, 0.025, 0.03, 0.04):
        pairing.knob.append(t, int(t * 1e6), (t, 0.0, 0.0), False)
    for t in (0.0, 0.01):
        pairing.append(pairing.tip, t, int(t * 1e6), (t, 1.0, 0.0))
    pairing.missed(pairing.tip, 10_000)  # the newest's own stamp: nothing lost after it
    assert pairing.missing == {}
    pairing.missed(pairing.tip, 20_000)
    pairing.missed(pairing.tip, 25_000)  # a later one changes nothing: the earliest counts
    assert pairing.missing == {'tip': 20_000}
    for t in (0.03, 0.04):
        pairing.append(pairing.tip, t, int(t * 1e6), (t, 1.0, 0.0))
    assert pairing.missing == {} and pairing.tip.breaks == [True, False, True, False]
    assert [t for t, _, _ in pairing.pairs(max_gap=0.05)] == [0.0, 0.01, 0.03, 0.04]


def test_a_point_sent_at_the_missed_stamp_keeps_the_stream_whole() -> None:
    """A missed frame whose stamp then brings a good point (sent twice) was not lost."""
    pairing = Pairing()
    pairing.append(pairing.tip, 0.0, 1, (0.0, 1.0, 0.0))
    pairing.missed(pairing.tip, 2)
    pairing.append(pairing.tip, 0.01, 2, (0.01, 1.0, 0.0))
    pairing.append(pairing.tip, 0.02, 3, (0.02, 1.0, 0.0))
    assert pairing.missing == {} and pairing.tip.breaks == [True, False, False]


@given(a=st.lists(st.integers(0, 50), unique=True), b=st.lists(st.integers(0, 50), unique=True))
def test_the_merge_walk_is_the_sorted_union(a: List[int], b: List[int]) -> None:
    """Merging two sorted lists of times gives the sorted union, without repeats."""
    assert _merged(sorted(a), sorted(b)) == sorted(set(a) | set(b))


def test_a_dead_tip_keeps_the_knob_short() -> None:
    """Tip silent, knob at 1 kHz for 5 s: the knob keeps a few samples, not all 5000."""
    pairing = Pairing()
    pairing.tip.append(0.0, 1, (0.0, 1.0, 0.0), False)
    largest = 0
    for i in range(5000):
        pairing.knob.append(i * 0.001, 10 + i, (0.0, 0.0, 0.0), False)
        pairing.pairs(max_gap=0.05)
        pairing.trim()
        largest = max(largest, len(pairing.knob.times))
    assert largest < max(SILENT_AFTER * 1000, SILENT_KEEP) + 100


def test_a_tip_never_seen_keeps_the_knob_short() -> None:
    """No tip at all: the knob is trimmed by its own newest (after ``SILENT_KEEP``)."""
    pairing = Pairing()
    largest = 0
    for i in range(6000):
        pairing.knob.append(i * 0.001, 10 + i, (0.0, 0.0, 0.0), False)
        pairing.pairs(max_gap=0.05)
        pairing.trim()
        largest = max(largest, len(pairing.knob.times))
    assert largest <= SILENT_KEEP + 1 and len(pairing.knob.times) < 3000
