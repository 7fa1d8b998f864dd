"""Tests for baseball_collision.bags.plans: an arm's bat plans recorded in a bag."""

from pathlib import Path

from baseball_collision.bags import BagReader, BagWriter, path_message
from baseball_collision.bags.plans import plan_arrays
from baseball_collision.core.prediction import MAX_PLAN_POSES
from baseball_collision.errors import BagError
from baseball_collision.tools.recording import PLAN_TOPIC, RecordingSpec, write_recording
import pytest
from rosbags.highlevel import AnyReader

BASE_NS = 1_700_000_000_000_000_000


def test_a_recordings_plans_come_back_as_written(tmp_path: Path) -> None:
    """
    ``simulate --plan``: one plan a pitch, read back in log order as the detector takes them.

    Its poses 5 ms apart over the pitch (0.4 s), in the recording's frame, logged right after
    the pitch's first message of every input (in the bag's order too, which ``replay``
    publishes in: the node then has the trackers' frame to check it against, as ``analyze``,
    which takes a plan after the samples logged at its instant); the topic's type and a bag
    without it are told apart.
    """
    bag = tmp_path / 'plans.mcap'
    document = write_recording(bag, RecordingSpec(count=3, rate_hz=120.0, plan_hz=200.0,
                                                  lead_s=0.25, trail_s=0.15))
    assert document['topics']['bat_plan'] == PLAN_TOPIC
    starts = [p['start_ns'] for p in document['pitches']]
    with BagReader(bag) as reader:
        plans = reader.plans(PLAN_TOPIC)
        assert reader.plans('/elsewhere') is None
        with pytest.raises(BagError, match="'/ball' of bag .* is of type .*PointStamped"):
            reader.plans('/ball')
        samples = list(reader.samples())
    assert len(plans) == 3 and all(p.refused is None and p.frames == {'world'} for p in plans)
    for plan, start in zip(plans, starts):
        assert len(plan.stamps_ns) == 80 and plan.stamps_ns[0] == start
        assert plan.stamps_ns[1] - plan.stamps_ns[0] == 5_000_000
        assert all(abs(sum(q * q for q in quaternion) - 1.0) < 1e-9
                   for quaternion in plan.quaternions)
        second = [s.log_time_ns for s in samples if s.stamp_ns >= start][1]
        assert plan.log_time_ns == second
    sample_topics = {topic for role, topic in document['topics'].items() if role != 'bat_plan'}
    with AnyReader([bag]) as reader:  # the bag's order: the order replay publishes in
        order = [(connection.topic, log_time) for connection, log_time, _ in reader.messages()]
    plan_at = [i for i, (topic, _) in enumerate(order) if topic == PLAN_TOPIC]
    assert len(plan_at) == 3
    for here, plan in zip(plan_at, plans):
        first = order[here - len(sample_topics):here]  # the pitch's first frame, then the plan
        assert {topic for topic, _ in first} == sample_topics, first
        assert {log_time for _, log_time in first} == {plan.log_time_ns}


def test_a_plan_too_large_is_refused_before_its_poses_are_read(tmp_path: Path) -> None:
    """Over ``MAX_PLAN_POSES`` poses: refused as the node refuses it, its poses never read."""
    bag = tmp_path / 'huge.mcap'
    count = MAX_PLAN_POSES + 1
    with BagWriter(bag) as writer:
        writer.write_point('/ball', BASE_NS, 'world', (0.0, 0.0, 1.0))
        writer.write_pose('/bat', BASE_NS, 'world', (0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0))
        writer.write_message('/plan', path_message(
            [BASE_NS + i for i in range(count)], [(0.0, 0.0, 1.0)] * count,
            [(0.0, 0.0, 0.0, 1.0)] * count, 'world', writer.typestore), BASE_NS + 1)
        writer.write_message('/plan', path_message([], [], [], 'world', writer.typestore),
                             BASE_NS + 2)
    with BagReader(bag, ball='/ball', bat_pose='/bat') as reader:
        huge, empty = reader.plans('/plan')
    assert huge.refused == f'{count} poses is more than the {MAX_PLAN_POSES} a plan may hold'
    assert huge.stamps_ns == [] and huge.log_time_ns == BASE_NS + 1
    assert empty.refused is None and empty.stamps_ns == [] and empty.frames == {'world'}


def test_plan_arrays_reads_a_typestore_path_as_the_nodes() -> None:
    """A rosbags message gives the stamps, positions, quaternions and frames rclpy's does."""
    message = path_message([BASE_NS, BASE_NS + 7], [(1.0, 2.0, 3.0), (4.0, 5.0, 6.0)],
                           [(0.0, 0.0, 0.0, 1.0), (0.0, 1.0, 0.0, 0.0)], 'arm')
    stamps, positions, quaternions, frames = plan_arrays(message)
    assert stamps == [BASE_NS, BASE_NS + 7] and frames == {'arm'}
    assert positions == [(1.0, 2.0, 3.0), (4.0, 5.0, 6.0)]
    assert quaternions[1] == (0.0, 1.0, 0.0, 0.0)
