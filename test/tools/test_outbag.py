"""
``analyze --out-bag`` on a bundled bag, read back with rosbags.

Every input topic as recorded, the node's outputs (events, reports, markers, diagnostics), the
QoS profiles, log-time order.
"""

import json
from pathlib import Path
from typing import Any, Callable, Dict, List, Tuple

from baseball_collision.bags import BagWriter, RawBag
from baseball_collision.core.detector import DEFAULTS
from baseball_collision.tools.parameters import build_config, load_parameters, output_topics
from baseball_collision.tools.report import ENTRY_KEYS
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.interfaces import QosDurability, QosReliability
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import get_types_from_msg, get_typestore, Stores
from support.bundled import bag_path, PARAMS

SETTINGS = {**DEFAULTS, **load_parameters(PARAMS)}
RunCli = Callable[[List[str]], Tuple[int, str, str]]
IMPACT_NAMESPACES = {'impact_bat', 'impact_ball', 'impact_contact', 'impact_normal',
                     'impact_label'}


def _read(path: Path) -> Tuple[Dict[str, Any], List[Tuple[str, int, bytes]]]:
    """Return a bag's connections by topic and its messages (topic, log time, CDR) in order."""
    with AnyReader([path], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        connections = {c.topic: c for c in reader.connections}
        messages = [(c.topic, log_time, bytes(raw)) for c, log_time, raw in reader.messages()]
    return connections, messages


def _decode(messages: List[Tuple[str, int, bytes]], topic: str, msgtype: str) -> List[Any]:
    store = get_typestore(Stores.ROS2_JAZZY)
    return [store.deserialize_cdr(raw, msgtype) for name, _, raw in messages if name == topic]


def _ns(stamp: Any) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


@pytest.fixture(scope='module')
def session(tmp_path_factory: pytest.TempPathFactory) -> Dict[str, Any]:
    """Run analyze --out-bag --json once on the 90 Hz MCAP (in-process)."""
    from baseball_collision.tools.cli import main
    directory = tmp_path_factory.mktemp('outbag')
    out, json_out = directory / 'session.mcap', directory / 'session.json'
    source = bag_path('pitches_90hz.mcap')
    assert main(['analyze', str(source), '--params', str(PARAMS), '--out-bag', str(out),
                 '--json', str(json_out), '--quiet', '--no-progress']) == 0
    connections, messages = _read(out)
    inputs, input_messages = _read(source)
    return {'document': json.loads(json_out.read_text()), 'connections': connections,
            'messages': messages, 'inputs': inputs, 'input_messages': input_messages}


def test_every_input_topic_copied_as_recorded_with_its_qos(session: Dict[str, Any]) -> None:
    """Each input topic: same type, same QoS profiles, same messages (bytes, log times)."""
    inputs, connections = session['inputs'], session['connections']
    assert set(inputs) <= set(connections)
    for topic, connection in inputs.items():
        copied = connections[topic]
        assert copied.msgtype == connection.msgtype
        assert copied.ext.offered_qos_profiles == connection.ext.offered_qos_profiles
        assert [m for m in session['messages'] if m[0] == topic] == \
            [m for m in session['input_messages'] if m[0] == topic]
    log_times = [log_time for _, log_time, _ in session['messages']]
    assert log_times == sorted(log_times)


def test_node_topics_recorded_with_the_nodes_qos(session: Dict[str, Any]) -> None:
    """The node's topics: reliable, volatile; events 100 deep, markers and diagnostics 10."""
    for name, topic in output_topics().items():
        (profile,) = session['connections'][topic].ext.offered_qos_profiles
        assert profile.reliability == QosReliability.RELIABLE
        assert profile.durability == QosDurability.VOLATILE
        assert profile.depth == (10 if name in ('markers', 'diagnostics') else 100)


def test_reports_are_the_json_records(session: Dict[str, Any]) -> None:
    """~/impact_report: one record per impact and near miss, equal to analyze --json's."""
    document = session['document']
    reports = [json.loads(m.data) for m in _decode(
        session['messages'], output_topics()['impact_report'], 'std_msgs/msg/String')]
    expected = sorted(document['impacts'] + document['near_misses'],
                      key=lambda record: record['stamp_ns'])
    assert len(reports) == len(expected) and document['impacts']
    for report, record in zip(sorted(reports, key=lambda r: r['stamp_ns']), expected):
        assert report == {key: record[key] for key in report}
        assert set(record) - set(report) <= {*ENTRY_KEYS, 'prediction_errors', 'truth'}


def test_impact_markers_show_bat_ball_contact_and_normal(session: Dict[str, Any]) -> None:
    """Each impact: a marker array at its stamp with the bat pieces, ball, contact, normal."""
    arrays = _decode(session['messages'], output_topics()['markers'],
                     'visualization_msgs/msg/MarkerArray')
    impacts = session['document']['impacts']
    scenes = [a for a in arrays if a.markers and a.markers[0].ns == 'impact_bat']
    assert [_ns(a.markers[0].header.stamp) for a in scenes] == [i['stamp_ns'] for i in impacts]
    pieces = len(build_config(load_parameters(PARAMS), bat_input='pose').profile.segments())
    for array, impact in zip(scenes, impacts):
        namespaces = [m.ns for m in array.markers]
        assert set(namespaces) == IMPACT_NAMESPACES
        assert namespaces.count('impact_bat') == pieces > 1
        (contact,) = [m for m in array.markers if m.ns == 'impact_contact']
        position = contact.pose.position
        assert [position.x, position.y, position.z] == pytest.approx(impact['point'])
        (normal,) = [m for m in array.markers if m.ns == 'impact_normal']
        start, end = normal.points
        assert [start.x, start.y, start.z] == pytest.approx(impact['point'])
        direction = [end.x - start.x, end.y - start.y, end.z - start.z]
        assert direction == pytest.approx([0.15 * n for n in impact['normal']], abs=1e-9)
        assert all(m.header.frame_id == impact['frame_id'] for m in array.markers)


def test_live_markers_at_the_marker_rate_stamped_by_samples(session: Dict[str, Any]) -> None:
    """Live bat and ball markers at most every 1/marker_rate of log time, while samples come."""
    topic = output_topics()['markers']
    times = [log_time for name, log_time, raw in session['messages'] if name == topic]
    arrays = _decode(session['messages'], topic, 'visualization_msgs/msg/MarkerArray')
    live = [(t, a) for t, a in zip(times, arrays) if {m.ns for m in a.markers} >= {
        'live_bat', 'live_ball'}]
    period_ns = 1e9 / SETTINGS['marker_rate']
    samples = [log_time for name, log_time, _ in session['input_messages']
               if name in ('/ball', '/bat_pose')]
    due, expected = samples[0], 0  # a reference: one at the first sample of each period
    for log_time in samples:
        if log_time >= due:
            expected, due = expected + 1, log_time + period_ns
    assert expected - 2 <= len(live) <= expected and len(live) > 20
    assert all(b - a >= period_ns - 1 for (a, _), (b, _) in zip(live, live[1:]))
    stamps = {_ns(m.header.stamp) for name in ('/ball', '/bat_pose') for m in _decode(
        session['input_messages'], name,
        'geometry_msgs/msg/' + ('PointStamped' if name == '/ball' else 'PoseStamped'))}
    assert all(_ns(a.markers[0].header.stamp) in stamps for _, a in live)
    assert all(m.lifetime.nanosec == int(2e9 / SETTINGS['marker_rate'])
               for _, a in live for m in a.markers)


def test_diagnostics_every_period_counting_the_impacts(session: Dict[str, Any]) -> None:
    """/diagnostics every diagnostics_period of log time (also between pitches); the counts."""
    topic = output_topics()['diagnostics']
    times = [log_time for name, log_time, _ in session['messages'] if name == topic]
    period_ns = int(SETTINGS['diagnostics_period'] * 1e9)
    assert all(b - a == period_ns for a, b in zip(times[:-2], times[1:-1]))
    first = min(t for name, t, _ in session['input_messages'] if name in ('/ball', '/bat_pose'))
    last = max(t for name, t, _ in session['input_messages'] if name in ('/ball', '/bat_pose'))
    assert times[0] == first + period_ns and times[-1] == last
    arrays = _decode(session['messages'], topic, 'diagnostic_msgs/msg/DiagnosticArray')
    levels = {status.level for array in arrays for status in array.status}
    assert levels >= {0, 1}  # tracking during pitches, stale between them
    (final,) = arrays[-1].status
    values = {kv.key: kv.value for kv in final.values}
    assert values['impacts'] == str(len(session['document']['impacts']))
    assert values['near_misses'] == str(len(session['document']['near_misses']))
    assert final.hardware_id == 'baseball_collision'
    assert final.name == 'impact_node: impact detector'


def test_markers_off_and_unknown_types_noted(tmp_path: Path, run_cli: RunCli) -> None:
    """publish_markers false: no ~/markers topic; the events and diagnostics still there."""
    params = tmp_path / 'p.yaml'
    params.write_text('impact_node:\n  ros__parameters:\n    publish_markers: false\n')
    out = tmp_path / 'o.mcap'
    code, _, stderr = run_cli(['analyze', str(bag_path('pitches_360hz.mcap')), '--params',
                               str(params), '--out-bag', str(out), '--quiet'])
    assert code == 0, stderr
    connections, _ = _read(out)
    topics = output_topics()
    assert topics['markers'] not in connections
    assert connections[topics['diagnostics']].msgcount > 0
    assert connections[topics['impact']].msgcount > 0


def test_a_live_sessions_outputs_are_kept_beside_the_analysis(
        tmp_path: Path, run_cli: RunCli) -> None:
    """A bag recorded with /diagnostics and the node's topics: copied under /recorded."""
    source = tmp_path / 'live.mcap'
    topics = output_topics()
    with RawBag(bag_path('pitches_360hz.mcap')) as bag, BagWriter(source) as writer:
        for message in bag.messages():
            writer.write_serialized(message.topic, message.msgtype, message.log_time_ns,
                                    message.data)
        store = writer.typestore
        first = min(m.log_time_ns for m in bag.messages(['/ball']))
        writer.write_message('/diagnostics', store.types['std_msgs/msg/String'](data='other'),
                             first)
        writer.write_point(topics['impact'], first, 'world', (1.0, 2.0, 3.0), first)
    out = tmp_path / 'o.mcap'
    code, stdout, stderr = run_cli(['analyze', str(source), '--out-bag', str(out)])
    assert code == 0, stderr
    assert ('note: --out-bag: the recorded /diagnostics is copied as /recorded/diagnostics'
            in stdout)
    connections, messages = _read(out)
    assert connections['/recorded/diagnostics'].msgtype == 'std_msgs/msg/String'
    assert connections['/diagnostics'].msgtype == 'diagnostic_msgs/msg/DiagnosticArray'
    recorded = _decode(messages, '/recorded' + topics['impact'], 'geometry_msgs/msg/PointStamped')
    assert [(p.point.x, p.point.y, p.point.z) for p in recorded] == [(1.0, 2.0, 3.0)]
    assert connections[topics['impact']].msgcount == 8


def test_custom_types_are_copied_with_the_inputs_own_definitions(
        tmp_path: Path, run_cli: RunCli) -> None:
    """
    A rig's own message types, defined in the bag: copied as recorded, with their definitions.

    ``rig_msgs/msg/Markers`` uses ``rig_msgs/msg/Marker`` (rosbag2 appends the definitions a
    type uses); ``rig_msgs/msg/Blob`` is recorded without a definition: left out, with a note.
    """
    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg('uint32 id\nfloat64[] values\nstring label\n',
                                      'rig_msgs/msg/Marker'))
    store.register(get_types_from_msg('std_msgs/Header header\nrig_msgs/Marker[] markers\n',
                                      'rig_msgs/msg/Markers'))
    types = store.types
    source = tmp_path / 'rig'
    with RawBag(bag_path('pitches_90hz.mcap')) as bag, Writer(
            source, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        markers = writer.add_connection('/rig/markers', 'rig_msgs/msg/Markers', typestore=store)
        blob = writer.add_connection('/rig/blob', 'rig_msgs/msg/Blob', msgdef='',
                                     rihs01='RIHS01_' + '0' * 64)
        connections = {topic.name: writer.add_connection(topic.name, topic.msgtype,
                                                         typestore=store)
                       for topic in bag.topics.values()}
        written = []
        for number, message in enumerate(bag.messages()):
            writer.write(connections[message.topic], message.log_time_ns, message.data)
            if number % 50 == 0:
                rig = types['rig_msgs/msg/Markers'](
                    header=types['std_msgs/msg/Header'](
                        stamp=types['builtin_interfaces/msg/Time'](sec=1, nanosec=number),
                        frame_id='rig'),
                    markers=[types['rig_msgs/msg/Marker'](
                        id=number, values=np.arange(3.0), label='knob')])
                written.append(bytes(store.serialize_cdr(rig, 'rig_msgs/msg/Markers')))
                writer.write(markers, message.log_time_ns, written[-1])
                writer.write(blob, message.log_time_ns, b'\x00\x01\x00\x00\x07\x00\x00\x00')
    out = tmp_path / 'o.mcap'
    source = source / 'rig.mcap'  # (bare: rosbags checks no type hash of the blob there)
    code, stdout, stderr = run_cli(['analyze', str(source), '--out-bag', str(out), '--no-truth'])
    assert code == 0, stderr
    notes = [line for line in stdout.splitlines() if line.startswith('note: --out-bag')]
    assert notes == ['note: --out-bag: /rig/blob not copied (rig_msgs/msg/Blob is not a ROS 2 '
                     'Jazzy type and its definition is not in the bag)']
    with AnyReader([out]) as reader:  # (no default types: the bag's own definitions only)
        copied = [c for c in reader.connections if c.topic == '/rig/markers']
        assert len(copied) == 1 and copied[0].msgtype == 'rig_msgs/msg/Markers'
        raw = [bytes(data) for _, _, data in reader.messages(connections=copied)]
        assert raw == written
        first = reader.deserialize(raw[0], 'rig_msgs/msg/Markers')
        assert first.markers[0].label == 'knob' and list(first.markers[0].values) == [0, 1, 2]
    assert 'rig_msgs/msg/Marker' not in get_typestore(Stores.ROS2_JAZZY).types


def test_remapped_outputs_are_written_where_the_node_would_publish_them(
        tmp_path: Path, run_cli: RunCli) -> None:
    """``--remap``: a node moved to /cage2 with its ~/impact renamed writes those topics."""
    out = tmp_path / 'o.mcap'
    code, _, stderr = run_cli(['analyze', str(bag_path('pitches_90hz.mcap')), '--out-bag',
                               str(out), '--quiet', '--remap', '__ns:=/cage2',
                               '--remap', '~/impact:=/arm/impact'])
    assert code == 0, stderr
    connections, _ = _read(out)
    assert connections['/arm/impact'].msgcount > 0
    assert connections['/cage2/impact_node/impact_report'].msgcount > 0
    assert '/impact_node/impact' not in connections
    assert '/cage2/impact_node/impact' not in connections
