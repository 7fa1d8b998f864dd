"""The demo's pure side: the node's impacts and their records paired and printed."""

import io
from pathlib import Path

from baseball_collision.core.detector import MPS_TO_MPH
from baseball_collision.core.records import contact_from_tip, event_record, record_text
from baseball_collision.errors import ToolError
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag
from baseball_collision.tools.demo import (
    isolated_environment, LiveEvents, node_command, run_demo)
from baseball_collision.tools.parameters import load_parameters
from baseball_collision.tools.truth import compare_truth, load_truth, truth_path
import pytest
from support import REPO_ROOT
from support.bundled import bag_path, PARAMS

BAG = bag_path('pitches_360hz.mcap')


@pytest.mark.parametrize('report_first', [False, True])
def test_live_events_print_an_impact_with_the_nodes_own_numbers(report_first: bool) -> None:
    """
    ``~/impact`` and its ``~/impact_report`` record in either order: one line, the record's.

    The spot and speeds printed are the node's (before, the demo placed ``~/impact``'s point on
    the bag's bat moved rigidly: 11.9 cm and 74.9 mph where the node said 11.7 and 74.6).
    """
    offline = analyze_bag(BAG, AnalysisOptions(parameters=load_parameters(PARAMS)),
                          progress=False)
    out = io.StringIO()
    events = LiveEvents(offline.first_stamp_ns, out)
    events.on_report(record_text(event_record(offline.near_misses[0], 'world', offline.config)))
    for impact in offline.impacts:
        record = record_text(event_record(impact, 'world', offline.config))
        if report_first:
            events.on_report(record)
            assert events.complete_impacts() == [] or events.complete_impacts()[-1].stamp_ns \
                != impact.stamp_ns
        events.on_impact(impact.stamp_ns, impact.point)
        if not report_first:
            events.on_report(record)
    live = events.complete_impacts()
    assert [each.stamp_ns for each in live] == [impact.stamp_ns for impact in offline.impacts]
    assert out.getvalue().count('\n') == len(offline.impacts)
    first = offline.impacts[0]
    assert out.getvalue().startswith(
        f'  impact     {offline.relative_s(first.stamp_ns):8.4f} s  (stamp {first.stamp_ns})  '
        f'{contact_from_tip(first) * 100:5.1f} cm from the tip, sweet spot '
        f'{first.sweet_spot_speed_mps * MPS_TO_MPH:5.1f} mph')
    for each, impact in zip(live, offline.impacts):
        assert each.distance_from_tip_m == pytest.approx(impact.distance_from_tip_m, abs=1e-12)
        assert each.sweet_spot_speed_mps == impact.sweet_spot_speed_mps
    truth = load_truth(truth_path(BAG))
    comparison = compare_truth(live, [], truth, truth_path(BAG))
    assert len(comparison.matched) == len(offline.impacts) and not comparison.false_impacts
    for (pitch, _), each in zip(comparison.matched, live):
        assert abs(each.distance_from_tip_m - pitch['distance_from_tip_m']) < 1e-3
    events.on_near_miss(first.stamp_ns + 5, (0.0, 0.03, -0.04))
    assert out.getvalue().splitlines()[-1].endswith(
        'the ball passed   5.0 cm from the bat (under it)')


def test_the_node_command_takes_the_parameter_file() -> None:
    """The node starts with the parameter file and the transport overrides."""
    command = node_command(Path('p.yaml'))
    assert command[command.index('--params-file') + 1] == 'p.yaml'
    assert 'qos:=reliable_all' in command and 'use_sim_time:=true' in command


def test_the_domain_is_the_one_asked_for_else_random() -> None:
    """isolated_environment(7) runs on domain 7, this host only; None: a random 1-101."""
    env = isolated_environment(7)
    assert env['ROS_DOMAIN_ID'] == '7' and env['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'
    assert 1 <= int(isolated_environment()['ROS_DOMAIN_ID']) <= 101


def test_a_parameter_file_of_other_topics_is_refused_before_the_node_starts() -> None:
    """The points file (topics under /mocap) with the bundled bag: one line, no flag named."""
    with pytest.raises(ToolError) as refused:
        run_demo(params=REPO_ROOT / 'config' / 'impact_node_points.yaml')
    said = str(refused.value)
    assert said.startswith("ball_topic '/mocap/ball' (from the parameter file) is not in the "
                           'bag; topics: /ball (geometry_msgs/msg/PointStamped)')
    assert said.endswith("(the demo replays pitches_360hz.mcap's own topics: give --params a "
                         "file whose topics are the bag's)")
    assert '--ball-topic' not in said and '\n' not in said
