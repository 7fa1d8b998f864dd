"""The Foxglove layout and the RViz config: the node's topics, its frame, installed."""

import json
import runpy
from typing import Any, Dict, Iterator, List
from unittest import mock

from baseball_collision.core.health import HARDWARE_ID
from baseball_collision.tools.parameters import NODE_NAME, output_topics
import pytest
from support import REPO_ROOT
import yaml

LAYOUT = REPO_ROOT / 'config' / 'foxglove_layout.json'
RVIZ = REPO_ROOT / 'config' / 'impact_node.rviz'
INPUT_TOPICS = {'/ball', '/bat_pose', '/bat_knob', '/bat_tip'}  # bags/README.md


def _panel_ids(tree: Any) -> Iterator[str]:
    if isinstance(tree, str):
        yield tree
    else:
        yield from _panel_ids(tree['first'])
        yield from _panel_ids(tree['second'])


def _topic_of(path: str) -> str:
    """Return the topic of a Foxglove message path (``/a/b.field.x`` -> ``/a/b``)."""
    return path.split('.', 1)[0]


def test_foxglove_layout_shows_the_nodes_topics() -> None:
    """3D: markers and impact points visible; report, plot and diagnostics on real topics."""
    layout: Dict[str, Any] = json.loads(LAYOUT.read_text())
    panels = layout['configById']
    assert sorted(_panel_ids(layout['layout'])) == sorted(panels)
    outputs = output_topics()
    (three_d,) = [config for name, config in panels.items() if name.startswith('3D!')]
    visible = {topic for topic, shown in three_d['topics'].items() if shown['visible']}
    assert visible == {outputs['markers'], outputs['impact'], outputs['predicted_impact']}
    assert set(three_d['topics']) <= set(outputs.values()) | INPUT_TOPICS
    assert three_d['followTfFrame'] == 'world'
    paths: List[str] = [panels['RawMessages!report']['topicPath']]
    paths += [entry['value'] for name, config in panels.items() if name.startswith('Plot!')
              for entry in config['paths']]
    paths += [config['topicToRender'] for name, config in panels.items()
              if name.startswith('Diagnostic')]
    assert {_topic_of(path) for path in paths} <= set(outputs.values()) | INPUT_TOPICS
    assert _topic_of(paths[0]) == outputs['impact_report']
    status = panels['DiagnosticStatusPanel!detector']
    assert status['selectedHardwareId'] == HARDWARE_ID
    assert status['selectedName'] == f'{NODE_NAME}: impact detector'


def test_rviz_config_shows_the_nodes_topics_with_its_qos() -> None:
    """The displays subscribe to the node's topics, reliable like its publishers; frame world."""
    config = yaml.safe_load(RVIZ.read_text())
    manager = config['Visualization Manager']
    assert manager['Global Options']['Fixed Frame'] == 'world'
    topics = {display['Topic']['Value']: display['Topic'] for display in manager['Displays']
              if 'Topic' in display}
    outputs = output_topics()
    assert set(topics) == {outputs['markers'], outputs['impact'], outputs['predicted_impact']}
    assert all(qos['Reliability Policy'] == 'Reliable' and qos['Durability Policy'] == 'Volatile'
               for qos in topics.values())


def test_views_and_the_cli_names_are_installed(monkeypatch: pytest.MonkeyPatch) -> None:
    """setup.py installs both files into share/<package>/config; both CLI names are scripts."""
    monkeypatch.chdir(REPO_ROOT)
    with mock.patch('setuptools.setup') as setup:
        runpy.run_path(str(REPO_ROOT / 'setup.py'), run_name='__main__')
    arguments = setup.call_args.kwargs
    installed = {file for target, files in arguments['data_files']
                 if target == 'share/baseball_collision/config' for file in files}
    assert {'config/foxglove_layout.json', 'config/impact_node.rviz'} <= installed
    scripts = arguments['entry_points']['console_scripts']
    targets = dict(tuple(part.strip() for part in line.split('=')) for line in scripts)
    assert set(targets) >= {'baseball-collision', 'baseball_collision', 'impact_node'}
    # through the functions that start numpy with one BLAS thread (test_threads.py)
    assert {target.split(':')[0] for target in targets.values()} == {
        'baseball_collision.entry_points'}
