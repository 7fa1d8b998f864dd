"""The analysis layer: parameter files, configuration precedence, truth files, outputs."""

import json
from pathlib import Path
import sys
from typing import Any, Dict

from baseball_collision.core.bat import WOOD_BAT_34
from baseball_collision.core.detector import NearMiss
from baseball_collision.errors import ToolError
from baseball_collision.tools.analysis import (
    _progress, build_config, compare_truth, load_parameters, NODE_NAME, OFFLINE_MODEL,
    output_topics, Outputs, truth_path)
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


def test_truth_file_names() -> None:
    """The truth file sits beside the bag, the bag suffix replaced."""
    assert truth_path('runs/a.mcap') == Path('runs/a.truth.json')
    assert truth_path('runs/a.db3') == Path('runs/a.truth.json')
    assert truth_path('a.bag') == Path('a.truth.json')
    assert truth_path('runs/session.v2') == Path('runs/session.v2.truth.json')


class _Hit:

    def __init__(self, stamp_ns: int, from_tip: float = 0.1, speed: float = 30.0) -> None:
        self.stamp_ns = stamp_ns
        self.distance_from_tip_m = from_tip
        self.sweet_spot_speed_mps = speed


def _pitch(start: int, contact: bool, stamp: int = 0) -> Dict[str, Any]:
    return {'name': f'p{start}', 'kind': 'barrel' if contact else 'miss_over',
            'start_ns': start, 'end_ns': start + 1000, 'contact': contact,
            'stamp_ns': stamp if contact else None, 'distance_from_tip_m': 0.1 if contact
            else None, 'sweet_spot_speed_mps': 30.0 if contact else None}


def test_truth_comparison_matches_per_pitch() -> None:
    """Closest impact in a pitch's span is the match; others and strays are false impacts."""
    truth = {'pitches': [_pitch(0, True, 500), _pitch(2000, True, 2500), _pitch(4000, False)]}
    impacts = [_Hit(510, 0.101, 30.3), _Hit(700), _Hit(3500), _Hit(9000)]
    misses = [NearMiss(4100, 0.05, (0.0, 0.0, 0.05), (0.0, 0.0, 0.0), 0.9, 0.08)]
    result = compare_truth(impacts, misses, truth, 'x.truth.json')
    assert result.contacts == 2 and len(result.matched) == 1
    assert [p['name'] for p in result.missed] == ['p2000']
    assert [i.stamp_ns for i in result.false_impacts] == [700, 3500, 9000]
    assert result.time_errors_ns == [10]
    assert result.spot_errors_m == [pytest.approx(0.001)]
    assert result.speed_errors == [pytest.approx(0.01)]
    assert (result.misses, result.near_misses_in_misses) == (1, 1)
    data = result.as_dict()
    assert data['max_abs_time_error_ns'] == 10 and data['missed'] == ['p2000']
    json.dumps(data, allow_nan=False)
    with pytest.raises(ToolError, match='malformed pitch'):
        compare_truth([], [], {'pitches': [{'contact': True}]}, 'x')


def test_outputs_are_all_or_nothing(tmp_path: Path) -> None:
    """Nothing appears before commit; an exception removes every temporary."""
    targets = {'json': tmp_path / 'a.json', 'plot': tmp_path / 'plots',
               'out_bag': tmp_path / 'o.mcap'}
    with pytest.raises(RuntimeError):
        with Outputs(**targets) as outputs:
            outputs.bag_writer('out_bag', 'mcap').write_point('/x', 1, 'f', (0.0, 0.0, 0.0))
            outputs.stage_text('json', '{}')
            outputs.stage_directory('plot', lambda d: (d / 'a.png').write_bytes(b'x'))
            raise RuntimeError('boom')
    assert list(tmp_path.iterdir()) == []
    with Outputs(**targets) as outputs:
        outputs.bag_writer('out_bag', 'mcap').write_point('/x', 1, 'f', (0.0, 0.0, 0.0))
        outputs.stage_text('json', '{}')
        outputs.stage_directory('plot', lambda d: (d / 'a.png').write_bytes(b'x'))
        assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith('.')) == []
        outputs.commit()
    assert sorted(p.name for p in tmp_path.iterdir()) == ['a.json', 'o.mcap', 'plots']
    assert (tmp_path / 'plots' / 'a.png').read_bytes() == b'x'
    with pytest.raises(ToolError, match='exists already'):
        Outputs(json=tmp_path / 'a.json')
    with pytest.raises(ToolError, match='does not exist'):
        Outputs(csv=tmp_path / 'nowhere' / 'a.csv')


def test_progress_bar_only_on_long_bags_or_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    """A tqdm bar on stderr above 100k messages; none for a short bag off a terminal."""
    monkeypatch.setattr(sys.stderr, 'isatty', lambda: False)
    assert _progress(1000, 'x') is None
    bar = _progress(200_000, 'x')
    assert bar is not None
    bar.close()


def test_output_topics_are_the_nodes() -> None:
    """The output bag uses the node's private topic names."""
    assert output_topics(NODE_NAME) == {
        'impact': '/impact_node/impact', 'impact_velocity': '/impact_node/impact_velocity',
        'near_miss': '/impact_node/near_miss',
        'predicted_impact': '/impact_node/predicted_impact'}
