"""Tests for baseball_collision.bags decoding: the fixed-offset fast path against rosbags."""

from pathlib import Path
from typing import List

from baseball_collision.bags import BagReader, POSE_STAMPED, read_samples, Sample
from baseball_collision.bags.decode import _groups, _layout, BULK_GROUP, Route
from hypothesis import given, settings, strategies as st
import numpy as np
import pytest
from support import examples
from support.bagfiles import expected_samples, read_by_rosbags, reference_bag, tracker_rows


@pytest.mark.parametrize('name', ['dir_mcap', 'dir_sqlite3', 'ros1.bag'])
def test_fast_decode_equals_rosbags_deserialize(tmp_path: Path, name: str) -> None:
    """Samples from the struct fast path equal rosbags' deserialisation, field for field."""
    path = tmp_path / name
    rows = tracker_rows()
    reference_bag(path, rows)
    samples = list(read_samples(path))
    reference = read_by_rosbags(path)
    assert len(samples) == len(reference) == len(rows)
    roles = {'/ball': 'ball', '/bat/pose': 'bat_pose'}
    for sample, (topic, stamp, frame, values, log_time) in zip(samples, reference):
        assert sample == Sample(roles[topic], stamp, frame, values, log_time)
        assert all(type(v) is float for v in sample.values)
    assert samples == expected_samples(rows, roles)


def test_big_endian_cdr_is_read_through_the_fallback(tmp_path: Path) -> None:
    """Big-endian CDR is legal; it is decoded by rosbags and gives the same samples."""
    rows = tracker_rows(6)
    reference_bag(tmp_path / 'be', rows, little_endian=False)
    assert list(read_samples(tmp_path / 'be')) == expected_samples(
        rows, {'/ball': 'ball', '/bat/pose': 'bat_pose'})


@pytest.mark.parametrize('name', ['dir_mcap', 'ros1.bag'])
def test_ball_pose_gives_its_position(tmp_path: Path, name: str) -> None:
    """A PoseStamped ball topic yields (x, y, z) of its position; the selection says its type."""
    rows = tracker_rows(5, ball_type=POSE_STAMPED)
    reference_bag(tmp_path / name, rows)
    with BagReader(tmp_path / name) as bag:
        assert bag.selection.ball_type == POSE_STAMPED
        samples = list(bag.samples())
    assert samples == expected_samples(rows, {'/ball': 'ball', '/bat/pose': 'bat_pose'})
    assert all(len(s.values) == 3 for s in samples if s.role == 'ball')


@settings(max_examples=examples(200), deadline=None)
@given(st.lists(st.integers(0, 12), max_size=400), st.integers(1, 3))
def test_groups_are_the_sorted_groups_of_equal_keys(kinds: List[int], lengths: int) -> None:
    """
    ``_groups``: each key's indices in order, by key, the groups of ``BULK_GROUP`` or more.

    Against a sort (``np.unique`` and a stable ``argsort``), with fewer and more distinct keys
    than ``GROUPS_PICKED``.
    """
    keys = np.array(kinds, dtype=np.int64) * 1000 + np.arange(len(kinds)) % lengths
    got = _groups(keys)
    distinct = sorted(set(keys.tolist()))
    expected = [np.flatnonzero(keys == key) for key in distinct]
    expected = [members for members in expected if len(members) >= BULK_GROUP]
    assert [members.tolist() for members in got] == [members.tolist() for members in expected]


@settings(max_examples=examples(200), deadline=None)
@given(st.integers(0, 2 ** 32 - 1), st.integers(0, 12), st.integers(1, 40))
def test_layout_keeps_the_rows_of_the_first_frame_field(seed: int, name: int, k: int) -> None:
    """
    ``_layout``'s rows: those whose frame_id field is the first's byte for byte (a CDR header).

    Rows changed in any byte of the field (its length included) or of the header are left out.
    """
    rng = np.random.default_rng(seed)
    frame = bytes(rng.integers(97, 123, name, dtype=np.uint8)) + b'\x00'
    field = len(frame).to_bytes(4, 'little') + frame
    head = b'\x00\x01\x00\x00' + b'\x00' * 8
    message = head + field + b'\x00' * ((-len(field)) % 8) + b'\x00' * 56
    table = np.tile(np.frombuffer(message, np.uint8), (k, 1))
    for row in rng.integers(1, k, rng.integers(0, k)).tolist() if k > 1 else []:  # (not the first)
        table[row, int(rng.integers(0, 12 + len(field)))] ^= int(rng.integers(1, 256))
    _, _, rows = _layout(Route('ball', True, 3, 'geometry_msgs/msg/PointStamped'), table)
    end = 12 + len(field)
    expected = (table[:, 12:end] == table[0, 12:end]).all(axis=1) & (table[:, 0] == 0) & (
        table[:, 1] == 1)
    assert rows.tolist() == expected.tolist()
