"""Tests for baseball_collision.bags decoding: the fixed-offset fast path against rosbags."""

from pathlib import Path
from typing import List

from baseball_collision.bags import BagReader, POSE_STAMPED, read_samples, Sample
from baseball_collision.bags.decode import _groups, _layout, BULK_GROUP, Route
from baseball_collision.core.toi import _kernel
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
@given(st.integers(0, 2 ** 32 - 1), st.integers(0, 12), st.integers(1, 40), st.booleans())
def test_a_group_keeps_the_rows_of_the_first_frame_field(seed: int, name: int, k: int,
                                                         cdr: bool) -> None:
    """
    A group read in bulk: the messages whose frame_id field is the first's byte for byte.

    ``_layout`` of the first message, then ``_kernel.decode_group``: rows changed in any byte
    of the field (its length included) or, in CDR, of the header's first two are left out;
    the others' stamps (int32 seconds in CDR, uint32 in ROS 1) and float64s are the bytes'.
    """
    rng = np.random.default_rng(seed)
    frame = bytes(rng.integers(97, 123, name, dtype=np.uint8)) + (b'\x00' if cdr else b'')
    field = len(frame).to_bytes(4, 'little') + frame
    head = (b'\x00\x01\x00\x00' if cdr else b'\x07\x00\x00\x00') + b'\x00' * 8
    pad = (-len(field)) % 8 if cdr else 0
    message = head + field + b'\x00' * pad + b'\x00' * 56
    table = np.tile(np.frombuffer(message, np.uint8), (k, 1))
    table[:, 4:12] = rng.integers(0, 256, (k, 8), dtype=np.uint8)  # the stamps
    floats_at = 12 + len(field) + pad
    table[:, floats_at:] = rng.integers(0, 256, (k, 56), dtype=np.uint8)
    for row in rng.integers(1, k, rng.integers(0, k)).tolist() if k > 1 else []:  # (not the first)
        table[row, int(rng.integers(0, 12 + len(field)))] ^= int(rng.integers(1, 256))
    route = Route('bat_pose', cdr, 7, 'geometry_msgs/msg/PoseStamped')
    _, offset, end = _layout(route, table[0].tobytes())
    assert (offset, end) == (floats_at, 12 + len(field))
    members = rng.permutation(k + 3)[:k].astype(np.int64)  # (rows of a bigger chunk)
    stamps, values = np.zeros(k + 3, np.int64), np.zeros((k + 3, 7))
    done = np.zeros(k + 3, bool)
    count = _kernel.decode_group(table.ravel(), np.arange(k, dtype=np.int64) * table.shape[1],
                                 members, table.shape[1], end, offset, 7, cdr, stamps, values,
                                 done)
    expected = (table[:, 12:end] == table[0, 12:end]).all(axis=1)
    if cdr:
        expected &= (table[:, 0] == 0) & (table[:, 1] == 1)
    assert done[members].tolist() == expected.tolist() and count == expected.sum()
    assert not done[np.setdiff1d(np.arange(k + 3), members)].any()
    kept = members[expected]
    seconds = table[expected, 4:8].copy().view('<i4' if cdr else '<u4')[:, 0].astype(np.int64)
    nanoseconds = table[expected, 8:12].copy().view('<u4')[:, 0]
    assert stamps[kept].tolist() == (seconds * 1_000_000_000 + nanoseconds).tolist()
    read = table[expected, floats_at:floats_at + 56].copy().view('<f8')
    assert values[kept].tobytes() == read.tobytes()  # (NaNs too, bit for bit)


def test_a_group_refuses_what_is_not_its_layout() -> None:
    """``decode_group``: a message past the buffer, a row past the chunk, bad arrays: errors."""
    buffer = np.zeros(64, np.uint8)
    stamps, values, done = np.zeros(2, np.int64), np.zeros((2, 7)), np.zeros(2, bool)
    starts, members = np.array([0, 40], np.int64), np.array([0, 1], np.int64)
    good = (buffer, starts[:1], members[:1], 32, 20, 24, 1, True, stamps, values, done)
    assert _kernel.decode_group(*good) == 0  # (a zero header is not little-endian CDR)
    with pytest.raises(ValueError, match='outside the buffer'):
        _kernel.decode_group(buffer, starts, members, 32, 20, 24, 1, True, stamps, values, done)
    with pytest.raises(IndexError):
        _kernel.decode_group(buffer, starts[:1], members[1:] + 5, 32, 20, 24, 1, True, stamps,
                             values, done)
    for bad in ((8, 20, 24, 1), (32, 40, 24, 1), (32, 20, 24, 2)):  # layouts past the message
        with pytest.raises(ValueError):
            _kernel.decode_group(buffer, starts[:1], members[:1], *bad, True, stamps, values,
                                 done)
    with pytest.raises(ValueError):
        _kernel.decode_group(buffer, starts[:1].astype(np.int32), members[:1], 32, 20, 24, 1,
                             True, stamps, values, done)
    with pytest.raises(ValueError):
        _kernel.decode_group(buffer, starts[:1], members[:1], 32, 20, 24, 1, True, stamps,
                             np.zeros((2, 6)), done)
