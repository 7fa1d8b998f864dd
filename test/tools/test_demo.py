"""The demo's pure side: the bag's bat over time, and the node's events paired and printed."""

import io
from pathlib import Path

from baseball_collision.core.geometry import add, lerp, rotate, slerp_quaternions
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag
from baseball_collision.tools.demo import (
    BatTrack, isolated_environment, LiveEvents, node_command)
from baseball_collision.tools.parameters import load_parameters
import pytest
from support.bundled import bag_path, PARAMS

BAG = bag_path('pitches_360hz.mcap')


def test_the_bat_moves_rigidly_between_pose_samples() -> None:
    """Between poses: position linear, orientation SLERP; outside the samples: nothing."""
    offline = analyze_bag(BAG, AnalysisOptions(parameters=load_parameters(PARAMS)),
                          progress=False)
    track = BatTrack(BAG, offline.config, offline)
    geometry = offline.config.geometry
    k = 40
    (p0, q0), (p1, q1) = [(s.position, s.quaternion) for s in track.samples[k:k + 2]]
    stamp = track.stamps[k] + (track.stamps[k + 1] - track.stamps[k]) // 3
    s = (stamp - track.stamps[k]) / (track.stamps[k + 1] - track.stamps[k])
    q = slerp_quaternions(q0, q1, s)
    knob, tip = track.ends(stamp)
    assert knob == pytest.approx(add(lerp(p0, p1, s), rotate(q, geometry.knob_offset)),
                                 abs=1e-12)
    assert tip == pytest.approx(add(lerp(p0, p1, s), rotate(q, geometry.tip_offset)), abs=1e-12)
    at_sample = track.ends(track.stamps[k])
    expected = geometry.knob_and_tip(p0, q0)
    assert at_sample[0] == pytest.approx(expected[0]) and at_sample[1] == pytest.approx(
        expected[1])
    assert track.ends(track.stamps[0] - 1) is None and track.ends(track.stamps[-1]) is None


def test_knob_and_tip_points_move_linearly() -> None:
    """A bat given as knob and tip points: each end on its chord."""
    offline = analyze_bag(BAG, AnalysisOptions(knob_topic='/bat_knob', tip_topic='/bat_tip'),
                          progress=False)
    track = BatTrack(BAG, offline.config, offline)
    assert track.model == 'linear' and len(track.samples) == len(track.stamps) > 100
    first, second = track.samples[10:12]
    stamp = (track.stamps[10] + track.stamps[11]) // 2
    s = (stamp - track.stamps[10]) / (track.stamps[11] - track.stamps[10])
    knob, tip = track.ends(stamp)
    assert knob == pytest.approx(lerp(first.knob, second.knob, s), abs=1e-12)
    assert tip == pytest.approx(lerp(first.tip, second.tip, s), abs=1e-12)


def test_live_events_print_an_impact_once_it_has_its_velocity() -> None:
    """Point and twist in either order: one line, placed on the bat; near misses at once."""
    offline = analyze_bag(BAG, AnalysisOptions(parameters=load_parameters(PARAMS)),
                          progress=False)
    impact = offline.impacts[0]
    out = io.StringIO()
    events = LiveEvents(BatTrack(BAG, offline.config, offline), offline.first_stamp_ns, out)
    events.on_velocity(impact.stamp_ns, impact.bat_velocity, impact.bat_angular_velocity)
    assert out.getvalue() == '' and events.complete_impacts() == []
    events.on_impact(impact.stamp_ns, impact.point)
    events.on_velocity(impact.stamp_ns, impact.bat_velocity, impact.bat_angular_velocity)
    live = events.complete_impacts()
    assert len(live) == 1 and out.getvalue().count('\n') == 1
    assert out.getvalue().startswith(f'  impact     {offline.relative_s(impact.stamp_ns):8.4f} s')
    assert live[0].distance_from_tip_m == pytest.approx(impact.distance_from_tip_m, abs=2e-3)
    assert live[0].sweet_spot_speed_mps == pytest.approx(impact.sweet_spot_speed_mps, rel=1e-3)
    events.on_near_miss(impact.stamp_ns + 5, (0.0, 0.03, -0.04))
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
