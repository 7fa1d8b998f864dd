"""Parameter files: sections, flattening, configuration precedence, the node's topics."""

from pathlib import Path

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.errors import ToolError
from baseball_collision.tools.parameters import (
    build_config, load_parameters, NODE_NAME, OFFLINE_MODEL, output_topics)
import pytest
from support import REPO_ROOT


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def test_the_bundled_parameter_files_parse() -> None:
    """Both config files give the node's section, flattened, and build a detector config."""
    pose = load_parameters(REPO_ROOT / 'config' / 'impact_node.yaml')
    assert pose['model'] == 'rigid' and pose['bat_input'] == 'pose'
    config = build_config(pose, bat_input='pose')
    assert config.model == 'rigid' and config.profile == WOOD_BAT_34
    points = load_parameters(REPO_ROOT / 'config' / 'impact_node_points.yaml')
    config = build_config(points, bat_input='points')
    assert config.bat_input == 'points' and config.frame_id == 'mocap'
    assert config.profile.length == pytest.approx(0.8382)
    assert config.near_miss_threshold == pytest.approx(0.1)


def test_wildcard_named_and_nested_sections(tmp_path: Path) -> None:
    """'/**' applies first, the node's own section wins; nested keys join with dots."""
    path = _write(tmp_path / 'p.yaml', '\n'.join([
        '/**:', '  ros__parameters:', '    model: linear', '    ball_radius: 0.04',
        '    use_sim_time: true',
        '/team/impact_node:', '  ros__parameters:', '    model: spline',
        '    extra:', '      depth: 3',
        'other_node:', '  ros__parameters:', '    model: rigid']))
    parameters = load_parameters(path)
    assert parameters == {'model': 'spline', 'ball_radius': 0.04, 'use_sim_time': True,
                          'extra.depth': 3}
    only_wildcard = _write(tmp_path / 'w.yaml', '/**:\n  ros__parameters:\n    max_gap: 1\n')
    config = build_config(load_parameters(only_wildcard), bat_input='pose')
    assert config.max_gap == 1.0 and config.model == OFFLINE_MODEL


@pytest.mark.parametrize('text, words', [
    ('other:\n  ros__parameters:\n    model: rigid\n',
     ["no section for node 'impact_node'", 'other']),
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


def test_output_topics_are_the_nodes() -> None:
    """The output bag uses the node's private topic names."""
    assert output_topics(NODE_NAME) == {
        'impact': '/impact_node/impact', 'impact_velocity': '/impact_node/impact_velocity',
        'near_miss': '/impact_node/near_miss',
        'predicted_impact': '/impact_node/predicted_impact'}
