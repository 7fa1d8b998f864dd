"""Parameter files: sections, flattening, configuration precedence, the node's topics."""

from pathlib import Path
import re
from typing import Callable, List, Tuple

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.errors import ToolError
from baseball_collision.tools.analyze import AnalysisOptions, analyze_bag
from baseball_collision.tools.parameters import (
    build_config, load_parameters, NODE_NAME, OFFLINE_MODEL, OFFLINE_PARAMETERS, output_topics,
    Remapping, resolve_topic)
from baseball_collision.tools.report import summary_line
import pytest
from support import REPO_ROOT
from support.bagfiles import reference_bag, still_rows

RunCli = Callable[[List[str]], Tuple[int, str, str]]


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def test_the_bundled_parameter_files_parse() -> None:
    """Both config files give the node's section, flattened, and build a detector config."""
    pose = load_parameters(REPO_ROOT / 'config' / 'impact_node.yaml')
    assert pose['model'] == 'c2' and pose['bat_input'] == 'pose'
    config = build_config(pose, bat_input='pose')
    assert (config.model, config.look_ahead, config.tracker_noise) == ('c2', 0, -1.0)
    assert config.profile == WOOD_BAT_34
    points = load_parameters(REPO_ROOT / 'config' / 'impact_node_points.yaml')
    config = build_config(points, bat_input='points')
    assert config.bat_input == 'points' and config.frame_id == 'mocap'
    assert config.profile.length == pytest.approx(0.8382)
    assert config.near_miss_threshold == pytest.approx(0.1)


def test_wildcard_named_and_nested_sections(tmp_path: Path) -> None:
    """
    '/**' applies, then the node's own section (later in the file: it wins); nested keys join.

    A section under a namespace applies to the node of that namespace only, as in rcl (the
    node's own parameters against these files: test/ros/test_parameters.py).
    """
    path = _write(tmp_path / 'p.yaml', '\n'.join([
        '/**:', '  ros__parameters:', '    model: linear', '    ball_radius: 0.04',
        '    use_sim_time: true',
        '/team/impact_node:', '  ros__parameters:', '    model: spline',
        '    extra:', '      depth: 3',
        'other_node:', '  ros__parameters:', '    model: rigid']))
    parameters = load_parameters(path, 'team/impact_node')
    assert parameters == {'model': 'spline', 'ball_radius': 0.04, 'use_sim_time': True,
                          'extra.depth': 3}
    assert load_parameters(path) == {'model': 'linear', 'ball_radius': 0.04,
                                     'use_sim_time': True}
    only_wildcard = _write(tmp_path / 'w.yaml', '/**:\n  ros__parameters:\n    max_gap: 1\n')
    config = build_config(load_parameters(only_wildcard), bat_input='pose')
    assert config.max_gap == 1.0 and config.model == OFFLINE_MODEL


@pytest.mark.parametrize('text, words', [
    ('other:\n  ros__parameters:\n    model: rigid\n',
     ["no section for node '/impact_node'", 'other']),
    ('impact_node:\n  model: rigid\n', ['no ros__parameters']),
    ('impact_node: [unclosed\n', ['not valid YAML']),
    ('- a\n- b\n', ['not a mapping']),
])
def test_bad_parameter_files(tmp_path: Path, text: str, words: list) -> None:
    """A parameter file that cannot be used raises one line naming the problem."""
    with pytest.raises(ToolError) as caught:
        load_parameters(_write(tmp_path / 'bad.yaml', text))
    message = str(caught.value)
    assert '\n' not in message
    for word in words:
        assert word in message
    with pytest.raises(ToolError, match='cannot read parameter file'):
        load_parameters(tmp_path / 'missing.yaml')


def test_the_offline_default_is_c2_with_look_ahead_2_and_auto_noise() -> None:
    """
    No model named: ``c2``, look-ahead 2, noise auto, each where the file does not say.

    A model named by a flag or by the file keeps the node's defaults (a node's file gives the
    node's answers).
    """
    config = build_config({}, bat_input='pose')
    assert (config.model, config.look_ahead, config.tracker_noise) == ('c2', 2, -1.0)
    assert OFFLINE_PARAMETERS == {'look_ahead': 2, 'tracker_noise': -1.0}
    config = build_config({'look_ahead': 1, 'max_gap': 1.0}, bat_input='pose')
    assert (config.model, config.look_ahead, config.tracker_noise) == ('c2', 1, -1.0)
    config = build_config({'tracker_noise': 0.001}, bat_input='points')
    assert (config.look_ahead, config.tracker_noise) == (2, 0.001)
    for named in (build_config({'model': 'c2'}, bat_input='pose'),
                  build_config({}, bat_input='pose', model='c2')):
        assert (named.model, named.look_ahead, named.tracker_noise) == ('c2', 0, -1.0)
    assert build_config({}, bat_input='pose', model='spline').tracker_noise == -1.0
    told = build_config({'tracker_noise': 0.0}, bat_input='pose', model='rigid')
    assert (told.model, told.look_ahead, told.tracker_noise) == ('rigid', 0, 0.0)


def test_flags_win_over_the_parameter_file() -> None:
    """model, ball_radius and bat_radius: flag > parameter file > offline default."""
    parameters = {'model': 'linear', 'ball_radius': 0.05, 'bat_input': 'pose'}
    assert build_config({}, bat_input='pose').model == OFFLINE_MODEL
    assert build_config(parameters, bat_input='pose').model == 'linear'
    config = build_config(parameters, bat_input='points', model='rigid', ball_radius=0.03,
                          bat_radius=0.02)
    assert (config.model, config.bat_input, config.ball_radius) == ('rigid', 'points', 0.03)
    assert config.profile.max_radius == pytest.approx(0.02)
    assert len(config.profile.stations) == 2
    with pytest.raises(ToolError, match='ball_radius'):
        build_config({'ball_radius': -1.0}, bat_input='pose')


def test_analyze_predicts_only_with_predict() -> None:
    """
    The file's ``prediction_horizon`` is the node's (on by default): analyze predicts on --predict.

    Then at the file's ``prediction_period``, else the table's (the node's cadence).
    """
    node_file = {'prediction_horizon': 0.3, 'prediction_period': 0.02}
    assert build_config({}, bat_input='pose').prediction_horizon == 0.0
    assert build_config(node_file, bat_input='pose').prediction_horizon == 0.0
    config = build_config(node_file, bat_input='pose', prediction_horizon=0.2)
    assert (config.prediction_horizon, config.prediction_period) == (0.2, 0.02)
    config = build_config({}, bat_input='pose', prediction_horizon=0.3)
    assert (config.prediction_horizon, config.prediction_period) == (0.3, 0.01)


def test_output_topics_are_the_nodes() -> None:
    """The output bag uses the node's private topic names."""
    assert output_topics(NODE_NAME) == {
        'impact': '/impact_node/impact', 'impact_velocity': '/impact_node/impact_velocity',
        'near_miss': '/impact_node/near_miss',
        'predicted_impact': '/impact_node/predicted_impact',
        'impact_report': '/impact_node/impact_report', 'markers': '/impact_node/markers',
        'diagnostics': '/diagnostics'}
    assert output_topics('/ns/other')['markers'] == '/ns/other/markers'


@pytest.mark.parametrize('line, words', [
    ('bat_profile: [0, 0.03, 0.8636, 0.03]', ["'bat_profile' mixes value types", 'float, int']),
    ('up_axis: [0.0, 0.0, 1]', ["'up_axis' mixes value types"]),
    ("ball_topic: 'a b'", ["'ball_topic' = 'a b': Invalid topic name", 'alphanumerics']),
    ("knob_topic: 'mocap//knob'", ['Invalid topic name', "repeated '/'"]),
    ("tip_topic: '2tip'", ['Invalid topic name', 'number']),
    # refused once expanded in the root namespace ('///tip_2'), as the node refuses it
    ("tip_topic: '/{ns}/tip_2'", ["'tip_topic' = '/{ns}/tip_2': Invalid topic name",
                                  "repeated '/'"]),
    ("bat_plan_topic: '{foo}/plan'", ['Invalid topic name', 'unknown substitution {foo}']),
])
def test_what_the_node_refuses_is_refused(tmp_path: Path, line: str, words: list) -> None:
    """Lists mixing int and float (rcl's parser), topic names rcl refuses: refused here too."""
    path = _write(tmp_path / 'p.yaml', f'impact_node:\n  ros__parameters:\n    {line}\n')
    with pytest.raises(ToolError) as caught:
        load_parameters(path)
    for word in words:
        assert word in str(caught.value)
    fine = _write(tmp_path / 'f.yaml', 'impact_node:\n  ros__parameters:\n    up_axis: '
                  "[0, 0, 1]\n    ball_topic: '~/ball'\n    tip_topic: /{node}/tip_2\n")
    assert load_parameters(fine)['up_axis'] == [0, 0, 1]


@pytest.mark.parametrize('node_name', ['impact_node', '/impact_node', 'cage2/impact_node',
                                       '/lab/cage2/tracker'])
def test_topics_are_expanded_as_rcl_expands_them(tmp_path: Path, node_name: str) -> None:
    """
    A parameter file's topic is expanded as the node expands it: rclpy's own expansion.

    The node's namespace before a relative name (``ball`` was ``/ball`` for
    ``cage2/impact_node``, whose node subscribes ``/cage2/ball``), ``~`` its full name,
    ``{node}``, ``{ns}`` and ``{namespace}`` substituted.
    """
    from rclpy.expand_topic_name import expand_topic_name

    namespace, _, name = ('/' + node_name.strip('/')).rpartition('/')
    for topic in ('ball', 'mocap/ball', '/ball', '~', '~/bat', '{node}/x', '{ns}/x',
                  '{namespace}/x', 'a/{node}', '/{ns}/y', '~/{node}'):
        assert resolve_topic(topic, node_name) == \
            expand_topic_name(topic, name, namespace or '/'), topic
    with pytest.raises(ToolError, match=re.escape('unknown substitution {foo}')):
        resolve_topic('{foo}/x', node_name)
    path = _write(tmp_path / 'p.yaml', '/**:\n  ros__parameters:\n    ball_topic: ball\n'
                  "    bat_pose_topic: '~/bat'\n")
    options = AnalysisOptions(parameters=load_parameters(path, node_name), node_name=node_name)
    assert (options.topic('ball'), options.topic('bat_pose')) == (
        f'{namespace}/ball', f'{namespace}/{name}/bat')


def test_the_parameter_files_topics_are_read(tmp_path: Path, run_cli: RunCli) -> None:
    """A file's topics are used (resolved as the node does); a flag overrides them."""
    bag = str(REPO_ROOT / 'bags' / 'pitches_90hz.mcap')
    points = _write(tmp_path / 'p.yaml', 'impact_node:\n  ros__parameters:\n'
                    '    bat_input: points\n    knob_topic: bat_knob\n    tip_topic: /bat_tip\n')
    code, stdout, stderr = run_cli(['analyze', bag, '--params', str(points), '--no-truth'])
    assert code == 0 and 'bat /bat_knob + /bat_tip (knob/tip)' in stdout, stderr
    other = _write(tmp_path / 'o.yaml', 'impact_node:\n  ros__parameters:\n'
                   '    ball_topic: tracking/ball\n')
    code, _, stderr = run_cli(['analyze', bag, '--params', str(other)])
    assert code == 2 and stderr.startswith(
        "baseball-collision: error: ball_topic '/tracking/ball' (from the parameter file; "
        '--ball-topic overrides it) is not in the bag; topics: ')
    code, _, _ = run_cli(['analyze', bag, '--params', str(other), '--ball-topic', '/ball',
                          '--quiet'])
    assert code == 0


def test_remapped_topics_are_read_as_the_node_would_read_them(
        tmp_path: Path, run_cli: RunCli) -> None:
    """
    ``--remap``: the node's default or file topics renamed; the node moved or renamed.

    A rule for the default topic names it in the error; a file's relative topic moves with
    ``__ns`` and a rule brings it back; a rule for another node does nothing; a flag wins over
    a rule; a rule rcl refuses is one line and exit 2.
    """
    bag = str(REPO_ROOT / 'bags' / 'pitches_90hz.mcap')
    code, _, stderr = run_cli(['analyze', bag, '--remap', 'ball:=/tracking/ball'])
    assert code == 2 and stderr.startswith(
        "baseball-collision: error: ball_topic '/tracking/ball' (the default, remapped by "
        '--remap ball:=/tracking/ball; --ball-topic overrides it) is not in the bag')
    code, _, _ = run_cli(['analyze', bag, '--remap', 'ball:=/tracking/ball', '--ball-topic',
                          '/ball', '--quiet'])
    assert code == 0
    code, _, _ = run_cli(['analyze', bag, '--remap', 'other_node:ball:=/tracking/ball',
                          '--quiet'])
    assert code == 0
    params = _write(tmp_path / 'p.yaml', '/**:\n  ros__parameters:\n    ball_topic: ball\n'
                    '    bat_pose_topic: bat_pose\n')
    code, _, stderr = run_cli(['analyze', bag, '--params', str(params), '--remap',
                               '__ns:=/cage2'])
    assert code == 2 and "ball_topic '/cage2/ball' (from the parameter file; " in stderr
    code, stdout, stderr = run_cli(['analyze', bag, '--params', str(params), '--remap',
                                    '__ns:=/cage2', '--remap', 'ball:=/ball', '--remap',
                                    '/cage2/bat_pose:=/bat_pose', '--no-truth'])
    assert code == 0 and 'ball /ball, bat /bat_pose (pose)' in stdout, stderr
    code, _, stderr = run_cli(['analyze', bag, '--remap', '__ns:=cage2'])
    assert code == 2 and stderr == ("baseball-collision: error: remapping rule '__ns:=cage2': "
                                    'a namespace must be absolute (/cage2)\n')


def test_a_renamed_node_takes_its_own_section(tmp_path: Path) -> None:
    """``__node:=arm`` (``--remap``): the parameter file's section for ``arm`` applies."""
    params = _write(tmp_path / 'p.yaml', 'arm:\n  ros__parameters:\n    ball_topic: /arm_ball\n'
                    'impact_node:\n  ros__parameters:\n    ball_topic: /node_ball\n')
    remapping = Remapping.parse(['__node:=arm'])
    options = AnalysisOptions(parameters=load_parameters(params, remapping.node_name),
                              remaps=('__node:=arm',))
    assert remapping.node_name == 'arm' and options.topic('ball') == '/arm_ball'
    with pytest.raises(ToolError, match='takes a sequence of rules'):
        AnalysisOptions(remaps='ball:=/x')


def test_every_sample_dropped_is_an_error(tmp_path: Path, run_cli: RunCli) -> None:
    """frame_id of another frame drops every sample: exit 2 with the reason, no output."""
    wrong = _write(tmp_path / 'w.yaml', 'impact_node:\n  ros__parameters:\n    frame_id: map\n')
    out = tmp_path / 'o.json'
    code, stdout, stderr = run_cli(['analyze', str(REPO_ROOT / 'bags' / 'pitches_90hz.mcap'),
                                    '--params', str(wrong), '--json', str(out)])
    assert code == 2 and stdout == '' and not out.exists()
    assert 'every sample of /ball (430) and /bat_pose (430) was dropped (wrong_frame)' in stderr
    assert "frame_id 'map' is configured and /ball in 'world', /bat_pose in 'world'" in stderr
    assert len(stderr.splitlines()) == 1


def test_a_bat_in_another_frame_than_the_ball_names_both_frames(
        tmp_path: Path, run_cli: RunCli) -> None:
    """
    No frame_id configured, the bat's samples in another frame: no frame is adopted.

    The bat's samples wait for a frame every input sends and are dropped as
    ``no_common_frame`` (the ball's frame, the most common, was adopted and the bat dropped as
    ``wrong_frame``); the error names each stream's frame, and the summary counts the reason.
    """
    bag = tmp_path / 'frames'
    reference_bag(bag, still_rows(40, 30, 10_000_000, 'mocap'))
    code, _, stderr = run_cli(['analyze', str(bag), '--no-truth'])
    assert code == 2
    assert stderr.splitlines() == [
        f'baseball-collision: error: {bag}: every sample of /bat_pose (30) was dropped '
        "(no_common_frame): ball sends 'world', bat_pose sends 'mocap': no frame every input "
        "sends, so none was adopted (frame_id ''): set frame_id or transform one stream into "
        "the other's frame (no TF)"]
    analysis = analyze_bag(bag, AnalysisOptions(), progress=False, use_truth=False)
    assert 'dropped (no_common_frame 30)' in summary_line(analysis)
    assert analysis.frame_disagreement == "ball sends 'world', bat_pose sends 'mocap'"


def test_yaml_aliases_and_deep_nesting_are_refused(tmp_path: Path) -> None:
    """A 'billion laughs' alias bomb and 10,000 nested lists: one line each, read as events."""
    bomb = ['a0: &a0 [x, x, x, x, x, x, x, x, x]']
    bomb += [f'a{i}: &a{i} [' + ', '.join([f'*a{i - 1}'] * 9) + ']' for i in range(1, 10)]
    path = _write(tmp_path / 'bomb.yaml', '\n'.join(bomb) + '\nimpact_node:\n  '
                  'ros__parameters:\n    bat_profile: *a9\n')
    with pytest.raises(ToolError, match=r'YAML aliases are not allowed \(line 2\)'):
        load_parameters(path)
    deep = _write(tmp_path / 'deep.yaml', 'impact_node:\n  ros__parameters:\n    up_axis: '
                  + '[' * 10_000 + ']' * 10_000 + '\n')
    with pytest.raises(ToolError, match='nested deeper than 32 levels'):
        load_parameters(deep)


def test_long_bat_profiles_are_refused_quickly(tmp_path: Path) -> None:
    """More than 256 stations: the table's refusal; a million values: refused while parsing."""
    def profile(stations: int) -> Path:
        flat = ', '.join(f'{0.8 * i / stations:.6f}, 0.03' for i in range(stations))
        return _write(tmp_path / f'{stations}.yaml',
                      f'impact_node:\n  ros__parameters:\n    bat_profile: [{flat}]\n')

    assert len(build_config(load_parameters(profile(256)), bat_input='pose').profile
               .stations) == 256
    with pytest.raises(ToolError, match="'bat_profile' has 600 values, at most 512 are taken"):
        load_parameters(profile(300))
    with pytest.raises(ToolError, match=r'a list longer than 4096 values \(line 3\)'):
        load_parameters(profile(500_000))
