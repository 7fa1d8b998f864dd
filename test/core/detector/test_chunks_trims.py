"""A plan's trims (``chunks._trims``) against the trim rule applied sample by sample."""

from typing import List, Tuple

from baseball_collision.core.detector.chunks import _trims, TRIM_FROM
from hypothesis import given, settings, strategies as st
import numpy as np


def _one_at_a_time(counts: List[int], cuts: List[int]) -> Tuple[List[int], List[int]]:
    """After each sample: a stream of TRIM_FROM or more drops what is before a later cut."""
    start, after, lengths = 0, [], []
    for count, cut in zip(counts, cuts):
        lengths.append(count - start)
        if count - start >= TRIM_FROM and cut > start:
            start = cut
        after.append(start)
    return after, lengths


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 40)), min_size=1, max_size=600),
       st.integers(0, 200), st.integers(0, 2 * TRIM_FROM))
def test_trims_are_the_rule_applied_sample_by_sample(
        steps: List[Tuple[int, int]], first: int, lag: int) -> None:
    """Counts and cuts that never decrease; histories shorter and longer than TRIM_FROM."""
    counts = np.cumsum([step for step, _ in steps]) + first
    cuts = np.maximum.accumulate(counts - lag - np.array([jitter for _, jitter in steps]))
    after, lengths = _trims(counts, cuts)
    expected_after, expected_lengths = _one_at_a_time(counts.tolist(), cuts.tolist())
    assert after.tolist() == expected_after
    assert lengths.tolist() == expected_lengths
