"""
Tests for launch/impact_node.launch.py (needs launch_ros: a ROS 2 Jazzy install).

The PyPI wheels this repository's venv uses have no ``launch``/``launch_ros``, so here the
module is skipped; in a sourced Jazzy workspace (``colcon test``) it runs.
"""

import importlib.util
from pathlib import Path
from types import ModuleType
from typing import List

import pytest
from support import REPO_ROOT

launch_ros = pytest.importorskip('launch_ros')

from launch import LaunchContext, LaunchDescription  # noqa: E402, I100 - after the skip
from launch.actions import DeclareLaunchArgument, OpaqueFunction  # noqa: E402
from launch.utilities import perform_substitutions  # noqa: E402
from launch_ros.actions import Node  # noqa: E402

LAUNCH_FILE = REPO_ROOT / 'launch' / 'impact_node.launch.py'
CONFIG = REPO_ROOT / 'config' / 'impact_node.yaml'


def load_launch_file(path: Path) -> ModuleType:
    """Import a ``*.launch.py`` file as a module."""
    spec = importlib.util.spec_from_file_location('impact_node_launch', path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def description() -> LaunchDescription:
    """Return the launch description the file generates."""
    return load_launch_file(LAUNCH_FILE).generate_launch_description()


def test_arguments_default_to_the_package_share_params_file(
        description: LaunchDescription) -> None:
    """params_file defaults to <share>/baseball_collision/config/impact_node.yaml."""
    arguments = {a.name: a for a in description.entities if isinstance(a, DeclareLaunchArgument)}
    assert set(arguments) == {'params_file', 'use_sim_time', 'namespace', 'log_level',
                              'remappings'}
    default = ' '.join(s.describe() for s in arguments['params_file'].default_value)
    assert 'baseball_collision' in default and 'impact_node.yaml' in default
    assert arguments['use_sim_time'].default_value[0].describe() == "'false'"


def command_line(node: Node, context: LaunchContext) -> List[str]:
    """Return the node's command line after substitution (the executable may not resolve)."""
    node._perform_substitutions(context)  # what execute() does first: adds the ROS arguments
    words = []
    for part in node.cmd:
        try:
            words.append(perform_substitutions(context, part))
        except Exception:  # the executable, when the package is not installed here
            words.append('<unresolved>')
    return words


def test_node_action_runs_impact_node_with_the_params_file(
        description: LaunchDescription) -> None:
    """The Node action starts baseball_collision/impact_node with the arguments given."""
    functions = [e for e in description.entities if isinstance(e, OpaqueFunction)]
    assert len(functions) == 1
    context = LaunchContext()
    context.launch_configurations.update({
        'params_file': str(CONFIG), 'use_sim_time': 'true', 'namespace': 'cage2',
        'log_level': 'debug', 'remappings': 'ball:=/mocap/ball, bat_pose:=/mocap/bat'})
    nodes = functions[0].function(context)
    assert len(nodes) == 1 and isinstance(nodes[0], Node)
    node = nodes[0]
    assert node.node_package == 'baseball_collision'
    assert node.node_executable == 'impact_node'
    words = command_line(node, context)
    assert 'ball:=/mocap/ball' in words and 'bat_pose:=/mocap/bat' in words
    assert 'debug' in words and '__ns:=/cage2' in words
    files = [words[i + 1] for i, word in enumerate(words[:-1]) if word == '--params-file']
    assert files[0] == str(CONFIG)
    assert len(files) == 2 and 'use_sim_time: true' in Path(files[1]).read_text()


def test_remappings_are_parsed_or_refused() -> None:
    """FROM:=TO items, comma-separated; an item without := is a ValueError naming it."""
    parse = load_launch_file(LAUNCH_FILE).parse_remappings
    assert parse('') == [] and parse(' /a:=/b ,c:=d,') == [('/a', '/b'), ('c', 'd')]
    with pytest.raises(ValueError, match="'/a' is not FROM:=TO"):
        parse('/a')
