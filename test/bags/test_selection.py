"""Tests for baseball_collision.bags topic selection: auto-detection, explicit topics, errors."""

from pathlib import Path
from typing import List

from baseball_collision.bags import (
    BagReader, POINT_STAMPED, POSE_STAMPED, read_samples, select_topics, TopicSelection)
from baseball_collision.bags.selection import name_words
from baseball_collision.errors import BagError
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer as Writer2
from support.bagfiles import reference_bag, TS2


def test_auto_detection_unambiguous() -> None:
    """One ball-like and one bat-like topic are picked; knob/tip pairs too; others ignored."""
    selection = select_topics({'/tracker/ball': POINT_STAMPED, '/tracker/bat': POSE_STAMPED,
                               '/camera/image': 'sensor_msgs/msg/Image',
                               '/ball_count': 'std_msgs/msg/String'})
    assert selection == TopicSelection(ball='/tracker/ball', ball_type=POINT_STAMPED,
                                       bat_pose='/tracker/bat')
    assert selection.bat_mode == 'pose'
    points = select_topics({'/baseball': POSE_STAMPED, '/bat/knob': POINT_STAMPED,
                            '/bat/barrel_end': POINT_STAMPED})
    assert (points.ball, points.ball_type, points.knob, points.tip) == (
        '/baseball', POSE_STAMPED, '/bat/knob', '/bat/barrel_end')
    assert points.bat_mode == 'points'
    # 'baseball_bat' names a bat, not a ball; 'multiple' does not contain the word 'tip'.
    named = select_topics({'/baseball_bat/pose': POSE_STAMPED, '/ball': POINT_STAMPED,
                           '/multiple': POINT_STAMPED})
    assert (named.ball, named.bat_pose) == ('/ball', '/baseball_bat/pose')


@pytest.mark.parametrize('topic, words', [
    ('/batting_cage/ball', ['batting', 'cage', 'ball']),
    ('/tracker/batPose2', ['tracker', 'bat', 'pose', '2']),
    ('/MOCAP-Bat.tip', ['mocap', 'bat', 'tip']),
    ('/HTTPServer/baseball', ['http', 'server', 'baseball'])])
def test_topic_names_are_cut_into_whole_words(topic: str, words: List[str]) -> None:
    """Words: at / _ - . and other signs, at camelCase and letter-digit boundaries."""
    assert name_words(topic) == words


def test_a_role_word_inside_another_word_is_not_that_role() -> None:
    """'batting', 'combat', 'handler', 'ballot': no bat, handle or ball."""
    robot = select_topics({'/ball': POINT_STAMPED, '/batting_robot/goal_pose': POSE_STAMPED,
                           '/bat_knob': POINT_STAMPED, '/bat_tip': POINT_STAMPED})
    assert (robot.bat_pose, robot.knob, robot.tip, robot.note) == (
        None, '/bat_knob', '/bat_tip', '')
    cage = select_topics({'/batting_cage/ball': POINT_STAMPED,
                          '/batting_cage/bat': POSE_STAMPED})
    assert (cage.ball, cage.bat_pose) == ('/batting_cage/ball', '/batting_cage/bat')
    others = {'/ball': POINT_STAMPED, '/combat/pose': POSE_STAMPED, '/ballot': POINT_STAMPED,
              '/rig/batPose': POSE_STAMPED, '/handler/point': POINT_STAMPED,
              '/softball2': POINT_STAMPED, '/extended': POINT_STAMPED}
    assert select_topics(others, ball='/ball').bat_pose == '/rig/batPose'
    with pytest.raises(BagError, match='2 ball topics: /ball, /softball2'):
        select_topics(others)


def test_a_batting_robot_bag_is_read_with_its_bat_points(tmp_path: Path) -> None:
    """A real bag: the robot's goal pose is not the bat; the knob and tip points are."""
    bag = tmp_path / 'robot'
    rows = [(topic, msgtype, 10**9 + i, 'world', (0.0,) * 7, 10**9 + i)
            for i, (topic, msgtype) in enumerate([
                ('/batting_cage/ball', POINT_STAMPED), ('/batting_robot/goal_pose', POSE_STAMPED),
                ('/batting_cage/bat_knob', POINT_STAMPED),
                ('/batting_cage/bat_tip', POINT_STAMPED)])]
    reference_bag(bag, rows)
    with BagReader(bag) as reader:
        selection = reader.selection
    assert (selection.ball, selection.bat_pose, selection.knob, selection.tip) == (
        '/batting_cage/ball', None, '/batting_cage/bat_knob', '/batting_cage/bat_tip')


@pytest.mark.parametrize('ball, bat', [('/tracker/ballpos', '/mocap/batpose'),
                                       ('/balls', '/bats'), ('/rig/baseballs', '/rig/batPose')])
def test_run_together_role_words_are_found(ball: str, bat: str) -> None:
    """A word starting with 'ball' is a ball word, one starting with 'bat' a bat word."""
    selection = select_topics({ball: POINT_STAMPED, bat: POSE_STAMPED,
                               '/bat_ballot': POINT_STAMPED})
    assert (selection.ball, selection.bat_pose) == (ball, bat)


def test_words_starting_with_bat_that_are_no_bat() -> None:
    """Batting, batter(y), batch: no bat; a bat word's rest names a part (batknob, battip)."""
    topics = {'/ball': POINT_STAMPED, '/battery/pose': POSE_STAMPED,
              '/batteries': POSE_STAMPED, '/batter/pose': POSE_STAMPED,
              '/batch_pose': POSE_STAMPED, '/battingcage/pose': POSE_STAMPED,
              '/batknob': POINT_STAMPED, '/battip': POINT_STAMPED}
    selection = select_topics(topics)
    assert (selection.ball, selection.bat_pose, selection.knob, selection.tip) == (
        '/ball', None, '/batknob', '/battip')
    assert select_topics(dict(topics, **{'/bats/pose': POSE_STAMPED})).bat_pose == '/bats/pose'
    with pytest.raises(BagError, match='no ball topic found'):
        select_topics({'/battip/ball': POINT_STAMPED, '/bat': POSE_STAMPED})


def test_run_together_topic_names_are_found_in_a_real_bag(tmp_path: Path) -> None:
    """A tracker's /tracker/ballpos and a mocap's /mocap/batpose: read without any flag."""
    bag = tmp_path / 'names'
    rows = [(topic, msgtype, 10**9 + i, 'world', (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
             10**9 + i)
            for i, (topic, msgtype) in enumerate([
                ('/tracker/ballpos', POINT_STAMPED), ('/mocap/batpose', POSE_STAMPED),
                ('/battery/state', POSE_STAMPED)])]
    reference_bag(bag, rows)
    with BagReader(bag) as reader:
        selection = reader.selection
    assert (selection.ball, selection.bat_pose) == ('/tracker/ballpos', '/mocap/batpose')


def test_explicit_topics_override_detection() -> None:
    """Names given win, and a given knob picks the knob+tip bat with the tip detected."""
    topics = {'/ball_a': POINT_STAMPED, '/ball_b': POINT_STAMPED, '/bat': POSE_STAMPED,
              '/hand/knob': POINT_STAMPED, '/hand/tip': POINT_STAMPED, '/x': POINT_STAMPED}
    chosen = select_topics(topics, ball='/ball_b', knob='/x')
    assert (chosen.ball, chosen.bat_pose, chosen.knob, chosen.tip) == (
        '/ball_b', None, '/x', '/hand/tip')
    assert select_topics(topics, ball='/ball_a', bat_pose='/bat').bat_pose == '/bat'


def test_bat_pose_preferred_to_knob_and_tip_points() -> None:
    """A bag with both bats (as `simulate` writes) uses the pose and notes the points."""
    topics = {'/ball': POINT_STAMPED, '/bat': POSE_STAMPED, '/bat/knob': POINT_STAMPED,
              '/bat/tip': POINT_STAMPED}
    chosen = select_topics(topics)
    assert (chosen.bat_pose, chosen.knob, chosen.tip) == ('/bat', None, None)
    assert '/bat/knob' in chosen.note and '--knob-topic + --tip-topic' in chosen.note
    assert '\n' not in chosen.note
    points = select_topics(topics, prefer_bat='points')
    assert (points.bat_pose, points.knob, points.tip) == (None, '/bat/knob', '/bat/tip')
    assert '--bat-pose-topic' in points.note
    assert select_topics(topics, knob='/bat/knob').note == ''
    assert select_topics({'/ball': POINT_STAMPED, '/bat': POSE_STAMPED}).note == ''
    with pytest.raises(BagError, match='prefer_bat'):
        select_topics(topics, prefer_bat='knob')


@pytest.mark.parametrize('topics, kwargs, flag, words', [
    ({'/ball_a': POINT_STAMPED, '/ball_b': POINT_STAMPED, '/bat': POSE_STAMPED}, {},
     '--ball-topic', ['/ball_a', '/ball_b']),
    ({'/p': POINT_STAMPED, '/bat': POSE_STAMPED}, {}, '--ball-topic', ['/p (geometry_msgs']),
    ({'/ball': POINT_STAMPED, '/bat/knob': POINT_STAMPED}, {}, '--tip-topic', ['no tip']),
    ({'/ball': POINT_STAMPED}, {}, '--bat-pose-topic', ['no bat_pose']),
    ({'/ball': POINT_STAMPED, '/bat': POSE_STAMPED}, {'ball': '/missing'}, '--ball-topic',
     ['not in the bag', '/bat (geometry_msgs/msg/PoseStamped)']),
    ({'/ball': 'std_msgs/msg/String', '/bat': POSE_STAMPED}, {'ball': '/ball'}, '--ball-topic',
     ['has type std_msgs/msg/String']),
    ({'/ball': POINT_STAMPED, '/bat': POINT_STAMPED}, {'bat_pose': '/bat'},
     '--bat-pose-topic', ['; the bat_pose topic needs geometry_msgs/msg/PoseStamped']),
    ({'/ball': POINT_STAMPED, '/bat': POSE_STAMPED, '/k': POINT_STAMPED},
     {'bat_pose': '/bat', 'knob': '/k'}, '--bat-pose-topic', ['not both']),
])
def test_selection_errors_name_the_flag(topics: dict, kwargs: dict, flag: str,
                                        words: List[str]) -> None:
    """Every selection error is one line naming the flag to pass (and what it found)."""
    with pytest.raises(BagError) as caught:
        select_topics(topics, **kwargs)
    message = str(caught.value)
    assert '\n' not in message
    assert flag in message
    for word in words:
        assert word in message


def test_selection_errors_from_a_real_bag(tmp_path: Path) -> None:
    """A bag without the needed topics, or with a wrong explicit topic, raises BagError."""
    path = tmp_path / 'unrelated'
    with Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection('/chatter', 'std_msgs/msg/String', typestore=TS2)
        writer.write(conn, 1, TS2.serialize_cdr(
            TS2.types['std_msgs/msg/String'](data='hi'), 'std_msgs/msg/String'))
    with pytest.raises(BagError, match='no ball topic found.*--ball-topic.*/chatter'):
        BagReader(path).open()
    with pytest.raises(BagError, match="--ball-topic '/chatter' has type std_msgs/msg/String"):
        list(read_samples(path, ball='/chatter', bat_pose='/chatter'))
